// One language client and the server processes it talks to, from start to dispose.
//
// vscode-languageclient's own handling of a server that will not run is six notifications
// that never say why ("Pending response rejected...", "couldn't create connection...",
// "crashed 5 times...") and a restart loop for a server that exits before answering
// `initialize`. Here a session reports a failure once, quoting the server's standard error
// (Session.fail), restarts only a server that had been running, and leaves the library's
// forced notifications to the log.
"use strict";
const { LanguageClient, State, CloseAction, ErrorAction } = require("vscode-languageclient/node");
const { ServerProcess, locate } = require("./server");
const { describeFailure } = require("./messages");

const MAX_RESTARTS = 4; // of a server that was running: as the library's default handler,
const RESTART_WINDOW_MS = 3 * 60 * 1000; // 4 restarts in 3 minutes, the 5th crash is final

function clientOptions(extra = {}) {
  return {
    documentSelector: [
      { scheme: "file", language: "mcm" },
      { scheme: "untitled", language: "mcm" },
      // rig files (several controllers on one link): TOML, whatever language an editor
      // gives them, so matched by name; the server checks them as `mercmac check RIG` does
      { scheme: "file", pattern: "**/*.rig.toml" },
    ],
    // the server asks for the `mercmac` section (target, select, ignore) through
    // workspace/configuration and is told of changes to it
    synchronize: { configurationSection: "mercmac" },
    ...extra,
  };
}

class MercmacClient extends LanguageClient {
  /** The library forces a notification for each lifecycle failure; Session reports those
   *  itself, once, so they only go to the log. So do the errors of a client that is not
   *  running: a notification that a client being replaced could not send (the settings
   *  change that restarts it) is no news. Other errors (a failed request) are shown as the
   *  library decides. */
  error(message, data, showNotification) {
    const show = showNotification !== "force" && this.state === State.Running && showNotification;
    super.error(message, data, show);
  }

  /** When the server's output closes before it answered `initialize`, vscode-languageclient
   *  9.0.1's close handler forgets the start promise (`_onStart`) before start() returns it:
   *  start() resolves, and that promise's rejection is unhandled. It is marked handled here;
   *  Session learns of the failure from its closed() handler. */
  start() {
    const started = super.start();
    const pending = this._onStart;
    if (pending && typeof pending.catch === "function") {
      pending.catch(() => undefined);
    }
    return started;
  }

  /** The library stops a client whose `initialize` failed although it never ran, which
   *  rejects ("Client is not running and can't be stopped") with nobody to catch it; and a
   *  stop that times out is left to ServerProcess.stop. Either is only logged. */
  stop(timeout) {
    return super.stop(timeout).catch((error) => {
      this.outputChannel.appendLine(`[mercmac] stopping the client: ${error.message}`);
    });
  }
}

class Session {
  /** A client for `COMMAND lsp --stdio` run in CWD, logging to CHANNEL; EVENTS are told
   *  starting(session), running(session) and failed(session, {kind, text}). */
  constructor(command, cwd, channel, events) {
    this.command = command;
    this.cwd = cwd;
    this.channel = channel;
    this.events = events;
    this.process = undefined; // the latest ServerProcess
    this.restarts = []; // when the library restarted a crashed server
    this.failure = undefined; // the promise of the one report
    this.disposed = false;
    this.client = new MercmacClient("mercmac", "mercmac", () => this.spawn(), clientOptions({
      outputChannel: channel,
      traceOutputChannel: channel,
      errorHandler: {
        error: (error, message, count) => this.errored(error, count),
        closed: () => this.closed(),
      },
      // false: do not retry; the rejection of start() is then reported by Session.start
      initializationFailedHandler: (error) => {
        channel.appendLine(`[mercmac] initialize failed: ${(error && error.message) || error}`);
        return false;
      },
    }));
    this.client.onDidChangeState(({ newState }) => {
      if (newState === State.Running && this.process) {
        this.process.initialized = true;
        events.running(this);
      } else if (newState === State.Starting) {
        events.starting(this);
      }
    });
  }

  /** The ServerOptions function: the client's transport is our process's stdin/stdout. */
  async spawn() {
    const server = new ServerProcess(this.command, this.cwd, this.channel);
    this.process = server;
    await server.spawned;
    return { reader: server.child.stdout, writer: server.input, detached: false };
  }

  /** Start the client; a failure is reported, never thrown. True if it runs. */
  async start() {
    try {
      await this.client.start();
    } catch (error) {
      await this.fail(error);
      return false;
    }
    if (this.failure) {
      await this.failure; // closed() saw it exit before answering `initialize`
      return false;
    }
    return this.client.isRunning();
  }

  /** Whether the client runs (the server answered `initialize` and is still there). */
  running() {
    return !this.disposed && this.client.isRunning();
  }

  /** The mercmac version the server gave in its `initialize` answer. */
  version() {
    const info = this.client.initializeResult && this.client.initializeResult.serverInfo;
    return info && info.version;
  }

  /** Where the executable is, for the status item and Show Version. */
  where() {
    return locate(this.command, this.cwd) || this.command;
  }

  /** A write to or read from the server failed. A server that exited is the closed()
   *  handler's to judge; one that keeps erroring is shut down, and that is reported. */
  errored(error, count) {
    if (count !== undefined && count > 3) {
      void this.fail(error);
      return { action: ErrorAction.Shutdown, handled: true };
    }
    return { action: ErrorAction.Continue, handled: true };
  }

  /** The server's output closed: it exited. Restart it only if it had been running, and
   *  not more than MAX_RESTARTS times in RESTART_WINDOW_MS. */
  closed() {
    const server = this.process;
    if (this.disposed) {
      return { action: CloseAction.DoNotRestart, handled: true };
    }
    if (!server || !server.initialized) {
      void this.fail(undefined);
      return { action: CloseAction.DoNotRestart, handled: true,
        message: "[mercmac] the server exited before it answered initialize: not restarting it" };
    }
    const now = Date.now();
    this.restarts = this.restarts.filter((then) => now - then < RESTART_WINDOW_MS);
    if (this.restarts.length >= MAX_RESTARTS) {
      void this.fail(undefined, true);
      return { action: CloseAction.DoNotRestart, handled: true,
        message: "[mercmac] the server stopped too often: not restarting it" };
    }
    this.restarts.push(now);
    return { action: CloseAction.Restart, handled: true,
      message: `[mercmac] the server stopped: restarting it (${this.restarts.length} of ${MAX_RESTARTS})` };
  }

  /** Report why the server is not running, once per session: wait for the process to end
   *  (all its standard error read) or end it, then tell events.failed. */
  fail(error, crashed = false) {
    if (!this.failure) {
      this.failure = this.report(error, crashed);
    }
    return this.failure;
  }

  async report(error, crashed) {
    const server = this.process;
    const exit = server ? await server.ended(2000) : undefined;
    if (server && exit === undefined) {
      server.child.kill(); // it answered `initialize` with an error, or never at all
    }
    if (this.disposed) {
      return undefined;
    }
    const failure = describeFailure({ command: this.command, error, crashed, exit,
      stderr: server ? server.stderr() : [], restarts: this.restarts.length });
    this.channel.appendLine(failure.text);
    this.events.failed(this, failure);
    return failure;
  }

  /** Stop the client for good (vscode-languageclient 9: dispose) and its process. */
  async dispose() {
    this.disposed = true;
    const server = this.process;
    await this.client.dispose(2000);
    if (server) {
      await server.stop(1000);
    }
  }
}

module.exports = { Session, clientOptions };
