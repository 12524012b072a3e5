// The scratch workspace and what mercmac itself says about it (check, fmt, build).
import fs from "node:fs";
import path from "node:path";
import { REPO, run, runOk } from "./common.mjs";

// ---------------------------------------------------------------------------------------------
// the workspace and what mercmac itself says about it

export const BROKEN_MCM = `target C-863

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
export function messy(text) {
  return text.split("\n").map((line, i) => {
    let out = line;
    if (out.startsWith("    ") && i % 2) out = `  ${out.trimStart()}`;
    if (i % 3 === 0) out = out.replace(", ", " ,");
    return out;
  }).join("\n").replace("macro steps {", "macro   steps   {");
}

export function makeWorkspace(scratch, mercmac) {
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

export function findFiles(folder, test) {
  const found = [];
  for (const entry of fs.readdirSync(folder, { withFileTypes: true })) {
    const full = path.join(folder, entry.name);
    if (entry.isDirectory()) found.push(...findFiles(full, test));
    else if (test(entry.name)) found.push(full);
  }
  return found.sort();
}

/** `mercmac check --format json FILE`'s diagnostics of FILE itself, 0-based as VS Code has them. */
export function checkJson(mercmac, file) {
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

export function sortDiagnostics(list) {
  return [...list].sort((a, b) => a.range.join(",").localeCompare(b.range.join(","), undefined, { numeric: true })
    || a.code.localeCompare(b.code));
}

export function describeDiagnostic(d) {
  const [l, c, el, ec] = d.range;
  return `${d.code} ${["error", "warning", "info", "hint"][d.severity]} ${l + 1}:${c + 1}-${el + 1}:${ec + 1} ${JSON.stringify(d.message)}`;
}

/** Apply the 1-based, end-exclusive edits of a `mercmac check --format json` fix to TEXT. */
export function applyFix(text, fix) {
  const lines = text.split("\n");
  const offset = (line, column) => lines.slice(0, line - 1).reduce((n, l) => n + l.length + 1, 0) + column - 1;
  const edits = [...fix.edits].sort((a, b) => offset(b.line, b.column) - offset(a.line, a.column));
  let out = text;
  for (const edit of edits) {
    out = out.slice(0, offset(edit.line, edit.column)) + edit.content + out.slice(offset(edit.end_line, edit.end_column));
  }
  return out;
}

