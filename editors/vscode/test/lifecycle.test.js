// The client's life against stand-in servers (test/fakes.js), no Python needed: a mercmac
// without the lsp extra, a server that crashes, restarts, workspace trust.
"use strict";
const assert = require("node:assert");
const test = require("node:test");
const { activated, deactivateAll, waitFor, pause } = require("./vscode");
const { fakeMercmac, mercmacWithoutLsp, NO_LSP_EXTRA } = require("./fakes");

test.afterEach(deactivateAll);

const REASON = NO_LSP_EXTRA.replace(/^mercmac: /, "");

test("mercmac without the lsp extra: one message quoting its reason, no restart", async () => {
  const mercmac = mercmacWithoutLsp();
  const { extension, seen } = await activated({ "mercmac.path": mercmac.path });
  await pause(500); // time for a restart or a late notification, which must not come
  assert.strictEqual(extension.current(), undefined);
  assert.strictEqual(seen.messages.length, 1, JSON.stringify(seen.messages, null, 1));
  const [{ kind, text, items }] = seen.messages;
  assert.strictEqual(kind, "error");
  assert.ok(text.includes(REASON), text);
  assert.ok(text.startsWith("mercmac: "), text);
  assert.ok(items.includes("Show Server Log"), JSON.stringify(items));
  assert.deepStrictEqual(mercmac.starts(), ["lsp --stdio"]);
  assert.strictEqual(seen.statusItems[0].text, "mercmac: needs the lsp extra");
  assert.ok(seen.output.join("").includes(NO_LSP_EXTRA), "its stderr is in the log");
  await extension.deactivate();
});

test("Show Server Log on that message shows the one log channel", async () => {
  const { extension, seen } = await activated({ "mercmac.path": mercmacWithoutLsp().path },
    { answer: (text, items) => items.find((item) => item === "Show Server Log") });
  await waitFor(() => seen.channels[0].shown);
  assert.strictEqual(seen.channels.length, 1);
  await extension.deactivate();
});

test("Restart Server twice: one log channel, each old client disposed", async () => {
  const mercmac = fakeMercmac();
  const { extension, seen, vscode } = await activated({ "mercmac.path": mercmac.path });
  const clients = [extension.current()];
  assert.ok(clients[0], `no client: ${seen.errors.join(" | ")}`);
  for (let i = 0; i < 2; i += 1) {
    await vscode.commands.executeCommand("mercmac.restartServer");
    clients.push(extension.current());
  }
  assert.strictEqual(new Set(clients).size, 3);
  assert.ok(clients[2] && clients[2].isRunning());
  assert.strictEqual(seen.channels.length, 1, seen.channels.map((c) => c.name).join(", "));
  for (const client of clients) assert.strictEqual(client.outputChannel, seen.channels[0]);
  for (const old of clients.slice(0, 2)) {
    assert.ok(!old.isRunning());
    await assert.rejects(old.start(), /disposed/); // vscode-languageclient 9: dispose, not stop
  }
  assert.deepStrictEqual(mercmac.starts(), ["lsp --stdio", "lsp --stdio", "lsp --stdio"]);
  assert.deepStrictEqual(seen.errors, []);
  await extension.deactivate();
  assert.ok(!clients[2].isRunning());
});

test("a change of mercmac.path restarts without a second log channel", async () => {
  const first = fakeMercmac();
  const second = fakeMercmac();
  const { extension, seen, change } = await activated({ "mercmac.path": first.path });
  const before = extension.current();
  change("mercmac.path", second.path);
  await waitFor(() => extension.current() && extension.current() !== before);
  assert.strictEqual(seen.channels.length, 1);
  assert.deepStrictEqual(second.starts(), ["lsp --stdio"]);
  await extension.deactivate();
});

test("a server that crashes once running is restarted 4 times, then one message", async () => {
  const mercmac = fakeMercmac("crash");
  const { extension, seen } = await activated({ "mercmac.path": mercmac.path });
  await waitFor(() => seen.messages.length);
  await pause(300);
  assert.strictEqual(mercmac.starts().length, 5);
  assert.strictEqual(seen.messages.length, 1, JSON.stringify(seen.messages, null, 1));
  assert.match(seen.messages[0].text, /stopped \(code 1\) 5 times .*: fake mercmac: boom$/);
  assert.strictEqual(seen.statusItems[0].text, "mercmac: stopped");
  assert.strictEqual(seen.channels.length, 1);
  await extension.deactivate();
});

test("the status item names the running mercmac's version and path", async () => {
  const mercmac = fakeMercmac();
  const { extension, seen } = await activated({ "mercmac.path": mercmac.path });
  const [item] = seen.statusItems;
  assert.strictEqual(item.text, "mercmac 9.9.9-fake");
  assert.strictEqual(item.detail, mercmac.path);
  assert.strictEqual(item.command.command, "mercmac.showServerLog");
  assert.deepStrictEqual(item.selector, [{ language: "mcm" }, { pattern: "**/*.rig.toml" }]);
  await extension.deactivate();
});

test("an untrusted workspace: no server until trust is granted", async () => {
  const mercmac = fakeMercmac();
  const { extension, seen, grantTrust, vscode } = await activated({ "mercmac.path": mercmac.path },
    { trusted: false });
  await pause(200);
  assert.deepStrictEqual(mercmac.starts(), [], "it ran the executable in Restricted Mode");
  assert.strictEqual(extension.current(), undefined);
  assert.match(seen.statusItems[0].text, /waiting for workspace trust/);
  await vscode.commands.executeCommand("mercmac.restartServer");
  assert.deepStrictEqual(mercmac.starts(), []);
  assert.deepStrictEqual(seen.errors, []);
  grantTrust();
  const client = await waitFor(() => extension.current());
  assert.strictEqual(client.initializeResult.serverInfo.version, "9.9.9-fake");
  assert.deepStrictEqual(mercmac.starts(), ["lsp --stdio"]);
  assert.strictEqual(seen.statusItems[0].text, "mercmac 9.9.9-fake");
  await extension.deactivate();
});

test("the trace setting goes to the one log channel", async () => {
  const mercmac = fakeMercmac();
  const { extension, seen } = await activated({ "mercmac.path": mercmac.path, "mercmac.trace.server": "messages" });
  assert.ok(seen.output.join("").includes("Received response 'initialize"), seen.output.join(""));
  assert.strictEqual(seen.channels.length, 1);
  await extension.deactivate();
});
