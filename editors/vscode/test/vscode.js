// The `vscode` module exists only inside VS Code. This is the part of its API that the
// extension and vscode-languageclient 9 use while starting and stopping a client; every other
// member is an inert function. The client library itself is the real one (node_modules, or
// bundled in dist/extension.js): it spawns the server and speaks JSON-RPC to it.
"use strict";
const Module = require("node:module");
const { fileURLToPath, pathToFileURL } = require("node:url");

class EventEmitter {
  constructor() {
    this.listeners = [];
    this.event = (listener) => {
      this.listeners.push(listener);
      return { dispose: () => (this.listeners = this.listeners.filter((l) => l !== listener)) };
    };
  }
  fire(value) {
    this.listeners.forEach((l) => l(value));
  }
  dispose() {
    this.listeners = [];
  }
}

class Disposable {
  constructor(callOnDispose) {
    this.callOnDispose = callOnDispose;
  }
  static from(...items) {
    return new Disposable(() => items.forEach((d) => d && d.dispose && d.dispose()));
  }
  dispose() {
    if (this.callOnDispose) this.callOnDispose();
  }
}

/** vscode.Uri, for file: and untitled: URIs (what the simulate command is given). */
class Uri {
  constructor(scheme, fsPath, text) {
    Object.assign(this, { scheme, fsPath, path: scheme === "file" ? pathToFileURL(fsPath).pathname : fsPath });
    this.text = text || (scheme === "file" ? pathToFileURL(fsPath).href : `${scheme}:${fsPath}`);
  }
  static file(fsPath) {
    return new Uri("file", fsPath);
  }
  static parse(text) {
    if (text.startsWith("file:")) return new Uri("file", fileURLToPath(text));
    const colon = text.indexOf(":");
    return new Uri(text.slice(0, colon), text.slice(colon + 1), text);
  }
  toString() {
    return this.text;
  }
}

/** A webview panel as createWebviewPanel makes it: `posted` holds what the extension sent the
 *  page; `send(message)` is the page posting MESSAGE; `dispose()` the person closing it. */
function makePanel(viewType, title, showOptions, options) {
  const received = new EventEmitter();
  const disposed = new EventEmitter();
  const panel = {
    viewType, title, showOptions, options, revealed: 0, disposed: false, posted: [],
    webview: {
      html: "", cspSource: "https://fake.vscode-cdn.net", options,
      postMessage: async (message) => {
        if (panel.disposed) throw new Error("Webview is disposed");
        panel.posted.push(message);
        return true;
      },
      onDidReceiveMessage: received.event,
    },
    onDidDispose: disposed.event,
    reveal() { panel.revealed += 1; },
    dispose() {
      if (panel.disposed) return;
      panel.disposed = true;
      disposed.fire();
    },
    send(message) { received.fire(message); },
  };
  return panel;
}

/** A callable, constructible value whose every member is another such value. */
function inert(name) {
  const fn = function () {
    return inert(`${name}()`);
  };
  return new Proxy(fn, {
    get(target, prop) {
      if (prop === "then") return undefined; // not a promise
      if (prop === Symbol.toPrimitive) return () => name;
      if (!(prop in target)) target[prop] = inert(`${name}.${String(prop)}`);
      return target[prop];
    },
    construct: () => inert(`new ${name}`),
  });
}

/** An object whose missing members are inert values (the parts of a namespace no test needs). */
function withInert(object, name) {
  return new Proxy(object, {
    get(target, prop) {
      if (!(prop in target)) target[prop] = inert(`${name}.${String(prop)}`);
      return target[prop];
    },
  });
}

/**
 * A fresh `vscode` with SETTINGS ({"mercmac.path": ...}); `seen` records what was shown:
 * errors (error and warning messages), infos, messages ({kind, text, items}), output (text
 * written to any channel), channels (every createOutputChannel), statusItems, executed
 * commands, the clipboard, panels (every createWebviewPanel, see makePanel), saved (the files
 * workspace.fs.writeFile wrote). OPTIONS: trusted (workspace trust, default true),
 * answer(message, items) picks the button a message gets (default: none), saveAs(options) the
 * Uri the save dialog answers (default: none, cancelled).
 */
function makeVscode(settings, options = {}) {
  const seen = { errors: [], infos: [], messages: [], output: [], channels: [], statusItems: [],
                 executed: [], clipboard: undefined, panels: [], saved: [] };
  const configuration = new EventEmitter();
  const trust = new EventEmitter();
  const commands = new Map();
  const none = () => new Disposable();
  const answer = options.answer || (() => undefined);
  function show(kind, list) {
    return (text, ...items) => {
      list.push(text);
      seen.messages.push({ kind, text, items });
      return Promise.resolve(answer(text, items));
    };
  }
  const api = {
    version: "1.90.0",
    env: { appName: "Visual Studio Code", language: "en", machineId: "test", sessionId: "test",
           uriScheme: "vscode", shell: "/bin/sh", uiKind: 1,
           clipboard: { writeText: async (text) => (seen.clipboard = text), readText: async () => seen.clipboard } },
    EventEmitter,
    Disposable,
    Uri,
    ViewColumn: { Active: -1, Beside: -2, One: 1, Two: 2 },
    LanguageStatusSeverity: { Information: 0, Warning: 1, Error: 2 },
    workspace: {
      getConfiguration: (section) => ({
        get: (key, fallback) => {
          const value = settings[section ? `${section}.${key}` : key];
          return value === undefined ? fallback : value;
        },
      }),
      onDidChangeConfiguration: configuration.event,
      isTrusted: options.trusted !== false,
      onDidGrantWorkspaceTrust: trust.event,
      textDocuments: [],
      notebookDocuments: [],
      workspaceFolders: undefined,
      onDidOpenTextDocument: none,
      onDidChangeTextDocument: none,
      onDidCloseTextDocument: none,
      onDidSaveTextDocument: none,
      onWillSaveTextDocument: none,
      onDidChangeWorkspaceFolders: none,
      fs: {
        writeFile: async (uri, bytes) => {
          require("node:fs").writeFileSync(uri.fsPath, bytes);
          seen.saved.push(uri.fsPath);
        },
      },
    },
    window: {
      createOutputChannel: (name) => {
        const channel = {
          name, shown: 0, disposed: false,
          append: (text) => seen.output.push(text),
          appendLine: (text) => seen.output.push(`${text}\n`),
          show() { channel.shown += 1; }, hide() {}, clear() {}, replace() {},
          dispose() { channel.disposed = true; },
        };
        seen.channels.push(channel);
        return channel;
      },
      showErrorMessage: show("error", seen.errors),
      showWarningMessage: show("warning", seen.errors),
      showInformationMessage: show("info", seen.infos),
      activeTextEditor: undefined,
      createWebviewPanel: (...args) => {
        const panel = makePanel(...args);
        seen.panels.push(panel);
        return panel;
      },
      showSaveDialog: async (saveOptions) => (options.saveAs ? options.saveAs(saveOptions) : undefined),
      setStatusBarMessage: () => new Disposable(),
    },
    commands: {
      registerCommand: (id, handler) => {
        if (commands.has(id)) throw new Error(`command '${id}' already exists`);
        commands.set(id, handler);
        return new Disposable(() => commands.delete(id));
      },
      executeCommand: async (id, ...args) => {
        seen.executed.push([id, ...args]);
        return commands.has(id) ? commands.get(id)(...args) : undefined;
      },
      getCommands: async () => [...commands.keys()],
    },
    languages: withInert({
      createLanguageStatusItem: (id, selector) => {
        const item = { id, selector, text: "", disposed: false, dispose() { item.disposed = true; } };
        seen.statusItems.push(item);
        return item;
      },
    }, "vscode.languages"),
  };
  const vscode = withInert(api, "vscode");
  /** Change a setting as the Settings editor does, and tell the listeners. */
  function change(key, value) {
    settings[key] = value;
    configuration.fire({ affectsConfiguration: (section) => key === section || key.startsWith(`${section}.`) });
  }
  /** Trust the workspace, as the user does in the Restricted Mode banner. */
  function grantTrust() {
    api.workspace.isTrusted = true;
    trust.fire();
  }
  return { vscode, seen, change, grantTrust };
}

// esbuild's bundle requires `vscode` lazily (when a bundled module first runs), so the
// resolution stays in place for the whole test process; it answers the latest stand-in.
let current;
const original = Module._load;
Module._load = (request, ...rest) => (request === "vscode" && current ? current : original(request, ...rest));

/** require(PATH) afresh, with `vscode` resolved to VSCODE (so each test has its own client). */
function requireWith(vscode, path) {
  current = vscode;
  delete require.cache[require.resolve(path)];
  return require(path);
}

const BUNDLE = require("node:path").join(__dirname, "..", "dist", "extension.js");

/** The bundle activated in a fresh stand-in (SETTINGS, OPTIONS as makeVscode's). */
async function activated(settings, options) {
  const editor = makeVscode(settings, options);
  const extension = requireWith(editor.vscode, BUNDLE);
  const context = { subscriptions: [] };
  active.push(extension);
  await extension.activate(context);
  return { ...editor, extension, context };
}

// Extensions activated and not yet deactivated: a failed test leaves its server running,
// which would keep the test process alive.
const active = [];

/** Deactivate what `activated` activated (test.afterEach: even after a failure). */
async function deactivateAll() {
  while (active.length) await active.pop().deactivate();
}

/** PROBE's first truthy value, asked every 50 ms for up to MS milliseconds. */
async function waitFor(probe, ms = 20000) {
  const end = Date.now() + ms;
  for (;;) {
    const value = probe();
    if (value) return value;
    if (Date.now() > end) throw new Error(`timed out waiting for ${probe}`);
    await new Promise((resolve) => setTimeout(resolve, 50));
  }
}

const pause = (ms) => new Promise((resolve) => setTimeout(resolve, ms));

module.exports = { makeVscode, requireWith, activated, deactivateAll, waitFor, pause, BUNDLE };
