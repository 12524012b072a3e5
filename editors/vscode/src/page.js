// The webview's HTML: the page of `mercmac sim --web` (index.html as its server gives it),
// with its stylesheet and script put inline under a nonce, the bridge (bridge.js) before the
// script, and a strict Content-Security-Policy: nothing from the network, no script or style
// but ours.
"use strict";
const crypto = require("crypto");
const { bridge } = require("./bridge");

function nonce() {
  return crypto.randomBytes(18).toString("base64").replace(/[+/=]/g, "");
}

/** TEXT safe inside <script> or <style>: no closing tag of the element ("<\/script" means
 *  the same in a JavaScript string or regular expression). */
function inline(text, tag) {
  return text.replace(new RegExp(`</(${tag})`, "gi"), "<\\/$1");
}

/**
 * The webview's HTML from the server's INDEX, CSS and JS (the texts of /, /static/style.css,
 * /static/app.js); CSP_SOURCE is the webview's cspSource. The link and the script tag of
 * index.html are replaced; the scripts go at the end of the body, where the page's own
 * `defer` would have run it. Replacements are by function, so that no `$&` of the assets is
 * read as a pattern.
 */
function pageHtml({ index, css, js, cspSource, nonce: given }) {
  const n = given || nonce();
  const csp = [
    "default-src 'none'",
    `script-src 'nonce-${n}'`,
    `style-src 'nonce-${n}' ${cspSource}`,
    "img-src data:",
    `font-src ${cspSource}`,
    "base-uri 'none'",
    "form-action 'none'",
  ].join("; ");
  const meta = `<meta http-equiv="Content-Security-Policy" content="${csp}">`;
  // VS Code's default styles for webviews pad the body by 20px on each side; the page is
  // drawn to the edges, as in a browser
  const style = `<style nonce="${n}">\n${inline(css, "style")}\nbody { padding: 0; }\n</style>`;
  const scripts = `<script nonce="${n}">(${bridge.toString()})(acquireVsCodeApi(), window);</script>\n` +
    `<script nonce="${n}">\n${inline(js, "script")}\n</script>\n`;
  let html = index
    .replace(/<link\b[^>]*rel="stylesheet"[^>]*>/i, () => style)
    .replace(/<script\b[^>]*src="[^"]*app\.js[^"]*"[^>]*>\s*<\/script>/i, () => "")
    .replace(/<link\b[^>]*rel="icon"[^>]*>/i, () => "");
  html = /<head[^>]*>/i.test(html) ? html.replace(/<head[^>]*>/i, (head) => `${head}\n${meta}`) : meta + html;
  html = /<\/body>/i.test(html) ? html.replace(/<\/body>/i, () => `${scripts}</body>`) : html + scripts;
  if (!html.includes(style)) {
    html = html.replace(meta, () => `${meta}\n${style}`); // an index.html without the link
  }
  return html;
}

module.exports = { pageHtml, nonce };
