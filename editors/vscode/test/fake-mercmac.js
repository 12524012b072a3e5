// A stand-in for `mercmac` (run through a shell wrapper, test/fakes.js), so that the client's
// lifecycle is tested without Python: `--version` prints a version, `lsp --stdio` is a
// language server that answers initialize, shutdown and exit, and FAKE_MERCMAC_MODE makes
// it misbehave: "crash" exits (code 1, after "boom" on stderr) once initialized; `sim FILE
// --web` is test/fake-sim.js, and its modes are there.
// `node --test test/` runs every .js file here as a test file: without arguments it does
// nothing.
"use strict";

const VERSION = "9.9.9-fake";

function send(message) {
  const body = Buffer.from(JSON.stringify({ jsonrpc: "2.0", ...message }), "utf8");
  process.stdout.write(`Content-Length: ${body.length}\r\n\r\n`);
  process.stdout.write(body);
}

function handle(message, mode) {
  if (message.method === "initialize") {
    send({ id: message.id, result: { capabilities: {}, serverInfo: { name: "mercmac", version: VERSION } } });
  } else if (message.method === "initialized" && mode === "crash") {
    process.stderr.write("fake mercmac: boom\n", () => process.exit(1));
  } else if (message.method === "shutdown") {
    send({ id: message.id, result: null });
  } else if (message.method === "exit") {
    process.exit(0);
  } else if (message.id !== undefined && message.method !== undefined) {
    send({ id: message.id, error: { code: -32601, message: `${message.method}: not in the fake` } });
  }
}

function serve(mode) {
  process.stderr.write(`fake mercmac ${VERSION}: serving\n`);
  let buffer = Buffer.alloc(0);
  process.stdin.on("data", (chunk) => {
    buffer = Buffer.concat([buffer, chunk]);
    for (;;) {
      const end = buffer.indexOf("\r\n\r\n");
      if (end < 0) return;
      const length = Number(/Content-Length: (\d+)/i.exec(buffer.slice(0, end).toString())[1]);
      if (buffer.length < end + 4 + length) return;
      const body = buffer.slice(end + 4, end + 4 + length).toString("utf8");
      buffer = buffer.slice(end + 4 + length);
      handle(JSON.parse(body), mode);
    }
  });
  process.stdin.on("end", () => process.exit(0));
}

const args = process.argv.slice(2);
if (args[0] === "--version") {
  process.stdout.write(`mercmac, version ${VERSION}\n`);
} else if (args[0] === "lsp") {
  serve(process.env.FAKE_MERCMAC_MODE || "ok");
} else if (args[0] === "sim") {
  require("./fake-sim").simulate(args.slice(1), process.env.FAKE_MERCMAC_MODE || "ok");
}

module.exports = { VERSION };
