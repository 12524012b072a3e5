// The checks that need a code-server of their own, started inside the check (one that cannot
// start fails that check only) and stopped at its end: missing-lsp (mercmac.path names a
// mercmac without pygls) and restricted-mode (workspace trust on, the folder untrusted).
import { assert, check, log, sleep, until } from "../lib/common.mjs";
import { languageStatusText } from "./features.mjs";

async function inOwnSession(name, session, options, fn) {
  await check(name, options, async (c) => {
    try {
      await session.start(session.browserType);
      await fn(c);
    } finally {
      await session.stop();
    }
  });
}

export async function missingLspSession(session, options) {
  await inOwnSession("missing-lsp", session, options, async (c) => {
    const { page } = session;
    await session.open("four-modes.mcm");
    // give the client time to start the server, see it exit, and say everything it has to say
    await until("the mercmac extension to be active", () => session.probe(
      "const e = vscode.extensions.getExtension('mercmac.mercmac'); return e && e.isActive;"), { timeout: 30000 });
    await session.probe("await vscode.commands.executeCommand('notifications.showList');");
    const rows = page.locator(".notifications-center .notification-list-item");
    await until("a notification", async () => (await rows.count()) > 0, { timeout: 30000 }).catch(() => undefined);
    // then give the client time to say anything more (a second message, a crash report):
    // this check is about what is NOT said, so it has to wait
    await sleep(8000);
    const notes = [];
    for (let i = 0; i < await rows.count(); i++) {
      const row = rows.nth(i);
      const message = (await row.locator(".notification-list-item-message").innerText()).replace(/\s+/g, " ").trim();
      const icon = await row.locator(".notification-list-item-icon").getAttribute("class");
      const severity = /codicon-error/.test(icon) ? "error" : /codicon-warning/.test(icon) ? "warning" : "info";
      notes.push({ severity, message });
    }
    c.shots.push(await session.shot("13-missing-lsp"));
    const quoting = notes.filter((n) => n.message.includes("the language server needs the lsp extra"));
    const errors = notes.filter((n) => n.severity === "error");
    c.note(`notifications: ${JSON.stringify(notes.map((n) => `${n.severity}: ${n.message}`))}`);
    assert(quoting.length === 1 && quoting[0].severity === "error" && errors.length === 1,
      `want exactly one error notification, quoting "the language server needs the lsp extra"; ` +
      `got ${errors.length} error notification(s), ${quoting.length} quoting it`);
  });
}

export async function restrictedModeSession(session, options) {
  await inOwnSession("restricted-mode", session, options, async (c) => {
    const { page } = session;
    // code-server asks whether to trust the folder (a modal dialog) when it is new to this
    // user-data folder: answer "No" (Restricted Mode). Wait for the dialog or for the workbench
    // to say it is restricted, whichever comes.
    let prompt = "none";
    await until("the trust prompt or Restricted Mode", async () => {
      const dialog = page.locator(".monaco-dialog-box").first();
      if (await dialog.isVisible().catch(() => false)) {
        prompt = (await dialog.innerText()).replace(/\s+/g, " ").trim();
        c.shots.push(await session.shot("27-restricted-mode-prompt"));
        const no = dialog.locator(".monaco-button", { hasText: /don't trust|No,/i }).first();
        await no.click();
        return true;
      }
      return (await session.probe("return vscode.workspace.isTrusted;")) === false
        && await page.locator(".part.statusbar", { hasText: "Restricted Mode" }).count();
    }, { timeout: 30000 });
    log(`[restricted] trust prompt: ${JSON.stringify(prompt.slice(0, 160))}`);
    await session.open("four-modes.mcm");
    const state = await until("the extension active, the folder untrusted", async () => {
      const s = await session.probe(`
        const ext = vscode.extensions.getExtension('mercmac.mercmac');
        return { trusted: vscode.workspace.isTrusted, active: !!(ext && ext.isActive),
                 language: vscode.window.activeTextEditor && vscode.window.activeTextEditor.document.languageId };`);
      return s.active && s.trusted === false && s.language === "mcm" ? s : false;
    }, { timeout: 30000 });
    // the TextMate grammar colours the text: the keyword `macro` and a comment in colours of
    // their own, not the editor's default foreground
    const colours = await until("highlighting", async () => {
      const found = await page.locator(".monaco-editor .view-lines").first().evaluate((root) => {
        const colour = {};
        const plain = getComputedStyle(root).color;
        for (const span of root.querySelectorAll("span > span")) {
          const t = span.textContent.trim();
          const kind = t === "macro" ? "keyword macro" : t.startsWith("//") ? "comment" : /^\d+$/.test(t) ? "number" : null;
          if (kind && !colour[kind]) colour[kind] = getComputedStyle(span).color;
        }
        return { plain, ...colour };
      });
      return found["keyword macro"] && found.comment && found["keyword macro"] !== found.plain && found.comment !== found.plain ? found : false;
    }, { timeout: 15000 }).catch(() => { throw new Error("the .mcm file is not highlighted in Restricted Mode"); });
    const status = await until("the language status waiting for trust", async () => {
      const text = await languageStatusText(session);
      return /waiting for workspace trust/.test(text) ? text : false;
    }, { timeout: 15000 });
    session.keepMouse = true;
    c.shots.push(await session.shot("27-restricted-mode"));
    session.keepMouse = false;
    await session.escape();
    const bar = (await page.locator(".part.statusbar").innerText()).replace(/\s+/g, " ");
    // no server: none was started (activate returned before starting one) and none runs now
    const servers = session.serverProcesses();
    c.note(`trust prompt: ${JSON.stringify(prompt.slice(0, 100))}; isTrusted ${state.trusted}, the extension active, four-modes.mcm coloured ${JSON.stringify(colours)}; language status ${JSON.stringify(status)}; status bar ${JSON.stringify(bar.slice(0, 100))}; mercmac lsp processes: ${servers.length}`);
    assert(servers.length === 0, `a language server runs in Restricted Mode: ${JSON.stringify(servers)}`);
    assert(/Restricted Mode/.test(bar), "the status bar does not say Restricted Mode");
  });
}
