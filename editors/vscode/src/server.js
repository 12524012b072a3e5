// The server process, spawned by us rather than by vscode-languageclient: so that we keep
// the last lines of its standard error (the reason it stopped, quoted in our one message)
// and know when it has ended, all its output read. `mercmac sim --web` (simulate.js) is run
// the same way.
"use strict";
const childProcess = require("child_process");
const fs = require("fs");
const path = require("path");
const { Writable } = require("stream");

const TAIL = 20; // lines of standard error kept for the failure message

/** COMMAND as a full path: itself when it names a file (relative ones from CWD), else the
 *  executable file of that name on PATH (with PATHEXT on Windows); undefined if none. */
function locate(command, cwd) {
  const windows = process.platform === "win32";
  const endings = windows ? ["", ...(process.env.PATHEXT || ".EXE;.CMD;.BAT").split(";")] : [""];
  const named = command.includes("/") || (windows && command.includes("\\"));
  const folders = named ? [cwd || process.cwd()] : (process.env.PATH || "").split(path.delimiter);
  for (const folder of folders) {
    for (const ending of endings) {
      const candidate = path.resolve(folder, command + ending);
      try {
        fs.accessSync(candidate, windows ? fs.constants.F_OK : fs.constants.X_OK);
        if (fs.statSync(candidate).isFile()) {
          return candidate;
        }
      } catch {
        // not this one
      }
    }
  }
  return undefined;
}

/**
 * What the client writes to the server's standard input. A server that has exited (mercmac
 * without the lsp extra exits before reading anything) makes every write fail, and
 * vscode-jsonrpc 8 turns a failed request write into an unhandled rejection ("Cannot call
 * write after a stream was destroyed") besides failing the request. Here a write to a
 * server that is gone is dropped (and logged): the end of its output is what closes the
 * connection, and that is reported with the server's reason (Session.closed).
 */
class ServerInput extends Writable {
  constructor(stdin, log) {
    super();
    this.stdin = stdin;
    this.log = log;
    this.dropped = false;
    stdin.on("error", (error) => this.drop(error)); // EPIPE: it has exited
  }

  drop(error) {
    if (!this.dropped) {
      this.dropped = true;
      this.log.appendLine(`[mercmac] the server's input is closed (${error ? error.message : "it exited"}): ` +
        "messages to it are dropped");
    }
  }

  _write(chunk, encoding, callback) {
    if (this.stdin.destroyed || this.stdin.writableEnded) {
      this.drop();
      callback();
      return;
    }
    this.stdin.write(chunk, (error) => {
      if (error) {
        this.drop(error);
      }
      callback();
    });
  }

  _final(callback) {
    if (!this.stdin.destroyed) {
      this.stdin.end();
    }
    callback();
  }
}

/** The processes below PID (their ids), from /proc where there is one (Linux); else none. */
function descendants(pid) {
  let entries;
  try {
    entries = fs.readdirSync("/proc").filter((entry) => /^\d+$/.test(entry));
  } catch {
    return [];
  }
  const children = new Map();
  for (const entry of entries) {
    try {
      const stat = fs.readFileSync(`/proc/${entry}/stat`, "utf8");
      const parent = Number(stat.slice(stat.lastIndexOf(")") + 2).split(" ")[1]);
      if (!children.has(parent)) children.set(parent, []);
      children.get(parent).push(Number(entry));
    } catch {
      // gone meanwhile
    }
  }
  const found = [];
  const walk = (parent) => (children.get(parent) || []).forEach((child) => {
    found.push(child);
    walk(child);
  });
  walk(pid);
  return found;
}

/** One run of `COMMAND lsp --stdio` (or COMMAND ARGS) in CWD; its standard error goes to LOG
 *  as it comes. */
class ServerProcess {
  constructor(command, cwd, log, args = ["lsp", "--stdio"]) {
    this.command = command;
    this.lines = [];
    this.partial = "";
    this.initialized = false; // set by Session when the client reaches Running
    this.child = childProcess.spawn(command, args, { cwd, stdio: "pipe" });
    // `spawn` fails asynchronously (ENOENT, EACCES): an 'error' event instead of 'spawn'
    this.spawned = new Promise((resolve, reject) => {
      this.child.once("spawn", resolve);
      this.child.once("error", reject);
    });
    this.spawned.catch(() => undefined);
    // a later 'error' (a failed kill) must not be an unhandled event in the extension host
    this.child.on("error", (error) => log.appendLine(`[mercmac] ${command}: ${error.message}`));
    // 'close' comes after 'exit' once stdout and stderr are drained: the whole reason is in
    this.exited = new Promise((resolve) => {
      this.child.once("close", (code, signal) => resolve({ code, signal }));
      this.child.once("error", () => resolve(undefined));
    });
    this.input = new ServerInput(this.child.stdin, log);
    this.child.stderr.setEncoding("utf8");
    this.child.stderr.on("data", (text) => {
      log.append(text);
      const lines = (this.partial + text).split(/\r?\n/);
      this.partial = lines.pop();
      this.lines.push(...lines);
      this.lines.splice(0, Math.max(0, this.lines.length - TAIL));
    });
  }

  /** The last lines it wrote on standard error. */
  stderr() {
    return this.partial ? [...this.lines, this.partial] : [...this.lines];
  }

  /** How it ended ({code, signal}), or undefined if it has not within MS milliseconds. */
  ended(ms) {
    let timer;
    const late = new Promise((resolve) => (timer = setTimeout(resolve, ms, undefined)));
    return Promise.race([this.exited, late]).finally(() => clearTimeout(timer));
  }

  /** Send SIGNAL to it and to OTHERS (process ids: its descendants, say, so that a
   *  mercmac.path that is a shell script running Python without exec leaves nothing
   *  behind); false if it has ended. */
  signal(signal, others = []) {
    if (this.child.exitCode !== null || this.child.signalCode !== null || !this.child.pid) {
      return false;
    }
    for (const pid of others) {
      try {
        process.kill(pid, signal);
      } catch {
        // gone
      }
    }
    return this.child.kill(signal);
  }

  /** End it if the shutdown request and exit notification did not (a server stuck, or one
   *  that never got them because the client was not running). */
  async stop(ms = 2000) {
    if (await this.ended(ms) === undefined && this.child.exitCode === null) {
      this.child.kill();
    }
  }
}

module.exports = { ServerProcess, locate, descendants };
