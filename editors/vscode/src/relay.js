// HTTP to the local server of `mercmac sim --web`, from the extension host: the webview may
// not reach 127.0.0.1 itself (a remote window, code-server), so the extension fetches the
// page and relays the page's actions and the event stream (mercmac/web/server.py says what
// the server answers). Every request carries the session's token and names the server in
// its Host header, as the server requires.
"use strict";
const http = require("http");

const RETRY_MS = 1000; // between the end of the event stream and the next try
const TIMEOUT_MS = 10000; // for the page's files and the actions (not the stream)

/** The address `mercmac sim --web` prints on standard error: {url, port, token}, or undefined. */
function parseAddress(line) {
  const found = /(http:\/\/(?:127\.0\.0\.1|localhost):(\d+)\/\?token=([\w-]+))/.exec(line);
  return found ? { url: found[1], port: Number(found[2]), token: found[3] } : undefined;
}

/** Server-sent events, fed in chunks: calls ON_DATA with each event's data (its `data:`
 *  lines joined by newlines); comment lines (`: still here`) and other fields are skipped. */
class EventParser {
  constructor(onData) {
    this.onData = onData;
    this.partial = "";
    this.data = [];
  }

  feed(text) {
    const lines = (this.partial + text).split("\n");
    this.partial = lines.pop();
    for (const raw of lines) {
      const line = raw.endsWith("\r") ? raw.slice(0, -1) : raw;
      if (line === "") {
        if (this.data.length) {
          const data = this.data.join("\n");
          this.data = [];
          this.onData(data);
        }
      } else if (line.startsWith("data:")) {
        this.data.push(line.slice(line.startsWith("data: ") ? 6 : 5));
      }
    }
  }
}

class Relay {
  /** The server on 127.0.0.1:PORT whose token is TOKEN. */
  constructor(port, token) {
    this.port = port;
    this.token = token;
    this.closed = false;
    this.streams = new Set();
  }

  /** {status, text} of METHOD PATH with BODY (an object sent as JSON). */
  request(method, path, body) {
    const payload = body === undefined ? undefined : Buffer.from(JSON.stringify(body), "utf8");
    return new Promise((resolve, reject) => {
      const request = http.request({
        host: "127.0.0.1", port: this.port, method, path, timeout: TIMEOUT_MS,
        headers: { ...this.headers(),
          ...(payload ? { "Content-Type": "application/json", "Content-Length": payload.length } : {}) },
      }, (response) => {
        const chunks = [];
        response.on("data", (chunk) => chunks.push(chunk));
        response.on("end", () => resolve({ status: response.statusCode,
          text: Buffer.concat(chunks).toString("utf8") }));
        response.on("error", reject);
      });
      request.on("timeout", () => request.destroy(new Error(`no answer in ${TIMEOUT_MS / 1000} s`)));
      request.on("error", (error) => reject(new Error(`${path}: ${error.message}`)));
      request.end(payload);
    });
  }

  headers() {
    return { Host: `127.0.0.1:${this.port}`, "X-Mercmac-Token": this.token };
  }

  /** The text of GET PATH; an answer other than 200 throws, saying why. */
  async get(path) {
    const { status, text } = await this.request("GET", path);
    if (status !== 200) {
      throw new Error(`${path}: ${status} ${text.trim()}`.trim());
    }
    return text;
  }

  /** POST BODY to PATH (an action: 204); an answer other than 2xx throws with the server's
   *  reason, as the page's own fetch does: "/api/press: 400 no button 9 on ...". */
  async post(path, body) {
    const { status, text } = await this.request("POST", path, body);
    if (status < 200 || status > 299) {
      throw new Error(`${path}: ${status} ${text.trim()}`.trim());
    }
  }

  /**
   * The event stream, to HANDLERS {open(), message(data), error(closed)} as the page's
   * EventSource would: open when the stream answers, message with each event's data,
   * error(false) when it ends and is tried again, error(true) once the relay is closed.
   * Returns {close()}, which ends it without a word.
   */
  events(handlers) {
    const stream = { closed: false, request: undefined, timer: undefined, handlers };
    stream.close = () => {
      stream.closed = true;
      clearTimeout(stream.timer);
      if (stream.request) stream.request.destroy();
      this.streams.delete(stream);
    };
    const ended = () => {
      stream.request = undefined;
      if (stream.closed) return;
      if (this.closed) {
        stream.close();
        handlers.error(true);
        return;
      }
      handlers.error(false);
      stream.timer = setTimeout(connect, RETRY_MS);
    };
    const connect = () => {
      if (stream.closed) return;
      let done = false; // 'end' and 'close' both come for one request: the first counts
      const finish = () => {
        if (!done) {
          done = true;
          ended();
        }
      };
      const parser = new EventParser((data) => !stream.closed && handlers.message(data));
      const request = http.get({ host: "127.0.0.1", port: this.port, path: "/api/events",
        headers: { ...this.headers(), Accept: "text/event-stream" } }, (response) => {
        if (response.statusCode === 200 && !stream.closed) {
          handlers.open();
          response.setEncoding("utf8");
          response.on("data", (text) => parser.feed(text));
        } else {
          response.resume();
        }
        response.on("end", finish);
        response.on("error", () => undefined); // 'close' follows
      });
      request.on("error", () => undefined); // refused, reset: 'close' follows
      request.on("close", finish);
      stream.request = request;
    };
    this.streams.add(stream);
    if (this.closed) {
      ended();
    } else {
      connect();
    }
    return stream;
  }

  /** The server is gone: streams say error(true), no request is tried again. */
  close() {
    this.closed = true;
    for (const stream of [...this.streams]) {
      clearTimeout(stream.timer);
      if (stream.request) {
        stream.request.destroy(); // its 'close' reports error(true)
      } else {
        stream.close();
        stream.handlers.error(true);
      }
    }
  }
}

module.exports = { Relay, EventParser, parseAddress };
