// The client: VS Code starts `mercmac lsp --stdio` (the language server over stdio) for .mcm
// documents and rig files (*.rig.toml), once the workspace is trusted.
// Bundled by esbuild into dist/extension.js (`npm run build`), which is what the .vsix holds.
//   session.js   one client and its server processes; failures reported once
//   server.js    the server process (spawned here, to keep its standard error)
//   status.js    the language status item
//   messages.js  what a failure says
//   commands.js  copyBuild (the code lens's command), --version
//   simulate.js  mercmac.simulate: `mercmac sim FILE --web` in a webview (relay.js, page.js,
//                bridge.js)
"use strict";
const vscode = require("vscode");
const { Session, clientOptions } = require("./session");
const { Status } = require("./status");
const { describeFailure, INSTALL_HINT } = require("./messages");
const { copyBuild, askVersion } = require("./commands");
const { locate } = require("./server");
const { Simulations } = require("./simulate");

// For the extension's life (activate to deactivate): one log channel, whatever the number
// of restarts; the status item; the current session.
let channel;
let status;
let session;
let simulations; // the panels of mercmac.simulate and their processes
let queue = Promise.resolve(); // see enqueue
let active = false;

/** The executable the `mercmac.path` setting names ("mercmac" on PATH by default). */
function executable() {
  return vscode.workspace.getConfiguration("mercmac").get("path") || "mercmac";
}

/** The first workspace folder on disk: the server's working directory, and where a relative
 *  mercmac.path (.venv/bin/mercmac) is found. */
function folder() {
  const first = (vscode.workspace.workspaceFolders || [])[0];
  return first && first.uri && first.uri.scheme === "file" ? first.uri.fsPath : undefined;
}

/** One error notification, with the buttons that fix it. */
async function showFailure(failure) {
  const missing = failure.kind === "not-found" || failure.kind === "not-executable";
  const actions = missing ? ["Open Settings", "Restart Server"] : ["Show Server Log", "Open Settings"];
  const choice = await vscode.window.showErrorMessage(failure.text, ...actions);
  if (choice === "Open Settings") {
    await vscode.commands.executeCommand("workbench.action.openSettings", "mercmac.path");
  } else if (choice === "Show Server Log") {
    channel.show(true);
  } else if (choice === "Restart Server") {
    await restart();
  }
}

const events = {
  starting: (s) => s === session && status.starting(s.where()),
  running: (s) => s === session && status.running(s.version(), s.where()),
  failed: (s, failure) => {
    if (s === session) {
      status.failed(failure, s.where());
      void showFailure(failure);
    }
  },
};

/** Start a session for the current setting; a failure is shown, not thrown. */
async function start() {
  const made = new Session(executable(), folder(), channel, events);
  session = made;
  await made.start();
  return made;
}

/** Run STEP after the steps before it (restarts, the stop at deactivate): never two
 *  sessions at once, and none started after deactivate. */
function enqueue(step) {
  queue = queue.then(step).catch((error) => {
    channel.appendLine(`[mercmac] ${(error && error.stack) || error}`);
  });
  return queue;
}

async function stopSession() {
  const old = session;
  session = undefined;
  if (old) {
    await old.dispose();
  }
}

/** Dispose of the running session (if any) and start one for the current setting. */
function restart() {
  return enqueue(async () => {
    await stopSession();
    if (!active) {
      return undefined;
    }
    if (!vscode.workspace.isTrusted) {
      status.waiting();
      return undefined;
    }
    return start();
  });
}

/** mercmac.showVersion: the running server's version, else what the executable says. */
async function showVersion() {
  if (!vscode.workspace.isTrusted) {
    void vscode.window.showInformationMessage(
      "mercmac: waiting for workspace trust; in Restricted Mode mercmac is not run, so its version is not known.");
    return;
  }
  const command = session ? session.command : executable();
  const where = locate(command, folder()) || command;
  if (session && session.running() && session.version()) {
    void vscode.window.showInformationMessage(
      `mercmac ${session.version()} (${where}) is the running language server.`);
    return;
  }
  if (!locate(command, folder())) {
    void vscode.window.showInformationMessage(`mercmac: '${command}' was not found. ${INSTALL_HINT}`);
    return;
  }
  let said;
  try {
    said = `mercmac ${await askVersion(where, folder())} (${where})`;
  } catch (error) {
    said = `mercmac: '${where} --version' failed: ${error.message}`;
  }
  const why = status.reason || "it is not running";
  void vscode.window.showInformationMessage(`${said}; the language server is not running: ${why}.`);
}

function activate(context) {
  channel = vscode.window.createOutputChannel("mercmac");
  status = new Status();
  session = undefined;
  queue = Promise.resolve();
  active = true;
  // the same executable, run where the language server runs, as the server is
  simulations = new Simulations(channel, () => ({ command: executable(), cwd: folder() }),
    context.extensionUri && vscode.Uri.joinPath(context.extensionUri, "icons", "mcm.svg"));
  context.subscriptions.push(
    channel,
    status,
    vscode.commands.registerCommand("mercmac.restartServer", () => restart()),
    vscode.commands.registerCommand("mercmac.showServerLog", () => channel.show(true)),
    vscode.commands.registerCommand("mercmac.showVersion", () => showVersion()),
    vscode.commands.registerCommand("mercmac.copyBuild", (argument) => copyBuild(argument)),
    vscode.commands.registerCommand("mercmac.simulate", (argument) => simulations.run(argument)),
    vscode.workspace.onDidChangeConfiguration((event) => {
      if (event.affectsConfiguration("mercmac.path")) {
        return restart();
      }
      return undefined;
    }),
  );
  if (!vscode.workspace.isTrusted) {
    // Restricted Mode: highlighting works, but no executable is run until the user trusts
    // the workspace (a workspace setting could name any program as mercmac.path)
    status.waiting();
    context.subscriptions.push(vscode.workspace.onDidGrantWorkspaceTrust(() => restart()));
    return undefined;
  }
  return restart();
}

function deactivate() {
  active = false;
  const stopping = simulations ? simulations.dispose() : undefined;
  return Promise.all([stopping, enqueue(stopSession)]).then(() => undefined);
}

/** The running client, if any (for the tests). */
function current() {
  return session && session.running() ? session.client : undefined;
}

/** The simulations that run, [{file, pid, running, title}] (for the tests). */
function simulating() {
  return simulations ? simulations.list() : [];
}

module.exports = { activate, deactivate, clientOptions, current, describeFailure, simulating };
