// Commands that need no client: copying what a code lens hands over, asking the executable
// for its version.
"use strict";
const childProcess = require("child_process");
const vscode = require("vscode");

/** mercmac.copyBuild, run by the server's "build" code lens with {macro, lines}: the MD
 *  lines `mercmac build` writes for that macro, to paste into a terminal program. */
async function copyBuild(argument) {
  const lines = argument && Array.isArray(argument.lines) ? argument.lines.map(String) : undefined;
  if (!lines) {
    void vscode.window.showErrorMessage("mercmac: nothing to copy (the code lens gave no MD lines).");
    return;
  }
  await vscode.env.clipboard.writeText(lines.join("\n"));
  const what = lines.length === 1 ? "the MD line" : `the ${lines.length} MD lines`;
  void vscode.window.showInformationMessage(`Copied ${what} of ${argument.macro}`);
}

/** What `COMMAND --version` says ("mercmac, version 0.1.0" gives "0.1.0"), or throws. */
function askVersion(command, cwd) {
  return new Promise((resolve, reject) => {
    childProcess.execFile(command, ["--version"], { cwd, timeout: 10000 }, (error, stdout, stderr) => {
      if (error) {
        reject(new Error(String(stderr).trim() || error.message));
        return;
      }
      const found = /version\s+(\S+)/.exec(stdout);
      resolve(found ? found[1] : String(stdout).trim());
    });
  });
}

module.exports = { copyBuild, askVersion };
