// The checks of the first kind: activation, diagnostics, hovers, format, quick fix,
// definition, outline, rig diagnostics, inlay hints (in this order: format and quick-fix
// change files that the later checks do not read).
import fs from "node:fs";
import path from "node:path";
import { assert, check, lineOf, sleep, until } from "../lib/common.mjs";
import { applyFix, checkJson, describeDiagnostic, sortDiagnostics } from "../lib/workspace.mjs";

export async function hoverText(session) {
  const hover = session.page.locator(".monaco-editor .monaco-hover:not(.hidden) .monaco-hover-content, .workbench-hover-container .monaco-hover-content").first();
  await hover.waitFor({ state: "visible", timeout: 10000 });
  await until("the hover's text", async () => ((await hover.innerText()) || "").trim().length > 0, { timeout: 10000 });
  await sleep(300);
  return (await hover.innerText()).trim();
}

export async function showHoverAt(session, line, character) {
  await session.escape();
  await session.cursor(line, character);
  await session.probe("await vscode.commands.executeCommand('editor.action.showHover');");
  return hoverText(session);
}

export async function coreChecks(session, options) {
  const { page } = session;

  await check("activation", options, async (c) => {
    await session.open("four-modes.mcm");
    const state = await until("the mercmac extension to be active", async () => {
      const s = await session.probe(`
        const extension = vscode.extensions.getExtension('mercmac.mercmac');
        return extension && { active: extension.isActive, version: extension.packageJSON.version };`);
      return s && s.active ? s : false;
    });
    // the server answers: a document symbol request goes through the client to `mercmac lsp`
    const symbols = await until("an answer from the language server", async () => {
      const list = await session.probe(`
        const uri = vscode.Uri.file(${JSON.stringify(session.file("four-modes.mcm"))});
        return (await vscode.commands.executeCommand('vscode.executeDocumentSymbolProvider', uri)) || [];`);
      return list.length ? list : false;
    });
    // what a person looks at: the Output channel "mercmac" (the client's and the server's log)
    await session.palette("Output: Show Output Channels...", { opensPicker: true });
    const input = page.locator(".quick-input-widget input");
    await input.waitFor({ state: "visible" });
    await input.fill("mercmac");
    const row = page.locator(".quick-input-widget .monaco-list-row", { hasText: /^mercmac$/ }).first();
    const rows = await page.locator(".quick-input-widget .monaco-list-row").allInnerTexts();
    await row.waitFor({ state: "visible", timeout: 10000 }).catch(() => {
      throw new Error(`no Output channel named "mercmac" (channels matching: ${JSON.stringify(rows)})`);
    });
    await row.click();
    await sleep(1000);
    const channel = await page.locator(".part.panel .monaco-editor .view-lines").first().innerText().catch(() => "");
    const statusBar = (await page.locator(".part.statusbar").innerText()).replace(/\s+/g, " ");
    c.shots.push(await session.shot("01-activation-output"));
    await session.probe("await vscode.commands.executeCommand('workbench.action.closePanel');");
    // the language status ({} in the status bar) of an .mcm file, where the extension has one
    let languageStatus = "none";
    const item = page.locator("#status\\.languageStatus").first();
    if (await item.count()) {
      await item.click();
      const hover = page.locator(".monaco-hover:not(.hidden), .workbench-hover-container").last();
      await hover.waitFor({ state: "visible", timeout: 5000 }).catch(() => undefined);
      await sleep(500);
      languageStatus = JSON.stringify((await hover.innerText().catch(() => "")).replace(/\s+/g, " ").trim());
      session.keepMouse = true;
      c.shots.push(await session.shot("01-activation-language-status"));
      session.keepMouse = false;
      await session.escape();
    }
    const logLines = channel.split("\n").filter((l) => l.trim()).length;
    const selected = await page.locator(".part.panel .monaco-select-box").first().evaluate((box) =>
      box.tagName === "SELECT" ? box.options[box.selectedIndex].text : box.textContent, null, { timeout: 3000 }).catch(() => "");
    c.note(`mercmac.mercmac ${state.version} active, the server answered (${symbols.length} symbols), Output channel ${JSON.stringify(selected.trim() || "mercmac")} shown (${logLines} lines in it), language status: ${languageStatus}, status bar: ${JSON.stringify(statusBar.slice(0, 160))}`);
  });

  await check("diagnostics", options, async (c) => {
    const checked = [];
    for (const relative of ["broken.mcm", "four-modes.mcm", "messy.mcm"]) {
      const file = session.file(relative);
      const expected = sortDiagnostics(checkJson(session.mercmac, file)).map(({ fix, ...d }) => d);
      await session.open(relative);
      const opened = Date.now();
      let got;
      try {
        await until(`the editor's diagnostics of ${relative} to equal mercmac check's`, async () => {
          got = (await session.diagnostics(file)).map(({ source, ...d }) => d);
          // an empty list also needs the server to have had its say: wait a moment for it
          return JSON.stringify(got) === JSON.stringify(expected) && (expected.length || Date.now() - opened > 3000);
        }, { timeout: 30000 });
      } catch (error) {
        throw new Error(`${relative}: VS Code has [${(got || []).map(describeDiagnostic).join("; ")}], ` +
          `mercmac check --format json has [${expected.map(describeDiagnostic).join("; ")}]`);
      }
      checked.push(`${relative}: ${expected.length ? expected.map(describeDiagnostic).join("; ") : "none"}`);
      if (relative === "broken.mcm") {
        await session.probe("await vscode.commands.executeCommand('workbench.actions.view.problems');");
        const problems = page.locator(".markers-panel .monaco-list-row");
        await until("the Problems panel to list them", async () => (await problems.count()) >= expected.length + 1);
        const rows = (await problems.allInnerTexts()).map((t) => t.replace(/\s+/g, " ").trim());
        for (const d of expected) {
          const shown = rows.some((row) => row.includes(d.message) && row.includes(`[Ln ${d.range[0] + 1}, Col ${d.range[1] + 1}]`));
          assert(shown, `the Problems panel does not show ${describeDiagnostic(d)}: rows ${JSON.stringify(rows)}`);
        }
        c.shots.push(await session.shot("02-diagnostics-problems"));
        await session.probe("await vscode.commands.executeCommand('workbench.action.closePanel');");
      }
    }
    c.note(`code, severity, message and range equal \`mercmac check --format json\`: ${checked.join(" | ")}`);
  });

  await check("hover-command", options, async (c) => {
    const file = await session.open("four-modes.mcm");
    const at = lineOf(fs.readFileSync(file, "utf8"), /\bSV\b/);
    const text = await showHoverAt(session, at.line, at.character);
    c.shots.push(await session.shot("03-hover-command"));
    assert(/\bSV\b/.test(text) && text.length > 20, `the hover on SV (line ${at.line + 1}) shows ${JSON.stringify(text)}`);
    c.note(`SV at ${at.line + 1}:${at.character + 1}: ${JSON.stringify(text.replace(/\s+/g, " ").slice(0, 120))}`);
    await session.escape();
  });

  await check("hover-macro", options, async (c) => {
    const file = await session.open("four-modes.mcm");
    const at = lineOf(fs.readFileSync(file, "utf8"), /call (init)\b/);
    const text = await showHoverAt(session, at.line, at.character + 5);
    c.shots.push(await session.shot("04-hover-macro"));
    assert(/\binit\b/.test(text), `the hover on the macro name init (line ${at.line + 1}) shows ${JSON.stringify(text)}`);
    c.note(`init at ${at.line + 1}:${at.character + 6}: ${JSON.stringify(text.replace(/\s+/g, " ").slice(0, 120))}`);
    await session.escape();
  });

  await check("format", options, async (c) => {
    const file = await session.open("messy.mcm");
    const before = fs.readFileSync(file, "utf8");
    c.shots.push(await session.shot("05-format-before"));
    await session.palette("Format Document");
    await until("the document to change", async () => (await session.activeEditor()).text !== before, { timeout: 15000 });
    await page.keyboard.press("Control+S");
    const saved = await until("messy.mcm saved", async () => {
      const editor = await session.activeEditor();
      return !editor.dirty && fs.readFileSync(file, "utf8") !== before ? fs.readFileSync(file) : false;
    }, { timeout: 15000 });
    c.shots.push(await session.shot("05-format-after"));
    const want = Buffer.from(session.expected.format, "utf8");
    if (!saved.equals(want)) {
      const a = saved.toString("utf8").split("\n");
      const b = session.expected.format.split("\n");
      const i = a.findIndex((line, k) => line !== b[k]);
      throw new Error(`the saved file differs from \`mercmac fmt -\` at line ${i + 1}: ${JSON.stringify(a[i])} vs ${JSON.stringify(b[i])}`);
    }
    c.note(`Format Document (command palette) + save: ${saved.length} bytes, byte-identical to \`mercmac fmt -\``);
  });

  await check("quick-fix", options, async (c) => {
    const file = await session.open("broken.mcm");
    const text = fs.readFileSync(file, "utf8");
    const expected = checkJson(session.mercmac, file).find((d) => d.code === "MM002");
    assert(expected && expected.fix, `mercmac check gives no fix for the unknown command XM: ${JSON.stringify(expected)}`);
    await until("the diagnostic on XM", async () => (await session.diagnostics(file)).some((d) => d.code === "MM002"));
    await session.cursor(expected.range[0], expected.range[1]);
    const menu = page.locator(".action-widget:not(.action-list-submenu-panel)").first();
    // Ctrl+. right after the diagnostic came can find no code actions yet ("No code actions
    // available"): press it again until the menu opens
    await until("the quick fix menu", async () => {
      await page.keyboard.press("Control+.");
      return menu.waitFor({ state: "visible", timeout: 3000 }).then(() => true, async () => {
        await session.escape(1);
        await session.focusEditor();
        return false;
      });
    }, { timeout: 20000 });
    const item = menu.locator(".monaco-list-row", { hasText: expected.fix.message }).first();
    const items = (await menu.locator(".monaco-list-row").allInnerTexts()).map((t) => t.replace(/\s+/g, " ").trim());
    await item.waitFor({ state: "visible", timeout: 5000 }).catch(() => {
      throw new Error(`the quick fix menu has no "${expected.fix.message}": ${JSON.stringify(items)}`);
    });
    await item.hover();
    await sleep(400);
    c.shots.push(await session.shot("06-quick-fix-menu"));
    await item.click();
    const want = applyFix(text, expected.fix);
    await until("the fix applied", async () => (await session.activeEditor()).text === want, { timeout: 10000 });
    await until("the diagnostic on XM to go", async () => !(await session.diagnostics(file)).some((d) => d.code === "MM002"), { timeout: 10000 });
    c.shots.push(await session.shot("07-quick-fix-applied"));
    const fixedLine = want.split("\n")[expected.range[0]];
    c.note(`Ctrl+. on XM offered ${JSON.stringify(items)}; "${expected.fix.message}" made line ${expected.range[0] + 1} ${JSON.stringify(fixedLine)}, as check's fix does`);
    await session.closeEditors();
  });

  await check("definition", options, async (c) => {
    const file = await session.open("four-modes.mcm");
    const text = fs.readFileSync(file, "utf8");
    const call = lineOf(text, /call (init)\b/);
    const header = lineOf(text, /^\s*macro init\b/);
    await session.escape();
    await session.cursor(call.line, call.character + 6);
    await page.keyboard.press("F12");
    const editor = await until(`the cursor on macro init (line ${header.line + 1})`, async () => {
      const e = await session.activeEditor();
      return e.selection.start.line === header.line ? e : false;
    }, { timeout: 10000 });
    await sleep(500);
    c.shots.push(await session.shot("08-definition"));
    c.note(`F12 on \`call init\` (line ${call.line + 1}) moved to ${editor.selection.start.line + 1}:${editor.selection.start.character + 1}: ${JSON.stringify(header.text.trim())}`);
  });

  await check("outline", options, async (c) => {
    const file = await session.open("four-modes.mcm");
    const text = fs.readFileSync(file, "utf8");
    const names = [...text.matchAll(/^\s*macro\s+(\w+)/gm)].map((m) => m[1]);
    await session.probe("await vscode.commands.executeCommand('workbench.view.explorer');");
    // fold the file tree away so that the Outline has the side bar's height, then show it
    // with its top-level symbols only (Collapse All): every macro is then a row on screen
    const folders = page.locator(".sidebar .pane-header", { hasText: path.basename(session.ws) }).first();
    if ((await folders.getAttribute("aria-expanded")) === "true") await folders.click();
    await session.restMouse();
    await session.probe("await vscode.commands.executeCommand('outline.focus');");
    await sleep(500);
    await session.probe("await vscode.commands.executeCommand('outline.collapse');").catch(() => undefined);
    const outlineLabels = page.locator(".sidebar .monaco-list-row .outline-element .label-name");
    let labels = [];
    await until("the outline to list the macros", async () => {
      labels = (await outlineLabels.allInnerTexts()).map((t) => t.trim());
      return names.every((name) => labels.includes(name));
    }, { timeout: 15000 }).catch(() => {
      throw new Error(`the Outline shows ${JSON.stringify(labels)}; the file's macros are ${JSON.stringify(names)}`);
    });
    c.shots.push(await session.shot("09-outline"));
    c.note(`Outline rows: ${JSON.stringify(labels)} (the file's macros: ${names.join(", ")})`);
    if ((await folders.getAttribute("aria-expanded")) === "false") await folders.click();
    await session.restMouse();
  });

  await check("rig", options, async (c) => {
    const details = [];
    for (const relative of [path.join("rig", "broken.rig.toml"), path.join("rig", session.rigName)]) {
      const file = session.file(relative);
      const expected = sortDiagnostics(checkJson(session.mercmac, file)).map(({ fix, ...d }) => d);
      await session.open(relative);
      const opened = Date.now();
      let got;
      await until(`the editor's diagnostics of ${relative} to equal mercmac check's`, async () => {
        got = (await session.diagnostics(file)).map(({ source, ...d }) => d);
        return JSON.stringify(got) === JSON.stringify(expected) && (expected.length || Date.now() - opened > 3000);
      }, { timeout: 30000 }).catch(() => {
        throw new Error(`${relative}: VS Code has [${(got || []).map(describeDiagnostic).join("; ")}], ` +
          `mercmac check has [${expected.map(describeDiagnostic).join("; ")}]`);
      });
      if (expected.length) {
        await session.probe("await vscode.commands.executeCommand('workbench.actions.view.problems');");
        await sleep(800);
        c.shots.push(await session.shot("10-rig"));
        await session.probe("await vscode.commands.executeCommand('workbench.action.closePanel');");
      }
      details.push(`${relative}: ${expected.length ? expected.map(describeDiagnostic).join("; ") : "none"}`);
    }
    c.note(`equal to \`mercmac check RIG --format json\`: ${details.join(" | ")}`);
  });

  await check("inlay-hints", options, async (c) => {
    const file = await session.open("four-modes.mcm");
    const text = fs.readFileSync(file, "utf8");
    const header = lineOf(text, /^\s*macro init\b/);
    await session.probe("await vscode.commands.executeCommand('workbench.action.closeSidebar');");
    let hints = [];
    try {
      await until("inlay hints from the server", async () => {
        hints = await session.probe(`
          const document = vscode.window.activeTextEditor.document;
          const range = new vscode.Range(0, 0, document.lineCount, 0);
          const hints = (await vscode.commands.executeCommand('vscode.executeInlayHintProvider', document.uri, range)) || [];
          return hints.map((h) => ({ line: h.position.line, character: h.position.character,
            label: typeof h.label === 'string' ? h.label : h.label.map((p) => p.value).join('') }));`);
        return hints.length > 0;
      }, { timeout: 8000 });
    } catch { /* none: said below */ }
    await sleep(800);
    // VS Code draws an inlay hint as CSS content (::before/::after) of a span in the line
    const visible = await page.locator(".monaco-editor .view-lines").first().evaluate((root) => {
      const texts = [];
      for (const span of root.querySelectorAll("span")) {
        for (const pseudo of ["::before", "::after"]) {
          const content = getComputedStyle(span, pseudo).content;
          if (content && content !== "none" && content !== "normal") texts.push(content.replace(/^"|"$/g, ""));
        }
        if (/inlay|dyn-rule|ced-/.test(span.className)) texts.push(span.textContent);
      }
      return texts.join("\n").replace(/\u00a0/g, " ");
    });
    c.shots.push(await session.shot("11-inlay-hints"));
    const budget = hints.find((h) => h.line === 0 && /\b\d+ of 32 slots\b/.test(h.label));
    const slot = hints.find((h) => h.line === header.line && /\bMC?\d\d\b/.test(h.label));
    c.note(`the server gave ${hints.length} hints: ${JSON.stringify(hints.slice(0, 6).map((h) => `${h.line + 1}:${h.character + 1} ${h.label}`))}`);
    assert(budget, `no hint like "N of 32 slots" on line 1`);
    assert(slot, `no slot hint (like MC03) on the header of macro init, line ${header.line + 1}`);
    for (const hint of [budget, slot]) {
      assert(visible.includes(hint.label.trim()), `the hint ${JSON.stringify(hint.label)} is not shown in the editor`);
    }
  });
}
