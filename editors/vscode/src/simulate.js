// mercmac.simulate ("mercmac: Simulate", and the server's "simulate" lens on `autostart`):
// `mercmac sim FILE --web --no-open` for an .mcm program or a rig file, its page in a webview
// beside the editor. The extension host relays between the two (relay.js), so the webview
// needs no way to 127.0.0.1. One panel per file; closing it stops the process (SIGINT, then
// SIGKILL), as does deactivate; a process that ends by itself is reported once, quoting its
// standard error, and its panel says so. The server follows saves of the file by itself.
"use strict";
const fs = require("fs");
const path = require("path");
const vscode = require("vscode");
const { ServerProcess, descendants } = require("./server");
const { Relay, parseAddress } = require("./relay");
const { pageHtml } = require("./page");
const { INSTALL_HINT, ending } = require("./messages");

const ADDRESS_MS = 30000; // for the address on standard error (check runs first)
const STOP_MS = 3000; // from SIGINT to SIGKILL
const QUOTED = 4; // lines of standard error a message quotes
const ACTIONS = new Set(["/api/press", "/api/power", "/api/run", "/api/speed", "/api/joystick"]);
const SHOW_LOG = "Show Server Log";
const OPEN_SETTINGS = "Open Settings";
const MANAGE_TRUST = "Manage Workspace Trust";
const SIMULABLE = /(\.mcm|\.rig\.toml)$/i;

/** The file's name without .mcm or .rig.toml: "four-modes", "raster". */
function stem(file) {
  return path.basename(file).replace(SIMULABLE, "");
}

/** A path for a command line: quoted when it holds a space or a quote. */
function shellWord(text) {
  return /[\s'"]/.test(text) ? `"${text.replace(/"/g, '\\"')}"` : text;
}

/** The URI the command is for: ARGUMENT (a Uri, a URI string, {uri}) or the active editor's. */
function targetOf(argument) {
  if (argument === undefined || argument === null) {
    const editor = vscode.window.activeTextEditor;
    return editor ? editor.document.uri : undefined;
  }
  if (argument instanceof vscode.Uri) return argument;
  if (typeof argument === "string") {
    return path.isAbsolute(argument) ? vscode.Uri.file(argument) : vscode.Uri.parse(argument);
  }
  if (typeof argument === "object") {
    if (argument.uri !== undefined) return targetOf(argument.uri);
    if (typeof argument.scheme === "string" && typeof argument.fsPath === "string") return argument;
  }
  return undefined;
}

/** What the process last said on standard error, for a message: its last QUOTED lines that
 *  are not a finding's excerpt (indented) nor the address, FILE's path shortened to its name. */
function lastWords(lines, file) {
  const said = lines.map((line) => line.trimEnd())
    .filter((line) => line.trim() && !/^\s/.test(line) && !/the box in the browser:|Ctrl-C stops it/.test(line))
    .map((line) => line.split(file).join(path.basename(file)).replace(/^mercmac: /, ""));
  const quoted = said.slice(-QUOTED).join(" · ");
  return said.length > QUOTED ? `… ${quoted}` : quoted;
}

/** An output channel's stand-in that writes each line of the process's standard error with
 *  PREFIX (so that it reads apart from the language server's). */
function prefixed(channel, prefix) {
  let partial = "";
  return {
    append(text) {
      const lines = (partial + text).split(/\r?\n/);
      partial = lines.pop();
      for (const line of lines) channel.appendLine(prefix + line);
    },
    appendLine(text) {
      channel.appendLine(prefix + text);
    },
    flush() {
      if (partial) channel.appendLine(prefix + partial);
      partial = "";
    },
  };
}

/** One `mercmac sim FILE --web` and its panel. */
class Simulation {
  constructor(owner, file) {
    this.owner = owner;
    this.file = file;
    this.name = path.basename(file);
    this.process = undefined;
    this.relay = undefined;
    this.stream = undefined;
    this.panel = undefined;
    this.listeners = [];
    this.stopping = undefined; // the promise of stop()
    this.ended = false; // the process has exited
    this.ready = undefined; // the promise of start()
  }

  log(text) {
    this.owner.channel.appendLine(`[mercmac] sim ${this.name}: ${text}`);
  }

  /** Spawn it, wait for its address, open the panel; a failure is reported, never thrown. */
  async start() {
    const { command, cwd } = this.owner.mercmac();
    // the pipe of its standard input ends when this editor goes, however it goes: it stops then
    const args = ["sim", this.file, "--web", "--no-open", "--stop-when-stdin-closes"];
    const stderr = prefixed(this.owner.channel, `[sim ${this.name}] `);
    this.log(`starting ${command} ${args.map(shellWord).join(" ")}`);
    const server = new ServerProcess(command, cwd, stderr, args);
    this.process = server;
    server.exited.then((exit) => {
      stderr.flush();
      this.ended = true;
      if (this.relay) this.relay.close();
      this.log(exit ? `stopped (${ending(exit)})` : "not started");
      if (this.panel && !this.stopping) this.stoppedByItself(exit);
    });
    const address = await this.address(server);
    if (this.stopping) return;
    if (!address) {
      await this.failedToStart(server, command, address === null);
      return;
    }
    this.relay = new Relay(address.port, address.token);
    let page;
    try {
      const [index, css, js] = await Promise.all(
        ["/", "/static/style.css", "/static/app.js"].map((p) => this.relay.get(p)));
      page = { index, css, js };
    } catch (error) {
      if (!this.ended) {
        await this.stop();
        this.owner.report(`mercmac: cannot simulate ${this.name}: its page did not load (${error.message}).`);
        return;
      }
    }
    if (this.stopping) return;
    if (this.ended) {
      await this.failedToStart(server, command, false); // it exited meanwhile: it says why
      return;
    }
    if (!page.js.includes("mercmacBridge")) {
      await this.stop();
      this.owner.report(`mercmac: cannot simulate ${this.name} in VS Code: this mercmac's page ` +
        "(mercmac sim --web) cannot run in a webview; upgrade mercmac.");
      return;
    }
    this.log(`running (pid ${server.child.pid}) at http://127.0.0.1:${address.port}/`);
    this.open(page);
  }

  /** {port, token} once it prints its address; undefined if it exits first (or never ran),
   *  null if it says nothing of the kind in ADDRESS_MS. */
  address(server) {
    return new Promise((resolve) => {
      let seen = "";
      const timer = setTimeout(() => done(null), ADDRESS_MS);
      const look = (text) => {
        seen += text;
        const complete = seen.slice(0, seen.lastIndexOf("\n") + 1);
        const found = parseAddress(complete);
        if (found) done(found);
      };
      const done = (value) => {
        clearTimeout(timer);
        server.child.stderr.off("data", look);
        resolve(value);
      };
      server.child.stderr.on("data", look);
      server.exited.then(() => done(undefined));
    });
  }

  async failedToStart(server, command, late) {
    const error = await server.spawned.then(() => undefined, (e) => e);
    const code = error && error.code;
    if (code === "ENOENT" || code === "EACCES") {
      const what = code === "ENOENT" ? "was not found" : "is not executable";
      this.owner.report(`mercmac: cannot simulate ${this.name}: '${command}' ${what}. ${INSTALL_HINT}`,
        OPEN_SETTINGS);
      return;
    }
    if (error) {
      this.owner.report(`mercmac: cannot simulate ${this.name}: ${error.message}`);
      return;
    }
    if (late) {
      this.log(`no address on its standard error in ${ADDRESS_MS / 1000} s: stopping it`);
      await this.stop();
    }
    const exit = await server.exited;
    const said = lastWords(server.stderr(), this.file);
    const how = late ? `it gave no address in ${ADDRESS_MS / 1000} s` : ending(exit);
    this.owner.report(`mercmac: cannot simulate ${this.name} (${how})` +
      (said ? `: ${said}` : "; see the server log."));
  }

  /** The panel beside the editor, the page in it. */
  open(page) {
    const panel = vscode.window.createWebviewPanel("mercmac.simulate", `Simulate ${this.name}`,
      { viewColumn: vscode.ViewColumn.Beside, preserveFocus: true },
      { enableScripts: true, retainContextWhenHidden: true, localResourceRoots: [] });
    if (this.owner.icon) panel.iconPath = this.owner.icon;
    this.panel = panel;
    this.listeners.push(
      panel.webview.onDidReceiveMessage((message) => this.received(message)),
      panel.onDidDispose(() => {
        this.panel = undefined;
        this.owner.forget(this);
        void this.stop();
      }),
    );
    panel.webview.html = pageHtml({ ...page, cspSource: panel.webview.cspSource });
  }

  reveal() {
    if (this.panel) this.panel.reveal(undefined, true);
  }

  /** Tell the page (nothing once the panel is gone). */
  tell(message) {
    if (!this.panel) return;
    try {
      Promise.resolve(this.panel.webview.postMessage(message)).catch(() => undefined);
    } catch {
      // disposed meanwhile
    }
  }

  /** A message of the page's bridge (bridge.js). */
  async received(message) {
    if (!message || typeof message !== "object") return;
    if (message.type === "events") {
      this.relayEvents();
    } else if (message.type === "post" || message.type === "saveScenario") {
      const reply = { type: "reply", id: message.id };
      try {
        if (message.type === "post") {
          await this.post(message.path, message.body);
        } else {
          reply.value = await this.saveScenario();
        }
      } catch (error) {
        reply.error = String((error && error.message) || error);
      }
      this.tell(reply);
    }
  }

  post(where, body) {
    if (!ACTIONS.has(where)) throw new Error(`${where}: not an action of the page`);
    if (this.ended || !this.relay) throw new Error(`${where}: the simulation has stopped`);
    return this.relay.post(where, body && typeof body === "object" ? body : {});
  }

  /** The event stream to the page (again, when the page asks again: a reload). */
  relayEvents() {
    if (this.stream) this.stream.close();
    if (!this.relay) return;
    this.stream = this.relay.events({
      open: () => this.tell({ type: "open" }),
      message: (data) => this.tell({ type: "event", data }),
      error: (closed) => this.tell({ type: "error", closed }),
    });
  }

  /** The session as a scenario file, where the person says: the note the page shows. */
  async saveScenario() {
    if (this.ended || !this.relay) throw new Error("the simulation has stopped");
    const text = await this.relay.get("/api/scenario");
    const folder = path.dirname(this.file);
    const target = await vscode.window.showSaveDialog({
      defaultUri: vscode.Uri.file(path.join(folder, `${stem(this.file)}.scenario.toml`)),
      filters: { "mercmac scenario": ["toml"] },
      saveLabel: "Save Scenario",
      title: `Save this session of ${this.name} as a scenario`,
    });
    if (!target) return null;
    await vscode.workspace.fs.writeFile(target, Buffer.from(text, "utf8"));
    const where = target.scheme === "file" ? path.relative(folder, target.fsPath) : target.toString();
    this.log(`the session saved as a scenario: ${target.scheme === "file" ? target.fsPath : where}`);
    return `Saved ${where} (replay with mercmac sim ${shellWord(this.name)} --scenario ${shellWord(where)})`;
  }

  /** It ended without being asked: one message, and the panel says so. */
  stoppedByItself(exit) {
    const said = lastWords(this.process.stderr(), this.file);
    const text = `the simulation of ${this.name} stopped (${ending(exit)})` + (said ? `: ${said}` : "");
    if (this.panel) {
      this.panel.title = `Simulate ${this.name} (stopped)`;
      this.tell({ type: "stopped", text: said ? `${ending(exit)}: ${said}` : ending(exit) });
    }
    this.owner.report(`mercmac: ${text}${said ? "" : "; see the server log."}`);
  }

  /** End the process and any below it (a wrapper script's): SIGINT (it exits 130), SIGKILL
   *  after STOP_MS. Once; awaited to its end. The process stays in the extension host's
   *  process group, so that a signal to the whole editor reaches it too. */
  stop() {
    if (!this.stopping) {
      this.stopping = this.end();
    }
    return this.stopping;
  }

  async end() {
    if (this.stream) this.stream.close();
    if (this.relay) this.relay.close();
    const server = this.process;
    if (!server) return;
    const below = server.child.pid ? descendants(server.child.pid) : [];
    if (server.signal("SIGINT", below) && await server.ended(STOP_MS) === undefined) {
      this.log(`still running ${STOP_MS / 1000} s after SIGINT: killing it`);
      server.signal("SIGKILL", below);
    }
    await server.ended(STOP_MS);
  }

  /** Close the panel and stop the process. */
  dispose() {
    const stopped = this.stop();
    for (const listener of this.listeners.splice(0)) listener.dispose();
    if (this.panel) {
      const panel = this.panel;
      this.panel = undefined;
      panel.dispose();
    }
    return stopped;
  }
}

/** The simulations of the extension's life, one per file. */
class Simulations {
  /** CHANNEL: the extension's log; MERCMAC() gives {command, cwd} as the language server's;
   *  ICON: the panels' icon (a Uri), if any. */
  constructor(channel, mercmac, icon) {
    this.channel = channel;
    this.mercmac = mercmac;
    this.icon = icon;
    this.byFile = new Map();
    this.disposed = false;
  }

  /** The command: ARGUMENT as targetOf takes it. */
  async run(argument) {
    if (this.disposed) return;
    const uri = targetOf(argument);
    const file = await this.checked(uri);
    if (!file) return;
    const existing = this.byFile.get(file);
    if (existing && !existing.ended && !existing.stopping) {
      await existing.ready;
      existing.reveal();
      return;
    }
    if (existing) {
      this.forget(existing);
      void existing.dispose();
    }
    const simulation = new Simulation(this, file);
    this.byFile.set(file, simulation);
    simulation.ready = simulation.start();
    vscode.window.setStatusBarMessage(`mercmac: starting the simulation of ${simulation.name}…`, simulation.ready);
    await simulation.ready;
    if (!simulation.panel) this.forget(simulation);
  }

  /** The file on disk that URI names, saved; else undefined, the reason said. */
  async checked(uri) {
    const refuse = (text, ...items) => {
      void vscode.window.showErrorMessage(text, ...items).then((choice) => {
        if (choice === MANAGE_TRUST) return vscode.commands.executeCommand("workbench.trust.manage");
        return undefined;
      });
      return undefined;
    };
    if (!uri) {
      return refuse("mercmac: Simulate runs an .mcm program or a rig file (*.rig.toml): open one first.");
    }
    const name = path.basename(uri.path || uri.fsPath || String(uri));
    if (uri.scheme === "untitled") {
      return refuse(`mercmac: save ${name} first: Simulate runs a file on disk.`);
    }
    if (uri.scheme !== "file") {
      return refuse(`mercmac: Simulate runs files on disk; ${uri.toString()} is not one.`);
    }
    if (!SIMULABLE.test(uri.fsPath)) {
      return refuse(`mercmac: Simulate runs .mcm programs and rig files (*.rig.toml), not ${name}.`);
    }
    if (!vscode.workspace.isTrusted) {
      return refuse("mercmac: Simulate runs the mercmac executable, which Restricted Mode does not " +
        "allow: trust the workspace first.", MANAGE_TRUST);
    }
    const document = (vscode.workspace.textDocuments || []).find((d) => d.uri.toString() === uri.toString());
    if (document && document.isDirty && !(await document.save())) {
      return refuse(`mercmac: ${name} could not be saved; Simulate runs the file as saved.`);
    }
    try {
      if (!fs.statSync(uri.fsPath).isFile()) throw new Error("not a file");
    } catch {
      return refuse(`mercmac: ${uri.fsPath} is not a file on disk.`);
    }
    return uri.fsPath;
  }

  forget(simulation) {
    if (this.byFile.get(simulation.file) === simulation) this.byFile.delete(simulation.file);
  }

  /** One error message, with the button that helps. */
  report(text, action = SHOW_LOG) {
    this.channel.appendLine(text);
    void vscode.window.showErrorMessage(text, action).then((choice) => {
      if (choice === SHOW_LOG) {
        this.channel.show(true);
      } else if (choice === OPEN_SETTINGS) {
        return vscode.commands.executeCommand("workbench.action.openSettings", "mercmac.path");
      }
      return undefined;
    });
  }

  /** What runs (for the tests): [{file, pid, running}]. */
  list() {
    return [...this.byFile.values()].map((s) => ({ file: s.file, pid: s.process && s.process.child.pid,
      running: Boolean(s.panel) && !s.ended, title: s.panel && s.panel.title }));
  }

  /** Stop every simulation and close its panel (deactivate). */
  dispose() {
    this.disposed = true;
    const all = [...this.byFile.values()];
    this.byFile.clear();
    return Promise.all(all.map((s) => s.dispose())).then(() => undefined);
  }
}

module.exports = { Simulations, targetOf, lastWords, stem };
