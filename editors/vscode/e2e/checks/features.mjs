// The checks of the server's and the extension's other features, in the main session: code
// lenses, semantic tokens, folding, signature help, completion, references, rename, document
// links, workspace symbols, formatting a rig, the diagnostics' rule links, the commands, the
// file icon. Each drives the UI as a person would and reads the providers' answers through
// the probe; each leaves the editors closed.
import fs from "node:fs";
import path from "node:path";
import { assert, check, lineOf, run, runOk, sleep, until } from "../lib/common.mjs";
import { checkJson } from "../lib/workspace.mjs";
import { hoverText, showHoverAt } from "./core.mjs";

export const FEATURE_CHECKS = [
  "code-lens", "semantic-tokens", "folding", "signature-help", "completion", "references",
  "rename", "rig-format", "document-links", "workspace-symbols", "diagnostic-link", "commands",
  "icon",
];

const RULES_URL = /\/docs\/rules\.md#mm002-unknown-command$/;

/** The rows of the notification toasts (and of the center when it is open): their texts. */
async function notificationTexts(page) {
  const rows = page.locator(".notifications-toasts .notification-list-item-message, .notifications-center .notification-list-item-message");
  return (await rows.allInnerTexts()).map((t) => t.replace(/\s+/g, " ").trim());
}

async function waitNotification(session, regex, what, timeout = 15000) {
  let seen = [];
  return until(what, async () => {
    seen = await notificationTexts(session.page);
    return seen.find((t) => regex.test(t));
  }, { timeout }).catch(() => {
    throw new Error(`no notification like ${regex}: the notifications say ${JSON.stringify(seen)}`);
  });
}

async function clearNotifications(session) {
  await session.probe("await vscode.commands.executeCommand('notifications.clearAll');").catch(() => undefined);
  await session.probe("await vscode.commands.executeCommand('notifications.hideList');").catch(() => undefined);
}

/** A copy of an example in the workspace, for checks that type into a file. */
function scratchCopy(session, from, name) {
  const file = session.file(name);
  fs.copyFileSync(session.file(from), file);
  return name;
}

/** Close the editors (reverting the scratch copy) and delete the copy. */
async function dropScratch(session, name) {
  await session.closeEditors();
  fs.rmSync(session.file(name), { force: true });
}

/** The LSP's relative encoding of semantic tokens, decoded: {line, character, length, type, modifiers}. */
function decodeTokens(data, legend) {
  const out = [];
  let line = 0;
  let character = 0;
  for (let i = 0; i + 4 < data.length; i += 5) {
    line += data[i];
    character = data[i] === 0 ? character + data[i + 1] : data[i + 1];
    const modifiers = legend.tokenModifiers.filter((_, bit) => data[i + 4] & (1 << bit));
    out.push({ line, character, length: data[i + 2], type: legend.tokenTypes[data[i + 3]], modifiers });
  }
  return out;
}

export async function featureChecks(session, options) {
  const { page } = session;
  const mercmac = session.mercmac;

  await check("code-lens", options, async (c) => {
    await clearNotifications(session);
    const file = await session.open("four-modes.mcm");
    const text = fs.readFileSync(file, "utf8");
    const header = lineOf(text, /^\s*macro jog\b/);
    const lenses = await until("the server's code lenses", async () => {
      const list = await session.probe(`
        const uri = vscode.window.activeTextEditor.document.uri;
        const lenses = (await vscode.commands.executeCommand('vscode.executeCodeLensProvider', uri)) || [];
        return lenses.map((l) => ({ line: l.range.start.line, title: l.command ? l.command.title : '',
          command: l.command ? l.command.command : '', arguments: l.command ? l.command.arguments : [] }));`);
      return list.length ? list : false;
    }, { timeout: 15000 });
    const lens = lenses.find((l) => l.line === header.line);
    assert(lens && /^build: /.test(lens.title) && lens.command === "mercmac.copyBuild",
      `no "build" lens running mercmac.copyBuild on macro jog (line ${header.line + 1}): ${JSON.stringify(lenses.map((l) => `${l.line + 1}: ${l.title} [${l.command}]`))}`);
    // what `mercmac build FILE` prints for that macro's slots (the lens's title names them)
    const slots = [...lens.title.matchAll(/\bMC(\d+)\b/g)].map((m) => Number(m[1]));
    const built = runOk(mercmac, ["build", path.basename(file)], { cwd: path.dirname(file) }).stdout.split("\n").filter(Boolean);
    const want = built.filter((line) => slots.includes(Number(/^MD(\d+),/.exec(line)?.[1])));
    assert(want.length === slots.length, `mercmac build gives ${JSON.stringify(want)} for the slots ${slots.join(", ")}`);
    // the lens as drawn above the header: click it
    await session.cursor(header.line, 0);
    const drawn = page.locator(".monaco-editor .codelens-decoration a", { hasText: lens.title }).first();
    await drawn.waitFor({ state: "visible", timeout: 10000 }).catch(async () => {
      const all = await page.locator(".monaco-editor .codelens-decoration").allInnerTexts();
      throw new Error(`the lens "${lens.title}" is not drawn; drawn lenses: ${JSON.stringify(all)}`);
    });
    await session.probe("await vscode.env.clipboard.writeText('(nothing copied yet)');");
    await drawn.click();
    let clipboard = "";
    await until("the clipboard to hold the MD lines", async () => {
      clipboard = await session.probe("return vscode.env.clipboard.readText();");
      return clipboard === want.join("\n");
    }, { timeout: 10000 }).catch(() => {
      throw new Error(`after clicking the lens the clipboard holds ${JSON.stringify(clipboard)}, not ${JSON.stringify(want.join("\n"))}`);
    });
    const note = await waitNotification(session, /Copied the 5 MD lines of jog/, "the notification");
    c.shots.push(await session.shot("14-code-lens-copied"));
    c.note(`lens "${lens.title}" on line ${header.line + 1} clicked: the clipboard holds ${want.length} lines equal to \`mercmac build\`'s (${want.map((l) => l.split(",")[0]).join(", ")}); notification ${JSON.stringify(note)}`);
    await clearNotifications(session);

    // a file with errors: the lens says it is not built
    // counted by `mercmac check` on the text the editor holds: the quick-fix check may have
    // left broken.mcm changed and unsaved
    const brokenFile = await session.open("broken.mcm");
    const held = path.join(path.dirname(brokenFile), "held-broken.mcm");
    fs.writeFileSync(held, (await session.activeEditor()).text);
    const errors = checkJson(mercmac, held).filter((d) => d.severity === 0).length;
    fs.rmSync(held);
    const notBuilt = page.locator(".monaco-editor .codelens-decoration", { hasText: /not built while the file has \d+ errors?/ }).first();
    await notBuilt.waitFor({ state: "visible", timeout: 10000 }).catch(async () => {
      const all = await page.locator(".monaco-editor .codelens-decoration").allInnerTexts();
      throw new Error(`broken.mcm shows no "not built while the file has N errors" lens; drawn lenses: ${JSON.stringify(all)}`);
    });
    // the editor may first draw the lens it held for the file's last version: wait for the
    // server's answer to this one
    let said = "";
    await until(`the lens to count ${errors} errors`, async () => {
      said = (await notBuilt.innerText()).trim();
      return said.includes(`has ${errors} error`);
    }, { timeout: 15000 }).catch(() => {
      throw new Error(`the lens says ${JSON.stringify(said)}, mercmac check counts ${errors} errors`);
    });
    c.shots.push(await session.shot("14-code-lens-not-built"));
    c.note(`broken.mcm: ${JSON.stringify(said)} (mercmac check: ${errors} errors)`);
    await session.closeEditors();
  });

  await check("semantic-tokens", options, async (c) => {
    const file = await session.open("four-modes.mcm");
    const text = fs.readFileSync(file, "utf8");
    const answer = await until("semantic tokens from the server", async () => {
      const a = await session.probe(`
        const uri = vscode.window.activeTextEditor.document.uri;
        const legend = await vscode.commands.executeCommand('vscode.provideDocumentSemanticTokensLegend', uri);
        const tokens = await vscode.commands.executeCommand('vscode.provideDocumentSemanticTokens', uri);
        return { legend, data: tokens ? Array.from(tokens.data) : [] };`);
      return a.legend && a.data.length ? a : false;
    }, { timeout: 15000 });
    const tokens = decodeTokens(answer.data, answer.legend);
    const lines = text.split("\n");
    const at = (found, word) => tokens.find((t) => t.line === found.line && t.character === found.character
      && lines[t.line].slice(t.character, t.character + t.length) === word);
    const mnemonic = lineOf(text, /\bBF\b/);
    const constDef = lineOf(text, /const (FAR)\b/);
    const constUse = lineOf(text, /MR (FAR)\b/);
    const macroUse = lineOf(text, /call (init)\b/);
    const wanted = [
      ["mnemonic BF", at({ line: mnemonic.line, character: mnemonic.character }, "BF"), "function", "defaultLibrary"],
      ["const FAR (its definition)", at({ line: constDef.line, character: constDef.character + 6 }, "FAR"), "variable", "readonly"],
      ["const FAR (a use)", at({ line: constUse.line, character: constUse.character + 3 }, "FAR"), "variable", "readonly"],
      ["macro init (call init)", at({ line: macroUse.line, character: macroUse.character + 5 }, "init"), "function", null],
    ];
    const said = [];
    for (const [what, token, type, modifier] of wanted) {
      assert(token, `no semantic token on ${what}`);
      assert(token.type === type && (!modifier || token.modifiers.includes(modifier)),
        `${what} is ${token.type} [${token.modifiers}], want ${type}${modifier ? ` + ${modifier}` : ""}`);
      said.push(`${what}: ${token.type}${token.modifiers.length ? `+${token.modifiers.join("+")}` : ""}`);
    }
    // the colours as drawn: the semantic colour of FAR differs from an unstyled word's
    await session.cursor(constUse.line, 0);
    await sleep(500);
    const colours = await page.locator(".monaco-editor .view-lines").first().evaluate((root) => {
      const colour = {};
      for (const span of root.querySelectorAll("span > span")) {
        const word = span.textContent.trim();
        if (["FAR", "MR", "every", "macro", "init"].includes(word) && !colour[word]) colour[word] = getComputedStyle(span).color;
      }
      return colour;
    });
    c.shots.push(await session.shot("15-semantic-tokens"));
    const distinct = new Set(Object.values(colours)).size;
    c.note(`${tokens.length} tokens (legend ${JSON.stringify(answer.legend.tokenTypes)} / ${JSON.stringify(answer.legend.tokenModifiers)}): ${said.join("; ")}; drawn colours ${JSON.stringify(colours)}`);
    assert(distinct >= 2, `the editor draws these words in one colour: ${JSON.stringify(colours)}`);
    await session.closeEditors();
  });

  await check("folding", options, async (c) => {
    const file = await session.open("four-modes.mcm");
    const text = fs.readFileSync(file, "utf8");
    const lines = text.split("\n");
    const header = lineOf(text, /^\s*macro init\b/);
    const close = lines.findIndex((line, i) => i > header.line && /^}/.test(line));
    const ranges = await until("folding ranges", async () => {
      const list = await session.probe(`
        const uri = vscode.window.activeTextEditor.document.uri;
        return (await vscode.commands.executeCommand('vscode.executeFoldingRangeProvider', uri)) || [];`);
      return list.length ? list : false;
    }, { timeout: 15000 });
    const fold = ranges.find((r) => r.start === header.line);
    assert(fold && fold.end === close - 1,
      `no folding range for macro init from line ${header.line + 1} to ${close} (before its brace): ${JSON.stringify(ranges.map((r) => `${r.start + 1}-${r.end + 1}`))}`);
    await session.cursor(header.line, 4);
    await session.palette("Fold");
    const visible = await until("the macro's body to be hidden", async () => {
      const v = await session.probe("return vscode.window.activeTextEditor.visibleRanges.map((r) => [r.start.line, r.end.line]);");
      const shown = (line) => v.some(([a, b]) => a <= line && line <= b);
      return !shown(header.line + 1) && shown(header.line) && shown(close) ? v : false;
    }, { timeout: 10000 });
    const folded = await page.locator(".monaco-editor .inline-folded, .monaco-editor .codicon-folding-collapsed, .monaco-editor .codicon-folded").count();
    c.shots.push(await session.shot("16-folding"));
    c.note(`the server folds macro init ${fold.start + 1}-${fold.end + 1} (${ranges.length} ranges); Fold on its header hid lines ${header.line + 2}-${fold.end + 1} (visible ranges ${JSON.stringify(visible.map(([a, b]) => `${a + 1}-${b + 1}`))}); ${folded} folded marker(s) drawn`);
    assert(folded > 0, "no folded marker (… or a collapsed chevron) is drawn");
    await session.probe("await vscode.commands.executeCommand('editor.unfoldAll');");
    await session.closeEditors();
  });

  await check("signature-help", options, async (c) => {
    const relative = scratchCopy(session, "four-modes.mcm", "scratch-signature.mcm");
    const file = await session.open(relative);
    const text = fs.readFileSync(file, "utf8");
    const inside = lineOf(text, /^\s*SV 250000$/);
    await session.cursor(inside.line, inside.text.length);
    await page.keyboard.press("Enter");
    await page.keyboard.type("MR ", { delay: 60 });
    const widget = page.locator(".parameter-hints-widget").first();
    await widget.waitFor({ state: "visible", timeout: 10000 });
    let shown = "";
    await until("the signature MR n with its range", async () => {
      shown = (await widget.innerText()).replace(/\s+/g, " ").trim();
      return /\bMR n\b/.test(shown) && /range:/.test(shown);
    }, { timeout: 10000 }).catch(() => { throw new Error(`the signature widget shows ${JSON.stringify(shown)}`); });
    const active = (await widget.locator(".signature .parameter.active").first().innerText().catch(() => "")).trim();
    c.shots.push(await session.shot("17-signature-help"));
    c.note(`typing "MR " inside macro init: ${JSON.stringify(shown.slice(0, 200))}; active parameter ${JSON.stringify(active)}`);
    assert(active === "n", `the active parameter is ${JSON.stringify(active)}, not n`);
    await session.escape();
    await dropScratch(session, relative);
  });

  await check("completion", options, async (c) => {
    const relative = scratchCopy(session, "four-modes.mcm", "scratch-completion.mcm");
    const file = await session.open(relative);
    const text = fs.readFileSync(file, "utf8");
    const names = [...text.matchAll(/^\s*macro\s+(\w+)/gm)].map((m) => m[1]);
    const inside = lineOf(text, /^\s*SV 250000$/);
    await session.cursor(inside.line, inside.text.length);
    await page.keyboard.press("Enter");
    await page.keyboard.type("call ", { delay: 60 });
    const rows = page.locator(".editor-widget.suggest-widget .monaco-list-row .label-name");
    let labels = [];
    await until("the suggestions to list the macros", async () => {
      labels = (await rows.allInnerTexts()).map((t) => t.trim());
      return names.filter((n) => n !== "init").every((n) => labels.includes(n));
    }, { timeout: 10000 }).catch(() => {
      throw new Error(`after "call " the suggestions are ${JSON.stringify(labels)}; the macros are ${JSON.stringify(names)}`);
    });
    c.shots.push(await session.shot("18-completion"));
    await page.keyboard.press("Escape");
    c.note(`"call " inside macro init suggests ${JSON.stringify(labels)}`);
    await dropScratch(session, relative);
  });

  await check("references", options, async (c) => {
    const file = await session.open("four-modes.mcm");
    const text = fs.readFileSync(file, "utf8");
    const header = lineOf(text, /^\s*macro (positions)\b/);
    const uses = text.split("\n").flatMap((line, i) => [...line.replace(/\/\/.*/, "").matchAll(/\bpositions\b/g)].map((m) => `${i}:${m.index}`));
    const refs = await session.probe(`
      const uri = vscode.window.activeTextEditor.document.uri;
      const found = (await vscode.commands.executeCommand('vscode.executeReferenceProvider', uri, new vscode.Position(${header.line}, ${header.character + 6}))) || [];
      return found.map((l) => l.range.start.line + ':' + l.range.start.character);`);
    assert(uses.every((u) => refs.includes(u)) && refs.length === uses.length,
      `references of positions: ${JSON.stringify(refs)}, the file's uses: ${JSON.stringify(uses)}`);
    await session.cursor(header.line, header.character + 8);
    await page.keyboard.press("Shift+F12");
    const peek = page.locator(".monaco-editor .peekview-widget").first();
    await peek.waitFor({ state: "visible", timeout: 10000 });
    let title = "";
    await until("the peek view's title", async () => {
      title = (await peek.locator(".peekview-title").innerText()).replace(/\s+/g, " ").trim();
      // "References (3)" in the title, or "3 references" in older versions
      return new RegExp(`References \\(${uses.length}\\)|\\b${uses.length} references\\b`, "i").test(title);
    }, { timeout: 10000 }).catch(() => { throw new Error(`the peek view says ${JSON.stringify(title)}; want ${uses.length} references`); });
    c.shots.push(await session.shot("19-references"));
    c.note(`Shift+F12 on macro positions: ${JSON.stringify(title)}; the server gives ${refs.length} (lines ${refs.map((r) => Number(r.split(":")[0]) + 1).join(", ")})`);
    await session.escape();
    await session.closeEditors();
  });

  await check("rename", options, async (c) => {
    const relative = scratchCopy(session, "four-modes.mcm", "scratch-rename.mcm");
    const file = await session.open(relative);
    const text = fs.readFileSync(file, "utf8");
    const header = lineOf(text, /^\s*macro (jog)\b/);
    const count = (t, word) => (t.match(new RegExp(`\\b${word}\\b`, "g")) || []).length;
    const before = count(text, "jog");
    await session.cursor(header.line, header.character + 7);
    await page.keyboard.press("F2");
    const input = page.locator(".rename-box input").first();
    await input.waitFor({ state: "visible", timeout: 10000 });
    await input.fill("joggle");
    c.shots.push(await session.shot("20-rename-box"));
    await page.keyboard.press("Enter");
    const after = await until("the rename applied", async () => {
      const t = (await session.activeEditor()).text;
      return count(t, "joggle") === before && count(t, "jog") === 0 ? t : false;
    }, { timeout: 10000 });
    c.shots.push(await session.shot("20-rename-done"));
    const diagnostics = await session.diagnostics(file);
    c.note(`F2 on macro jog, "joggle": ${before} occurrences renamed (${after.split("\n").filter((l) => /\bjoggle\b/.test(l)).map((l) => l.trim()).join(" | ")}); diagnostics after: ${diagnostics.length}`);
    assert(diagnostics.length === 0, `the renamed file has diagnostics: ${JSON.stringify(diagnostics)}`);
    await dropScratch(session, relative);
  });

  await check("rig-format", options, async (c) => {
    await clearNotifications(session);
    const rigFile = path.join("rig", session.rigName);
    const program = session.file(path.join("rig", "x.mcm"));
    const clean = fs.readFileSync(program, "utf8");
    const spoiled = clean.split("\n").map((line) => (line.trim() ? `${line}   ` : line)).join("\n");
    fs.writeFileSync(program, spoiled);
    const want = runOk(mercmac, ["fmt", "-"], { input: spoiled }).stdout;
    assert(want !== spoiled, "the spoiled x.mcm is formatted already: the check would prove nothing");
    const rigText = fs.readFileSync(session.file(rigFile), "utf8");
    await session.open(rigFile);
    await session.palette("Format Document");
    const note = await waitNotification(session, /formatted.*\(the rig file itself is left as written\)/, "the rig's format message", 20000);
    let got = "";
    await until("x.mcm formatted in the editor", async () => {
      got = await session.probe(`return (await vscode.workspace.openTextDocument(vscode.Uri.file(${JSON.stringify(program)}))).getText();`);
      return got === want;
    }, { timeout: 10000 }).catch(() => {
      throw new Error(`x.mcm's text after Format Document of the rig is not \`mercmac fmt\`'s (${JSON.stringify(got.split("\n").slice(0, 3))}…)`);
    });
    const rigNow = (await session.activeEditor()).text;
    c.shots.push(await session.shot("21-rig-format"));
    c.note(`Format Document on ${session.rigName} made x.mcm equal \`mercmac fmt\`'s output (trailing spaces gone); the rig file ${rigNow === rigText ? "unchanged" : "CHANGED"}; notification ${JSON.stringify(note)}`);
    assert(rigNow === rigText, "the rig file's text changed");
    await session.probe("await vscode.commands.executeCommand('workbench.action.files.saveAll');");
    await until("x.mcm saved", () => fs.readFileSync(program, "utf8") === want, { timeout: 10000 });
    await clearNotifications(session);
    await session.closeEditors();
  });

  await check("document-links", options, async (c) => {
    const rigFile = path.join("rig", session.rigName);
    const file = await session.open(rigFile);
    const text = fs.readFileSync(file, "utf8");
    const links = await until("document links", async () => {
      const list = await session.probe(`
        const uri = vscode.window.activeTextEditor.document.uri;
        return ((await vscode.commands.executeCommand('vscode.executeLinkProvider', uri)) || [])
          .map((l) => ({ line: l.range.start.line, character: l.range.start.character, end: l.range.end.character,
                         target: l.target ? l.target.toString() : null, tooltip: l.tooltip || '' }));`);
      return list.length ? list : false;
    }, { timeout: 15000 });
    const targets = links.map((l) => decodeURIComponent(l.target || ""));
    for (const name of ["x.mcm", "y.mcm"]) {
      assert(targets.some((t) => t.endsWith(`/rig/${name}`)), `no link to rig/${name}: ${JSON.stringify(targets)}`);
    }
    const value = lineOf(text, /program = "(x\.mcm)"/);
    const xLink = links.find((l) => l.line === value.line);
    assert(xLink, `no link on line ${value.line + 1} (${value.text.trim()})`);
    assert(text.split("\n")[xLink.line].slice(xLink.character, xLink.end) === "x.mcm",
      `the link on line ${value.line + 1} covers ${JSON.stringify(text.split("\n")[xLink.line].slice(xLink.character, xLink.end))}`);
    // the link as drawn (underlined on hover with Ctrl held), then followed: "Open Link"
    await session.cursor(value.line, xLink.character + 1);
    await session.palette("Open Link");
    const opened = await until("x.mcm opened", async () => {
      const editor = await session.activeEditor();
      return editor && editor.file.endsWith(`${path.sep}rig${path.sep}x.mcm`) ? editor : false;
    }, { timeout: 10000 });
    c.shots.push(await session.shot("22-document-link-followed"));
    c.note(`links in ${session.rigName}: ${links.map((l) => `${l.line + 1}:${l.character + 1} -> ${decodeURIComponent(l.target).split("/").slice(-2).join("/")} (${l.tooltip})`).join("; ")}; Open Link on "x.mcm" opened ${path.relative(session.ws, opened.file)}`);
    await session.closeEditors();
  });

  await check("workspace-symbols", options, async (c) => {
    // only the rig is open: the macro comes from a program it names, not from an open file
    await session.closeEditors();
    const rigFile = path.join("rig", session.rigName);
    await session.open(rigFile);
    const xText = fs.readFileSync(session.file(path.join("rig", "x.mcm")), "utf8");
    const name = lineOf(xText, /^\s*macro (next_row|\w+)\b/).match[1];
    const found = await until(`workspace symbols for ${name}`, async () => {
      const list = await session.probe(`
        return ((await vscode.commands.executeCommand('vscode.executeWorkspaceSymbolProvider', ${JSON.stringify(name)})) || [])
          .map((s) => ({ name: s.name, file: s.location.uri.fsPath, line: s.location.range.start.line }));`);
      return list.some((s) => s.name === name) ? list : false;
    }, { timeout: 15000 });
    const symbol = found.find((s) => s.name === name);
    assert(symbol.file.endsWith(`${path.sep}rig${path.sep}x.mcm`), `${name} is in ${symbol.file}, not rig/x.mcm`);
    await session.probe("await vscode.commands.executeCommand('workbench.action.showAllSymbols');");
    const input = page.locator(".quick-input-widget input");
    await input.waitFor({ state: "visible" });
    await input.fill(`#${name}`);
    let rows = [];
    await until(`the picker to list ${name}`, async () => {
      rows = (await page.locator(".quick-input-widget .monaco-list-row").allInnerTexts()).map((t) => t.replace(/\s+/g, " ").trim());
      return rows.some((r) => r.includes(name) && r.includes("x.mcm"));
    }, { timeout: 15000 }).catch(() => { throw new Error(`Go to Symbol in Workspace "${name}" lists ${JSON.stringify(rows)}`); });
    c.shots.push(await session.shot("23-workspace-symbols"));
    c.note(`"${name}" (a macro of rig/x.mcm, not open; the rig is): the picker lists ${JSON.stringify(rows.slice(0, 4))}; the provider: ${found.map((s) => `${s.name} ${path.relative(session.ws, s.file)}:${s.line + 1}`).join(", ")}`);
    await session.escape();
    await session.closeEditors();
  });

  await check("diagnostic-link", options, async (c) => {
    const file = await session.open("broken.mcm");
    const expected = checkJson(mercmac, file).find((d) => d.code === "MM002");
    const codes = await until("the diagnostic MM002 with its code link", async () => {
      const list = await session.probe(`
        return vscode.languages.getDiagnostics(vscode.Uri.file(${JSON.stringify(file)})).map((d) => ({
          value: d.code && typeof d.code === 'object' ? d.code.value : d.code,
          target: d.code && typeof d.code === 'object' && d.code.target ? d.code.target.toString(true) : null }));`);
      return list.some((d) => d.value === "MM002") ? list : false;
    }, { timeout: 15000 });
    const mm002 = codes.find((d) => d.value === "MM002");
    assert(mm002.target && RULES_URL.test(mm002.target), `MM002's code links to ${mm002.target}, not …/docs/rules.md#mm002-unknown-command`);
    // the hover on the squiggle: the message, and the server's rule summary with its link
    const text = await showHoverAt(session, expected.range[0], expected.range[1] + 1);
    const links = await page.locator(".monaco-hover:not(.hidden) a").evaluateAll((as) => as.map((a) => ({ text: a.textContent.trim(), href: a.getAttribute("data-href") || a.getAttribute("href") || "" })));
    c.shots.push(await session.shot("24-diagnostic-hover"));
    const story = links.find((l) => /The whole story/.test(l.text));
    assert(/MM002/.test(text) && /unknown-command|unknown command/.test(text), `the hover on XM shows ${JSON.stringify(text)}`);
    assert(story && RULES_URL.test(story.href), `the hover has no "The whole story" link to the rule: links ${JSON.stringify(links)}`);
    await session.escape();
    // the Problems panel: the code as a link
    await session.probe("await vscode.commands.executeCommand('workbench.actions.view.problems');");
    const code = page.locator(".markers-panel .monaco-list-row .code-link, .markers-panel .monaco-list-row a.monaco-link", { hasText: "MM002" }).first();
    await code.waitFor({ state: "visible", timeout: 10000 }).catch(async () => {
      const html = await page.locator(".markers-panel .monaco-list-row").first().innerHTML().catch(() => "");
      throw new Error(`the Problems panel shows MM002 as no link: ${html.slice(0, 400)}`);
    });
    const href = await code.evaluate((el) => {
      const a = el.closest("a") || el.querySelector("a") || el;
      return a.getAttribute("href") || a.getAttribute("data-href") || a.title || "";
    });
    c.shots.push(await session.shot("24-diagnostic-problems-link"));
    c.note(`MM002's code target ${mm002.target}; the hover: ${JSON.stringify(text.replace(/\s+/g, " ").slice(0, 160))}, link "${story.text}" -> ${story.href}; the Problems panel draws MM002 as a link (${href || "no href attribute"})`);
    await session.probe("await vscode.commands.executeCommand('workbench.action.closePanel');");
    await session.closeEditors();
  });

  await check("commands", options, async (c) => {
    await clearNotifications(session);
    await session.open("four-modes.mcm");
    const version = run(mercmac, ["--version"]).stdout.trim().match(/version\s+(\S+)/)[1];
    // Show Version
    await session.palette("mercmac: Show Version");
    const shown = await waitNotification(session, new RegExp(`mercmac ${version.replace(/\./g, "\\.")} \\(.*mercmac\\)`), "the version notification");
    c.shots.push(await session.shot("25-command-show-version"));
    assert(shown.includes(mercmac), `the version notification names no ${mercmac}: ${JSON.stringify(shown)}`);
    await clearNotifications(session);
    // Restart Server: a new server process, the status back at "mercmac <version>", diagnostics again
    const before = session.serverProcesses().map((p) => p.pid);
    assert(before.length === 1, `before the restart ${before.length} mercmac lsp processes run: ${JSON.stringify(session.serverProcesses())}`);
    const broken = session.file("broken.mcm");
    await session.open("broken.mcm");
    await until("broken.mcm's diagnostics", async () => (await session.diagnostics(broken)).length > 0, { timeout: 15000 });
    await session.palette("mercmac: Restart Server");
    const after = await until("a new server process", () => {
      const now = session.serverProcesses().map((p) => p.pid);
      return now.length === 1 && !before.includes(now[0]) ? now : false;
    }, { timeout: 20000 });
    const diagnostics = await until("diagnostics after the restart", async () => {
      const list = await session.diagnostics(broken);
      return list.length === checkJson(mercmac, broken).length ? list : false;
    }, { timeout: 20000 });
    let statusNow = "";
    await until(`the language status "mercmac ${version}"`, async () => {
      statusNow = await languageStatusText(session);
      return statusNow.includes(`mercmac ${version}`);
    }, { timeout: 20000 }).catch(() => { throw new Error(`the language status says ${JSON.stringify(statusNow)}`); });
    session.keepMouse = true;
    c.shots.push(await session.shot("25-command-restart-server"));
    session.keepMouse = false;
    await session.escape();
    // Show Server Log
    await session.probe("await vscode.commands.executeCommand('workbench.action.closePanel');");
    await session.palette("mercmac: Show Server Log");
    let channel = "";
    await until("the Output panel on the channel mercmac", async () => {
      channel = await page.locator(".part.panel .monaco-select-box").first().evaluate((box) =>
        box.tagName === "SELECT" ? box.options[box.selectedIndex].text : box.textContent, null, { timeout: 2000 }).catch(() => "");
      return /^mercmac$/.test(channel.trim()) && await page.locator(".part.panel .monaco-editor .view-lines").first().isVisible();
    }, { timeout: 10000 }).catch(() => { throw new Error(`the panel shows the channel ${JSON.stringify(channel)}`); });
    const logText = await page.locator(".part.panel .monaco-editor .view-lines").first().innerText();
    c.shots.push(await session.shot("25-command-show-server-log"));
    c.note(`Show Version: ${JSON.stringify(shown)}; Restart Server: server pid ${before[0]} -> ${after[0]}, language status ${JSON.stringify(statusNow)}, ${diagnostics.length} diagnostics of broken.mcm again; Show Server Log: the Output panel on ${JSON.stringify(channel.trim())} (${logText.split("\n").filter((l) => l.trim()).length} lines shown)`);
    await session.probe("await vscode.commands.executeCommand('workbench.action.closePanel');");
    await session.closeEditors();
  });

  await check("icon", options, async (c) => {
    await session.closeEditors();
    await session.probe("await vscode.commands.executeCommand('workbench.view.explorer');");
    const theme = await session.probe("return vscode.workspace.getConfiguration('workbench').get('iconTheme');");
    const folders = page.locator(".sidebar .pane-header", { hasText: path.basename(session.ws) }).first();
    if ((await folders.getAttribute("aria-expanded")) === "false") await folders.click();
    const row = page.locator(".explorer-folders-view .monaco-list-row", { hasText: "four-modes.mcm" }).first();
    await row.waitFor({ state: "visible", timeout: 10000 });
    let icon;
    await until("the explorer's .mcm icon", async () => {
      icon = await row.locator(".monaco-icon-label").first().evaluate((label) => {
        const before = getComputedStyle(label, "::before");
        return { classes: label.className, image: before.backgroundImage, content: before.content, font: before.fontFamily };
      });
      return /mcm\.svg/.test(icon.image);
    }, { timeout: 10000 }).catch(() => undefined);
    c.shots.push(await session.shot("26-icon"));
    c.note(`icon theme ${JSON.stringify(theme)}; four-modes.mcm's label classes ${JSON.stringify(icon && icon.classes.split(" ").filter((k) => /icon|mcm/.test(k)))}, ::before background-image ${JSON.stringify(icon && icon.image)}`);
    assert(icon && /mcm\.svg/.test(icon.image), "the explorer's icon of four-modes.mcm does not use the extension's icons/mcm.svg");
  });
}

/** The language status ({} in the status bar): the text of its hover. */
async function languageStatusText(session) {
  const { page } = session;
  const item = page.locator("#status\\.languageStatus").first();
  if (!(await item.count())) return "";
  const hover = page.locator(".monaco-hover:not(.hidden), .workbench-hover-container").last();
  await page.keyboard.press("Escape");
  await item.click();
  await hover.waitFor({ state: "visible", timeout: 5000 }).catch(() => undefined);
  await sleep(300);
  return (await hover.innerText().catch(() => "")).replace(/\s+/g, " ").trim();
}

export { languageStatusText, hoverText };
