// What the extension tells the user. Notifications and the status item are plain text (no
// Markdown), so commands and settings are quoted, not put in backticks.
"use strict";

const INSTALL_HINT =
  "Install it with pip install 'mercmac[lsp]', or set the mercmac.path setting to the " +
  "mercmac executable (for a virtual environment: .venv/bin/mercmac).";

/** The server's own reason, from the last lines of its standard error: the last line (a
 *  Python traceback ends with the exception), with the line before it when that one is a
 *  "hint:" (mercmac says a message, then its hint); without the "mercmac: " prefix, which
 *  our messages carry already. */
function reasonFrom(stderrLines) {
  const lines = stderrLines.map((line) => line.trim()).filter(Boolean);
  if (lines.length === 0) {
    return "";
  }
  const last = lines.slice(/^hint:/.test(lines[lines.length - 1]) ? -2 : -1);
  return last.join(" ").replace(/^mercmac: /, "");
}

/** How a process ended: "code 2", "signal SIGKILL". */
function ending(exit) {
  if (!exit) {
    return "";
  }
  return exit.signal ? `signal ${exit.signal}` : `code ${exit.code}`;
}

/**
 * Why the server is not running, for the one error message and the status item:
 * { text, kind } where kind is "not-found", "not-executable", "no-lsp-extra", "crashed" or
 * "failed". FAILURE is what Session gathered: the command, the spawn or start error, the
 * last lines of standard error, the exit ({code, signal}) and whether it CRASHED: stopped
 * after it had answered `initialize`, RESTARTS times restarted.
 */
function describeFailure({ command, error, stderr = [], exit, crashed = false, restarts = 0 }) {
  const code = error && error.code;
  if (code === "ENOENT") {
    return { kind: "not-found",
      text: `mercmac: cannot start the language server: '${command}' was not found. ${INSTALL_HINT}` };
  }
  if (code === "EACCES") {
    return { kind: "not-executable",
      text: `mercmac: cannot start the language server: '${command}' is not executable. ${INSTALL_HINT}` };
  }
  const reason = reasonFrom(stderr);
  const kind = /lsp extra/.test(reason) ? "no-lsp-extra" : crashed ? "crashed" : "failed";
  const how = exit ? ` (${ending(exit)})` : "";
  let text;
  if (crashed) {
    text = `mercmac: the language server '${command} lsp' stopped${how} ` +
      `${restarts + 1} time${restarts ? "s" : ""} in a few minutes and will not be restarted` +
      (reason ? `: ${reason}` : "; see the server log.");
  } else if (exit) {
    text = `mercmac: the language server '${command} lsp' exited${how} before it started` +
      (reason ? `: ${reason}` : "; see the server log.");
  } else {
    // it is still there (answered `initialize` with an error, or kept failing): its answer
    // says more than its standard error
    const said = error ? String(error.message || error) : reason || "see the server log";
    text = `mercmac: the language server '${command} lsp' did not start: ${said}`;
  }
  return { kind, text };
}

/** Few words for the status item. */
const SHORT = {
  "not-found": "not found",
  "not-executable": "not executable",
  "no-lsp-extra": "needs the lsp extra",
  crashed: "stopped",
  failed: "not running",
};

module.exports = { INSTALL_HINT, reasonFrom, describeFailure, ending, SHORT };
