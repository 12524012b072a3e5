// `mercmac sim FILE --web --no-open` for the tests without Python (test/fake-mercmac.js runs
// it): a small HTTP server that answers as mercmac/web/server.py does (the token, the Host
// header, the page and its two files, the event stream, the actions, the scenario) and says
// its address on standard error. FAKE_MERCMAC_MODE makes it misbehave:
//   sim-errors  the file "has errors": findings on stderr, exit 1, no address
//   sim-crash   POST /api/power makes it exit 1, a traceback on stderr
//   sim-deaf    it ignores SIGINT (so that it has to be killed)
// `node --test test/` runs every .js file here as a test file: required by no test, it does
// nothing.
"use strict";
const crypto = require("node:crypto");
const fs = require("node:fs");
const http = require("node:http");
const path = require("node:path");

// the page as mercmac ships it (its link and script tags are what the webview rewrites); an
// app.js and a style.css with texts that a careless inlining would break (a closing script
// tag, replacement patterns)
const INDEX = fs.readFileSync(path.join(__dirname, "..", "..", "..", "mercmac", "web", "static",
  "index.html"), "utf8");
const APP_JS = `"use strict";
// fake app.js: uses window.mercmacBridge; "$&" and "$'" and "</script>" must arrive as written
window.fakeApp = { bridge: Boolean(window.mercmacBridge), text: "$& $' </script>" };
`;
const STYLE_CSS = "body { margin: 0; } /* $& */\n";
const BUTTONS = [1, 2, 3, 4];

function simulate(args, mode) {
  const file = args.find((a) => !a.startsWith("--"));
  if (!file || !fs.existsSync(file)) {
    process.stderr.write(`mercmac: cannot read ${file}: No such file or directory\n`);
    process.exit(2);
  }
  if (mode === "sim-errors") {
    process.stderr.write(`${file}:2:3: error[MM002 unknown-command]: unknown command 'XM'; did you mean XF or XN?\n` +
      "    2 |   XM 1\n          ^~\n1 error, 0 warnings, 0 infos in 1 file.\n", () => process.exit(1));
    return;
  }
  const token = crypto.randomBytes(18).toString("base64url");
  const state = { t: 0, buttons: [false, false, false, false], presses: [] };
  const streams = new Set();
  const server = http.createServer((request, response) => {
    const url = new URL(request.url, "http://x");
    const send = (status, body, type = "text/plain; charset=utf-8") => {
      response.writeHead(status, { "Content-Type": type, "Content-Length": Buffer.byteLength(body) });
      response.end(body);
    };
    const port = server.address().port;
    if (![`127.0.0.1:${port}`, `localhost:${port}`].includes(request.headers.host)) {
      send(403, "this server answers to its own address only (the Host header names another)");
      return;
    }
    if ((request.headers["x-mercmac-token"] || url.searchParams.get("token")) !== token) {
      send(403, "the token is missing or wrong");
      return;
    }
    if (request.method === "GET") {
      if (url.pathname === "/") send(200, INDEX.replace(/\{\{TOKEN\}\}/g, token), "text/html; charset=utf-8");
      else if (url.pathname === "/static/app.js") send(200, APP_JS, "text/javascript; charset=utf-8");
      else if (url.pathname === "/static/style.css") send(200, STYLE_CSS, "text/css; charset=utf-8");
      else if (url.pathname === "/api/scenario") send(200, `# fake\nuntil = "${state.t}ms"\n`, "application/toml");
      else if (url.pathname === "/api/events") {
        response.writeHead(200, { "Content-Type": "text/event-stream", Connection: "close" });
        response.write(": still here\n\n");
        streams.add(response);
        response.on("close", () => streams.delete(response));
      } else send(404, `no such page: ${url.pathname}`);
      return;
    }
    let body = "";
    request.on("data", (chunk) => (body += chunk));
    request.on("end", () => {
      let data;
      try {
        data = JSON.parse(body || "{}");
      } catch (error) {
        send(400, String(error.message));
        return;
      }
      if (url.pathname === "/api/press") {
        if (!BUTTONS.includes(data.button)) {
          send(400, `no button ${data.button} on a controller '${data.controller}'`);
          return;
        }
        state.buttons[data.button - 1] = Boolean(data.down);
        state.presses.push(data.button);
      } else if (url.pathname === "/api/power" && mode === "sim-crash") {
        process.stderr.write("Traceback (most recent call last):\n  File \"live.py\", line 1, in power_cycle\n" +
          "RuntimeError: fake mercmac: boom\n", () => process.exit(1));
        return;
      } else if (!["/api/power", "/api/run", "/api/speed", "/api/joystick"].includes(url.pathname)) {
        send(400, `no such action: ${url.pathname}`);
        return;
      }
      response.writeHead(204);
      response.end();
    });
  });
  const timer = setInterval(() => {
    state.t += 33;
    const data = JSON.stringify({ t_ms: state.t, file: path.basename(file),
      controllers: [{ name: "fake", buttons: state.buttons, position: state.presses.length }], lines: [] });
    // split in two writes, as a network may: the relay must join them
    for (const stream of streams) {
      stream.write(`data: ${data.slice(0, 10)}`);
      stream.write(`${data.slice(10)}\n\n`);
    }
  }, 33);
  process.on("SIGINT", () => {
    if (mode === "sim-deaf") return;
    clearInterval(timer);
    process.stderr.write("mercmac: interrupted\n", () => process.exit(130));
  });
  server.listen(0, "127.0.0.1", () => {
    const url = `http://127.0.0.1:${server.address().port}/?token=${token}`;
    process.stderr.write(`mercmac: the box in the browser: ${url}\nmercmac: Ctrl-C stops it; open the address above in a browser\n`);
  });
}

module.exports = { simulate };
