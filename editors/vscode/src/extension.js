// The client: VS Code starts `mercmac lsp --stdio` (the language server over stdio) for .mcm
// documents and rig files (*.rig.toml). vscode-languageclient appends `--stdio` itself for
// TransportKind.stdio.
// Bundled by esbuild into dist/extension.js (`npm run build`), which is what the .vsix holds.
"use strict";
const fs = require("fs");
const path = require("path");
const vscode = require("vscode");
const { LanguageClient, TransportKind } = require("vscode-languageclient/node");

const INSTALL_HINT =
  "Install it with `pip install 'mercmac[lsp]'`, or set the `mercmac.path` setting to the " +
  "mercmac executable (for a virtual environment: `.venv/bin/mercmac`).";

let client;

/** The executable the `mercmac.path` setting names ("mercmac" on PATH by default). */
function executable() {
  return vscode.workspace.getConfiguration("mercmac").get("path") || "mercmac";
}

/** What starts the server: `<path> lsp`, to which the client adds `--stdio`. */
function serverOptions(command) {
  return { command, args: ["lsp"], transport: TransportKind.stdio };
}

function clientOptions() {
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
  };
}

/** Whether COMMAND names an executable file, itself or on PATH (with PATHEXT on Windows),
 *  so that a missing one gets our message instead of the client's "couldn't create connection". */
function findable(command) {
  const windows = process.platform === "win32";
  const endings = windows ? ["", ...(process.env.PATHEXT || ".EXE;.CMD;.BAT").split(";")] : [""];
  const folders = command.includes("/") || (windows && command.includes("\\"))
    ? [""] : (process.env.PATH || "").split(path.delimiter);
  return folders.some((folder) => endings.some((ending) => {
    try {
      fs.accessSync(path.join(folder, command + ending), windows ? fs.constants.F_OK : fs.constants.X_OK);
      return fs.statSync(path.join(folder, command + ending)).isFile();
    } catch {
      return false;
    }
  }));
}

/** Why the server did not start, in words a user can act on. */
function startFailure(command, error) {
  const text = String((error && error.message) || error);
  if (/ENOENT/.test(text)) {
    return `mercmac: cannot start the language server: '${command}' was not found. ${INSTALL_HINT}`;
  }
  if (/EACCES/.test(text)) {
    return `mercmac: cannot start the language server: '${command}' is not executable. ${INSTALL_HINT}`;
  }
  return `mercmac: the language server '${command} lsp' did not start: ${text}. ${INSTALL_HINT}`;
}

/** Start a client for the current setting; a failure is shown, not thrown. */
async function start() {
  const command = executable();
  if (!findable(command)) {
    vscode.window.showErrorMessage(startFailure(command, new Error("ENOENT")));
    return undefined;
  }
  const made = new LanguageClient("mercmac", "mercmac", serverOptions(command), clientOptions());
  client = made;
  try {
    await made.start();
  } catch (error) {
    if (client === made) {
      client = undefined;
    }
    vscode.window.showErrorMessage(startFailure(command, error));
  }
  return made;
}

/** Stop the running client (if any) and start one for the new setting. */
async function restart() {
  const old = client;
  client = undefined;
  if (old) {
    await old.stop().catch(() => undefined);
  }
  return start();
}

function activate(context) {
  context.subscriptions.push(
    vscode.workspace.onDidChangeConfiguration((event) => {
      if (event.affectsConfiguration("mercmac.path")) {
        return restart();
      }
      return undefined;
    }),
  );
  return start();
}

function deactivate() {
  const old = client;
  client = undefined;
  return old ? old.stop() : undefined;
}

module.exports = { activate, deactivate, startFailure, clientOptions, current: () => client };
