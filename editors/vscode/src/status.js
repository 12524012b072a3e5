// The language status item ({} in the status bar of an .mcm or rig file): which mercmac
// serves the window, or why none does, with the command that helps.
"use strict";
const vscode = require("vscode");
const { SHORT } = require("./messages");

const SELECTOR = [{ language: "mcm" }, { pattern: "**/*.rig.toml" }];

const SHOW_LOG = { title: "Show Server Log", command: "mercmac.showServerLog" };
const RESTART = { title: "Restart Server", command: "mercmac.restartServer" };
const OPEN_SETTINGS = { title: "Open Settings", command: "workbench.action.openSettings",
  arguments: ["mercmac.path"] };
const MANAGE_TRUST = { title: "Manage Workspace Trust", command: "workbench.trust.manage" };

class Status {
  constructor() {
    this.item = vscode.languages.createLanguageStatusItem("mercmac.server", SELECTOR);
    this.item.name = "mercmac language server";
    this.reason = "it has not started"; // why it is not running, for Show Version
  }

  set({ text, detail, severity = vscode.LanguageStatusSeverity.Information, busy = false, command }) {
    Object.assign(this.item, { text, detail, severity, busy, command });
  }

  waiting() {
    this.reason = "waiting for workspace trust";
    this.set({ text: "mercmac: waiting for workspace trust", command: MANAGE_TRUST,
      detail: "the language server starts when the workspace is trusted",
      severity: vscode.LanguageStatusSeverity.Warning });
  }

  starting(where) {
    this.reason = "it is starting";
    this.set({ text: "mercmac", detail: `starting ${where}`, busy: true, command: SHOW_LOG });
  }

  running(version, where) {
    this.reason = undefined;
    this.set({ text: version ? `mercmac ${version}` : "mercmac", detail: where, command: SHOW_LOG });
  }

  /** FAILURE: {kind, text} (messages.describeFailure). */
  failed(failure, where) {
    this.reason = SHORT[failure.kind] || "not running";
    const missing = failure.kind === "not-found" || failure.kind === "not-executable";
    this.set({ text: `mercmac: ${this.reason}`, detail: where,
      severity: vscode.LanguageStatusSeverity.Error, command: missing ? OPEN_SETTINGS : RESTART });
  }

  dispose() {
    this.item.dispose();
  }
}

module.exports = { Status, SELECTOR };
