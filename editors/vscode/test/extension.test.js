// The extension as VS Code runs it: dist/extension.js (the esbuild bundle that the .vsix
// holds, with the real vscode-languageclient inside) activated with a stand-in for the editor
// API (test/vscode.js). The client spawns the server and must get its answer to `initialize`.
// MERCMAC_BIN names the mercmac executable under test (default: `mercmac` on PATH).
"use strict";
const assert = require("node:assert");
const fs = require("node:fs");
const os = require("node:os");
const path = require("node:path");
const test = require("node:test");
const { makeVscode, requireWith } = require("./vscode");

const BUNDLE = path.join(__dirname, "..", "dist", "extension.js");
const MERCMAC = process.env.MERCMAC_BIN || "mercmac";

/** A wrapper executable that records its arguments in LOG, then runs mercmac with them. */
function recordingMercmac(dir) {
  const log = path.join(dir, "argv.log");
  const wrapper = path.join(dir, "mercmac-wrapper");
  fs.writeFileSync(wrapper, `#!/bin/sh\nprintf '%s\\n' "$*" >> '${log}'\nexec '${MERCMAC}' "$@"\n`, { mode: 0o755 });
  return { wrapper, log };
}

async function activated(settings) {
  const editor = makeVscode(settings);
  const extension = requireWith(editor.vscode, BUNDLE);
  const context = { subscriptions: [] };
  await extension.activate(context);
  return { ...editor, extension, context };
}

test("the bundle exists (npm run build)", () => {
  assert.ok(fs.existsSync(BUNDLE), "run `npm run build` first");
});

test("the client spawns `mercmac lsp --stdio` and the server answers initialize", async () => {
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), "mercmac-vscode-"));
  const { wrapper, log } = recordingMercmac(dir);
  const { extension, seen } = await activated({ "mercmac.path": wrapper });
  const client = extension.current();
  assert.ok(client, `no client: ${seen.errors.join(" | ")}`);
  assert.strictEqual(client.initializeResult.serverInfo.name, "mercmac");
  assert.deepStrictEqual(fs.readFileSync(log, "utf8").trim().split("\n"), ["lsp --stdio"]);
  assert.deepStrictEqual(seen.errors, []);
  await extension.deactivate();
});

test("a mercmac that is not there: a message that says how to fix it", async () => {
  const { extension, seen } = await activated({ "mercmac.path": "/nonexistent/bin/mercmac" });
  assert.strictEqual(extension.current(), undefined);
  const message = seen.errors.find((m) => m.startsWith("mercmac:"));
  assert.ok(message, `no message of ours among: ${seen.errors.join(" | ")}`);
  assert.match(message, /\/nonexistent\/bin\/mercmac' was not found/);
  assert.match(message, /mercmac\.path/);
  assert.match(message, /pip install 'mercmac\[lsp\]'/);
  await extension.deactivate();
});

test("a change of mercmac.path restarts the client with the new executable", async () => {
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), "mercmac-vscode-"));
  const first = recordingMercmac(fs.mkdtempSync(path.join(dir, "a-")));
  const second = recordingMercmac(fs.mkdtempSync(path.join(dir, "b-")));
  const { extension, seen, change } = await activated({ "mercmac.path": first.wrapper });
  const before = extension.current();
  change("mercmac.path", second.wrapper);
  await new Promise((resolve) => setTimeout(resolve, 0));
  const restarted = await waitFor(() => {
    const now = extension.current();
    return now && now !== before && now.initializeResult ? now : undefined;
  });
  assert.strictEqual(restarted.initializeResult.serverInfo.name, "mercmac");
  assert.ok(!before.isRunning(), "the old client was not stopped");
  assert.deepStrictEqual(fs.readFileSync(second.log, "utf8").trim().split("\n"), ["lsp --stdio"]);
  assert.deepStrictEqual(seen.infos.filter((m) => /reload/i.test(m)), []);
  await extension.deactivate();
});

test("package.json contributes the language, its grammar and the settings", () => {
  const pkg = require("../package.json");
  assert.deepStrictEqual(pkg.activationEvents,
    ["onLanguage:mcm", "workspaceContains:**/*.rig.toml"]);
  assert.strictEqual(pkg.main, "./dist/extension.js");
  assert.deepStrictEqual(pkg.contributes.languages[0].extensions, [".mcm"]);
  assert.strictEqual(pkg.contributes.grammars[0].scopeName, "source.mcm");
  const settings = pkg.contributes.configuration.properties;
  assert.strictEqual(settings["mercmac.path"].default, "mercmac");
  for (const key of ["target", "select", "ignore"]) assert.ok(settings[`mercmac.${key}`], key);
});

async function waitFor(probe, ms = 20000) {
  const end = Date.now() + ms;
  for (;;) {
    const value = probe();
    if (value) return value;
    if (Date.now() > end) throw new Error("timed out");
    await new Promise((resolve) => setTimeout(resolve, 50));
  }
}

test("rig files go to the server too, by name: they are TOML, not mcm", () => {
  const extension = requireWith(makeVscode({}).vscode, BUNDLE);
  const selector = extension.clientOptions().documentSelector;
  assert.ok(selector.some((s) => s.scheme === "file" && s.pattern === "**/*.rig.toml"),
    JSON.stringify(selector));
  assert.ok(selector.some((s) => s.language === "mcm"));
});
