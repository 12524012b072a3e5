"""The local server of `sim --web`: the page, its assets, the state as server-sent events,
and the page's presses, on 127.0.0.1 only (docs/simulator.md, "Scenarios and the live box").

The standard library's threading HTTP server: one thread per connection, the event stream
one of them. It is a tool for the person at this machine, and guards against the others:

- every request carries the session's random token (the printed address holds it, as
  Jupyter's does): in the query, or for the page's POSTs in the X-Mercmac-Token header
  (which a page of another origin cannot send without a preflight this server refuses);
- the Host header must name this address, so that a DNS-rebinding page cannot reach it;
- the page loads nothing from the network and is served with a strict Content-Security-
  Policy: scripts and styles of this server only, no inline script, no eval.
"""
from __future__ import annotations

import hmac
import json
import secrets
import threading
import time
from http import HTTPStatus
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from importlib import resources
from urllib.parse import parse_qs, urlsplit

from mercmac.web.live import Live

# The event stream's period while something moves: on a fixed schedule, a little more often
# than the page's goal of 30 frames a second, so that a late wake-up never drops it below.
FRAME_S = 1 / 32
STILL_S = 0.1  # while only the clock goes on, the clock is sent this often
IDLE_S = 0.25  # and while the simulation is paused
BEAT_S = 15.0  # a comment line this often keeps proxies and the browser from timing out
MAX_BODY = 4096  # a POST of the page is a few dozen bytes
ASSETS = {"app.js": "text/javascript", "style.css": "text/css"}
CSP = ("default-src 'none'; script-src 'self'; style-src 'self'; img-src 'self' data:; "
       "connect-src 'self'; base-uri 'none'; form-action 'none'; frame-ancestors 'self'")


class WebServer(ThreadingHTTPServer):
    """The HTTP server of one live session, on 127.0.0.1."""

    daemon_threads = True  # an open event stream does not keep Ctrl-C waiting

    def __init__(self, live: Live, port: int = 0):
        super().__init__(("127.0.0.1", port), _Handler)
        self.live = live
        self.token = secrets.token_urlsafe(24)
        self.stopping = threading.Event()

    @property
    def port(self) -> int:
        return self.server_address[1]

    @property
    def url(self) -> str:
        return f"http://127.0.0.1:{self.port}/?token={self.token}"

    def hosts(self) -> set[str]:
        """The Host headers that name this server."""
        return {f"127.0.0.1:{self.port}", f"localhost:{self.port}"}

    def shutdown(self) -> None:
        self.stopping.set()
        super().shutdown()


def asset(name: str) -> bytes:
    """A file of the page, as the package ships it (mercmac/web/static)."""
    return resources.files("mercmac.web").joinpath("static", name).read_bytes()


class _Handler(BaseHTTPRequestHandler):
    server: WebServer
    protocol_version = "HTTP/1.1"

    def log_message(self, format: str, *args) -> None:  # the terminal shows the address only
        pass

    # ------------------------------------------------------------ guards
    def _allowed(self) -> bool:
        """The Host names this server and the request carries the token; else answered."""
        if self.headers.get("Host") not in self.server.hosts():
            self._refuse(HTTPStatus.FORBIDDEN, "this server answers to its own address only "
                                               "(the Host header names another)")
            return False
        given = (self.headers.get("X-Mercmac-Token")
                 or parse_qs(urlsplit(self.path).query).get("token", [""])[0])
        if not hmac.compare_digest(given.encode(), self.server.token.encode()):
            self._refuse(HTTPStatus.FORBIDDEN, "the token is missing or wrong: open the "
                                               "address `mercmac sim --web` printed")
            return False
        return True

    def _refuse(self, status: HTTPStatus, why: str) -> None:
        self._send(status, why.encode(), "text/plain; charset=utf-8")

    def _send(self, status: HTTPStatus, body: bytes, kind: str) -> None:
        self.send_response(status)
        self._common(kind)
        self.send_header("Content-Length", str(len(body)))
        self.end_headers()
        self.wfile.write(body)

    def _common(self, kind: str) -> None:
        self.send_header("Content-Type", kind)
        self.send_header("Content-Security-Policy", CSP)
        self.send_header("X-Content-Type-Options", "nosniff")
        self.send_header("Referrer-Policy", "no-referrer")
        self.send_header("Cache-Control", "no-store")

    # ------------------------------------------------------------ GET
    def do_GET(self) -> None:
        if not self._allowed():
            return
        path = urlsplit(self.path).path
        if path == "/":
            page = asset("index.html").decode().replace("{{TOKEN}}", self.server.token)
            self._send(HTTPStatus.OK, page.encode(), "text/html; charset=utf-8")
        elif path.startswith("/static/") and path[len("/static/"):] in ASSETS:
            name = path[len("/static/"):]
            self._send(HTTPStatus.OK, asset(name), f"{ASSETS[name]}; charset=utf-8")
        elif path == "/api/events":
            self._events()
        elif path == "/api/scenario":
            self._send(HTTPStatus.OK, self.server.live.scenario().encode(),
                       "application/toml; charset=utf-8")
        else:
            self._refuse(HTTPStatus.NOT_FOUND, f"no such page: {path}")

    def _events(self) -> None:
        """The state as server-sent events until the page goes or the server stops."""
        self.send_response(HTTPStatus.OK)
        self._common("text/event-stream")
        self.send_header("Connection", "close")
        self.end_headers()
        self.close_connection = True
        live, seen, last, last_clock = self.server.live, (0, 0), None, None
        sent = due = time.monotonic()
        try:
            while not self.server.stopping.is_set():
                live.advance()
                state, seen = live.state(seen)
                clock = state.pop("t_ms")  # compared apart: it alone changes while still
                rest = json.dumps(state, separators=(",", ":"))
                now = time.monotonic()
                if (rest != last or state["log"] or state["path"]
                        or (clock != last_clock and now - sent >= STILL_S)):
                    data = json.dumps({"t_ms": clock, **state}, separators=(",", ":"))
                    self.wfile.write(f"data: {data}\n\n".encode())
                    self.wfile.flush()
                    last, last_clock, sent = rest, clock, now
                elif now - sent > BEAT_S:  # paused: a comment keeps the stream open
                    self.wfile.write(b": still here\n\n")
                    self.wfile.flush()
                    sent = now
                due = max(due + (IDLE_S if live.paused else FRAME_S), now)
                self.server.stopping.wait(due - now)
        except (BrokenPipeError, ConnectionResetError):
            pass  # the page was closed

    # ------------------------------------------------------------ POST
    def do_POST(self) -> None:
        if not self._allowed():
            return
        try:
            length = int(self.headers.get("Content-Length", "0"))
            if not 0 <= length <= MAX_BODY:
                raise ValueError(f"a body of {length} bytes: at most {MAX_BODY}")
            body = json.loads(self.rfile.read(length) or b"{}")
            if not isinstance(body, dict):
                raise ValueError("the body is no JSON object")
            self._act(urlsplit(self.path).path, body)
        except (ValueError, KeyError, TypeError) as e:
            self._refuse(HTTPStatus.BAD_REQUEST, str(e))
            return
        self._send(HTTPStatus.NO_CONTENT, b"", "text/plain; charset=utf-8")

    def _act(self, path: str, body: dict) -> None:
        live = self.server.live
        if path == "/api/press":
            live.press(str(body["controller"]), _int(body["button"]), bool(body["down"]))
        elif path == "/api/power":
            live.power_cycle()
        elif path == "/api/run":
            live.set_paused(bool(body["paused"]))
        elif path == "/api/speed":
            speed = body["speed"]
            live.set_speed(None if speed is None else float(speed))
        elif path == "/api/joystick":
            live.set_joystick(str(body["controller"]), float(body["deflection"]))
        else:
            raise ValueError(f"no such action: {path}")


def _int(value) -> int:
    if isinstance(value, bool) or not isinstance(value, int):
        raise ValueError(f"{value!r} is no button number")
    return value
