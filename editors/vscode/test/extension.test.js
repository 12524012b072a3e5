// The client starts `mercmac lsp` (or the `mercmac.path` setting) for .mcm documents.
// `vscode` exists only inside VS Code: a stand-in records what the extension asks of it.
"use strict";
const assert = require("node:assert");
const Module = require("node:module");
const test = require("node:test");

function load(settings) {
  const made = [];
  const vscode = {
    workspace: {
      getConfiguration: (section) => ({ get: (key) => settings[`${section}.${key}`] }),
      onDidChangeConfiguration: () => ({ dispose() {} }),
    },
    window: { showInformationMessage() {} },
  };
  class LanguageClient {
    constructor(id, name, server, options) { made.push({ id, server, options }); }
    start() { return Promise.resolve(); }
    stop() { return Promise.resolve(); }
  }
  const stubs = { vscode, "vscode-languageclient/node": { LanguageClient, TransportKind: { stdio: 0 } } };
  const original = Module._load;
  Module._load = (request, ...rest) => stubs[request] || original(request, ...rest);
  try {
    delete require.cache[require.resolve("../extension.js")];
    const extension = require("../extension.js");
    return { extension, made };
  } finally {
    Module._load = original;
  }
}

test("activate starts `mercmac lsp` for mcm documents", async () => {
  const { extension, made } = load({});
  await extension.activate({ subscriptions: [] });
  assert.strictEqual(made.length, 1);
  assert.strictEqual(made[0].server.command, "mercmac");
  assert.deepStrictEqual(made[0].server.args, ["lsp"]);
  assert.ok(made[0].options.documentSelector.every((s) => s.language === "mcm"));
  await extension.deactivate();
});

test("mercmac.path chooses the executable", async () => {
  const { extension, made } = load({ "mercmac.path": "/opt/venv/bin/mercmac" });
  await extension.activate({ subscriptions: [] });
  assert.strictEqual(made[0].server.command, "/opt/venv/bin/mercmac");
});

test("package.json contributes the language, its grammar and the setting", () => {
  const pkg = require("../package.json");
  assert.deepStrictEqual(pkg.activationEvents, ["onLanguage:mcm"]);
  assert.strictEqual(pkg.main, "./extension.js");
  assert.deepStrictEqual(pkg.contributes.languages[0].extensions, [".mcm"]);
  assert.strictEqual(pkg.contributes.grammars[0].scopeName, "source.mcm");
  assert.strictEqual(pkg.contributes.configuration.properties["mercmac.path"].default, "mercmac");
});
