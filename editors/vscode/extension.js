// A minimal client: VS Code starts `mercmac lsp` (language server over stdio) for .mcm files.
"use strict";
const vscode = require("vscode");
const { LanguageClient, TransportKind } = require("vscode-languageclient/node");

let client;

function activate(context) {
  const command = vscode.workspace.getConfiguration("mercmac").get("path") || "mercmac";
  const server = { command, args: ["lsp"], transport: TransportKind.stdio };
  client = new LanguageClient("mercmac", "mercmac", server, {
    documentSelector: [{ scheme: "file", language: "mcm" }, { scheme: "untitled", language: "mcm" }],
  });
  context.subscriptions.push(vscode.workspace.onDidChangeConfiguration((e) => {
    if (e.affectsConfiguration("mercmac.path")) {
      vscode.window.showInformationMessage("mercmac.path changed: reload the window to use it.");
    }
  }));
  return client.start();
}

function deactivate() {
  return client ? client.stop() : undefined;
}

module.exports = { activate, deactivate };
