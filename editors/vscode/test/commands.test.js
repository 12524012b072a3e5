// What package.json contributes, and the commands, against stand-in servers (test/fakes.js).
"use strict";
const assert = require("node:assert");
const fs = require("node:fs");
const path = require("node:path");
const test = require("node:test");
const { activated, deactivateAll, waitFor, makeVscode, requireWith, BUNDLE } = require("./vscode");
const { fakeMercmac, mercmacWithoutLsp } = require("./fakes");

const ROOT = path.join(__dirname, "..");
const pkg = require("../package.json");

test.afterEach(deactivateAll);

test("package.json contributes the language, its grammar and the settings", () => {
  assert.deepStrictEqual(pkg.activationEvents,
    ["onLanguage:mcm", "workspaceContains:**/*.rig.toml"]);
  assert.strictEqual(pkg.main, "./dist/extension.js");
  const [language] = pkg.contributes.languages;
  assert.deepStrictEqual(language.extensions, [".mcm"]);
  for (const theme of ["light", "dark"]) {
    assert.ok(fs.existsSync(path.join(ROOT, language.icon[theme])), `no ${theme} icon`);
  }
  assert.strictEqual(pkg.contributes.grammars[0].scopeName, "source.mcm");
  const settings = pkg.contributes.configuration.properties;
  assert.strictEqual(settings["mercmac.path"].default, "mercmac");
  for (const key of ["target", "select", "ignore"]) assert.ok(settings[`mercmac.${key}`], key);
  // vscode-languageclient reads `<client id>.trace.server`; the client's id is "mercmac"
  assert.deepStrictEqual(settings["mercmac.trace.server"].enum, ["off", "messages", "verbose"]);
  assert.strictEqual(settings["mercmac.trace.server"].default, "off");
  for (const [key, setting] of Object.entries(settings)) {
    // `description` is plain text: code formatting needs markdownDescription
    assert.ok(!/`/.test(setting.description || ""), `${key}: backticks in a plain description`);
  }
});

test("package.json: Restricted Mode keeps highlighting, not the server", () => {
  const trust = pkg.capabilities.untrustedWorkspaces;
  assert.strictEqual(trust.supported, "limited");
  assert.ok(trust.description);
  assert.deepStrictEqual(trust.restrictedConfigurations, ["mercmac.path"]);
});

test("the commands are declared and registered; copyBuild is not in the palette", async () => {
  const declared = pkg.contributes.commands.map((c) => c.command).sort();
  assert.deepStrictEqual(declared, ["mercmac.copyBuild", "mercmac.restartServer", "mercmac.showServerLog",
    "mercmac.showVersion", "mercmac.simulate"]);
  const titles = Object.fromEntries(pkg.contributes.commands.map((c) => [c.command, `${c.category}: ${c.title}`]));
  assert.strictEqual(titles["mercmac.restartServer"], "mercmac: Restart Server");
  assert.strictEqual(titles["mercmac.showServerLog"], "mercmac: Show Server Log");
  assert.strictEqual(titles["mercmac.showVersion"], "mercmac: Show Version");
  assert.strictEqual(titles["mercmac.simulate"], "mercmac: Simulate");
  const palette = pkg.contributes.menus.commandPalette;
  assert.deepStrictEqual(palette.map((m) => m.command), ["mercmac.copyBuild", "mercmac.simulate"]);
  assert.strictEqual(palette[0].when, "false");
  // Simulate: in the palette for .mcm and rig files, and a button on their editors' title
  for (const menu of [palette[1], ...pkg.contributes.menus["editor/title"]]) {
    assert.strictEqual(menu.command, "mercmac.simulate");
    assert.match(menu.when, /resourceExtname == \.mcm/);
    assert.ok(menu.when.includes("resourceFilename =~ /\\.rig\\.toml$/"), menu.when);
  }
  const { vscode } = await activated({ "mercmac.path": fakeMercmac().path });
  assert.deepStrictEqual((await vscode.commands.getCommands()).sort(), declared);
});

test("copyBuild copies the lens's MD lines and says so", async () => {
  const { vscode, seen } = await activated({ "mercmac.path": fakeMercmac().path });
  await vscode.commands.executeCommand("mercmac.copyBuild",
    { macro: "scan", lines: ["MD0,MR1000", "MD0,WS", "MD0,MR-1000"] });
  assert.strictEqual(seen.clipboard, "MD0,MR1000\nMD0,WS\nMD0,MR-1000");
  assert.deepStrictEqual(seen.infos, ["Copied the 3 MD lines of scan"]);
  await vscode.commands.executeCommand("mercmac.copyBuild", { macro: "home", lines: ["MD1,FE2"] });
  assert.strictEqual(seen.clipboard, "MD1,FE2");
  assert.strictEqual(seen.infos[1], "Copied the MD line of home");
});

test("Show Server Log shows the one log channel", async () => {
  const { vscode, seen } = await activated({ "mercmac.path": fakeMercmac().path });
  await vscode.commands.executeCommand("mercmac.showServerLog");
  assert.strictEqual(seen.channels.length, 1);
  assert.strictEqual(seen.channels[0].shown, 1);
  assert.ok(seen.output.join("").includes("fake mercmac 9.9.9-fake: serving"), "stderr is not in the log");
});

test("Show Version: the running server's version and path", async () => {
  const mercmac = fakeMercmac();
  const { vscode, seen } = await activated({ "mercmac.path": mercmac.path });
  await vscode.commands.executeCommand("mercmac.showVersion");
  assert.deepStrictEqual(seen.infos, [`mercmac 9.9.9-fake (${mercmac.path}) is the running language server.`]);
});

test("Show Version without a server: what --version says, and why it is not running", async () => {
  const mercmac = mercmacWithoutLsp();
  const { vscode, seen } = await activated({ "mercmac.path": mercmac.path });
  await vscode.commands.executeCommand("mercmac.showVersion");
  assert.strictEqual(seen.infos.length, 1);
  assert.strictEqual(seen.infos[0],
    `mercmac 0.1.0 (${mercmac.path}); the language server is not running: needs the lsp extra.`);
  assert.deepStrictEqual(mercmac.starts(), ["lsp --stdio", "--version"]);
});

test("Show Version when mercmac is not there, and in Restricted Mode", async () => {
  const missing = await activated({ "mercmac.path": "/nonexistent/bin/mercmac" });
  await missing.vscode.commands.executeCommand("mercmac.showVersion");
  assert.match(missing.seen.infos[0], /^mercmac: '\/nonexistent\/bin\/mercmac' was not found\. Install it/);
  const mercmac = fakeMercmac();
  const untrusted = await activated({ "mercmac.path": mercmac.path }, { trusted: false });
  await untrusted.vscode.commands.executeCommand("mercmac.showVersion");
  assert.match(untrusted.seen.infos[0], /waiting for workspace trust/);
  assert.deepStrictEqual(mercmac.starts(), [], "it ran the executable in Restricted Mode");
});

test("messages are plain text: no Markdown backticks", () => {
  const extension = requireWith(makeVscode({}).vscode, BUNDLE);
  for (const code of ["ENOENT", "EACCES", undefined]) {
    const { text } = extension.describeFailure({ command: "mercmac", error: { code, message: "boom" },
      stderr: ["Traceback", "ImportError: no `x`"], exit: { code: 1 } });
    assert.ok(!/`/.test(text.replace("no `x`", "")), text);
  }
});

test("the status item offers Open Settings when mercmac is not found", async () => {
  const { seen } = await activated({ "mercmac.path": "/nonexistent/bin/mercmac" });
  const [item] = seen.statusItems;
  assert.strictEqual(item.text, "mercmac: not found");
  assert.strictEqual(item.severity, 2);
  assert.deepStrictEqual([item.command.command, ...item.command.arguments],
    ["workbench.action.openSettings", "mercmac.path"]);
  await waitFor(() => seen.errors.length);
});
