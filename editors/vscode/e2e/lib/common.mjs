// Shared by the e2e modules: paths, logging, running commands, polling, the processes this run
// started (stopped on exit and on signals), and the PASS/FAIL record of the checks.
import { spawnSync } from "node:child_process";
import crypto from "node:crypto";
import fs from "node:fs";
import net from "node:net";
import path from "node:path";
import { fileURLToPath } from "node:url";

export const HERE = path.resolve(path.dirname(fileURLToPath(import.meta.url)), "..");
export const EXTENSION = path.resolve(HERE, "..");
export const REPO = path.resolve(EXTENSION, "..", "..");

export const started = Date.now();
export function log(message) {
  const seconds = ((Date.now() - started) / 1000).toFixed(1).padStart(6);
  process.stdout.write(`[${seconds}s] ${message}\n`);
}

/** Run a command to its end; throw with the tail of its output when it fails. */
export function run(command, args, { cwd, env, input, quiet = true } = {}) {
  const result = spawnSync(command, args, {
    cwd, env: env || process.env, input, encoding: "utf8", maxBuffer: 256 * 1024 * 1024,
    stdio: [input === undefined ? "ignore" : "pipe", quiet ? "pipe" : "inherit", quiet ? "pipe" : "inherit"],
  });
  if (result.error) throw result.error;
  return result;
}

export function runOk(command, args, options = {}) {
  const result = run(command, args, options);
  if (result.status !== 0) {
    const tail = `${result.stdout || ""}${result.stderr || ""}`.split("\n").slice(-40).join("\n");
    throw new Error(`${command} ${args.join(" ")} exited ${result.status}:\n${tail}`);
  }
  return result;
}

export function freePort() {
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

export const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));

/** Poll FN until it returns something truthy; the last value (or error) goes into the throw. */
export async function until(what, fn, { timeout = 30000, interval = 250 } = {}) {
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
export const children = new Set();
let scratchToRemove; // the scratch folder, removed on a signal too (unless --keep)
export function removeOnSignal(folder) { scratchToRemove = folder; }

export function stopGroup(child, name) {
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

export function killAllNow() {
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

/** The processes below PID (from /proc): [{pid, cmdline}]. */
export function descendants(pid) {
  const parents = new Map();
  for (const entry of fs.readdirSync("/proc")) {
    if (!/^\d+$/.test(entry)) continue;
    try {
      const stat = fs.readFileSync(`/proc/${entry}/stat`, "utf8");
      const ppid = Number(stat.slice(stat.lastIndexOf(")") + 2).split(" ")[1]);
      const cmdline = fs.readFileSync(`/proc/${entry}/cmdline`, "utf8").split("\0").join(" ").trim();
      parents.set(Number(entry), { ppid, cmdline });
    } catch { /* gone */ }
  }
  const found = [];
  const walk = (parent) => {
    for (const [child, info] of parents) {
      if (info.ppid === parent) {
        found.push({ pid: child, cmdline: info.cmdline });
        walk(child);
      }
    }
  };
  walk(pid);
  return found;
}

export function sha256(data) {
  return crypto.createHash("sha256").update(data).digest("hex");
}

// ---------------------------------------------------------------------------------------------
// the checks

export const results = [];

export async function check(name, options, fn) {
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

export function assert(condition, message) {
  if (!condition) throw new Error(message);
}

export function lineOf(text, regex) {
  const lines = text.split("\n");
  const index = lines.findIndex((line) => regex.test(line));
  if (index < 0) throw new Error(`no line matches ${regex}`);
  const match = lines[index].match(regex);
  return { line: index, character: match.index, text: lines[index], match };
}

