// mercmac.simulate: `mercmac sim FILE --web --no-open` and its page in a webview panel (a
// stand-in, test/vscode.js), the extension relaying the page's actions and the event stream.
// Against the stand-in server (test/fake-sim.js, no Python needed) always, and against the
// real mercmac (MERCMAC_BIN, else `mercmac` on PATH) when there is one.
"use strict";
const assert = require("node:assert");
const fs = require("node:fs");
const path = require("node:path");
const test = require("node:test");
const vm = require("node:vm");
const { activated, deactivateAll, waitFor, pause } = require("./vscode");
const { fakeMercmac, realMercmac, recordingMercmac, shellWrappedMercmac, tempDir } = require("./fakes");
const { descendants } = require("../src/server");

test.afterEach(deactivateAll);

const MERCMAC = realMercmac();
const NO_MERCMAC = "no mercmac to test against: MERCMAC_BIN is unset and `mercmac` is not on PATH";
const EXAMPLE = path.join(__dirname, "..", "..", "..", "examples", "macros", "four-modes.mcm");
const BROKEN = "macro init {\n  XM 1\n}\n"; // an unknown command: check reports MM002

/** NAME in a fresh folder, holding TEXT (default: the example four-modes.mcm). */
function program(name = "four-modes.mcm", text = fs.readFileSync(EXAMPLE, "utf8")) {
  const file = path.join(tempDir(), name);
  fs.writeFileSync(file, text);
  return file;
}

function alive(pid) {
  try {
    process.kill(pid, 0);
    return true;
  } catch {
    return false;
  }
}

/** The page's message ID answered: {type: "reply", id, value | error}. */
function reply(panel, id) {
  return waitFor(() => panel.posted.find((m) => m.type === "reply" && m.id === id), 10000);
}

/** The states the panel was sent so far, parsed. */
function states(panel) {
  return panel.posted.filter((m) => m.type === "event").map((m) => JSON.parse(m.data));
}

/** Simulate FILE the way the server's lens does ({uri}); the panel it opened. */
async function simulate(editor, file) {
  const before = editor.seen.errors.length;
  await editor.vscode.commands.executeCommand("mercmac.simulate", { uri: editor.vscode.Uri.file(file).toString() });
  assert.deepStrictEqual(editor.seen.errors.slice(before), [], "an error message");
  return editor.seen.panels[editor.seen.panels.length - 1];
}

/** The whole round: the page, the stream, a press, a refused press, a scenario, the panel
 *  again, the panel closed. */
async function roundTrip(mercmacPath) {
  const file = program();
  const editor = await activated({ "mercmac.path": mercmacPath }, { saveAs: (options) => options.defaultUri });
  const { extension, seen, vscode } = editor;
  const panel = await simulate(editor, file);
  assert.ok(panel, "no panel");
  assert.strictEqual(panel.title, "Simulate four-modes.mcm");
  assert.deepStrictEqual(panel.showOptions, { viewColumn: vscode.ViewColumn.Beside, preserveFocus: true });
  assert.strictEqual(panel.options.enableScripts, true);
  assert.strictEqual(panel.options.retainContextWhenHidden, true);
  assert.match(panel.webview.html, /<script nonce="[^"]+">\(function/, "no bridge script");
  assert.ok(panel.webview.html.includes("mercmacBridge"), "no app.js inside");
  const [{ pid }] = extension.simulating();
  assert.ok(alive(pid));

  panel.send({ type: "events" });
  await waitFor(() => panel.posted.some((m) => m.type === "open"), 10000);
  await waitFor(() => states(panel).length >= 3, 10000);
  const first = states(panel)[0];
  assert.ok(Number.isFinite(first.t_ms), JSON.stringify(first));
  const controller = first.controllers[0].name;

  panel.send({ type: "post", id: 1, path: "/api/press", body: { controller, button: 1, down: true } });
  assert.deepStrictEqual(await reply(panel, 1), { type: "reply", id: 1 });
  await waitFor(() => states(panel).some((s) => s.controllers[0].buttons[0] === true), 10000);
  panel.send({ type: "post", id: 2, path: "/api/press", body: { controller, button: 1, down: false } });
  assert.strictEqual((await reply(panel, 2)).error, undefined);

  panel.send({ type: "post", id: 3, path: "/api/press", body: { controller, button: 9, down: true } });
  assert.match((await reply(panel, 3)).error, /^\/api\/press: 400 no button 9 on a controller/);
  panel.send({ type: "post", id: 4, path: "/api/scenario", body: {} });
  assert.match((await reply(panel, 4)).error, /not an action of the page/);

  panel.send({ type: "saveScenario", id: 5 });
  assert.strictEqual((await reply(panel, 5)).value,
    "Saved four-modes.scenario.toml (replay with mercmac sim four-modes.mcm --scenario four-modes.scenario.toml)");
  const scenario = path.join(path.dirname(file), "four-modes.scenario.toml");
  assert.match(fs.readFileSync(scenario, "utf8"), /^until = "\d+ms"$/m);

  // the same file again: the same panel, shown; no second process
  await vscode.commands.executeCommand("mercmac.simulate", vscode.Uri.file(file));
  assert.strictEqual(seen.panels.length, 1);
  assert.strictEqual(panel.revealed, 1);
  assert.strictEqual(extension.simulating().length, 1);

  panel.dispose();
  await waitFor(() => !alive(pid), 6000);
  assert.deepStrictEqual(extension.simulating(), []);
  const log = seen.output.join("");
  assert.match(log, /\[mercmac\] sim four-modes\.mcm: running \(pid \d+\) at http:\/\/127\.0\.0\.1:\d+\//);
  assert.match(log, /\[mercmac\] sim four-modes\.mcm: stopped \(code 130\)/);
  assert.match(log, /\[sim four-modes\.mcm\] mercmac: the box in the browser/, "its stderr is not in the log");
  assert.deepStrictEqual(seen.errors, []);
  return editor;
}

test("Simulate relays the page, the stream and the actions; closing the panel stops it (stand-in)", async () => {
  await roundTrip(fakeMercmac().path);
});

test("Simulate relays the page, the stream and the actions; closing the panel stops it (mercmac)", async (t) => {
  if (!MERCMAC) return t.skip(NO_MERCMAC);
  const wrapper = recordingMercmac(MERCMAC);
  await roundTrip(wrapper.path);
  assert.ok(wrapper.starts().some((line) => /^sim \S+four-modes\.mcm --web --no-open --stop-when-stdin-closes$/.test(line)), wrapper.starts().join("\n"));
  return undefined;
});

test("the webview's HTML: the files inline under one nonce, a strict CSP, no token", async () => {
  const editor = await activated({ "mercmac.path": fakeMercmac().path });
  const panel = await simulate(editor, program());
  const html = panel.webview.html;
  const csp = /<meta http-equiv="Content-Security-Policy" content="([^"]+)">/.exec(html)[1];
  const nonce = /'nonce-([^']+)'/.exec(csp)[1];
  assert.match(csp, /^default-src 'none'; /);
  assert.ok(csp.includes(`script-src 'nonce-${nonce}';`), csp);
  assert.ok(csp.includes(`style-src 'nonce-${nonce}' https://fake.vscode-cdn.net;`), csp);
  assert.ok(csp.includes("img-src data:"), csp);
  assert.doesNotMatch(html, /\bsrc=|href="\/static|token=/, "something loaded from the server, or its token");
  const scripts = [...html.matchAll(/<script nonce="([^"]+)">([\s\S]*?)<\/script>/g)];
  assert.strictEqual(scripts.length, 2);
  assert.ok(scripts.every((s) => s[1] === nonce));
  assert.match(scripts[0][2], /acquireVsCodeApi\(\), window\);$/, "the bridge is not first");
  assert.ok(scripts[1][2].includes(`text: "$& $' <\\/script>"`), "app.js changed on its way in");
  assert.ok(html.includes(`<style nonce="${nonce}">\nbody { margin: 0; } /* $& */`), "style.css is not inline");
  assert.ok(html.indexOf("<script") > html.indexOf('id="controllers"'), "the scripts run before the body is there");
});

test("the bridge in the webview: posts, replies, the stream, a stop", async () => {
  const editor = await activated({ "mercmac.path": fakeMercmac().path });
  const panel = await simulate(editor, program());
  const bridgeScript = /<script nonce="[^"]+">([\s\S]*?)<\/script>/.exec(panel.webview.html)[1];
  const sent = [];
  const listeners = [];
  const nodes = new Map();
  const node = (tag) => ({ tag, children: [], set id(v) { nodes.set(v, this); }, setAttribute() {},
    append(...kids) { this.children.push(...kids); }, after(n) { this.next = n; } });
  const win = {
    addEventListener: (type, listener) => type === "message" && listeners.push(listener),
    document: { createElement: node, getElementById: (id) => nodes.get(id), querySelector: () => node("header"),
      body: node("body") },
  };
  vm.runInNewContext(bridgeScript, { acquireVsCodeApi: () => ({ postMessage: (m) => sent.push(m) }), window: win });
  const bridge = win.mercmacBridge;
  const deliver = (data) => listeners.forEach((l) => l({ data }));

  const ok = bridge.post("/api/press", { button: 1 });
  const bad = bridge.post("/api/press", { button: 9 });
  assert.deepStrictEqual(sent.map((m) => [m.type, m.id, m.path]), [["post", 1, "/api/press"], ["post", 2, "/api/press"]]);
  deliver({ type: "reply", id: 2, error: "/api/press: 400 no button 9" });
  deliver({ type: "reply", id: 1 });
  assert.strictEqual(await ok, null);
  await assert.rejects(bad, (error) => error.message === "/api/press: 400 no button 9");
  const said = [];
  bridge.events({ open: () => said.push("open"), message: (text) => said.push(text), error: (closed) => said.push(closed) });
  assert.strictEqual(JSON.stringify(sent[2]), "{\"type\":\"events\"}");
  deliver({ type: "open" });
  deliver({ type: "event", data: "{\"t_ms\":1}" });
  deliver({ type: "error", closed: false });
  deliver({ type: "stopped", text: "code 1: boom" });
  assert.deepStrictEqual(said, ["open", "{\"t_ms\":1}", false, true]);
  assert.strictEqual(nodes.get("mercmac-stopped-text").textContent, "code 1: boom");
  const note = bridge.saveScenario();
  deliver({ type: "reply", id: sent[3].id, value: "Saved x" });
  assert.strictEqual(await note, "Saved x");
});

/** A file with errors: one message quoting check, no panel, Show Server Log shows the log. */
async function refusedFile(mercmacPath) {
  const file = program("broken.mcm", BROKEN);
  const editor = await activated({ "mercmac.path": mercmacPath },
    { answer: (text, items) => (/cannot simulate/.test(text) ? "Show Server Log" : undefined) });
  await editor.vscode.commands.executeCommand("mercmac.simulate", editor.vscode.Uri.file(file));
  await pause(300); // a second message would come now
  const said = editor.seen.messages.filter((m) => /simulat/.test(m.text));
  assert.strictEqual(said.length, 1, JSON.stringify(editor.seen.messages, null, 1));
  const [{ kind, text, items }] = said;
  assert.strictEqual(kind, "error");
  assert.match(text, /^mercmac: cannot simulate broken\.mcm \(code 1\): broken\.mcm:2:3: error\[MM002 unknown-command\]: unknown command 'XM'.* · \d+ errors?, /);
  assert.deepStrictEqual(items, ["Show Server Log"]);
  assert.strictEqual(editor.seen.panels.length, 0);
  assert.deepStrictEqual(editor.extension.simulating(), []);
  await waitFor(() => editor.seen.channels[0].shown);
  assert.ok(editor.seen.output.join("").includes("[sim broken.mcm]     2 |   XM 1"), "the whole stderr is not in the log");
}

test("a file with errors: one message quoting check's findings, no panel (stand-in)", async () => {
  await refusedFile(fakeMercmac("sim-errors").path);
});

test("a file with errors: one message quoting check's findings, no panel (mercmac)", async (t) => {
  if (!MERCMAC) return t.skip(NO_MERCMAC);
  await refusedFile(MERCMAC);
  return undefined;
});

test("a simulation that dies: one message quoting it, the panel says it stopped", async () => {
  const editor = await activated({ "mercmac.path": fakeMercmac("sim-crash").path });
  const file = program();
  const panel = await simulate(editor, file);
  const [{ pid }] = editor.extension.simulating();
  panel.send({ type: "events" });
  await waitFor(() => states(panel).length > 0, 10000);
  panel.send({ type: "post", id: 1, path: "/api/power", body: {} });
  await waitFor(() => editor.seen.errors.length, 10000);
  await pause(500);
  assert.strictEqual(editor.seen.messages.length, 1, JSON.stringify(editor.seen.messages, null, 1));
  const [{ kind, text, items }] = editor.seen.messages;
  assert.strictEqual(kind, "error");
  assert.strictEqual(text, "mercmac: the simulation of four-modes.mcm stopped (code 1): " +
    "Traceback (most recent call last): · RuntimeError: fake mercmac: boom");
  assert.deepStrictEqual(items, ["Show Server Log"]);
  assert.ok(!alive(pid));
  assert.strictEqual(panel.title, "Simulate four-modes.mcm (stopped)");
  assert.ok(!panel.disposed);
  assert.deepStrictEqual(panel.posted.find((m) => m.type === "stopped"),
    { type: "stopped", text: "code 1: Traceback (most recent call last): · RuntimeError: fake mercmac: boom" });
  await waitFor(() => panel.posted.some((m) => m.type === "error" && m.closed === true));
  // again: a new panel and process, the stopped one closed
  const again = await simulate(editor, file);
  assert.notStrictEqual(again, panel);
  assert.ok(panel.disposed);
  assert.strictEqual(editor.extension.simulating().length, 1);
});

test("a simulation deaf to SIGINT is killed 3 s after it", async () => {
  const editor = await activated({ "mercmac.path": fakeMercmac("sim-deaf").path });
  const panel = await simulate(editor, program());
  const [{ pid }] = editor.extension.simulating();
  panel.dispose();
  await pause(1500);
  assert.ok(alive(pid), "it was killed at once");
  await waitFor(() => !alive(pid), 5000);
  assert.match(editor.seen.output.join(""), /still running 3 s after SIGINT: killing it/);
  assert.match(editor.seen.output.join(""), /stopped \(signal SIGKILL\)/);
  assert.deepStrictEqual(editor.seen.errors, []);
});

test("a mercmac.path script that does not exec: closing the panel stops its child too", async () => {
  const editor = await activated({ "mercmac.path": shellWrappedMercmac().path });
  const panel = await simulate(editor, program());
  const [{ pid }] = editor.extension.simulating();
  const below = descendants(pid);
  assert.strictEqual(below.length, 1, "the shell runs no child");
  panel.dispose();
  try {
    await waitFor(() => !alive(pid) && !alive(below[0]), 6000);
  } finally {
    if (alive(below[0])) process.kill(below[0], "SIGKILL"); // left behind: the test fails, not hangs
  }
  assert.doesNotMatch(editor.seen.output.join(""), /killing it/);
});

test("deactivate stops every simulation: a program and a rig", async () => {
  const editor = await activated({ "mercmac.path": fakeMercmac().path });
  const panels = [await simulate(editor, program()), await simulate(editor, program("raster.rig.toml", "# a rig\n"))];
  assert.deepStrictEqual(panels.map((p) => p.title), ["Simulate four-modes.mcm", "Simulate raster.rig.toml"]);
  const pids = editor.extension.simulating().map((s) => s.pid);
  assert.strictEqual(pids.length, 2);
  await editor.extension.deactivate();
  assert.deepStrictEqual(pids.filter(alive), []);
  assert.ok(panels.every((p) => p.disposed));
  assert.deepStrictEqual(editor.seen.errors, []);
});

test("the active editor's file, saved first; what Simulate refuses", async () => {
  const mercmac = fakeMercmac();
  const editor = await activated({ "mercmac.path": mercmac.path });
  const { vscode, seen } = editor;
  const refused = async (argument, regex) => {
    const before = seen.errors.length;
    await vscode.commands.executeCommand("mercmac.simulate", argument);
    await waitFor(() => seen.errors.length > before);
    assert.match(seen.errors[seen.errors.length - 1], regex);
  };
  await refused(undefined, /^mercmac: Simulate runs an \.mcm program or a rig file \(\*\.rig\.toml\): open one first\.$/);
  await refused(vscode.Uri.parse("untitled:Untitled-1"), /^mercmac: save Untitled-1 first: Simulate runs a file on disk\.$/);
  await refused(vscode.Uri.file(program("notes.txt", "hello")), /not notes\.txt\.$/);
  await refused({ uri: vscode.Uri.file("/nonexistent/x.mcm").toString() }, /\/nonexistent\/x\.mcm is not a file on disk/);
  assert.strictEqual(seen.panels.length, 0);
  assert.ok(!mercmac.starts().some((line) => line.startsWith("sim")));

  const file = program();
  let saves = 0;
  const document = { uri: vscode.Uri.file(file), isDirty: true, save: async () => { saves += 1; return true; } };
  vscode.workspace.textDocuments.push(document);
  vscode.window.activeTextEditor = { document };
  await vscode.commands.executeCommand("mercmac.simulate");
  assert.strictEqual(saves, 1);
  assert.strictEqual(seen.panels.length, 1);
  assert.strictEqual(seen.errors.length, 4);
});

test("Restricted Mode: Simulate runs nothing, and says so", async () => {
  const mercmac = fakeMercmac();
  const { vscode, seen } = await activated({ "mercmac.path": mercmac.path }, { trusted: false });
  await vscode.commands.executeCommand("mercmac.simulate", vscode.Uri.file(program()));
  await waitFor(() => seen.errors.length);
  assert.match(seen.errors[0], /Restricted Mode does not allow: trust the workspace first/);
  assert.deepStrictEqual(seen.messages[0].items, ["Manage Workspace Trust"]);
  assert.deepStrictEqual(mercmac.starts(), [], "it ran the executable in Restricted Mode");
  assert.strictEqual(seen.panels.length, 0);
});

test("a mercmac that is not there: one message with Open Settings", async () => {
  const { vscode, seen } = await activated({ "mercmac.path": "/nonexistent/bin/mercmac" });
  await vscode.commands.executeCommand("mercmac.simulate", vscode.Uri.file(program()));
  const said = await waitFor(() => seen.messages.filter((m) => /simulate/.test(m.text)).length && seen.messages.filter((m) => /simulate/.test(m.text)));
  assert.strictEqual(said.length, 1);
  assert.match(said[0].text, /^mercmac: cannot simulate four-modes\.mcm: '\/nonexistent\/bin\/mercmac' was not found\. Install it/);
  assert.deepStrictEqual(said[0].items, ["Open Settings"]);
  assert.strictEqual(seen.panels.length, 0);
});

test("the relay's reading of server-sent events and of the address", () => {
  const { EventParser, parseAddress } = require("../src/relay");
  const got = [];
  const parser = new EventParser((data) => got.push(data));
  for (const chunk of [": still here\r\n\r\ndata: {\"a\"", ":1}\n", "\ndata: one\ndata: two\n\nda", "ta:x\n\n"]) parser.feed(chunk);
  assert.deepStrictEqual(got, ["{\"a\":1}", "one\ntwo", "x"]);
  assert.deepStrictEqual(parseAddress("mercmac: the box in the browser: http://127.0.0.1:4242/?token=a-b_C9"),
    { url: "http://127.0.0.1:4242/?token=a-b_C9", port: 4242, token: "a-b_C9" });
  assert.strictEqual(parseAddress("mercmac: Ctrl-C stops it"), undefined);
});
