// The extension as VS Code runs it: dist/extension.js (the esbuild bundle that the .vsix
// holds, with the real vscode-languageclient inside) activated with a stand-in for the editor
// API (test/vscode.js), against the real mercmac: MERCMAC_BIN names it (default: `mercmac`
// on PATH); the tests that need it skip, saying so, when there is none.
// The client's lifecycle against stand-in servers is in lifecycle.test.js.
"use strict";
const assert = require("node:assert");
const fs = require("node:fs");
const test = require("node:test");
const { makeVscode, requireWith, activated, deactivateAll, waitFor, BUNDLE } = require("./vscode");
const { recordingMercmac, realMercmac } = require("./fakes");

test.afterEach(deactivateAll);

const MERCMAC = realMercmac();
const NO_MERCMAC = "no mercmac to test against: MERCMAC_BIN is unset and `mercmac` is not on PATH";

test("the bundle exists (npm run build)", () => {
  assert.ok(fs.existsSync(BUNDLE), "run `npm run build` first");
});

test("the client spawns `mercmac lsp --stdio` and the server answers initialize", async (t) => {
  if (!MERCMAC) return t.skip(NO_MERCMAC);
  const wrapper = recordingMercmac(MERCMAC);
  const { extension, seen } = await activated({ "mercmac.path": wrapper.path });
  const client = extension.current();
  assert.ok(client, `no client: ${seen.errors.join(" | ")}`);
  assert.strictEqual(client.initializeResult.serverInfo.name, "mercmac");
  assert.deepStrictEqual(wrapper.starts(), ["lsp --stdio"]);
  assert.deepStrictEqual(seen.errors, []);
  assert.match(seen.statusItems[0].text, /^mercmac \d/);
  await extension.deactivate();
  return undefined;
});

test("a mercmac that is not there: one message that says how to fix it", async () => {
  const { extension, seen } = await activated({ "mercmac.path": "/nonexistent/bin/mercmac" });
  assert.strictEqual(extension.current(), undefined);
  assert.strictEqual(seen.messages.length, 1, JSON.stringify(seen.messages));
  const [{ kind, text, items }] = seen.messages;
  assert.strictEqual(kind, "error");
  assert.match(text, /^mercmac: .*'\/nonexistent\/bin\/mercmac' was not found/);
  assert.match(text, /mercmac\.path/);
  assert.match(text, /pip install 'mercmac\[lsp\]'/);
  assert.doesNotMatch(text, /`/, "notifications are plain text: no Markdown backticks");
  assert.ok(items.includes("Open Settings"), JSON.stringify(items));
  assert.strictEqual(seen.statusItems[0].text, "mercmac: not found");
  await extension.deactivate();
});

test("the not-found message's Open Settings opens the mercmac.path setting", async () => {
  const { extension, seen } = await activated({ "mercmac.path": "/nonexistent/bin/mercmac" },
    { answer: (text, items) => items.find((item) => item === "Open Settings") });
  await waitFor(() => seen.executed.length);
  assert.deepStrictEqual(seen.executed, [["workbench.action.openSettings", "mercmac.path"]]);
  await extension.deactivate();
});

test("a change of mercmac.path restarts the client with the new executable", async (t) => {
  if (!MERCMAC) return t.skip(NO_MERCMAC);
  const first = recordingMercmac(MERCMAC);
  const second = recordingMercmac(MERCMAC);
  const { extension, seen, change } = await activated({ "mercmac.path": first.path });
  const before = extension.current();
  assert.ok(before, `no client: ${seen.errors.join(" | ")}`);
  change("mercmac.path", second.path);
  const restarted = await waitFor(() => {
    const now = extension.current();
    return now && now !== before && now.initializeResult ? now : undefined;
  });
  assert.strictEqual(restarted.initializeResult.serverInfo.name, "mercmac");
  assert.ok(!before.isRunning(), "the old client was not stopped");
  assert.deepStrictEqual(second.starts(), ["lsp --stdio"]);
  assert.deepStrictEqual(seen.infos.filter((m) => /reload/i.test(m)), []);
  assert.deepStrictEqual(seen.errors, []);
  await extension.deactivate();
  return undefined;
});

test("Show Version names the running mercmac's version and path", async (t) => {
  if (!MERCMAC) return t.skip(NO_MERCMAC);
  const { extension, seen, vscode } = await activated({ "mercmac.path": MERCMAC });
  const version = extension.current().initializeResult.serverInfo.version;
  assert.ok(version, "the server gives no version in serverInfo");
  await vscode.commands.executeCommand("mercmac.showVersion");
  assert.strictEqual(seen.infos.length, 1, JSON.stringify(seen.infos));
  assert.ok(seen.infos[0].includes(`mercmac ${version} (`) && seen.infos[0].includes(MERCMAC), seen.infos[0]);
  await extension.deactivate();
  return undefined;
});

test("rig files go to the server too, by name: they are TOML, not mcm", () => {
  const extension = requireWith(makeVscode({}).vscode, BUNDLE);
  const selector = extension.clientOptions().documentSelector;
  assert.ok(selector.some((s) => s.scheme === "file" && s.pattern === "**/*.rig.toml"),
    JSON.stringify(selector));
  assert.ok(selector.some((s) => s.language === "mcm"));
});
