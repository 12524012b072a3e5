// The webview's side of the relay: window.mercmacBridge, which the page of `mercmac sim --web`
// (app.js) uses instead of fetch and EventSource when it is set before app.js runs. The
// function's source is put into the webview as a script of its own (page.js), so it uses
// nothing from this module: its parameters and the webview's globals only.
//   post(path, body) -> Promise, rejected with an Error saying why ("/api/press: 400 ...")
//   events({open, message, error}): the stream's data texts; error(true) once it is gone
//   saveScenario() -> Promise of a note for the page's timeline, or null
// The extension answers {type: "post" | "saveScenario", id, ...} with {type: "reply", id,
// value | error}, streams {type: "open" | "event" | "error"} after {type: "events"}, and says
// {type: "stopped", text} when the simulation has ended.
"use strict";

function bridge(vscodeApi, win) {
  var pending = new Map();
  var next = 1;
  var listener = null;

  function ask(message) {
    var id = next++;
    message.id = id;
    return new Promise(function (resolve, reject) {
      pending.set(id, { resolve: resolve, reject: reject });
      vscodeApi.postMessage(message);
    });
  }

  function stopped(text) {
    var doc = win.document;
    var banner = doc.getElementById("mercmac-stopped");
    if (!banner) {
      banner = doc.createElement("div");
      banner.id = "mercmac-stopped";
      banner.className = "problems";
      banner.setAttribute("role", "alert");
      var title = doc.createElement("div");
      title.className = "problems-title";
      title.textContent = "The simulation stopped:";
      var why = doc.createElement("div");
      why.id = "mercmac-stopped-text";
      banner.append(title, why);
      var header = doc.querySelector("header");
      if (header && header.after) header.after(banner); else doc.body.prepend(banner);
    }
    doc.getElementById("mercmac-stopped-text").textContent = String(text || "");
  }

  win.addEventListener("message", function (event) {
    var m = event.data;
    if (!m || typeof m !== "object") return;
    if (m.type === "reply") {
      var waiting = pending.get(m.id);
      if (!waiting) return;
      pending.delete(m.id);
      if (m.error !== undefined) waiting.reject(new Error(String(m.error)));
      else waiting.resolve(m.value === undefined ? null : m.value);
    } else if (m.type === "event") {
      if (listener) listener.message(String(m.data));
    } else if (m.type === "open") {
      if (listener) listener.open();
    } else if (m.type === "error") {
      if (listener) listener.error(Boolean(m.closed));
    } else if (m.type === "stopped") {
      if (listener) listener.error(true);
      stopped(m.text);
    }
  });

  win.mercmacBridge = {
    post: function (path, body) {
      return ask({ type: "post", path: String(path), body: body });
    },
    events: function (handlers) {
      listener = handlers;
      vscodeApi.postMessage({ type: "events" });
    },
    saveScenario: function () {
      return ask({ type: "saveScenario" });
    },
  };
}

module.exports = { bridge };
