// Test-only helper of e2e/run.mjs, installed next to the mercmac extension in a throwaway
// code-server: it serves POST /eval on 127.0.0.1:$MERCMAC_E2E_PROBE_PORT, running the posted
// body as an async function of `vscode` in the extension host and answering its result as
// JSON. The run uses it to read exactly what the UI shows only approximately (diagnostics with
// their ranges, the active editor's text and selection) and to put the cursor somewhere;
// what the checks verify is done through the UI (keys, the command palette, the hover widget).
"use strict";
const http = require("http");
const vscode = require("vscode");

const AsyncFunction = Object.getPrototypeOf(async () => undefined).constructor;

/** Plain JSON for what the API returns: Uri, Position, Range, MarkdownString, ... */
function plain(value, seen = new Set()) {
  if (value === null || value === undefined) return value ?? null;
  if (typeof value !== "object") return typeof value === "function" ? undefined : value;
  if (seen.has(value)) return "[cycle]";
  seen.add(value);
  try {
    if (value instanceof vscode.Uri) return value.toString();
    if (value instanceof vscode.Range) {
      return { start: plain(value.start), end: plain(value.end) };
    }
    if (value instanceof vscode.Position) return { line: value.line, character: value.character };
    if (value instanceof vscode.MarkdownString) return value.value;
    if (value instanceof Uint32Array || value instanceof Uint8Array) return Array.from(value);
    if (Array.isArray(value)) return value.map((item) => plain(item, seen));
    const out = {};
    for (const key of Object.keys(value)) {
      if (key.startsWith("_")) continue;
      const item = plain(value[key], seen);
      if (item !== undefined) out[key] = item;
    }
    return out;
  } finally {
    seen.delete(value);
  }
}

let server;

function activate() {
  const port = Number(process.env.MERCMAC_E2E_PROBE_PORT);
  if (!port) return;
  server = http.createServer((request, response) => {
    let body = "";
    request.on("data", (chunk) => { body += chunk; });
    request.on("end", async () => {
      let answer;
      try {
        const result = await new AsyncFunction("vscode", body)(vscode);
        answer = { ok: true, result: plain(result) };
      } catch (error) {
        answer = { ok: false, error: String((error && error.stack) || error) };
      }
      response.writeHead(200, { "content-type": "application/json" });
      response.end(JSON.stringify(answer));
    });
  });
  server.listen(port, "127.0.0.1");
}

function deactivate() {
  if (server) server.close();
}

module.exports = { activate, deactivate };
