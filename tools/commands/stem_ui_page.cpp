// The stem-ui page: one static HTML file with its script and style, embedded in the binary so
// that the tool needs no files beside it. Plain JavaScript, no build step.
namespace fieldrig::tools {

extern const char* const kStemUiPage;

const char* const kStemUiPage = R"STEMUI(<!doctype html>
<html lang="en">
<head>
<meta charset="utf-8">
<title>fieldrig · stem diameter</title>
<style>
  body { font: 14px system-ui, sans-serif; margin: 0; background: #1d1f21; color: #ddd; }
  header { display: flex; gap: 12px; align-items: center; padding: 8px 12px; background: #2a2d30;
           flex-wrap: wrap; }
  main { display: grid; grid-template-columns: 3fr 1fr; gap: 8px; padding: 8px; }
  canvas { background: #000; width: 100%; display: block; cursor: crosshair; }
  #right { cursor: default; }
  .panel { background: #2a2d30; padding: 8px; border-radius: 4px; margin-bottom: 8px; }
  .big { font-size: 28px; font-weight: bold; color: #8fd18f; }
  .error { color: #f08080; }
  table { border-collapse: collapse; width: 100%; font-size: 12px; }
  td, th { border-bottom: 1px solid #444; padding: 2px 4px; text-align: right; }
  td:first-child, th:first-child { text-align: left; }
  button, select, input { font: inherit; }
  a { color: #9cf; }
</style>
</head>
<body>
<header>
  <label>Session <select id="session"></select></label>
  <label>FrameSet <select id="set"></select></label>
  <label>Head <select id="head"></select></label>
  <label>Stem <input id="label" size="10" placeholder="label"></label>
  <button id="undo" title="Remove the last click (z)">Undo click</button>
  <button id="clear">Clear</button>
  <button id="save" disabled>Save</button>
  <button id="delete-last">Delete last saved</button>
  <a id="export" href="#">Export CSV</a>
  <span>wheel: zoom · drag: pan · click: point (4)</span>
</header>
<main>
  <div><canvas id="left" width="1200" height="800"></canvas></div>
  <div>
    <div class="panel">
      <div>Diameter</div><div class="big"><span id="diameter">–</span> mm</div>
      <div>NCC <span id="ncc">–</span> · distinct <span id="distinct">–</span></div>
      <div>disparity <span id="disparity">–</span> px · width <span id="width">–</span> px</div>
      <div id="status"></div>
    </div>
    <div class="panel"><div>Matched patch (right image)</div>
      <canvas id="right" width="400" height="300"></canvas></div>
    <div class="panel"><div>Stems (mean ± SD of repeats)</div>
      <table id="summary"><thead><tr><th>stem</th><th>n</th><th>mean mm</th><th>SD mm</th></tr></thead><tbody></tbody></table></div>
    <div class="panel"><div>Measurements</div>
      <table id="measurements"><thead><tr><th>stem</th><th>#</th><th>set</th><th>head</th><th>mm</th><th>NCC</th></tr></thead><tbody></tbody></table></div>
  </div>
</main>
<script>
"use strict";
const $ = (id) => document.getElementById(id);
const state = { sessions: [], session: null, set: null, head: null, points: [], result: null,
                left: null, right: null, view: { scale: 1, x: 0, y: 0 }, busy: false };

async function api(method, path, body) {
  const response = await fetch(path, { method, headers: body ? { "Content-Type": "application/json" } : {},
                                       body: body ? JSON.stringify(body) : undefined });
  const json = await response.json().catch(() => ({}));
  if (!response.ok) throw new Error(json.error || response.statusText);
  return json;
}
const base = () => "/api/sessions/" + encodeURIComponent(state.session);
function setStatus(text, isError) { $("status").textContent = text; $("status").className = isError ? "error" : ""; }

function loadImage(url) {
  return new Promise((resolve, reject) => {
    const image = new Image();
    image.onload = () => resolve(image);
    image.onerror = () => reject(new Error("cannot load " + url));
    image.src = url;
  });
}

// Image pixel (x, y) → canvas pixel and back; the view keeps the image's top-left at (view.x,
// view.y) in canvas pixels, scaled by view.scale.
const toCanvas = (x, y) => [state.view.x + x * state.view.scale, state.view.y + y * state.view.scale];
const toImage = (cx, cy) => [(cx - state.view.x) / state.view.scale, (cy - state.view.y) / state.view.scale];
function canvasScale() { const c = $("left"); return c.width / c.getBoundingClientRect().width; }
function eventToCanvas(event) {
  const rect = $("left").getBoundingClientRect(), s = canvasScale();
  return [(event.clientX - rect.left) * s, (event.clientY - rect.top) * s];
}

function fit() {
  const c = $("left");
  if (!state.left) return;
  const s = Math.min(c.width / state.left.width, c.height / state.left.height);
  state.view = { scale: s, x: (c.width - state.left.width * s) / 2, y: (c.height - state.left.height * s) / 2 };
}

// Points in the outline order q1 q2 q4 q3 (sorted by angle about their centre) for drawing.
function outline(points) {
  const cx = points.reduce((a, p) => a + p[0], 0) / points.length;
  const cy = points.reduce((a, p) => a + p[1], 0) / points.length;
  return [...points].sort((a, b) => Math.atan2(a[1] - cy, a[0] - cx) - Math.atan2(b[1] - cy, b[0] - cx));
}

function drawLeft() {
  const c = $("left"), g = c.getContext("2d");
  g.fillStyle = "#000"; g.fillRect(0, 0, c.width, c.height);
  if (!state.left) return;
  g.imageSmoothingEnabled = state.view.scale < 2;
  g.drawImage(state.left, state.view.x, state.view.y, state.left.width * state.view.scale,
              state.left.height * state.view.scale);
  if (state.points.length === 4) {
    g.strokeStyle = state.result && state.result.status === "ok" ? "#8fd18f" : "#f0c040";
    g.lineWidth = 1.5; g.beginPath();
    outline(state.points).forEach((p, i) => { const [x, y] = toCanvas(p[0], p[1]); i ? g.lineTo(x, y) : g.moveTo(x, y); });
    g.closePath(); g.stroke();
  }
  g.fillStyle = "#ff4040";
  for (const p of state.points) {
    const [x, y] = toCanvas(p[0], p[1]);
    g.beginPath(); g.arc(x, y, 4, 0, 2 * Math.PI); g.fill();
  }
}

function drawRight() {
  const c = $("right"), g = c.getContext("2d");
  g.fillStyle = "#000"; g.fillRect(0, 0, c.width, c.height);
  const quad = state.result && state.result.right_patch_raw;
  if (!state.right || !quad) return;
  const xs = quad.map((p) => p[0]), ys = quad.map((p) => p[1]);
  const cx = (Math.min(...xs) + Math.max(...xs)) / 2, cy = (Math.min(...ys) + Math.max(...ys)) / 2;
  const span = Math.max(Math.max(...xs) - Math.min(...xs), Math.max(...ys) - Math.min(...ys), 20) * 2;
  const s = Math.min(c.width, c.height) / span;
  const ox = c.width / 2 - cx * s, oy = c.height / 2 - cy * s;
  g.imageSmoothingEnabled = s < 2;
  g.drawImage(state.right, ox, oy, state.right.width * s, state.right.height * s);
  g.strokeStyle = "#40c0ff"; g.lineWidth = 1.5; g.beginPath();
  outline(quad).forEach((p, i) => { const x = ox + p[0] * s, y = oy + p[1] * s; i ? g.lineTo(x, y) : g.moveTo(x, y); });
  g.closePath(); g.stroke();
}

function showResult() {
  const r = state.result;
  const fmt = (v, d) => (v === null || v === undefined ? "–" : Number(v).toFixed(d));
  $("diameter").textContent = r ? fmt(r.diameter_mm, 2) : "–";
  $("ncc").textContent = r ? fmt(r.ncc, 3) : "–";
  $("distinct").textContent = r ? fmt(r.distinctness, 3) : "–";
  $("disparity").textContent = r ? fmt(r.disparity_px, 2) : "–";
  $("width").textContent = r ? fmt(r.width_px.d, 2) : "–";
  $("save").disabled = !(r && r.status === "ok");
  if (r) setStatus(r.status === "ok" ? "measured in " + r.elapsed_ms.toFixed(1) + " ms" +
                   (r.edges_refined ? "" : " (edges not found: clicks taken as given)") : r.message,
                   r.status !== "ok");
  drawLeft(); drawRight();
}

async function measure() {
  if (state.points.length !== 4) { state.result = null; showResult(); return; }
  try {
    state.result = await api("POST", base() + "/measure",
                             { set: state.set, head: state.head, points: state.points.flat() });
  } catch (error) { state.result = null; setStatus(error.message, true); }
  showResult();
}

function renderMeasurements(data) {
  const rows = $("measurements").querySelector("tbody"), sums = $("summary").querySelector("tbody");
  rows.innerHTML = ""; sums.innerHTML = "";
  for (const r of data.rows) {
    const tr = rows.insertRow();
    for (const v of [r.label, r.repeat, r.set, r.head, r.diameter_mm.toFixed(2), r.ncc.toFixed(3)]) tr.insertCell().textContent = v;
  }
  for (const s of data.summary) {
    const tr = sums.insertRow();
    for (const v of [s.label, s.count, s.mean_mm.toFixed(2), s.sd_mm.toFixed(2)]) tr.insertCell().textContent = v;
  }
}
async function refreshMeasurements() { renderMeasurements(await api("GET", base() + "/measurements")); }

async function loadPair() {
  state.points = []; state.result = null;
  const prefix = base() + "/sets/" + state.set + "/" + encodeURIComponent(state.head) + "/";
  setStatus("loading images…");
  try {
    [state.left, state.right] = await Promise.all([loadImage(prefix + "left.png"), loadImage(prefix + "right.png")]);
    fit(); setStatus("");
  } catch (error) { state.left = state.right = null; setStatus(error.message, true); }
  showResult();
  document.body.dataset.ready = state.left ? "yes" : "no";
}

function fillSelect(select, values, label) {
  select.innerHTML = "";
  for (const v of values) { const o = document.createElement("option"); o.value = v; o.textContent = label(v); select.appendChild(o); }
}
function currentSession() { return state.sessions.find((s) => s.name === state.session); }
async function chooseSession(name) {
  state.session = name;
  const session = currentSession();
  fillSelect($("set"), session.sets.map((s) => s.set), (v) => {
    const s = session.sets.find((x) => x.set === v); return v + (s.location_id ? " · " + s.location_id : "") + " · " + s.time; });
  $("export").href = base() + "/measurements.csv";
  await chooseSet(session.sets.length ? session.sets[0].set : null);
  await refreshMeasurements();
}
async function chooseSet(index) {
  state.set = index;
  const set = currentSession().sets.find((s) => s.set === index);
  const heads = set ? set.heads : [];
  fillSelect($("head"), heads, (v) => v);
  state.head = heads.includes(state.head) ? state.head : heads[0];
  $("head").value = state.head;
  if (set && state.head) await loadPair();
}

// Zoom so that image point (x, y) sits at the canvas centre, `scale` canvas px per image px.
function zoomTo(x, y, scale) {
  const c = $("left");
  state.view = { scale, x: c.width / 2 - x * scale, y: c.height / 2 - y * scale };
  drawLeft();
}

let drag = null;
$("left").addEventListener("mousedown", (e) => { drag = { start: eventToCanvas(e), view: { ...state.view }, moved: false }; });
window.addEventListener("mousemove", (e) => {
  if (!drag) return;
  const [x, y] = eventToCanvas(e);
  const dx = x - drag.start[0], dy = y - drag.start[1];
  if (Math.abs(dx) + Math.abs(dy) > 4) drag.moved = true;
  if (drag.moved) { state.view.x = drag.view.x + dx; state.view.y = drag.view.y + dy; drawLeft(); }
});
window.addEventListener("mouseup", (e) => {
  if (!drag) return;
  const wasDrag = drag.moved; drag = null;
  if (wasDrag || !state.left || e.target !== $("left")) return;
  if (state.points.length >= 4) state.points = [];
  state.points.push(toImage(...eventToCanvas(e)));
  drawLeft();
  if (state.points.length === 4) measure(); else { state.result = null; showResult(); }
});
$("left").addEventListener("wheel", (e) => {
  e.preventDefault();
  const [cx, cy] = eventToCanvas(e);
  const [ix, iy] = toImage(cx, cy);
  const scale = Math.min(32, Math.max(0.1, state.view.scale * (e.deltaY < 0 ? 1.25 : 0.8)));
  state.view = { scale, x: cx - ix * scale, y: cy - iy * scale };
  drawLeft();
}, { passive: false });
$("undo").onclick = () => { state.points.pop(); state.result = null; showResult(); };
window.addEventListener("keydown", (e) => { if (e.key === "z" && e.target.tagName !== "INPUT") $("undo").onclick(); });
$("clear").onclick = () => { state.points = []; state.result = null; showResult(); };
$("save").onclick = async () => {
  const label = $("label").value.trim();
  if (!label) { setStatus("give the stem a label before saving", true); return; }
  try {
    const data = await api("POST", base() + "/measurements",
                           { set: state.set, head: state.head, label, points: state.points.flat() });
    renderMeasurements(data);
    setStatus("saved " + data.saved.label + " #" + data.saved.repeat + ": " + data.saved.diameter_mm.toFixed(2) + " mm");
    // The quadrangle and its result stay on screen; the next click starts a new measurement.
    $("save").disabled = true;
  } catch (error) { setStatus(error.message, true); }
};
$("delete-last").onclick = async () => {
  try { renderMeasurements(await api("DELETE", base() + "/measurements/last")); setStatus("last saved measurement deleted"); }
  catch (error) { setStatus(error.message, true); }
};
$("session").onchange = (e) => chooseSession(e.target.value);
$("set").onchange = (e) => chooseSet(Number(e.target.value));
$("head").onchange = async (e) => { state.head = e.target.value; await loadPair(); };

// For scripted use (the browser test): where an image pixel is on the screen, and zooming.
window.stemUi = {
  zoomTo,
  imageToClient(x, y) {
    const rect = $("left").getBoundingClientRect(), s = canvasScale();
    const [cx, cy] = toCanvas(x, y);
    return { x: rect.left + cx / s, y: rect.top + cy / s };
  },
  state,
};

(async () => {
  try {
    state.sessions = await api("GET", "/api/sessions");
    fillSelect($("session"), state.sessions.map((s) => s.name), (v) => v);
    if (state.sessions.length) await chooseSession(state.sessions[0].name);
  } catch (error) { setStatus(error.message, true); }
})();
</script>
</body>
</html>
)STEMUI";

}  // namespace fieldrig::tools
