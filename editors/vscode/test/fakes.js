// Executables for the tests: `mercmac` stand-ins that log each start, and the real one.
"use strict";
const fs = require("node:fs");
const os = require("node:os");
const path = require("node:path");

const FAKE = path.join(__dirname, "fake-mercmac.js");
// what `mercmac lsp` says on stderr, before exiting 2, when pygls is missing (mercmac/cli/lsp.py)
const NO_LSP_EXTRA = "mercmac: the language server needs the lsp extra: pip install 'mercmac[lsp]'";

function tempDir() {
  return fs.mkdtempSync(path.join(os.tmpdir(), "mercmac-vscode-"));
}

function quote(text) {
  return `'${text.replace(/'/g, "'\\''")}'`;
}

/** A shell script DIR/mercmac that appends its arguments to DIR/starts.log, then runs BODY. */
function script(dir, body) {
  const log = path.join(dir, "starts.log");
  const file = path.join(dir, "mercmac");
  fs.writeFileSync(file, `#!/bin/sh\nprintf '%s\\n' "$*" >> ${quote(log)}\n${body}\n`, { mode: 0o755 });
  return { path: file, log, starts: () => (fs.existsSync(log) ? fs.readFileSync(log, "utf8").trim().split("\n") : []) };
}

/** The fake language server (test/fake-mercmac.js) in MODE ("ok", "crash"). */
function fakeMercmac(mode = "ok", dir = tempDir()) {
  return script(dir, `FAKE_MERCMAC_MODE=${mode} exec ${quote(process.execPath)} ${quote(FAKE)} "$@"`);
}

/** The fake run by a shell script that does not exec it: a child of the shell (as a
 *  mercmac.path script that activates a venv, then runs mercmac, may be). */
function shellWrappedMercmac(mode = "ok", dir = tempDir()) {
  return script(dir, `FAKE_MERCMAC_MODE=${mode} ${quote(process.execPath)} ${quote(FAKE)} "$@"`);
}

/** mercmac installed without the lsp extra: `lsp` says so and exits 2 before reading anything. */
function mercmacWithoutLsp(dir = tempDir()) {
  return script(dir, `if [ "$1" = --version ]; then echo 'mercmac, version 0.1.0'; exit 0; fi\necho ${quote(NO_LSP_EXTRA)} >&2\nexit 2`);
}

/** A wrapper that logs its arguments, then runs the real mercmac (MERCMAC). */
function recordingMercmac(mercmac, dir = tempDir()) {
  return script(dir, `exec ${quote(mercmac)} "$@"`);
}

/** The real mercmac: MERCMAC_BIN, else `mercmac` on PATH; undefined if neither. */
function realMercmac() {
  if (process.env.MERCMAC_BIN) return process.env.MERCMAC_BIN;
  for (const folder of (process.env.PATH || "").split(path.delimiter)) {
    const candidate = path.join(folder || ".", "mercmac");
    try {
      fs.accessSync(candidate, fs.constants.X_OK);
      if (fs.statSync(candidate).isFile()) return candidate;
    } catch {
      // not here
    }
  }
  return undefined;
}

module.exports = { fakeMercmac, shellWrappedMercmac, mercmacWithoutLsp, recordingMercmac, realMercmac, tempDir, NO_LSP_EXTRA };
