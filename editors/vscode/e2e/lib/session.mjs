// One code-server and the chromium page that shows it, with the probe extension's answers.
import { spawn } from "node:child_process";
import fs from "node:fs";
import path from "node:path";
import { children, descendants, freePort, log, runOk, sleep, stopGroup, until } from "./common.mjs";
import { CHROMIUM, toolEnv } from "./tools.mjs";
import { sortDiagnostics } from "./workspace.mjs";

// ---------------------------------------------------------------------------------------------
// code-server and the browser

export const QUIET_SETTINGS = {
  "workbench.startupEditor": "none",
  "workbench.tips.enabled": false,
  "workbench.welcomePage.walkthroughs.openOnInstall": false,
  "workbench.enableExperiments": false,
  "workbench.secondarySideBar.defaultVisibility": "hidden",
  "workbench.editor.enablePreview": false,
  "workbench.layoutControl.enabled": false,
  "telemetry.telemetryLevel": "off",
  "update.mode": "none",
  "extensions.autoCheckUpdates": false,
  "extensions.autoUpdate": false,
  "extensions.ignoreRecommendations": true,
  "security.workspace.trust.enabled": false,
  "git.enabled": false,
  "git.openRepositoryInParentFolders": "never",
  "chat.disableAIFeatures": true,
  "chat.commandCenter.enabled": false,
  "window.restoreWindows": "none",
  "files.autoSave": "off",
  "editor.formatOnSave": false,
  "editor.minimap.enabled": false,
  "editor.inlayHints.enabled": "on",
  "editor.codeLens": true,
  "editor.semanticHighlighting.enabled": true,
  "editor.hover.delay": 300,
  "editor.fontSize": 14,
};

export class Session {
  /** TRUSTED false: workspace trust is left on (no --disable-workspace-trust), so that the
   *  folder opens in Restricted Mode in this fresh user-data folder. */
  constructor({ name, scratch, tools, mercmac, ws, out, trusted = true }) {
    Object.assign(this, { name, scratch, tools, mercmac, ws, out, trusted });
    this.home = path.join(scratch, name);
    this.userData = path.join(this.home, "user-data");
    this.extensions = path.join(scratch, "extensions");
    this.logFile = path.join(out, `code-server-${name}.log`);
  }

  static installExtensions(tools, scratch, vsixes) {
    const extensions = path.join(scratch, "extensions");
    const userData = path.join(scratch, "install-user-data");
    const config = path.join(scratch, "code-server.yaml");
    fs.writeFileSync(config, "auth: none\n");
    const args = [tools.codeServer.entry, "--config", config, "--extensions-dir", extensions, "--user-data-dir", userData];
    for (const vsix of vsixes) args.push("--install-extension", vsix);
    args.push("--force");
    const result = runOk(tools.node.node, args, { env: toolEnv(tools.node) });
    log(`installed into a fresh extensions folder: ${result.stdout.trim().replace(/\s*\n\s*/g, "; ")}`);
  }

  async start(browserType) {
    fs.mkdirSync(path.join(this.userData, "User"), { recursive: true });
    fs.writeFileSync(path.join(this.userData, "User", "settings.json"),
      `${JSON.stringify({ ...QUIET_SETTINGS, "mercmac.path": this.mercmac,
        ...(this.trusted ? {} : { "security.workspace.trust.enabled": true }) }, null, 2)}\n`);
    this.port = await freePort();
    this.probePort = await freePort();
    const config = path.join(this.scratch, "code-server.yaml");
    const logFd = fs.openSync(this.logFile, "w");
    const args = [
      this.tools.codeServer.entry, "--config", config,
      "--bind-addr", `127.0.0.1:${this.port}`,
      "--auth", "none", ...(this.trusted ? ["--disable-workspace-trust"] : []), "--disable-telemetry", "--disable-update-check",
      "--disable-getting-started-override", "--ignore-last-opened",
      "--user-data-dir", this.userData, "--extensions-dir", this.extensions,
    ];
    log(`[${this.name}] starting code-server on 127.0.0.1:${this.port} (mercmac.path = ${this.mercmac})`);
    this.server = spawn(this.tools.node.node, args, {
      detached: true, stdio: ["ignore", logFd, logFd],
      env: toolEnv(this.tools.node, {
        MERCMAC_E2E_PROBE_PORT: String(this.probePort),
        XDG_CONFIG_HOME: path.join(this.home, "xdg-config"),
        XDG_DATA_HOME: path.join(this.home, "xdg-data"),
      }),
    });
    fs.closeSync(logFd);
    children.add(this.server);
    await until("code-server's /healthz", async () => {
      if (this.server.exitCode !== null) throw new Error(`code-server exited ${this.server.exitCode}: see ${this.logFile}`);
      const response = await fetch(`http://127.0.0.1:${this.port}/healthz`);
      return response.ok;
    }, { timeout: 60000 });

    const profile = path.join(this.home, "chromium-profile");
    this.context = await browserType.launchPersistentContext(profile, {
      executablePath: CHROMIUM,
      headless: true,
      viewport: { width: 1500, height: 950 },
      // the code lens's command writes the clipboard, the probe reads it back
      permissions: ["clipboard-read", "clipboard-write"],
      args: [
        "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
        "--disable-background-networking", "--disable-component-update", "--disable-sync",
        "--disable-dev-shm-usage",
      ],
    });
    this.page = this.context.pages()[0] || await this.context.newPage();
    this.page.setDefaultTimeout(20000);
    await this.page.goto(`http://127.0.0.1:${this.port}/?folder=${encodeURIComponent(this.ws)}`);
    await this.page.waitForSelector(".monaco-workbench .part.statusbar", { timeout: 60000 });
    await until("the probe extension in the extension host", () => this.probe("return true;"), { timeout: 60000 });
    log(`[${this.name}] VS Code is up: workbench shown, extension host answering`);
  }

  async stop() {
    if (this.context) {
      await this.context.close().catch((error) => log(`closing chromium: ${error.message}`));
      this.context = undefined;
    }
    await stopGroup(this.server, `code-server (${this.name})`);
  }

  /** The `mercmac lsp` processes below this code-server (its process group's descendants). */
  serverProcesses() {
    return descendants(this.server.pid).filter((p) => /\blsp\b/.test(p.cmdline) && /mercmac/.test(p.cmdline));
  }

  /** Run BODY (an async function body with `vscode` in scope) in the extension host. */
  async probe(body) {
    const response = await fetch(`http://127.0.0.1:${this.probePort}/eval`, { method: "POST", body });
    const answer = await response.json();
    if (!answer.ok) throw new Error(`probe: ${answer.error}`);
    return answer.result;
  }

  file(relative) {
    return path.join(this.ws, relative);
  }

  /** Open FILE in an editor (the probe asks VS Code to show it, as a click in the explorer would). */
  async open(relative) {
    const file = this.file(relative);
    await this.probe(`
      const document = await vscode.workspace.openTextDocument(vscode.Uri.file(${JSON.stringify(file)}));
      await vscode.window.showTextDocument(document, { preview: false });
      return document.languageId;`);
    await until(`an editor tab for ${relative}`, async () =>
      (await this.page.locator(".tabs-container .tab.active").first().textContent({ timeout: 2000 })).includes(path.basename(file)));
    await this.focusEditor();
    return file;
  }

  async focusEditor() {
    await this.probe("await vscode.commands.executeCommand('workbench.action.focusActiveEditorGroup');");
    await sleep(200);
  }

  async cursor(line, character) {
    await this.probe(`
      const editor = vscode.window.activeTextEditor;
      const at = new vscode.Position(${line}, ${character});
      editor.selection = new vscode.Selection(at, at);
      editor.revealRange(new vscode.Range(at, at), vscode.TextEditorRevealType.InCenterIfOutsideViewport);`);
    await this.focusEditor();
  }

  async activeEditor() {
    return this.probe(`
      const editor = vscode.window.activeTextEditor;
      if (!editor) return null;
      return { file: editor.document.uri.fsPath, text: editor.document.getText(), dirty: editor.document.isDirty,
               selection: editor.selection, languageId: editor.document.languageId };`);
  }

  async diagnostics(file) {
    const list = await this.probe(`
      return vscode.languages.getDiagnostics(vscode.Uri.file(${JSON.stringify(file)})).map((d) => ({
        code: d.code && typeof d.code === "object" ? String(d.code.value) : String(d.code),
        severity: d.severity, message: d.message, source: d.source,
        range: [d.range.start.line, d.range.start.character, d.range.end.line, d.range.end.character],
      }));`);
    return sortDiagnostics(list);
  }

  /** Run a command through the command palette, as a person does: F1, its title, Enter. */
  async palette(title, { opensPicker = false } = {}) {
    await this.page.keyboard.press("F1");
    const input = this.page.locator(".quick-input-widget input");
    await input.waitFor({ state: "visible" });
    await input.fill(`>${title}`);
    const row = this.page.locator(".quick-input-widget .monaco-list-row", { hasText: title }).first();
    await row.waitFor({ state: "visible" });
    await sleep(300);
    // the first row is the best match; take the row whose label is exactly TITLE when there is one
    const labels = await this.page.locator(".quick-input-widget .monaco-list-row .label-name").allTextContents();
    const exact = labels.findIndex((label) => label.replace(/\s+/g, " ").trim() === title);
    if (exact > 0) {
      for (let i = 0; i < exact; i++) await this.page.keyboard.press("ArrowDown");
    }
    await this.page.keyboard.press("Enter");
    if (!opensPicker) await input.waitFor({ state: "hidden", timeout: 5000 }).catch(() => undefined);
    else await sleep(500);
  }

  /** Park the mouse on the empty title bar, away from anything with a tooltip or a hover,
   *  and give a tooltip it left time to go. */
  async restMouse() {
    await this.page.mouse.move(this.page.viewportSize().width - 40, 8);
    await sleep(600);
  }

  async escape(times = 2) {
    for (let i = 0; i < times; i++) {
      await this.page.keyboard.press("Escape");
      await sleep(100);
    }
  }

  async shot(name) {
    const file = path.join(this.out, `${name}.png`);
    if (!this.keepMouse) await this.restMouse();
    await this.page.screenshot({ path: file });
    return file;
  }

  async closeEditors() {
    await this.probe(`
      await vscode.commands.executeCommand('workbench.action.revertAndCloseActiveEditor').then(() => undefined, () => undefined);
      await vscode.commands.executeCommand('workbench.action.closeAllEditors');`);
  }
}

