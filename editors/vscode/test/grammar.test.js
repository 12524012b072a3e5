// The TextMate grammar on the examples (examples/macros/*.mcm), read by vscode-textmate
// with the Oniguruma regex engine, as VS Code reads it. Run: `node --test test/`.
"use strict";
const assert = require("node:assert");
const fs = require("node:fs");
const path = require("node:path");
const test = require("node:test");
const vsctm = require("vscode-textmate");
const oniguruma = require("vscode-oniguruma");

const ROOT = path.join(__dirname, "..", "..", "..");
const EXAMPLES = path.join(ROOT, "examples", "macros");
const GRAMMAR = path.join(__dirname, "..", "syntaxes", "mcm.tmLanguage.json");
// An example that expects one of these rules has an unknown word in it; every other one is clean.
const DIRTY = /\/\/\s*expect:.*\b(syntax|unknown-command)\b/;

async function loadGrammar() {
  const wasm = fs.readFileSync(require.resolve("vscode-oniguruma/release/onig.wasm"));
  await oniguruma.loadWASM(wasm.buffer.slice(wasm.byteOffset, wasm.byteOffset + wasm.byteLength));
  const registry = new vsctm.Registry({
    onigLib: Promise.resolve({
      createOnigScanner: (sources) => new oniguruma.OnigScanner(sources),
      createOnigString: (s) => new oniguruma.OnigString(s),
    }),
    loadGrammar: async () => vsctm.parseRawGrammar(fs.readFileSync(GRAMMAR, "utf8"), GRAMMAR),
  });
  return registry.loadGrammar("source.mcm");
}

/** [[text, scopes], ...] for every token of every line. */
function tokenize(grammar, text) {
  let stack = vsctm.INITIAL;
  const out = [];
  for (const line of text.split(/\r?\n/)) {
    const r = grammar.tokenizeLine(line, stack);
    for (const t of r.tokens) out.push([line.slice(t.startIndex, t.endIndex), t.scopes]);
    stack = r.ruleStack;
  }
  return out;
}

const scoped = (tokens, part) => tokens.filter(([, s]) => s.some((x) => x.startsWith(part)));
const texts = (tokens, part) => scoped(tokens, part).map(([t]) => t.trim());

let grammar;
test.before(async () => { grammar = await loadGrammar(); });

const files = fs.readdirSync(EXAMPLES).filter((f) => f.endsWith(".mcm")).sort();

test("there are examples", () => assert.ok(files.length >= 8));

for (const file of files) {
  test(`example ${file}`, () => {
    const text = fs.readFileSync(path.join(EXAMPLES, file), "utf8");
    const tokens = tokenize(grammar, text);
    assert.strictEqual(tokens.map(([t]) => t).join(""), text.split(/\r?\n/).join(""));
    const illegal = texts(tokens, "invalid.illegal");
    if (DIRTY.test(text)) assert.ok(illegal.length > 0, "an unknown word is marked");
    else assert.deepStrictEqual(illegal, [], "a clean example has no invalid token");
    assert.ok(texts(tokens, "support.function.mnemonic").length > 0, "mnemonics are marked");
    assert.ok(texts(tokens, "comment.line").length > 0, "comments are marked");
  });
}

test("raw blocks: slot, mnemonics, numbers, comment; EMxx is no command", () => {
  const tokens = tokenize(grammar, "[MC18] XN4,cf1,MA-50000,EM + 9,DI,EMxx   // expect: syntax\n");
  assert.deepStrictEqual(texts(tokens, "entity.name.tag.macro-slot"), ["[MC18]"]);
  assert.deepStrictEqual(texts(tokens, "support.function.mnemonic"), ["XN", "cf", "MA", "EM", "DI"]);
  assert.deepStrictEqual(texts(tokens, "constant.numeric"), ["4", "1", "-50000", "+ 9"]);
  assert.deepStrictEqual(texts(tokens, "invalid.illegal"), ["EMxx"]);
  assert.deepStrictEqual(texts(tokens, "comment.line"), ["// expect: syntax"]);
});

test("high-level constructs", () => {
  const text = [
    "target C-863", "const FAR = 9999999", "macro jog @20 {", "  every 20ms {",
    "    when 1 and not BUTTON { MR FAR, WF 1, FA?, AB 1 }", "  }", "  repeat STEPS { call pulse }",
    "  XYZ 5", "  goto idle", "}",
  ].join("\n");
  const tokens = tokenize(grammar, text);
  assert.deepStrictEqual(texts(tokens, "storage.type"), ["target", "const", "macro"]);
  assert.deepStrictEqual(texts(tokens, "support.constant.model"), ["C-863"]);
  assert.deepStrictEqual(texts(tokens, "entity.name.function"), ["jog", "pulse", "idle"]);
  assert.deepStrictEqual(texts(tokens, "keyword.control"), ["every", "when", "and", "repeat", "call", "goto"]);
  assert.deepStrictEqual(texts(tokens, "keyword.operator.logical"), ["not"]);
  assert.deepStrictEqual(texts(tokens, "variable.other.constant"), ["FAR", "BUTTON", "FAR", "STEPS"]);
  assert.deepStrictEqual(texts(tokens, "support.function.mnemonic"), ["MR", "WF", "FA?", "AB"]);
  assert.deepStrictEqual(texts(tokens, "constant.numeric.duration"), ["20ms"]);
  assert.deepStrictEqual(texts(tokens, "invalid.illegal"), ["XYZ"]);
});
