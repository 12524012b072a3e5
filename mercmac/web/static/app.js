/* The page of `mercmac sim FILE --web`: the simulation's state as it streams from
 * /api/events, drawn once per animation frame, and the buttons, joystick and controls that
 * post to /api/*. Plain JavaScript, no framework, nothing from the network; the strict
 * Content-Security-Policy of the server allows no inline script or style attribute, so all
 * styling is by class, SVG attribute or element.style from here. */
"use strict";

(function () {
  // ------------------------------------------------------------------ token and requests
  const TOKEN = (function () {
    try {
      const t = new URL(location.href).searchParams.get("token");
      if (t) return t;
    } catch (e) { /* fall through */ }
    const s = document.currentScript || document.querySelector('script[src*="app.js"]');
    try {
      return new URL(s.src, location.href).searchParams.get("token") || "";
    } catch (e) {
      return "";
    }
  })();

  const SVG_NS = "http://www.w3.org/2000/svg";
  const BUTTONS = [1, 2, 3, 4];
  const LOG_MAX = 500;
  const PLOT_MS = 10000;          // the position plot's window of simulated time
  const PLOT_W = 600, PLOT_H = 160;
  const BAR_W = 1000, BAR_H = 56;  // the stage bar's viewBox
  const XY_MAX = 60000;           // path points kept
  const LOG_KINDS = new Set(["line", "hazard", "note", "error"]);

  // How the page reaches the simulation: this server over HTTP, or, in VS Code's webview
  // (which may not reach 127.0.0.1 itself), the extension, which relays to the same server.
  // The extension's script sets window.mercmacBridge before this one runs:
  //   post(path, body) -> Promise (rejects with an Error saying why),
  //   events({open(), message(text), error(closed)}): the event stream's data lines,
  //   saveScenario() -> Promise of a note to show (the extension asks where to save).
  const BRIDGE = window.mercmacBridge || null;

  // Actions go one after the other, so that a release never overtakes its press.
  let queue = Promise.resolve();
  function post(path, body) {
    const run = () => BRIDGE ? BRIDGE.post(path, body) : fetch(path, {
      method: "POST",
      headers: {"Content-Type": "application/json", "X-Mercmac-Token": TOKEN},
      body: JSON.stringify(body),
    }).then(async (r) => {
      if (!r.ok) {
        let why = "";
        try { why = (await r.text()).trim(); } catch (e) { /* none */ }
        throw new Error(`${path}: ${r.status}${why ? " " + why : ""}`);
      }
      return r;
    });
    const p = queue.then(run, run);
    queue = p.catch((err) => { note(String(err.message || err), "error"); });
    return p;
  }

  // ------------------------------------------------------------------ small DOM helpers
  function el(tag, attrs, ...kids) {
    const e = document.createElement(tag);
    for (const [k, v] of Object.entries(attrs || {})) {
      if (k === "class") e.className = v; else if (k === "text") e.textContent = v;
      else e.setAttribute(k, v);
    }
    for (const k of kids) e.append(k);
    return e;
  }
  function sv(tag, attrs, ...kids) {
    const e = document.createElementNS(SVG_NS, tag);
    for (const [k, v] of Object.entries(attrs || {})) e.setAttribute(k, v);
    for (const k of kids) e.append(k);
    return e;
  }
  // Writes only what changed: the DOM is touched once per frame, and not even then for
  // the parts that stay.
  function setText(e, v) {
    v = String(v);
    if (e._t !== v) { e._t = v; e.textContent = v; }
  }
  function setAttr(e, k, v) {
    v = String(v);
    e._a = e._a || {};
    if (e._a[k] !== v) { e._a[k] = v; e.setAttribute(k, v); }
  }
  const $ = (id) => document.getElementById(id);
  const fmt = (n) => (n === null || n === undefined || Number.isNaN(n)) ? "–" : String(Math.round(n));

  // ------------------------------------------------------------------ state
  let latest = null;           // the last state received
  let dirty = false;           // a frame is asked for
  let pendingLog = [];         // [text, kind] lines not yet on the page
  let pendingProblems;         // undefined: no news; else the list to show
  const history = new Map();   // controller name -> {t: [], p: []}
  let lastT = -Infinity;
  const xy = {pts: [], str: "", minX: Infinity, maxX: -Infinity, minY: Infinity, maxY: -Infinity,
    changed: false, seen: false, axes: []};

  let cards = new Map();       // controller name -> card parts
  let signature = "";
  let several = false;
  let activeName = null;       // the controller keys 1-4 press on

  // held[name/n] = Set of sources ("pointer", "latch", "key:Digit1", "click")
  const held = new Map();

  // ------------------------------------------------------------------ the stream
  const conn = $("conn");
  function setConn(state, text) {
    conn.dataset.state = state;
    conn.textContent = text;
  }
  function received(data) {
    let s;
    try { s = JSON.parse(data); } catch (e) { return; }
    if (!s || typeof s !== "object") return;
    ingest(s);
    latest = s;
    ask();
  }
  function connect() {
    if (BRIDGE) {
      BRIDGE.events({
        open: () => setConn("open", "live"),
        message: received,
        error: (closed) => setConn(closed ? "closed" : "connecting",
          closed ? "disconnected" : "reconnecting"),
      });
      return;
    }
    const es = new EventSource("/api/events?token=" + encodeURIComponent(TOKEN));
    es.onopen = () => setConn("open", "live");
    es.onerror = () => {
      setConn(es.readyState === EventSource.CLOSED ? "closed" : "connecting",
        es.readyState === EventSource.CLOSED ? "disconnected" : "reconnecting");
      if (es.readyState === EventSource.CLOSED) setTimeout(connect, 2000);
    };
    es.onmessage = (ev) => received(ev.data);
  }

  function ask() {
    if (!dirty) { dirty = true; requestAnimationFrame(frame); }
  }

  // What each message adds (lines, path, history) is kept as it comes; what it says of the
  // present (positions, LEDs...) is drawn from the latest message only, once per frame.
  function ingest(s) {
    // the timeline as [text, kind]: kind "line", "hazard" (a hazard the run reports) or "note"
    if (Array.isArray(s.log)) {
      for (const e of s.log) {
        if (Array.isArray(e)) pendingLog.push([String(e[0]), LOG_KINDS.has(e[1]) ? e[1] : "line"]);
      }
    }
    if (pendingLog.length > LOG_MAX) pendingLog = pendingLog.slice(-LOG_MAX);
    if (Array.isArray(s.problems)) pendingProblems = s.problems;
    const t = Number(s.t_ms);
    if (Number.isFinite(t)) {
      if (t < lastT) { history.clear(); clearPath(); }  // the file was reloaded: a new run
      lastT = t;
      for (const c of s.controllers || []) {
        let h = history.get(c.name);
        if (!h) { h = {t: [], p: []}; history.set(c.name, h); }
        if (typeof c.position === "number") { h.t.push(t); h.p.push(c.position); }
        // keep a little more than the window, drop the rest in one go now and then
        if (h.t.length > 64 && h.t[0] < t - PLOT_MS * 1.5) {
          let i = 0;
          while (i < h.t.length && h.t[i] < t - PLOT_MS) i++;
          i = Math.max(0, i - 1);
          h.t.splice(0, i); h.p.splice(0, i);
        }
        if (h.t.length > 200000) { h.t.splice(0, 100000); h.p.splice(0, 100000); }
      }
    }
    if (Array.isArray(s.path_axes)) xy.axes = s.path_axes.map(String);
    if (Array.isArray(s.path) && s.path.length) {
      xy.seen = true;
      for (const pt of s.path) {
        if (!Array.isArray(pt) || pt.length < 2) continue;
        const x = Number(pt[0]), y = Number(pt[1]);
        if (!Number.isFinite(x) || !Number.isFinite(y)) continue;
        xy.pts.push(x, y);
        xy.str += `${x},${-y} `;
        if (x < xy.minX) xy.minX = x; if (x > xy.maxX) xy.maxX = x;
        if (y < xy.minY) xy.minY = y; if (y > xy.maxY) xy.maxY = y;
      }
      if (xy.pts.length > 2 * XY_MAX) {
        xy.pts = xy.pts.slice(-XY_MAX);
        let str = "";
        for (let i = 0; i < xy.pts.length; i += 2) str += `${xy.pts[i]},${-xy.pts[i + 1]} `;
        xy.str = str;
      }
      xy.changed = true;
    }
  }

  function note(text, kind) {
    pendingLog.push([text, kind || "note"]);
    ask();
  }

  // ------------------------------------------------------------------ cards
  const controllersEl = $("controllers");

  function label(name, what) {
    return several ? `${name} ${what}` : what;
  }

  function buildCards(list) {
    several = list.length > 1;
    controllersEl.textContent = "";
    cards = new Map();
    for (const c of list) {
      const card = buildCard(c);
      cards.set(c.name, card);
      controllersEl.append(card.root);
    }
    if (!cards.has(activeName)) activeName = null;
    for (const name of cards.keys()) for (const n of BUTTONS) showHeld(name, n);
    controllersEl.classList.toggle("several", several);
  }

  function buildCard(c) {
    const name = c.name;
    const parts = {name, root: null, leds: [], buttons: [], joy: null};

    // the C-170.PB box: four LEDs over four round buttons
    const grid = el("div", {class: "box-grid"});
    for (const n of BUTTONS) {
      const led = el("span", {class: "led", role: "img", "aria-label": label(name, `LED ${n}`),
        "data-on": "false"});
      const b = el("button", {type: "button", class: "pb", "aria-label": label(name, `button ${n}`),
        "aria-pressed": "false", "data-line": "false"}, el("span", {class: "pb-cap", text: String(n)}));
      wireButton(b, name, n);
      parts.leds.push(led);
      parts.buttons.push(b);
      grid.append(el("div", {class: "box-col"}, led, b, el("span", {class: "box-num", "aria-hidden": "true", text: String(n)})));
    }
    const box = el("div", {class: "box"},
      el("div", {class: "box-head"}, el("span", {class: "box-model", text: "C-170.PB"}),
        el("span", {class: "keys-hint", text: "keys 1–4", title: "keys 1-4 press these buttons"}),
        el("span", {class: "no-box-hint", text: "no box here", title: "the box is plugged into another controller, or wires drive these inputs"})),
      grid);

    // the stage: a rail over the travel range, soft limits, the target and the carriage
    const bar = sv("svg", {class: "stagebar", viewBox: `0 0 ${BAR_W} ${BAR_H}`, preserveAspectRatio: "none",
      role: "img", "aria-label": label(name, "stage")});
    const zoneLo = sv("rect", {class: "soft-zone", x: 0, y: 18, width: 0, height: 20});
    const zoneHi = sv("rect", {class: "soft-zone", x: BAR_W, y: 18, width: 0, height: 20});
    const rail = sv("rect", {class: "rail", x: 0, y: 24, width: BAR_W, height: 8, rx: 4});
    const softLo = sv("line", {class: "soft", x1: 0, x2: 0, y1: 10, y2: 46, visibility: "hidden"});
    const softHi = sv("line", {class: "soft", x1: 0, x2: 0, y1: 10, y2: 46, visibility: "hidden"});
    const target = sv("path", {class: "target-mark", d: "M-7 2 L7 2 L0 14 Z"});
    const carriage = sv("rect", {class: "carriage", x: -14, y: 16, width: 28, height: 24, rx: 4});
    // the reference switch's edge (MS176E §4.3) and the hard limit switches (§4.4.1)
    const ref = sv("g", {class: "ref", "data-found": "false", visibility: "hidden"},
      sv("line", {x1: 0, x2: 0, y1: 14, y2: 54}), sv("text", {x: 4, y: 54, text: ""}));
    ref.lastChild.textContent = "REF";
    const limLo = sv("rect", {class: "limit", x: 0, y: 12, width: 8, height: 32, "data-pressed": "false", visibility: "hidden"});
    const limHi = sv("rect", {class: "limit", x: 0, y: 12, width: 8, height: 32, "data-pressed": "false", visibility: "hidden"});
    bar.append(rail, zoneLo, zoneHi, softLo, softHi, ref, limLo, limHi, target, carriage);
    const tmin = el("span", {class: "travel-min"});
    const tmax = el("span", {class: "travel-max"});
    const travel = el("div", {class: "travel"}, tmin, el("span", {class: "travel-soft"}), tmax);
    const switches = el("div", {class: "switches", "aria-label": label(name, "switches")});
    const hazard = el("div", {class: "card-hazard", role: "status", "aria-label": label(name, "hazard"), hidden: ""});

    const pos = el("output", {class: "num pos", "aria-label": label(name, "position"), "aria-live": "off", text: "0"});
    const posUnit = el("span", {class: "unit"});
    const tgt = el("output", {class: "num", "aria-label": label(name, "target"), "aria-live": "off"});
    const tgtUnit = el("span", {class: "unit"});
    const macro = el("output", {class: "macro", "aria-label": label(name, "macro"), "aria-live": "off"});
    const readout = el("div", {class: "readout"},
      el("div", {class: "ro"}, el("span", {class: "ro-k", text: "position"}), el("span", {class: "ro-v"}, pos, " ", posUnit)),
      el("div", {class: "ro"}, el("span", {class: "ro-k", text: "target"}), el("span", {class: "ro-v"}, tgt, " ", tgtUnit)),
      el("div", {class: "ro ro-macro"}, el("span", {class: "ro-k", text: "macro"}), el("span", {class: "ro-v"}, macro)));

    // the position over the last 10 simulated seconds
    const plot = sv("svg", {class: "plot", viewBox: `0 0 ${PLOT_W} ${PLOT_H}`, preserveAspectRatio: "none",
      role: "img", "aria-label": label(name, "position over the last 10 s")});
    for (let i = 1; i < 10; i++) {
      plot.append(sv("line", {class: "grid", x1: i * PLOT_W / 10, x2: i * PLOT_W / 10, y1: 0, y2: PLOT_H}));
    }
    for (let i = 1; i < 4; i++) {
      plot.append(sv("line", {class: "grid", x1: 0, x2: PLOT_W, y1: i * PLOT_H / 4, y2: i * PLOT_H / 4}));
    }
    const plotSoftLo = sv("line", {class: "plot-soft", x1: 0, x2: PLOT_W, y1: 0, y2: 0, visibility: "hidden"});
    const plotSoftHi = sv("line", {class: "plot-soft", x1: 0, x2: PLOT_W, y1: 0, y2: 0, visibility: "hidden"});
    const plotTarget = sv("line", {class: "plot-target", x1: 0, x2: PLOT_W, y1: 0, y2: 0, visibility: "hidden"});
    const line = sv("polyline", {class: "plot-line", points: ""});
    plot.append(plotSoftLo, plotSoftHi, plotTarget, line);
    const plotWrap = el("div", {class: "plot-wrap"},
      el("div", {class: "plot-axis"}, el("span", {class: "plot-max"}), el("span", {class: "plot-min"})),
      plot,
      el("div", {class: "plot-foot"}, el("span", {text: "−10 s"}), el("span", {text: "position, last 10 s"}), el("span", {text: "now"})));

    const stage = el("div", {class: "stage"}, bar, travel, switches, readout);
    const head = el("header", {class: "card-head"},
      el("h2", {class: "card-name", text: name}),
      el("span", {class: "card-model"}),
      el("span", {class: "card-unit"}));
    const body = el("div", {class: "card-body"}, box, stage);
    const joyRow = el("div", {class: "joy-row", hidden: ""});
    const root = el("article", {class: "card", "data-name": name}, head, hazard, body, plotWrap, joyRow);
    root.addEventListener("pointerdown", () => { if (hasPressable(name)) activeName = name; ask(); });
    root.addEventListener("focusin", () => { if (hasPressable(name)) activeName = name; ask(); });

    Object.assign(parts, {root, bar, rail, zoneLo, zoneHi, softLo, softHi, target, carriage, tmin, tmax,
      ref, limLo, limHi, switches, hazard,
      pos, posUnit, tgt, tgtUnit, macro, plot, line, plotTarget, plotSoftLo, plotSoftHi, joyRow,
      plotMax: plotWrap.querySelector(".plot-max"), plotMin: plotWrap.querySelector(".plot-min"),
      model: head.querySelector(".card-model"), softText: travel.querySelector(".travel-soft"),
      box, barW: BAR_W, noBox: box.querySelector(".no-box-hint")});
    // the bar is drawn in its own pixels, so that the carriage and the marks keep their shape
    if (window.ResizeObserver) {
      new ResizeObserver((entries) => {
        const w = Math.round(entries[0].contentRect.width);
        if (w > 0 && w !== parts.barW) {
          parts.barW = w;
          bar.setAttribute("viewBox", `0 0 ${w} ${BAR_H}`);
          ask();
        }
      }).observe(bar);
    }
    return parts;
  }

  function buildJoystick(parts) {
    const name = parts.name;
    const input = el("input", {type: "range", min: "-1", max: "1", step: "0.01", value: "0",
      class: "joy", "aria-label": label(name, "joystick")});
    const val = el("output", {class: "num joy-val", "aria-live": "off", text: "0.00"});
    const center = el("button", {type: "button", class: "small", text: "center"});
    let dragging = false, sent = 0, timer = 0;
    const send = () => {
      timer = 0;
      const d = Number(input.value);
      if (d === sent) return;
      sent = d;
      post("/api/joystick", {controller: name, deflection: d});
    };
    // at most one post every 30 ms while dragging; the last value always goes
    const soon = () => { if (!timer) timer = setTimeout(send, 30); };
    input.addEventListener("input", () => { val.textContent = Number(input.value).toFixed(2); soon(); });
    input.addEventListener("pointerdown", () => { dragging = true; });
    const release = () => {
      if (!dragging) return;
      dragging = false;
      // a joystick springs back to the middle when let go
      input.value = "0";
      val.textContent = "0.00";
      soon();
    };
    input.addEventListener("pointerup", release);
    input.addEventListener("pointercancel", release);
    center.addEventListener("click", () => { input.value = "0"; val.textContent = "0.00"; soon(); });
    parts.joyRow.append(el("span", {class: "ro-k", text: "joystick"}), input, val, center);
    parts.joy = {input, val, busy: () => dragging || document.activeElement === input || timer !== 0};
  }

  // ------------------------------------------------------------------ pressing
  function key(name, n) { return name + "/" + n; }
  function isHeld(name, n) { const s = held.get(key(name, n)); return !!(s && s.size); }
  function canPress(name, n) {
    const c = latest && (latest.controllers || []).find((x) => x.name === name);
    return !c || !Array.isArray(c.pressable) || c.pressable[n - 1] !== false;
  }
  function hasPressable(name) {
    const c = latest && (latest.controllers || []).find((x) => x.name === name);
    return !!c && (!Array.isArray(c.pressable) || c.pressable.some((p) => p));
  }

  function hold(name, n, source) {
    const k = key(name, n);
    let s = held.get(k);
    if (!s) { s = new Set(); held.set(k, s); }
    const was = s.size > 0;
    s.add(source);
    if (!was) post("/api/press", {controller: name, button: n, down: true});
    showHeld(name, n);
  }
  function release(name, n, source) {
    const s = held.get(key(name, n));
    if (!s || !s.has(source)) return;
    s.delete(source);
    if (s.size === 0) post("/api/press", {controller: name, button: n, down: false});
    showHeld(name, n);
  }
  function showHeld(name, n) {
    const card = cards.get(name);
    if (!card) return;
    const b = card.buttons[n - 1];
    const s = held.get(key(name, n));
    // aria-pressed at once, not at the next frame: it is what a person (and a test) sees
    b.setAttribute("aria-pressed", isHeld(name, n) ? "true" : "false");
    b.classList.toggle("latched", !!(s && s.has("latch")));
  }
  function latchOn() { return $("latch").checked; }

  function toggleLatch(name, n) {
    if (held.get(key(name, n))?.has("latch")) release(name, n, "latch");
    else hold(name, n, "latch");
  }

  function wireButton(b, name, n) {
    let pid = null;
    b.addEventListener("pointerdown", (e) => {
      if (e.pointerType === "mouse" && e.button !== 0) return;
      if (!canPress(name, n)) return;
      e.preventDefault();     // no text selection, no focus ring, no scrolling by a touch
      if (latchOn()) { toggleLatch(name, n); return; }  // at once, as the pointer goes down
      pid = e.pointerId;
      try { b.setPointerCapture(pid); } catch (err) { /* not capturable: pointerleave ends it */ }
      hold(name, n, "pointer");
      release(name, n, "latch");  // a press without latch lets go of a latched button after
    });
    const end = (e) => {
      if (pid === null || e.pointerId !== pid) return;
      pid = null;
      release(name, n, "pointer");
    };
    b.addEventListener("pointerup", end);
    b.addEventListener("pointercancel", end);
    b.addEventListener("pointerleave", end);
    b.addEventListener("lostpointercapture", end);
    b.addEventListener("contextmenu", (e) => e.preventDefault());
    b.addEventListener("click", (e) => {
      if (!canPress(name, n) || e.detail !== 0) return;  // a pointer's click: done at pointerdown
      // Enter or Space on the focused button
      if (latchOn()) toggleLatch(name, n);
      else if (!isHeld(name, n)) {  // a short press
        hold(name, n, "click");
        setTimeout(() => release(name, n, "click"), 150);
      }
    });
  }

  function keyTarget() {
    if (activeName && cards.has(activeName) && hasPressable(activeName)) return activeName;
    for (const name of cards.keys()) if (hasPressable(name)) return name;
    return null;
  }
  const keysDown = new Map();  // KeyboardEvent.code -> [name, n]
  function typing(t) {
    if (!t || !t.tagName) return false;
    if (t.isContentEditable) return true;
    if (t.tagName === "SELECT" || t.tagName === "TEXTAREA") return true;
    if (t.tagName === "INPUT") return !["range", "checkbox", "button", "radio"].includes(t.type);
    return false;
  }
  document.addEventListener("keydown", (e) => {
    if (e.ctrlKey || e.metaKey || e.altKey) return;
    let n = 0;
    const m = /^(?:Digit|Numpad)([1-4])$/.exec(e.code || "");
    if (m) n = Number(m[1]); else if (/^[1-4]$/.test(e.key)) n = Number(e.key);
    if (!n) return;
    if (typing(e.target)) return;
    e.preventDefault();
    const code = e.code || e.key;
    if (e.repeat || keysDown.has(code)) return;
    const name = keyTarget();
    if (!name || !canPress(name, n)) return;
    keysDown.set(code, [name, n]);
    hold(name, n, "key:" + code);
  });
  document.addEventListener("keyup", (e) => {
    const code = e.code || e.key;
    const k = keysDown.get(code);
    if (!k) return;
    keysDown.delete(code);
    release(k[0], k[1], "key:" + code);
  });
  // a key or pointer let go while the page had no focus never says so: let go of them all
  window.addEventListener("blur", () => {
    for (const [code, [name, n]] of keysDown) release(name, n, "key:" + code);
    keysDown.clear();
  });

  // ------------------------------------------------------------------ controls
  const runBtn = $("run"), speedSel = $("speed");
  runBtn.addEventListener("click", () => {
    const paused = !(latest && latest.paused);
    showPaused(paused);
    post("/api/run", {paused});
  });
  function showPaused(paused) {
    setAttr(runBtn, "aria-label", paused ? "run" : "pause");
    setText($("run-text"), paused ? "Run" : "Pause");
    setText(runBtn.querySelector(".ctl-icon"), paused ? "▶" : "❚❚");
    runBtn.dataset.paused = String(paused);
    $("paused-badge").hidden = !paused;
  }
  let speedUntil = 0;  // the selector keeps the person's choice for a moment
  for (const ev of ["pointerdown", "keydown"]) {
    speedSel.addEventListener(ev, () => { speedUntil = performance.now() + 5000; });
  }
  speedSel.addEventListener("change", () => {
    speedUntil = performance.now() + 1500;
    const v = speedSel.value;
    post("/api/speed", {speed: v === "max" ? null : Number(v)});
  });
  function showSpeed(speed) {
    // not while the person has the list open or has just chosen
    if (performance.now() < speedUntil) return;
    const v = speed === null ? "max" : String(speed);
    if (speedSel.value === v) return;
    if (![...speedSel.options].some((o) => o.value === v)) {
      const o = el("option", {value: v, text: "×" + v});
      speedSel.insertBefore(o, speedSel.querySelector('option[value="max"]'));
    }
    speedSel.value = v;
  }
  $("power").addEventListener("click", () => { post("/api/power", {}); });
  $("save").addEventListener("click", async () => {
    try {
      if (BRIDGE) {
        const said = await BRIDGE.saveScenario();
        if (said) note(String(said), "note");
        return;
      }
      const r = await fetch("/api/scenario?token=" + encodeURIComponent(TOKEN),
        {headers: {"X-Mercmac-Token": TOKEN}});
      if (!r.ok) throw new Error(`scenario: ${r.status} ${(await r.text()).trim()}`);
      const text = await r.text();
      const url = URL.createObjectURL(new Blob([text], {type: "application/toml"}));
      const a = el("a", {href: url, download: "session.scenario.toml", class: "hidden-link"});
      document.body.append(a);
      a.click();
      a.remove();
      setTimeout(() => URL.revokeObjectURL(url), 10000);
    } catch (err) {
      note(String(err.message || err), "error");
    }
  });
  $("latch").addEventListener("change", () => {
    document.body.classList.toggle("latching", latchOn());
  });
  function clearPath() {
    Object.assign(xy, {pts: [], str: "", minX: Infinity, maxX: -Infinity, minY: Infinity,
      maxY: -Infinity, changed: true});
  }
  $("xy-clear").addEventListener("click", () => { clearPath(); ask(); });

  // ------------------------------------------------------------------ drawing, once a frame
  function frame() {
    dirty = false;
    const s = latest;
    if (s) {
      try {
        render(s);
      } catch (err) {
        console.error(err);
      }
    }
    renderLog();
    renderProblems();
  }

  function render(s) {
    setText($("file"), s.file || "");
    const t = Number(s.t_ms) || 0;
    setText($("time"), (t / 1000).toFixed(3));
    showPaused(!!s.paused);
    showSpeed(s.speed === undefined ? 1 : s.speed);
    if (s.file && document.title !== `${s.file} · mercmac sim`) document.title = `${s.file} · mercmac sim`;

    const list = Array.isArray(s.controllers) ? s.controllers : [];
    const sig = list.map((c) => c.name).join("\u0000");
    if (sig !== signature) { signature = sig; buildCards(list); }
    const keysTo = keyTarget();
    for (const c of list) {
      const card = cards.get(c.name);
      if (card) renderCard(card, c, t, keysTo === c.name);
    }
    renderWires(s.wires);
    renderXY(list);
    $("rig").hidden = $("wires-panel").hidden && $("xy-panel").hidden;
  }

  function renderCard(k, c, t, keysHere) {
    setText(k.model, c.model || "");
    k.root.classList.toggle("keys-here", keysHere);
    const unit = c.unit || "";
    for (const n of BUTTONS) {
      const led = k.leds[n - 1], b = k.buttons[n - 1];
      setAttr(led, "data-on", Array.isArray(c.leds) && c.leds[n - 1] ? "true" : "false");
      setAttr(b, "data-line", Array.isArray(c.buttons) && c.buttons[n - 1] ? "true" : "false");
      const ok = !Array.isArray(c.pressable) || c.pressable[n - 1] !== false;
      if (ok) { if (b._a && b._a["aria-disabled"] === "true") { b.removeAttribute("aria-disabled"); b._a["aria-disabled"] = "false"; b.title = ""; } }
      else setAttr(b, "aria-disabled", "true"), setAttr(b, "title", "cannot be pressed here (no box button, or a wire drives this input)");
    }
    k.box.classList.toggle("no-box", !(Array.isArray(c.pressable) ? c.pressable.some(Boolean) : true));

    // the travel: between the limit switches where the bench has them, padded a little so
    // the carriage at an end still shows whole
    const sw = Array.isArray(c.limit_switches) && c.limit_switches.length === 2 ? c.limit_switches.map(Number) : null;
    let [lo, hi] = sw ? [sw[0] - (sw[1] - sw[0]) * 0.03, sw[1] + (sw[1] - sw[0]) * 0.03] : [NaN, NaN];
    const p = Number(c.position), tg = Number(c.target), rf = Number(c.reference);
    if (!Number.isFinite(lo) || !Number.isFinite(hi) || hi <= lo) {
      // no travel given: the range seen so far (the reference switch in it), which only
      // grows, so the bar stays still
      const r = k.seen || (k.seen = [Infinity, -Infinity]);
      for (const v of [p, tg, rf]) if (Number.isFinite(v)) { r[0] = Math.min(r[0], v); r[1] = Math.max(r[1], v); }
      if (!(r[1] > r[0])) { lo = (Number.isFinite(r[0]) ? r[0] : 0) - 1000; hi = lo + 2000; } else {
        const m = (r[1] - r[0]) * 0.05; lo = r[0] - m; hi = r[1] + m;
      }
    }
    const W = k.barW, pad = 16, span = W - 2 * pad;
    const X = (v) => pad + Math.max(-0.02, Math.min(1.02, (v - lo) / (hi - lo))) * span;
    setAttr(k.rail, "x", pad); setAttr(k.rail, "width", span);
    setAttr(k.carriage, "x", (X(p) - 14).toFixed(1));
    setAttr(k.carriage, "data-out", p < lo || p > hi ? "true" : "false");
    if (Number.isFinite(tg)) {
      setAttr(k.target, "transform", `translate(${X(tg).toFixed(1)} 0)`);
      setAttr(k.target, "visibility", "visible");
    } else setAttr(k.target, "visibility", "hidden");
    const sl = Array.isArray(c.soft_limits) ? c.soft_limits : [null, null];
    const sLo = sl[0] === null || sl[0] === undefined ? null : Number(sl[0]);
    const sHi = sl[1] === null || sl[1] === undefined ? null : Number(sl[1]);
    const inside = (v) => v !== null && Number.isFinite(v) && v >= lo && v <= hi;
    if (inside(sLo)) {
      const x = X(sLo);
      setAttr(k.softLo, "x1", x.toFixed(1)); setAttr(k.softLo, "x2", x.toFixed(1));
      setAttr(k.softLo, "visibility", "visible");
      setAttr(k.zoneLo, "x", pad); setAttr(k.zoneLo, "width", Math.max(0, x - pad).toFixed(1));
    } else { setAttr(k.softLo, "visibility", "hidden"); setAttr(k.zoneLo, "width", 0); }
    if (inside(sHi)) {
      const x = X(sHi);
      setAttr(k.softHi, "x1", x.toFixed(1)); setAttr(k.softHi, "x2", x.toFixed(1));
      setAttr(k.softHi, "visibility", "visible");
      setAttr(k.zoneHi, "x", x.toFixed(1)); setAttr(k.zoneHi, "width", Math.max(0, W - pad - x).toFixed(1));
    } else { setAttr(k.softHi, "visibility", "hidden"); setAttr(k.zoneHi, "width", 0); }
    if (Number.isFinite(rf) && rf >= lo && rf <= hi) {
      setAttr(k.ref, "transform", `translate(${X(rf).toFixed(1)} 0)`);
      setAttr(k.ref, "visibility", "visible");
    } else setAttr(k.ref, "visibility", "hidden");
    setAttr(k.ref, "data-found", c.referenced ? "true" : "false");
    for (const [rect, at, side] of [[k.limLo, sw && sw[0], "negative"], [k.limHi, sw && sw[1], "positive"]]) {
      if (sw) {
        setAttr(rect, "x", (X(at) - (side === "negative" ? 8 : 0)).toFixed(1));
        setAttr(rect, "visibility", "visible");
        setAttr(rect, "data-pressed", c.at_limit === side ? "true" : "false");
      } else setAttr(rect, "visibility", "hidden");
    }
    const swText = [Number.isFinite(rf) ? `reference switch at ${fmt(rf)}${c.referenced ? " (found)" : ""}` : "",
      sw ? `limit switches at ${fmt(sw[0])} and ${fmt(sw[1])}` : "no limit switches",
      c.at_limit ? `on the ${c.at_limit} limit switch` : ""].filter(Boolean).join(" · ");
    setText(k.switches, swText);
    k.switches.classList.toggle("at-limit", !!c.at_limit);
    if (c.hazard) { setText(k.hazard, "⚠ hazard " + c.hazard); if (k.hazard.hidden) k.hazard.hidden = false; }
    else if (!k.hazard.hidden) k.hazard.hidden = true;
    k.root.classList.toggle("hazardous", !!c.hazard);
    setText(k.tmin, fmt(sw ? sw[0] : lo));
    setText(k.tmax, fmt(sw ? sw[1] : hi));
    setText(k.softText, sLo === null && sHi === null ? "no soft limits"
      : `soft limits ${sLo === null ? "–" : fmt(sLo)} … ${sHi === null ? "–" : fmt(sHi)}`);

    setText(k.pos, Number.isFinite(p) ? String(Math.round(p)) : "");
    setText(k.tgt, Number.isFinite(tg) ? String(Math.round(tg)) : "–");
    setText(k.posUnit, unit);
    setText(k.tgtUnit, unit);
    setText(k.macro, c.macro === null || c.macro === undefined ? "" : String(c.macro));

    renderPlot(k, c, t, lo, hi, tg, sLo, sHi);

    const hasJoy = c.joystick !== null && c.joystick !== undefined;
    if (hasJoy && !k.joy) buildJoystick(k);
    if (k.joyRow.hidden === hasJoy) k.joyRow.hidden = !hasJoy;
    if (hasJoy && !k.joy.busy()) {
      const d = Number(c.joystick);
      if (Number.isFinite(d) && Number(k.joy.input.value) !== d) {
        k.joy.input.value = String(d);
        k.joy.val.textContent = d.toFixed(2);
      }
    }
  }

  function renderPlot(k, c, t, lo, hi, tg, sLo, sHi) {
    const h = history.get(c.name);
    const Y = (v) => PLOT_H - 4 - ((v - lo) / (hi - lo)) * (PLOT_H - 8);
    setText(k.plotMax, fmt(hi));
    setText(k.plotMin, fmt(lo));
    const horiz = (line, v) => {
      if (v === null || !Number.isFinite(v)) { setAttr(line, "visibility", "hidden"); return; }
      const y = Y(v).toFixed(1);
      setAttr(line, "y1", y); setAttr(line, "y2", y); setAttr(line, "visibility", "visible");
    };
    horiz(k.plotTarget, tg);
    horiz(k.plotSoftLo, sLo);
    horiz(k.plotSoftHi, sHi);
    if (!h || !h.t.length) { setAttr(k.line, "points", ""); return; }
    if (k._plotT === t && k._plotN === h.t.length) return;  // nothing new since last frame
    k._plotT = t; k._plotN = h.t.length;
    const t0 = t - PLOT_MS;
    // one column of the plot per pixel of the viewBox: first, lowest, highest, last
    const cols = PLOT_W;
    let out = [];
    let col = -1, first = 0, mn = 0, mx = 0, last = 0;
    const flush = () => {
      if (col < 0) return;
      const x = col;
      out.push(`${x},${Y(first).toFixed(1)}`);
      if (mn !== first && mn !== last) out.push(`${x},${Y(mn).toFixed(1)}`);
      if (mx !== first && mx !== last && mx !== mn) out.push(`${x},${Y(mx).toFixed(1)}`);
      if (last !== first) out.push(`${x},${Y(last).toFixed(1)}`);
    };
    let start = 0;
    // the point just before the window, so the line enters from the left edge
    while (start + 1 < h.t.length && h.t[start + 1] < t0) start++;
    for (let i = start; i < h.t.length; i++) {
      const x = Math.max(0, Math.min(cols, Math.round(((h.t[i] - t0) / PLOT_MS) * cols)));
      const v = h.p[i];
      if (x !== col) {
        flush();
        col = x; first = mn = mx = last = v;
      } else {
        if (v < mn) mn = v; if (v > mx) mx = v; last = v;
      }
    }
    flush();
    // hold the last value to "now"
    const lastV = h.p[h.p.length - 1];
    if (col < cols) out.push(`${cols},${Y(lastV).toFixed(1)}`);
    setAttr(k.line, "points", out.join(" "));
  }

  const wiresEl = $("wires");
  let wireSig = "";
  let wireItems = [];
  function renderWires(wires) {
    const list = Array.isArray(wires) ? wires : [];
    const sig = list.map((w) => w.from + ">" + w.to).join("|");
    if (sig !== wireSig) {
      wireSig = sig;
      wiresEl.textContent = "";
      wireItems = list.map((w) => {
        const state = el("span", {class: "wire-state"});
        const li = el("li", {class: "wire", "data-high": "false"},
          el("span", {class: "wire-end", text: w.from}),
          el("span", {class: "wire-line", "aria-hidden": "true"}),
          el("span", {class: "wire-end", text: w.to}),
          state);
        li._state = state;
        wiresEl.append(li);
        return li;
      });
      $("wires-panel").hidden = list.length === 0;
    }
    list.forEach((w, i) => {
      const li = wireItems[i];
      setAttr(li, "data-high", w.high ? "true" : "false");
      setText(li._state, w.high ? "high" : "low");
    });
  }

  function renderXY(list) {
    const panel = $("xy-panel");
    if (panel.hidden === xy.seen) panel.hidden = !xy.seen;
    if (!xy.seen || !xy.changed) return;
    xy.changed = false;
    // the frame: the travel of the path's X and Y axes (if known) and whatever the path covers
    let minX = xy.minX, maxX = xy.maxX, minY = xy.minY, maxY = xy.maxY;
    const named = (i) => list.find((c) => c.name === xy.axes[i]);
    if (xy.axes.length >= 2 && named(0) && named(1)) {
      const tx = named(0).limit_switches, ty = named(1).limit_switches;
      if (Array.isArray(tx) && tx.length === 2) { minX = Math.min(minX, tx[0]); maxX = Math.max(maxX, tx[1]); }
      if (Array.isArray(ty) && ty.length === 2) { minY = Math.min(minY, ty[0]); maxY = Math.max(maxY, ty[1]); }
    }
    if (!Number.isFinite(minX)) { minX = 0; maxX = 1; minY = 0; maxY = 1; }
    if (maxX - minX < 1) { maxX = minX + 1; }
    if (maxY - minY < 1) { maxY = minY + 1; }
    const w = maxX - minX, h = maxY - minY;
    const padX = w * 0.04, padY = h * 0.04;
    const svg = $("xy");
    // y grows upwards: the points are (x, -y)
    svg.setAttribute("viewBox", `${minX - padX} ${-maxY - padY} ${w + 2 * padX} ${h + 2 * padY}`);
    const frameR = $("xy-frame");
    frameR.setAttribute("x", minX); frameR.setAttribute("y", -maxY);
    frameR.setAttribute("width", w); frameR.setAttribute("height", h);
    $("xy-line").setAttribute("points", xy.str);
    const dot = $("xy-dot");
    if (xy.pts.length) {
      dot.setAttribute("cx", xy.pts[xy.pts.length - 2]);
      dot.setAttribute("cy", -xy.pts[xy.pts.length - 1]);
      dot.setAttribute("r", Math.max(w, h) * 0.012);
      dot.setAttribute("visibility", "visible");
    } else dot.setAttribute("visibility", "hidden");
    const [nx, ny] = xy.axes.length >= 2 ? xy.axes : ["x", "y"];
    setText($("xy-range"), `${nx} ${fmt(minX)} … ${fmt(maxX)} (across)   ${ny} ${fmt(minY)} … ${fmt(maxY)} (up)`);
  }

  const logEl = $("log");
  function renderLog() {
    if (!pendingLog.length) return;
    const atEnd = logEl.scrollHeight - logEl.scrollTop - logEl.clientHeight < 24;
    const items = pendingLog.length > LOG_MAX ? pendingLog.slice(-LOG_MAX) : pendingLog;
    pendingLog = [];
    if (items.length >= LOG_MAX) logEl.textContent = "";
    const frag = document.createDocumentFragment();
    for (const [text, kind] of items) {
      frag.append(el("div", {class: "log-line " + kind, text: (kind === "hazard" ? "⚠ " : "") + text}));
    }
    logEl.append(frag);
    let extra = logEl.childElementCount - LOG_MAX;
    while (extra-- > 0) logEl.firstElementChild.remove();
    if (atEnd) logEl.scrollTop = logEl.scrollHeight;
  }

  function renderProblems() {
    if (pendingProblems === undefined) return;
    const list = pendingProblems.map(String);
    pendingProblems = undefined;
    const sig = JSON.stringify(list);
    if (sig === renderProblems.last) return;
    renderProblems.last = sig;
    const box = $("problems"), ul = $("problems-list");
    ul.textContent = "";
    for (const p of list) ul.append(el("li", {text: p}));
    box.hidden = list.length === 0;
  }

  // ------------------------------------------------------------------ go
  if (!TOKEN && !BRIDGE) setConn("closed", "no token in the address");
  connect();
})();
