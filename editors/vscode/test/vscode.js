// The `vscode` module exists only inside VS Code. This is the part of its API that the
// extension and vscode-languageclient 9 use while starting and stopping a client; every other
// member is an inert function. The client library itself is the real one (node_modules, or
// bundled in dist/extension.js): it spawns the server and speaks JSON-RPC to it.
"use strict";
const Module = require("node:module");

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

/** A fresh `vscode` with SETTINGS ({"mercmac.path": ...}); `seen` records what was shown. */
function makeVscode(settings) {
  const seen = { errors: [], infos: [], output: [] };
  const configuration = new EventEmitter();
  const none = () => new Disposable();
  const api = {
    version: "1.90.0",
    env: { appName: "Visual Studio Code", language: "en", machineId: "test", sessionId: "test",
           uriScheme: "vscode", shell: "/bin/sh", uiKind: 1 },
    EventEmitter,
    Disposable,
    workspace: {
      getConfiguration: (section) => ({
        get: (key, fallback) => {
          const value = settings[section ? `${section}.${key}` : key];
          return value === undefined ? fallback : value;
        },
      }),
      onDidChangeConfiguration: configuration.event,
      textDocuments: [],
      notebookDocuments: [],
      workspaceFolders: undefined,
      onDidOpenTextDocument: none,
      onDidChangeTextDocument: none,
      onDidCloseTextDocument: none,
      onDidSaveTextDocument: none,
      onWillSaveTextDocument: none,
      onDidChangeWorkspaceFolders: none,
    },
    window: {
      createOutputChannel: (name) => ({
        name,
        append: (text) => seen.output.push(text),
        appendLine: (text) => seen.output.push(`${text}\n`),
        show() {}, hide() {}, clear() {}, replace() {}, dispose() {},
      }),
      showErrorMessage: (message) => (seen.errors.push(message), Promise.resolve(undefined)),
      showWarningMessage: (message) => (seen.errors.push(message), Promise.resolve(undefined)),
      showInformationMessage: (message) => (seen.infos.push(message), Promise.resolve(undefined)),
    },
  };
  const vscode = new Proxy(api, {
    get(target, prop) {
      if (!(prop in target)) target[prop] = inert(`vscode.${String(prop)}`);
      return target[prop];
    },
  });
  /** Change a setting as the Settings editor does, and tell the listeners. */
  function change(key, value) {
    settings[key] = value;
    configuration.fire({ affectsConfiguration: (section) => key === section || key.startsWith(`${section}.`) });
  }
  return { vscode, seen, change };
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

module.exports = { makeVscode, requireWith };
