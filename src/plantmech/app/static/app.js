// plantmech app front end: state, edits with undo/redo, and drawing of what the server
// computed. The browser never computes physics: every number comes from /api/evaluate.
import { linePlot, scatterPlot, pickPoint } from "./plot.js";

const $ = (id) => document.getElementById(id);
const SECTION_COLOURS = { picking: "rgba(22,163,74,0.13)", transport: "rgba(37,99,235,0.10)",
  seeding: "rgba(220,38,38,0.13)", return: "rgba(107,114,128,0.13)",
  conveying: "rgba(37,99,235,0.10)", planting: "rgba(220,38,38,0.13)" };
const ARM_COLOURS = ["#2563eb", "#ea580c", "#16a34a", "#dc2626", "#7c3aed", "#92400e"];
const GEAR_STYLE = { sun: ["#374151", "rgba(55,65,81,0.10)"], gear2: ["#b45309", "rgba(245,158,11,0.18)"],
  gear3: ["#0f766e", "rgba(20,184,166,0.18)"], planet: ["#7c3aed", "rgba(139,92,246,0.15)"],
  middle: ["#b45309", "rgba(245,158,11,0.18)"],
  internal: ["#374151", "rgba(0,0,0,0)"] };

const state = {
  design: null, name: "", result: null, fullResult: null,
  undo: [], redo: [], frame: 0, playing: true, speed: 1, lastT: null,
  view: null, drag: null, inflight: false, pending: null, seq: 0, shown: 0,
  fieldErrors: [], optTask: null, optResult: null, optSelected: null, gearTask: null,
  hover: -1, lastFeasible: null, gearKey: null, optKeys: new Set(),
};
window.__plantmech = state; // for the tests and the benchmark
window.__dragTimes = [];
window.__dragBreakdown = []; // per drawn drag answer: where the milliseconds went
window.__answers = []; // the quality of every drawn answer, in order (the tests count them)

// ---------------------------------------------------------------- server calls
async function api(path, body) {
  const init = body === undefined ? {} : { method: "POST", headers: { "Content-Type": "application/json" }, body: JSON.stringify(body) };
  const r = await fetch(path, init);
  let data = null;
  try { data = await r.json(); } catch { data = { error: `${r.status} ${r.statusText}` }; }
  if (!r.ok) { const e = new Error(data.error || r.statusText); e.data = data; e.status = r.status; throw e; }
  return data;
}

function setStatus(text, error = false) {
  const s = $("status"); s.textContent = text; s.className = error ? "error" : "";
}

const clone = (o) => JSON.parse(JSON.stringify(o));

// ---------------------------------------------------------------- design + undo
// an undo entry is the design with its name: undoing a loaded optimized point brings back
// the user's design under the user's name
const snapshot = () => ({ design: clone(state.design), name: state.name });
function pushUndo(before) {
  state.undo.push(before); state.redo = [];
  if (state.undo.length > 200) state.undo.shift();
}

function blurEdit() { if (document.activeElement && document.activeElement.closest?.("#edit")) document.activeElement.blur(); }

function showName() { $("design-name").textContent = `${state.name} — ${state.design.mechanism}`; }

function loadDesign(design, name, keepUndo = false) {
  blurEdit();
  if (state.design && keepUndo) pushUndo(snapshot());
  // another design: its own fields come with its first answer
  if (!keepUndo) { state.undo = []; state.redo = []; state.parameters = null; clearTasks(); }
  state.design = clone(design); state.name = name || design.name || "design";
  state.fullResult = null; state.result = null; state.lastFeasible = null;
  showName();
  state.view = null;
  refreshProblems();
  evaluate("full");
}

function restore(entry) { state.design = entry.design; state.name = entry.name; showName(); evaluate("full"); }
function undo() {
  if (!state.undo.length) return;
  blurEdit();
  state.redo.push(snapshot()); restore(state.undo.pop());
}
function redo() {
  if (!state.redo.length) return;
  blurEdit();
  state.undo.push(snapshot()); restore(state.redo.pop());
}

// ---------------------------------------------------------------- edit stream
// Edits travel over one WebSocket (/api/ws): no HTTP request per pointer move (Chromium's
// fetch costs several ms per request on loopback, docs/app-performance.md). If the socket cannot be
// opened the page sends them by fetch to /api/evaluate (same answers).
const stream = { ws: null, opening: null, next: 1, waiting: new Map(), useFetch: false };

function openStream() {
  if (stream.ws) return Promise.resolve(stream.ws);
  if (stream.opening) return stream.opening;
  stream.opening = new Promise((resolve) => {
    let ws, opened = false;
    try { ws = new WebSocket(`${location.protocol === "https:" ? "wss" : "ws"}://${location.host}/api/ws`); }
    catch { stream.useFetch = true; stream.opening = null; resolve(null); return; }
    ws.onopen = () => { opened = true; stream.ws = ws; stream.opening = null; resolve(ws); };
    ws.onmessage = (ev) => {
      const tRecv = performance.now();
      const msg = JSON.parse(ev.data);
      const done = stream.waiting.get(msg.id);
      if (!done) return;
      stream.waiting.delete(msg.id);
      done({ msg, tRecv, tParsed: performance.now(), bytes: ev.data.length });
    };
    const lost = () => {
      if (!opened) stream.useFetch = true; // refused: fetch from now on
      stream.ws = null; stream.opening = null;
      for (const done of stream.waiting.values()) done({ msg: null }); // resent by fetch
      stream.waiting.clear();
      resolve(null);
    };
    ws.onclose = lost; ws.onerror = lost;
  });
  return stream.opening;
}

// one edit to the server: its answer and the times of its way (ms, performance.now()).
// On an open stream the message is sent before this function returns (no await first), so
// a caller can send the next edit and then draw the previous answer while it computes.
function postEdit(body) {
  const ws = stream.useFetch ? null : stream.ws;
  if (ws && ws.readyState === WebSocket.OPEN) return streamEdit(ws, body);
  return postEditOpening(body);
}

async function streamEdit(ws, body) {
  const id = stream.next++;
  const answered = new Promise((resolve) => stream.waiting.set(id, resolve));
  const tSend = performance.now();
  ws.send(JSON.stringify({ id, ...body }));
  stream.lastSend = tSend;
  const { msg, tRecv, tParsed, bytes } = await answered;
  if (msg && msg.superseded) return { superseded: true };
  if (msg) return { status: msg.status, res: msg.result, tSend, tHead: tRecv, tBody: tRecv, tParsed,
    compute: msg.compute, server: msg.server, bytes, transport: "websocket" };
  return postFetch(body); // the stream was lost meanwhile: resent by fetch
}

async function postEditOpening(body) {
  const ws = stream.useFetch ? null : await openStream();
  if (ws) return streamEdit(ws, body);
  return postFetch(body);
}

async function postFetch(body) {
  const tSend = performance.now();
  const r = await fetch("/api/evaluate", { method: "POST", headers: { "Content-Type": "application/json" },
    body: JSON.stringify(body) });
  const tHead = performance.now();
  const text = await r.text();
  const tBody = performance.now();
  let res;
  try { res = JSON.parse(text); } catch { res = { error: `${r.status} ${r.statusText}` }; }
  const timing = (name) => { const m = (r.headers.get("Server-Timing") || "").match(new RegExp(`${name};dur=([0-9.]+)`)); return m ? +m[1] : null; };
  return { status: r.status, res, tSend, tHead, tBody, tParsed: performance.now(), compute: timing("compute"),
    server: timing("server"), bytes: text.length, transport: "http" };
}

// ---------------------------------------------------------------- evaluation
// One request in flight; during a drag the newest design waits and replaces older ones
// (coalescing: the pointer moves faster than answers come, only the latest is computed).
// When an answer arrives the waiting edit is sent first and the answer drawn after, so the
// server computes the next edit while the page draws (docs/app-performance.md, "How an edit travels").
function sendPending() {
  if (!state.pending || state.inflight) return false;
  const p = state.pending; state.pending = null;
  evaluate(p.quality, p.t0);
  return true;
}

async function evaluate(quality, t0 = null) {
  if (state.inflight) {
    // a move replaced before it was answered is measured from its own time: the latency
    // of the oldest move still waiting counts, not only of the newest
    const older = state.pending && state.pending.t0 !== null && t0 !== null ? state.pending.t0 : t0;
    state.pending = { quality, t0: older };
    return;
  }
  state.inflight = true;
  const seq = ++state.seq;
  let a, failure = null;
  try { a = await postEdit({ quality, design: state.design }); } catch (e) { failure = e; }
  state.inflight = false;
  const tAnswer = performance.now();
  const sentNext = sendPending(); // the next edit computes while this answer is drawn
  // when it went out (ms after this answer arrived; on the stream it is sent at once)
  const nextSent = sentNext && stream.lastSend >= tAnswer ? stream.lastSend - tAnswer : null;
  try {
    if (failure) throw failure;
    if (a.superseded) return; // a newer edit of this page replaced it on the server
    const res = a.res;
    if (a.status !== 200) { const e = new Error(res.error || `${a.status}`); e.data = res; e.status = a.status; throw e; }
    state.fieldErrors = [];
    window.__answers.push(quality);
    state.result = res;
    if (quality === "full") state.fullResult = res;
    if (res.feasible && frameCount(res)) state.lastFeasible = res;
    if (res.parameters) state.parameters = res.parameters;
    setStatus(quality === "drag" ? "live (working resolution)" : "up to date");
    const tDraw = performance.now();
    const parts = render();
    if (t0 !== null) {
      // drag -> redraw of the mechanism and the objectives, measured in the browser:
      // from the pointer move to the drawn answer, and where that time went
      const t1 = performance.now();
      performance.measure("drag-redraw", { start: t0, end: t1 });
      window.__dragTimes.push(t1 - t0);
      window.__dragBreakdown.push({ total: t1 - t0, queued: a.tSend - t0, compute: a.compute, server: a.server,
        browser_http: a.tHead - a.tSend - (a.server || 0), body: a.tBody - a.tHead, parse: a.tParsed - a.tBody,
        send_next: tDraw - tAnswer, next_sent: nextSent, draw: t1 - a.tParsed, ...parts,
        bytes: a.bytes, transport: a.transport });
    }
  } catch (e) {
    state.fieldErrors = (e.data && e.data.fields) || [];
    setStatus(e.message.split("\n").slice(0, 2).join(" "), true);
    renderEdit();
    renderChecks();
    drawMechanism();
    markStale();
    const v = $("verdict");
    v.textContent = "INVALID INPUT (see the field marked red): the mechanism and checks shown are the last valid design's";
    v.className = "bad";
  } finally {
    state.shown = seq;
  }
}

// ---------------------------------------------------------------- mechanism view
function bounds(res) {
  let xs = [], ys = [];
  const add = (pts) => { for (const [x, y] of pts || []) { xs.push(x); ys.push(y); } };
  add(res.plan); add(res.points); add(res.tip_path);
  for (const p of res.tip_paths || []) add(p);
  if (res.box) add(res.box.mat);
  for (const g of res.gears || []) {
    let rmax = 0; for (const [x, y] of g.body) rmax = Math.max(rmax, Math.hypot(x, y));
    for (const [cx, cy] of g.centre) add([[cx - rmax, cy - rmax], [cx + rmax, cy + rmax]]);
  }
  if (res.ground_y_mm !== undefined) ys.push(res.ground_y_mm - 30);
  xs.push(0); ys.push(0);
  return [Math.min(...xs), Math.max(...xs), Math.min(...ys), Math.max(...ys)];
}

// a view: s px per mm, the pixel of the origin (ox, oy); y up in mm, down in pixels
function viewOf(s, ox, oy) {
  return { s, ox, oy, toPx: (x, y) => [ox + s * x, oy - s * y], toMM: (px, py) => [(px - ox) / s, (oy - py) / s] };
}

function makeView(res, canvas) {
  const [x0, x1, y0, y1] = bounds(res);
  const pad = 30, W = canvas.width, H = canvas.height;
  const s = Math.min((W - 2 * pad) / (x1 - x0 || 1), (H - 2 * pad) / (y1 - y0 || 1));
  const ox = pad + ((W - 2 * pad) - s * (x1 - x0)) / 2 - s * x0;
  const oy = H - pad - ((H - 2 * pad) - s * (y1 - y0)) / 2 + s * y0;
  return viewOf(s, ox, oy);
}

// zoom by factor k about the canvas pixel (px, py): the millimetre under it stays there
function zoomView(k, px, py) {
  const v = state.view; if (!v) return;
  const s = Math.min(Math.max(v.s * k, 0.02), 200);
  k = s / v.s;
  state.view = viewOf(s, px - k * (px - v.ox), py - k * (py - v.oy));
  drawMechanism();
}

function fitView() { state.view = null; drawMechanism(); }

function poly(ctx, v, pts, close = false) {
  ctx.beginPath();
  pts.forEach(([x, y], i) => { const [px, py] = v.toPx(x, y); if (i) ctx.lineTo(px, py); else ctx.moveTo(px, py); });
  if (close) ctx.closePath();
}

function frameCount(res) { return res && res.frames ? res.frames.carrier_angle_deg.length : 0; }

const GEAR_LABEL = { sun: "sun (fixed)", gear2: "gear 2", gear3: "gear 3", planet: "planet", middle: "middle gear", internal: "internal gear" };

// what the colours on the mechanism mean (drawn top right; canvas.legendBox for the tests)
function legendEntries(res) {
  const out = [], seen = new Set();
  for (const g of res.gears || []) {
    const key = g.style || g.role;
    if (seen.has(key)) continue; seen.add(key);
    const st = GEAR_STYLE[key] || ["#111"];
    out.push([st[0], GEAR_LABEL[key] || g.name || key, "line"]);
  }
  if (res.tip_path) out.push(["#2563eb", "tip path", "line"]);
  (res.tip_paths || []).forEach((_, j) => out.push([ARM_COLOURS[j], `tip path, arm ${j + 1}`, "line"]));
  if (res.plan) out.push(["#9ca3af", "planned trajectory", "dash"]);
  if (res.points && state.design && state.design.trajectory) {
    out.push(["#fff", state.design.train ? "type-value point q_i" : "type-value point q_i (drag)", "dot"]);
    if (res.sections_points) out.push(["#f59e0b", "section point", "dot"]);
  }
  if (redSpans(res).length) out.push(["#dc2626", "infeasible span", "line"]);
  if (!res.feasible && state.lastFeasible) out.push(["rgba(17,17,17,0.3)", "last feasible design (ghost)", "line"]);
  return out;
}

function drawLegend(ctx, canvas, entries) {
  if (!entries.length) { canvas.legendBox = null; canvas.legendEntries = []; return; }
  ctx.font = "11px system-ui";
  // placed again only when the entries, the view or the answer change (not every frame)
  const v = state.view, res = state.result;
  const key = `${entries.map((e) => e[1]).join("|")}|${v.s},${v.ox},${v.oy}`;
  if (canvas._legend && canvas._legend.key === key && canvas._legend.res === res) {
    paintLegend(ctx, canvas._legend.box, entries);
    return;
  }
  const w = 26 + Math.max(...entries.map((e) => ctx.measureText(e[1]).width)), h = 14 * entries.length + 6;
  // the corner that hides the fewest drawn points (the scale bar keeps the bottom left;
  // the reasons of an infeasible design the top left)
  const pts = [];
  const add = (a, step = 1) => { for (let i = 0; i < (a || []).length; i += step) pts.push(v.toPx(a[i][0], a[i][1])); };
  add(res.points); add(res.plan, 4); add(res.tip_path, 4); for (const p of res.tip_paths || []) add(p, 4);
  const corners = [[canvas.width - w - 6, 6], [canvas.width - w - 6, canvas.height - h - 6], [6, 6]];
  if ((res.diagnostics || []).some((d) => d.severity === "error")) corners.pop();
  const hidden = ([cx, cy]) => pts.filter(([px, py]) => px >= cx - 8 && px <= cx + w + 8 && py >= cy - 8 && py <= cy + h + 8).length;
  const [x, y] = corners.reduce((best, c) => (hidden(c) < hidden(best) ? c : best));
  canvas.legendBox = { x, y, w, h };
  canvas.legendEntries = entries.map((e) => e[1]);
  canvas._legend = { key, res, box: canvas.legendBox };
  paintLegend(ctx, canvas.legendBox, entries);
}

function paintLegend(ctx, { x, y, w, h }, entries) {
  ctx.fillStyle = "rgba(255,255,255,0.88)"; ctx.fillRect(x, y, w, h);
  ctx.strokeStyle = "#d1d5db"; ctx.lineWidth = 1; ctx.strokeRect(x, y, w, h);
  entries.forEach(([c, label, kind], i) => {
    const yy = y + 12 + 14 * i;
    ctx.strokeStyle = c; ctx.fillStyle = c; ctx.lineWidth = 2.5;
    if (kind === "dot") { ctx.strokeStyle = "#111"; ctx.lineWidth = 1; ctx.beginPath(); ctx.arc(x + 12, yy - 4, 4, 0, 2 * Math.PI); ctx.fill(); ctx.stroke(); }
    else { if (kind === "dash") ctx.setLineDash([4, 3]); ctx.beginPath(); ctx.moveTo(x + 4, yy - 4); ctx.lineTo(x + 20, yy - 4); ctx.stroke(); ctx.setLineDash([]); }
    ctx.fillStyle = "#111"; ctx.fillText(label, x + 24, yy);
  });
}

// the moving parts of a result at frame f: gears on their pitch curves (or cut teeth),
// links and the tip; alpha < 1: the ghost of the last feasible design
function drawMoving(ctx, v, res, f, alpha = 1) {
  if ($("show-gears").checked) {
    const teeth = alpha === 1 ? currentTeeth() : null;
    for (const g of res.gears || []) {
      const [cx, cy] = g.centre[Math.min(f, g.centre.length - 1)], a = g.rot[Math.min(f, g.rot.length - 1)];
      const c = Math.cos(a), s = Math.sin(a);
      const place = ([x, y]) => [cx + c * x - s * y, cy + s * x + c * y];
      const pts = g.body.map(place);
      const [stroke, fill] = GEAR_STYLE[g.style || g.role] || ["#111", "rgba(0,0,0,0.05)"];
      ctx.fillStyle = fill; ctx.strokeStyle = stroke; ctx.lineWidth = 1.3;
      const cut = teeth && teeth[g.role] && teeth[g.role].drawn ? teeth[g.role] : null;
      if (cut) {
        // the cut outline (teeth, bore) rolling with the gear; the pitch curve dashed
        ctx.beginPath();
        for (const ring of cut.rings) {
          ring.forEach((p, i) => { const [px, py] = v.toPx(...place(p)); if (i) ctx.lineTo(px, py); else ctx.moveTo(px, py); });
          ctx.closePath();
        }
        ctx.fill("evenodd"); ctx.lineWidth = 0.8; ctx.stroke();
        ctx.setLineDash([3, 3]); ctx.lineWidth = 0.7; poly(ctx, v, pts, true); ctx.stroke(); ctx.setLineDash([]);
        ctx.lineWidth = 1.3;
      } else { poly(ctx, v, pts, true); ctx.fill(); ctx.stroke(); }
      // a body-fixed spoke shows the rotation
      const [p0x, p0y] = v.toPx(cx, cy), [p1x, p1y] = v.toPx(...pts[0]);
      ctx.beginPath(); ctx.moveTo(p0x, p0y); ctx.lineTo(p1x, p1y); ctx.stroke();
    }
  }
  res.frames.links.forEach((l) => {
    const pts = l.points[Math.min(f, l.points.length - 1)];
    const arm = l.name.startsWith("arm");
    const j = parseInt((l.name.match(/\d+/) || ["1"])[0], 10) - 1;
    ctx.strokeStyle = arm ? (res.tip_paths ? ARM_COLOURS[j] : "#1d4ed8") : "#111";
    ctx.lineWidth = arm ? 4 : 5; ctx.globalAlpha = 0.85 * alpha;
    poly(ctx, v, pts); ctx.stroke(); ctx.globalAlpha = alpha;
    for (const p of pts) { const [px, py] = v.toPx(...p); ctx.fillStyle = "#fff"; ctx.strokeStyle = "#111"; ctx.lineWidth = 1.2; ctx.beginPath(); ctx.arc(px, py, 3.5, 0, 2 * Math.PI); ctx.fill(); ctx.stroke(); }
  });
  const [tx, ty] = v.toPx(...res.frames.tip[Math.min(f, res.frames.tip.length - 1)]);
  ctx.fillStyle = "#dc2626"; ctx.beginPath(); ctx.arc(tx, ty, 5, 0, 2 * Math.PI); ctx.fill();
}

// the type-value points a field error names: "q3 and q4", or the point's own field
function badPoints() {
  const out = new Set();
  for (const e of state.fieldErrors) {
    const m = e.field.match(/^trajectory\.points\.(\d+)/);
    if (m) { out.add(+m[1]); continue; }
    if (e.field === "trajectory.points" || e.field === "trajectory") {
      for (const q of e.message.matchAll(/\bq(\d+)\b/g)) out.add(+q[1]);
    }
  }
  return out;
}

// labels beside points, each where it overlaps no label placed before it, the legend
// or the canvas edge (tried: right-above, right-below, left-above, left-below, farther out)
function placeLabels(ctx, canvas, items) {
  // placed again only when a point, a label, the view or the legend moved (not every frame)
  const lb = canvas.legendBox;
  const key = items.map((it) => `${it.px.toFixed(1)},${it.py.toFixed(1)},${it.text}`).join(";") + (lb ? `|${lb.x},${lb.y},${lb.w},${lb.h}` : "");
  if (canvas._labelKey === key) { paintLabels(ctx, canvas.pointLabels); return; }
  const placed = [], boxes = lb ? [lb] : [];
  const clear = (b) => b.x >= 0 && b.y >= 0 && b.x + b.w <= canvas.width && b.y + b.h <= canvas.height
    && boxes.every((o) => b.x + b.w <= o.x || o.x + o.w <= b.x || b.y + b.h <= o.y || o.y + o.h <= b.y);
  for (const it of items) {
    const w = ctx.measureText(it.text).width, h = 11;
    for (const d of [7, 14, 22]) {
      const tries = [[d, -d - h + 4], [d, d - 3], [-d - w, -d - h + 4], [-d - w, d - 3], [-w / 2, -d - h - 2], [-w / 2, d + 2]];
      const b = tries.map(([dx, dy]) => ({ x: it.px + dx, y: it.py + dy, w, h })).find(clear);
      if (b) { boxes.push(b); placed.push({ ...b, text: it.text }); break; }
    }
  }
  canvas.pointLabels = placed; canvas._labelKey = key;
  paintLabels(ctx, placed);
}

function paintLabels(ctx, placed) {
  for (const b of placed) { ctx.fillStyle = "rgba(255,255,255,0.7)"; ctx.fillRect(b.x - 1, b.y, b.w + 2, b.h); ctx.fillStyle = "#111"; ctx.fillText(b.text, b.x, b.y + 9); }
}

function drawMechanism() {
  const canvas = $("mech"), ctx = canvas.getContext("2d");
  const res = state.result;
  ctx.clearRect(0, 0, canvas.width, canvas.height);
  if (!res) return;
  const ghost = !res.feasible && state.lastFeasible ? state.lastFeasible : null;
  if (!state.view) state.view = makeView(ghost || res, canvas);
  const v = state.view;
  ctx.lineJoin = "round";
  // scale bar
  const bar = [1, 2, 5, 10, 20, 50, 100, 200, 500, 1000].find((b) => b * v.s > 60) || 1000;
  ctx.strokeStyle = "#111"; ctx.lineWidth = 2; ctx.beginPath();
  ctx.moveTo(12, canvas.height - 12); ctx.lineTo(12 + bar * v.s, canvas.height - 12); ctx.stroke();
  ctx.font = "11px system-ui"; ctx.fillStyle = "#111"; ctx.fillText(`${bar} mm`, 14, canvas.height - 16);
  // axes cross at O
  const [ox, oy] = v.toPx(0, 0);
  ctx.strokeStyle = "#9ca3af"; ctx.lineWidth = 1; ctx.beginPath();
  ctx.moveTo(ox - 8, oy); ctx.lineTo(ox + 8, oy); ctx.moveTo(ox, oy - 8); ctx.lineTo(ox, oy + 8); ctx.stroke();
  if (res.box) {
    ctx.fillStyle = "rgba(132,204,22,0.35)"; poly(ctx, v, res.box.mat, true); ctx.fill();
    ctx.strokeStyle = "#111"; ctx.lineWidth = 3; poly(ctx, v, res.box.floor); ctx.stroke();
    const [, gy] = v.toPx(0, res.ground_y_mm);
    ctx.fillStyle = "rgba(146,64,14,0.15)"; ctx.fillRect(0, gy, canvas.width, canvas.height - gy);
    ctx.strokeStyle = "#92400e"; ctx.lineWidth = 2; ctx.beginPath(); ctx.moveTo(0, gy); ctx.lineTo(canvas.width, gy); ctx.stroke();
    ctx.fillStyle = "#92400e"; ctx.fillText("ground", 6, gy - 4);
    ctx.fillStyle = "#3f6212"; const [bx, by] = v.toPx(...res.box.mat[1]); ctx.fillText("seedling box", bx - 70, by - 6);
    ctx.strokeStyle = "#9ca3af"; ctx.setLineDash([4, 4]); ctx.beginPath();
    ctx.arc(ox, oy, res.gearbox_radius_mm * v.s, 0, 2 * Math.PI); ctx.stroke(); ctx.setLineDash([]);
  }
  const n = frameCount(res);
  // while infeasible the last feasible design stays, ghosted, at the same carrier angle
  if (ghost) {
    const gn = frameCount(ghost), gf = gn ? Math.floor(state.frame * gn / (n || gn)) % gn : 0;
    ctx.globalAlpha = 0.25;
    if (ghost.tip_path) { ctx.strokeStyle = "#2563eb"; ctx.lineWidth = 1.6; poly(ctx, v, ghost.tip_path, true); ctx.stroke(); }
    if (gn) drawMoving(ctx, v, ghost, gf, 0.25);
    ctx.globalAlpha = 1;
  }
  // planned trajectory, infeasible spans in red
  if (res.plan) { ctx.strokeStyle = "#9ca3af"; ctx.lineWidth = 1.2; ctx.setLineDash([6, 4]); poly(ctx, v, res.plan, true); ctx.stroke(); ctx.setLineDash([]); }
  const red = redSpans(res);
  if (res.spans) {
    ctx.strokeStyle = "#dc2626"; ctx.lineWidth = 5;
    for (const i of red) { poly(ctx, v, res.spans[i]); ctx.stroke(); }
  }
  // tip paths
  if (res.tip_path) { ctx.strokeStyle = "#2563eb"; ctx.lineWidth = 1.6; poly(ctx, v, res.tip_path, true); ctx.stroke(); }
  (res.tip_paths || []).forEach((p, j) => { ctx.strokeStyle = ARM_COLOURS[j]; ctx.lineWidth = 1.3; poly(ctx, v, p, true); ctx.stroke(); });
  const f = n ? state.frame % n : 0;
  if (n) drawMoving(ctx, v, res, f);
  drawLegend(ctx, canvas, legendEntries(res));
  // type-value points (drag handles) with section letters; only the points an error names red
  const labels = [];
  if (res.points && state.design && state.design.trajectory) {
    const sec = res.sections_points || {};
    const letter = {}; for (const [k, i] of Object.entries(sec)) letter[i] = k;
    const pts = state.design.trajectory.points;
    const editable = !state.design.train;
    const bad = badPoints();
    const active = state.drag && state.drag.kind === "point" ? state.drag.index : state.hover;
    pts.forEach(([x, y], i) => {
      const [px, py] = v.toPx(x, y);
      ctx.fillStyle = bad.has(i) ? "#dc2626" : (letter[i] ? "#f59e0b" : "#fff");
      ctx.strokeStyle = i === active ? "#2563eb" : "#111"; ctx.lineWidth = i === active ? 2.5 : 1.2;
      ctx.beginPath(); ctx.arc(px, py, editable ? (i === active ? 7 : 5) : 3, 0, 2 * Math.PI); ctx.fill(); ctx.stroke();
      labels.push({ px, py, text: `q${i}${letter[i] ? " " + letter[i] : ""}` });
    });
  }
  ctx.font = "10px system-ui";
  placeLabels(ctx, canvas, labels);
  // reasons of infeasible spans, beside the red span
  ctx.font = "12px system-ui"; ctx.fillStyle = "#b91c1c";
  const lw = canvas.width - (canvas.legendBox ? canvas.legendBox.w + 20 : 10);
  (res.diagnostics || []).filter((d) => d.severity === "error").slice(0, 3).forEach((d, i) => {
    let t = `✖ ${d.message}`; while (t.length > 4 && ctx.measureText(t).width > lw) t = t.slice(0, -4) + "…";
    ctx.fillText(t, 10, 16 + 15 * i);
  });
  const sense = res.mechanism === "planetary" && state.design && state.design.carrier && state.design.carrier.direction === "counterclockwise" ? "counter-clockwise" : "clockwise";
  if (n) $("angle").textContent = `carrier ${res.frames.carrier_angle_deg[f].toFixed(1)}° (${sense} from start)`;
}

// teeth of the last cut, drawn while the design is the one that was cut
function currentTeeth() {
  const t = state.teeth;
  if (!t || !state.design) return null;
  return t.key === JSON.stringify(state.design) ? t.gears : null;
}

function teethNote() {
  const t = state.teeth, el = $("teeth-note");
  if (!el) return;
  if (!t) { el.textContent = "Gears drawn as pitch curves: cut the teeth (Make) to see them in mesh."; return; }
  const missing = Object.entries(t.gears || {}).filter(([, e]) => !e.drawn).map(([k, e]) => `${k} (${e.reason || e.error || "not placed"})`);
  if (t.gears && t.gears.error) { el.textContent = `Teeth not drawn: ${t.gears.error}`; return; }
  if (currentTeeth()) el.textContent = `Teeth as cut (module ${t.module}) rolling on the pitch curves (dashed)${missing.length ? "; pitch curve only for " + missing.join(", ") : ""}.`;
  else el.textContent = "Teeth hidden: the design changed since they were cut (cut again to see them).";
}

function redSpans(res) {
  const out = new Set();
  const N = res.spans ? res.spans.length : 0;
  for (const d of res.diagnostics || []) {
    if (d.severity !== "error" || !d.between_points) continue;
    let [i, j] = d.between_points;
    for (let k = i, guard = 0; guard <= N; guard++) { out.add(k); if (k === j || (k + 1) % N === j) break; k = (k + 1) % N; }
  }
  return [...out];
}

// ---------------------------------------------------------------- gestures
// One machine owns every pointer gesture: a type-value point, a radius handle, a pan of the
// view. state.drag = {kind, ...} from the press to the release; while it lives the edit
// panel is updated in place, never rebuilt. A gesture that moved something is one undo
// entry and ends in one full-resolution evaluation.
function canvasPoint(ev, canvas) {
  const r = canvas.getBoundingClientRect();
  return [(ev.clientX - r.left) * canvas.width / r.width, (ev.clientY - r.top) * canvas.height / r.height];
}
// the pick radius: 10 CSS pixels in the canvas's own pixels
function pickRadius(canvas) { const r = canvas.getBoundingClientRect(); return 10 * canvas.width / (r.width || canvas.width); }

function beginGesture(kind, canvas, ev, info) {
  state.drag = { kind, canvas, before: snapshot(), moves: 0, ...info };
  canvas.setPointerCapture(ev.pointerId);
  canvas.style.cursor = "grabbing";
  ev.preventDefault();
}

function moveGesture(ev) {
  const g = state.drag;
  const t0 = performance.now();
  const [px, py] = canvasPoint(ev, g.canvas);
  if (g.kind === "pan") {
    const v = state.view;
    state.view = viewOf(v.s, g.ox + px - g.px, g.oy + py - g.py);
    drawMechanism();
    return;
  }
  performance.mark("drag-input");
  if (g.kind === "point") {
    const [x, y] = state.view.toMM(px, py);
    state.design.trajectory.points[g.index] = [Math.round(x * 100) / 100, Math.round(y * 100) / 100];
    readout(`q${g.index}: x ${x.toFixed(2)} mm, y ${y.toFixed(2)} mm`);
    drawMechanism(); // the handle follows at once; the mechanism follows the server
  } else {
    const [cx, cy] = g.L.centres[g.g];
    const r = ((px - cx) * Math.cos(g.a) - (py - cy) * Math.sin(g.a)) / g.L.s;
    state.design.train[g.g].radii_mm[g.i] = Math.round(r * 100) / 100;
    readout(`${g.g === "gear2" ? "gear 2" : "gear 3"} radius ${g.i}: ${r.toFixed(2)} mm`);
    drawRadiiEditor(g.canvas);
    updateEdit($("edit"));
  }
  g.moves++;
  evaluate("drag", t0);
}

function endGesture() {
  const g = state.drag;
  if (!g) return;
  state.drag = null;
  g.canvas.style.cursor = "";
  if (g.kind !== "pan" && g.moves) { pushUndo(g.before); evaluate("full"); }
}

function readout(text) { const el = $("readout"); if (el.textContent !== text) el.textContent = text; }

function hitPoint(canvas, px, py) {
  const d = state.design;
  if (!d || !d.trajectory || d.train || !state.view) return -1;
  let best = -1, bd = pickRadius(canvas) ** 2;
  d.trajectory.points.forEach(([x, y], i) => { const [qx, qy] = state.view.toPx(x, y); const dd = (qx - px) ** 2 + (qy - py) ** 2; if (dd < bd) { bd = dd; best = i; } });
  return best;
}

function setupDrag() {
  const canvas = $("mech");
  canvas.addEventListener("pointerdown", (ev) => {
    if (!state.view || ev.button !== 0) return;
    const [px, py] = canvasPoint(ev, canvas);
    const i = hitPoint(canvas, px, py);
    if (i >= 0) beginGesture("point", canvas, ev, { index: i });
    else beginGesture("pan", canvas, ev, { px, py, ox: state.view.ox, oy: state.view.oy });
  });
  canvas.addEventListener("pointermove", (ev) => {
    if (state.drag && state.drag.canvas === canvas) { moveGesture(ev); return; }
    if (state.drag || !state.view) return;
    const [px, py] = canvasPoint(ev, canvas);
    const i = hitPoint(canvas, px, py);
    canvas.style.cursor = i >= 0 ? "grab" : "move";
    const [x, y] = state.view.toMM(px, py);
    if (i >= 0) { const q = state.design.trajectory.points[i]; readout(`q${i}: x ${(+q[0]).toFixed(2)} mm, y ${(+q[1]).toFixed(2)} mm (drag to move)`); }
    else readout(`pointer x ${x.toFixed(1)} mm, y ${y.toFixed(1)} mm`);
    if (i !== state.hover) { state.hover = i; drawMechanism(); }
  });
  canvas.addEventListener("pointerleave", () => { if (!state.drag && state.hover >= 0) { state.hover = -1; drawMechanism(); } });
  canvas.addEventListener("wheel", (ev) => {
    ev.preventDefault();
    const [px, py] = canvasPoint(ev, canvas);
    zoomView(Math.exp(-ev.deltaY * 0.0015), px, py);
  }, { passive: false });
  canvas.addEventListener("dblclick", fitView);
  canvas.addEventListener("pointerup", endGesture);
  canvas.addEventListener("pointercancel", endGesture);
}

// ---------------------------------------------------------------- checks + plots
function renderChecks() {
  const res = state.result;
  const tb = $("checks").querySelector("tbody");
  const diag = $("diagnostics"); diag.innerHTML = "";
  const verdict = $("verdict");
  if (!res) { verdict.textContent = ""; tb.innerHTML = ""; tb.dataset.key = ""; return; }
  const checks = res.checks || [];
  const failed = checks.filter((c) => !c.ok).length;
  if (!res.feasible) { verdict.textContent = "INFEASIBLE: no gear train can follow this design (reasons below)"; verdict.className = "bad"; }
  else if (failed) { verdict.textContent = `${failed} of ${checks.length} ${res.quality === "drag" ? "live " : ""}checks not met`; verdict.className = "bad"; }
  else { verdict.textContent = `all ${checks.length} ${res.quality === "drag" ? "live " : ""}checks met`; verdict.className = "good"; }
  for (const d of res.diagnostics || []) {
    const li = document.createElement("li"); li.className = d.severity;
    let where = d.between_points ? ` between q${d.between_points[0]} and q${d.between_points[1]}` : "";
    if (d.carrier_angle_deg) where += ` (carrier ${d.carrier_angle_deg[0].toFixed(1)}–${d.carrier_angle_deg[1].toFixed(1)}°)`;
    li.textContent = `${d.severity.toUpperCase()} [${d.kind}]${where}: ${d.message}`;
    diag.appendChild(li);
  }
  // during a drag the checks computed on release only are kept from the last release, greyed
  const live = new Set(checks.map((c) => c.name));
  const kept = res.quality === "drag" && state.fullResult && state.fullResult.feasible
    ? (state.fullResult.checks || []).filter((c) => !live.has(c.name)).map((c) => ({ ...c, stale: true })) : [];
  const rows = checks.concat(kept);
  // the same checks as drawn last (every answer of a drag): their cells are updated in place
  const key = rows.map((c) => `${c.name}${c.stale ? "~" : ""}`).join("|");
  if (tb.dataset.key !== key) {
    tb.innerHTML = "";
    for (const c of rows) {
      const tr = document.createElement("tr");
      if (c.stale) { tr.className = "stale"; tr.title = "from the last release: updates on release"; }
      tr.innerHTML = `<td>${esc(c.name.replaceAll("_", " "))}</td><td class="num"></td><td></td><td></td>`;
      tr.dataset.check = c.name;
      tb.appendChild(tr);
    }
    tb.dataset.key = key;
  }
  rows.forEach((c, i) => {
    const cells = tb.rows[i].cells;
    const val = c.value === null ? "—" : `${+c.value.toPrecision(5)} ${c.unit}`;
    if (cells[1].textContent !== val) cells[1].textContent = val;
    if (cells[2].textContent !== String(c.limit)) cells[2].textContent = c.limit;
    const verdict = c.ok ? "pass" : "FAIL", cls = c.ok ? "ok" : "fail";
    if (cells[3].textContent !== verdict) { cells[3].textContent = verdict; cells[3].className = cls; }
  });
  $("quality").textContent = res.quality === "drag" ? `live, ${res.samples || ""} samples/turn${res.pending ? " — " + res.pending : ""}` : `${res.samples || ""} samples/turn`;
}

function sectionSpans(secDeg) {
  if (!secDeg) return [];
  const parts = [["a", "b", "picking ab", "picking"], ["b", "d", "transport bcd", "transport"], ["d", "e", "seeding de", "seeding"], ["e", "a", "return efca", "return"]];
  const out = [];
  for (const [p, q, label, kind] of parts) {
    const a = secDeg[p], b = secDeg[q];
    if (a === undefined || b === undefined) continue;
    out.push(...wrapped(a, b, label, SECTION_COLOURS[kind]));
  }
  return out;
}

// a span from a to b deg; one that wraps through 360 is two pieces, labelled on the longer
function wrapped(a, b, label, color) {
  if (b >= a) return [{ from: a, to: b, label, color }];
  const tailLonger = 360 - a >= b;
  return [{ from: a, to: 360, label: tailLonger ? label : undefined, color },
    { from: 0, to: b, label: tailLonger ? undefined : label, color }];
}

function stageSpans(stages) {
  const out = [];
  for (const [name, span] of Object.entries(stages || {})) {
    if (!span) continue;
    const [a, b] = span;
    const color = SECTION_COLOURS[name] || "rgba(0,0,0,0.05)";
    out.push(...wrapped(a, b, name, color));
  }
  return out;
}

// an angle series without its jumps at 0/360 deg (each step taken the short way round)
function unwrapDeg(y) {
  const out = new Array(y.length); let off = 0, last = null;
  for (let i = 0; i < y.length; i++) {
    if (!Number.isFinite(y[i])) { out[i] = y[i]; continue; }
    if (last !== null) { const d = y[i] - last; if (d > 180) off -= 360; else if (d < -180) off += 360; }
    last = y[i]; out[i] = y[i] + off;
  }
  return out;
}

function renderPlots() {
  const res = state.result;
  const p = res && res.plots;
  const marker = res && res.frames ? res.frames.carrier_angle_deg[state.frame % frameCount(res)] : undefined;
  const xl = "carrier angle (clockwise from start) / deg";
  if (!p) { for (const id of ["plot1", "plot2", "plot3"]) linePlot($(id), { series: [], empty: res && !res.feasible ? "infeasible: nothing to plot" : "no data" }); return; }
  if (res.mechanism === "sugarcane_seeder") {
    // while infeasible: the ratio the trajectory asks for, its bad span marked red
    const bad = (res.diagnostics || []).filter((d) => d.severity === "error" && d.carrier_angle_deg)
      .flatMap((d) => wrapped(d.carrier_angle_deg[0], d.carrier_angle_deg[1], "infeasible", "rgba(220,38,38,0.30)"));
    const spans = sectionSpans(res.sections_deg).concat(bad);
    const x = p.carrier_angle_deg;
    linePlot($("plot1"), { title: "cane attitude (from the initial attitude)", xlabel: xl, ylabel: "attitude / deg", xmin: 0, xmax: 360, spans, marker,
      series: [{ x, y: p.attitude_deg, color: "#111" }] });
    // speeds come with the full-resolution evaluation; during a drag the last full ones stay
    const sp = p.speed_static_m_s ? p : (state.fullResult && state.fullResult.plots && state.fullResult.plots.speed_static_m_s ? state.fullResult.plots : null);
    const stale = sp && sp !== p;
    const lim = state.design && state.design.speed ? state.design.speed : { seeding_max_m_s: 1.5, return_min_m_s: 1.1 };
    linePlot($("plot2"), { title: `tip speed${stale ? " (last release; updates on release)" : ""}, travel ${sp ? sp.travel_m_s.toFixed(3) : "?"} m/s`, xlabel: xl, ylabel: "speed / (m/s)", xmin: 0, xmax: 360,
      spans: stale ? sectionSpans(state.fullResult.sections_deg) : spans, marker, empty: "speeds follow on release",
      hlines: [{ y: lim.seeding_max_m_s, label: `seeding max ${lim.seeding_max_m_s} m/s` }, { y: lim.return_min_m_s, label: `return min ${lim.return_min_m_s} m/s`, color: "#92400e" }],
      series: sp ? [{ x: sp.speed_carrier_angle_deg || sp.carrier_angle_deg, y: sp.speed_static_m_s, color: "#2563eb", label: "static" },
        { x: sp.speed_carrier_angle_deg || sp.carrier_angle_deg, y: sp.speed_dynamic_m_s, color: "#dc2626", label: "dynamic (Eq. 17)" }] : [] });
    linePlot($("plot3"), { title: res.feasible ? "transmission ratios" : "transmission ratio the trajectory asks for (no train: red span infeasible)", xlabel: xl, ylabel: "ratio (driven/driver turn)", xmin: 0, xmax: 360, spans, marker,
      hlines: res.feasible ? [] : [{ y: 0, label: "0: the planet stops", color: "#dc2626" }],
      series: [{ x, y: p.total_ratio, color: "#111", label: "planet / carrier" }, { x, y: p.stage1_ratio, color: "#b45309", label: "gear 2 / carrier" }, { x, y: p.stage2_ratio, color: "#0f766e", label: "planet / gear 3" }] });
    $("plots-note").textContent = "sections shaded: picking ab, transport bcd, seeding de, return efca";
  } else if (res.mechanism === "planetary") {
    const x = p.carrier_angle_deg;
    linePlot($("plot1"), { title: "arm angle (absolute, CCW from +x)", xlabel: `carrier angle (${state.design.carrier.direction === "counterclockwise" ? "counter-clockwise" : "clockwise"} from start) / deg`, ylabel: "angle / deg", xmin: 0, xmax: 360, marker,
      series: p.arm_angle_deg.map((y, j) => ({ x, y, color: ARM_COLOURS[j], label: `arm ${j + 1}` })) });
    linePlot($("plot2"), { title: `tip speed at ${state.design.carrier.speed_deg_s} deg/s carrier speed`, xlabel: `carrier angle (${state.design.carrier.direction === "counterclockwise" ? "counter-clockwise" : "clockwise"} from start) / deg`, ylabel: "speed / (m/s)", xmin: 0, xmax: 360, marker,
      series: p.tip_speed_m_s.map((y, j) => ({ x, y, color: ARM_COLOURS[j], label: `arm ${j + 1}` })) });
    linePlot($("plot3"), { title: "planet turn per carrier turn (relative to the carrier), arm 1", xlabel: `carrier angle (${state.design.carrier.direction === "counterclockwise" ? "counter-clockwise" : "clockwise"} from start) / deg`, ylabel: "ratio", xmin: 0, xmax: 360, marker,
      series: [{ x, y: p.planet_ratio, color: "#111" }] });
    $("plots-note").textContent = "general planetary train: every arm";
  } else {
    const spans = stageSpans(res.stages_deg && res.stages_deg.arm_I);
    const x = p.carrier_angle_deg;
    linePlot($("plot1"), { title: "needle angle A→B (CCW from +x, unwrapped: continuous through 0/360)", xlabel: xl, ylabel: "angle / deg", xmin: 0, xmax: 360, spans, marker,
      series: p.needle_angle_deg.map((y, j) => ({ x, y: unwrapDeg(y), color: ARM_COLOURS[j], label: `arm ${j + 1}` })) });
    linePlot($("plot2"), { title: "tip speed relative to the machine", xlabel: xl, ylabel: "speed / (m/s)", xmin: 0, xmax: 360, spans, marker,
      series: p.tip_speed_m_s.map((y, j) => ({ x, y, color: ARM_COLOURS[j], label: `arm ${j + 1}` })) });
    linePlot($("plot3"), { title: "planet turn per carrier turn (relative to the carrier), arm 1", xlabel: xl, ylabel: "ratio", xmin: 0, xmax: 360, spans, marker,
      series: [{ x, y: p.planet_ratio, color: "#111" }] });
    $("plots-note").textContent = "stages of arm 1 shaded";
  }
}

// ---------------------------------------------------------------- edit panel
function getPath(obj, path) { return path.split(".").reduce((o, k) => (o == null ? undefined : o[k]), obj); }
function setPath(obj, path, value) {
  const ks = path.split("."); let o = obj;
  for (const k of ks.slice(0, -1)) o = o[k];
  o[ks[ks.length - 1]] = value;
}
function fieldError(path) {
  const e = state.fieldErrors.find((f) => f.field === path || f.field.startsWith(path + "."));
  return e ? e.message : null;
}
function numberOrText(s) { const t = s.trim(); const v = Number(t); return t !== "" && Number.isFinite(v) ? v : t; }

function inputFor(path, unit, lim) {
  const wrap = document.createElement("span");
  const inp = document.createElement("input");
  inp.type = "text"; inp.value = getPath(state.design, path); inp.dataset.field = path;
  inp.title = lim ? `limits ${lim}` : "";
  inp.addEventListener("change", () => {
    const before = snapshot();
    // text goes to the server as typed: its validation names the field
    setPath(state.design, path, numberOrText(inp.value));
    pushUndo(before);
    evaluate("full");
  });
  wrap.appendChild(inp);
  return wrap;
}

// the fields the panel shows: it is rebuilt only when they change (another design, another
// number of points or radii); every answer updates it in place, under the focus and gestures
function editKey(d) {
  if (d.mechanism === "sugarcane_seeder" && !d.train) return `points:${d.trajectory.points.length}`;
  if (d.mechanism === "sugarcane_seeder") return `radii:${d.train.gear2.radii_mm.length}:${d.train.gear3.radii_mm.length}`;
  return `fields:${(state.parameters || []).map((p) => p.field).join(",")}`;
}

function renderEdit() {
  const box = $("edit"), d = state.design;
  if (!d) { box.innerHTML = ""; box.dataset.key = ""; return; }
  const key = `${state.name}|${d.mechanism}|${editKey(d)}`;
  if (box.dataset.key !== key && !state.drag) { buildEdit(box, d); box.dataset.key = key; }
  updateEdit(box);
}

// values, red fields and their messages, in place: a corrected field loses its error even
// while it has the focus; a focused field keeps what is being typed
function updateEdit(box) {
  const inputs = box.querySelectorAll("input[data-field]");
  const fields = [];
  for (const inp of inputs) {
    const path = inp.dataset.field; fields.push(path);
    const v = getPath(state.design, path);
    if (document.activeElement !== inp && v !== undefined && inp.value !== String(v)) inp.value = v;
    const err = fieldError(path);
    if (inp.classList.contains("invalid") !== !!err) inp.classList.toggle("invalid", !!err);
    let span = inp.nextElementSibling;
    if (err) {
      if (!span) { span = document.createElement("span"); span.className = "field-error"; span.dataset.errorFor = path; inp.after(span); }
      if (span.textContent !== err) span.textContent = err;
    } else if (span) span.remove();
  }
  // errors of no field of the panel's own (the whole trajectory, a gear): under the fields
  const other = state.fieldErrors.filter((e) => !fields.some((f) => f === e.field || f.startsWith(e.field + ".") || e.field.startsWith(f + ".")));
  const texts = other.map((e) => [e.field, `${e.field}: ${e.message}`]);
  if (state.result && state.result.train_error) texts.push(["train", state.result.train_error]);
  let list = box.querySelector(".edit-errors");
  if (!list) { list = document.createElement("div"); list.className = "edit-errors"; box.prepend(list); }
  const key = JSON.stringify(texts);
  if (list.dataset.key !== key) {
    list.innerHTML = ""; list.dataset.key = key;
    for (const [f, t] of texts) { const s = document.createElement("div"); s.className = "field-error"; s.dataset.errorFor = f; s.textContent = t; list.appendChild(s); }
  }
  const c = box.querySelector("#radii");
  if (c && state.design.train) drawRadiiEditor(c);
}

function buildEdit(box, d) {
  box.innerHTML = "";
  const hint = $("hint");
  if (d.mechanism === "sugarcane_seeder" && !d.train) {
    hint.textContent = "Drag a type-value point q_i (white; section points amber) — live inverse design at the working resolution (360 samples per turn: Table 1, attitude and speed objectives update as you drag; gear checks, greyed, and the forward simulation at the design's own resolution follow on release). Wheel: zoom; drag the background: pan; double-click or Fit: the whole mechanism.";
    const t = document.createElement("table");
    t.innerHTML = "<tr><th>point</th><th>x / mm</th><th>y / mm</th></tr>";
    d.trajectory.points.forEach((_, i) => {
      const tr = document.createElement("tr");
      const td0 = document.createElement("td"); td0.textContent = `q${i}`; tr.appendChild(td0);
      for (const c of [0, 1]) { const td = document.createElement("td"); td.appendChild(inputFor(`trajectory.points.${i}.${c}`)); tr.appendChild(td); }
      t.appendChild(tr);
    });
    box.appendChild(t);
  } else if (d.mechanism === "sugarcane_seeder") {
    hint.textContent = "Drag a radius handle of gear 2 or 3 (polar view) or type a radius — live forward simulation.";
    const c = document.createElement("canvas"); c.id = "radii"; c.width = 700; c.height = 300; box.appendChild(c);
    setupRadiiDrag(c);
    for (const g of ["gear2", "gear3"]) {
      const row = document.createElement("div"); row.className = "row";
      row.innerHTML = `<b>${g === "gear2" ? "gear 2" : "gear 3"} radii / mm</b>`;
      d.train[g].radii_mm.forEach((_, i) => row.appendChild(inputFor(`train.${g}.radii_mm.${i}`)));
      box.appendChild(row);
    }
    for (const [p, u] of [["train.L1_mm", "mm"], ["train.L2_mm", "mm"], ["train.initial_arm_angle_deg", "deg"]]) {
      const row = document.createElement("div"); row.className = "param";
      row.innerHTML = `<span>${p.split(".").pop()}</span>`; row.appendChild(inputFor(p)); row.insertAdjacentHTML("beforeend", `<span>${u}</span><span></span>`); box.appendChild(row);
    }
  } else {
    hint.textContent = d.mechanism === "planetary"
      ? (d.optimize ? "Edit the fields the file frees in [optimize.variables] (limits: their bounds)." : "Edit the train's numbers (limits: a box of ±25 %, angles ±45 deg, around the file's value; free fields for the optimizer in [optimize.variables]).")
      : "Edit the design's numbers (limits: the optimizer's search box around the current value, else a box of ±25 %, angles ±45 deg).";
    const params = state.parameters || [];
    const lim = (v) => (Math.abs(v) >= 10 ? v.toFixed(1) : `${+v.toPrecision(3)}`);
    // the optimizer's bounds, or (a train no problem describes) a box around the value
    const what = (d.mechanism === "planetary" && !d.optimize) || d.mechanism === "rice_transplanter_khv" ? "box" : "search box";
    for (const p of params) {
      const row = document.createElement("div"); row.className = "param";
      row.innerHTML = `<span>${esc(p.label)}</span>`;
      row.appendChild(inputFor(p.field, p.unit, `${lim(p.min)}–${lim(p.max)} ${p.unit}`));
      row.insertAdjacentHTML("beforeend", `<span>${esc(p.unit)}</span><span class="lim">${what} ${esc(lim(p.min))} … ${esc(lim(p.max))}</span>`);
      box.appendChild(row);
    }
  }
}

// polar editor of the interpolation radii of gears 2 and 3 (body frame)
function radiiLayout(c) {
  const d = state.design.train;
  let rmax = 0; for (const g of ["gear2", "gear3"]) for (const r of d[g].radii_mm) rmax = Math.max(rmax, typeof r === "number" ? r : 0);
  const s = (c.height / 2 - 20) / (rmax * 1.15 || 1);
  return { s, centres: { gear2: [c.width * 0.27, c.height / 2], gear3: [c.width * 0.73, c.height / 2] } };
}
function angleList(g) { return g.angles_deg || g.radii_mm.map((_, i) => 360 * i / g.radii_mm.length); }
function radiusHandles(c, L) {
  const d = state.design.train, out = [];
  for (const g of ["gear2", "gear3"]) {
    const [cx, cy] = L.centres[g], angs = angleList(d[g]);
    d[g].radii_mm.forEach((r, i) => { const a = angs[i] * Math.PI / 180; out.push({ g, i, a, x: cx + L.s * r * Math.cos(a), y: cy - L.s * r * Math.sin(a) }); });
  }
  return out;
}
function drawRadiiEditor(c) {
  const ctx = c.getContext("2d"); ctx.clearRect(0, 0, c.width, c.height);
  // the scale stays as pressed during a radius drag: the handle stays under the pointer
  const L = state.drag && state.drag.kind === "radius" ? state.drag.L : radiiLayout(c);
  const d = state.design.train, res = state.result;
  ctx.font = "11px system-ui";
  for (const g of ["gear2", "gear3"]) {
    const [cx, cy] = L.centres[g];
    const tp = res && res.train_points && res.train_points[g];
    ctx.strokeStyle = g === "gear2" ? "#b45309" : "#0f766e"; ctx.lineWidth = 1.5;
    if (tp && tp.curve) { ctx.beginPath(); tp.curve.forEach((r, i) => { const a = tp.theta_deg[i] * Math.PI / 180; const x = cx + L.s * r * Math.cos(a), y = cy - L.s * r * Math.sin(a); if (i) ctx.lineTo(x, y); else ctx.moveTo(x, y); }); ctx.closePath(); ctx.stroke(); }
    ctx.fillStyle = "#111"; ctx.fillText(`${g === "gear2" ? "gear 2" : "gear 3"} pitch curve (body frame), radii in mm`, cx - 110, 12);
  }
  const active = state.drag && state.drag.kind === "radius" ? `${state.drag.g}${state.drag.i}` : c.hover;
  for (const h of radiusHandles(c, L)) {
    const [cx, cy] = L.centres[h.g], on = `${h.g}${h.i}` === active;
    ctx.strokeStyle = "#ccc"; ctx.lineWidth = 1; ctx.beginPath(); ctx.moveTo(cx, cy); ctx.lineTo(h.x, h.y); ctx.stroke();
    ctx.fillStyle = fieldError(`train.${h.g}.radii_mm.${h.i}`) ? "#dc2626" : "#fff";
    ctx.strokeStyle = on ? "#2563eb" : "#111"; ctx.lineWidth = on ? 2.5 : 1;
    ctx.beginPath(); ctx.arc(h.x, h.y, on ? 7 : 5, 0, 2 * Math.PI); ctx.fill(); ctx.stroke();
  }
}
// the radius handles where they are drawn (canvas pixels; for the tests)
window.__radiusHandles = () => { const c = $("radii"); return c ? radiusHandles(c, radiiLayout(c)) : []; };
function setupRadiiDrag(c) {
  const hit = (ev) => {
    const [px, py] = canvasPoint(ev, c), r2 = pickRadius(c) ** 2;
    let best = null, bd = r2;
    for (const h of radiusHandles(c, radiiLayout(c))) { const dd = (h.x - px) ** 2 + (h.y - py) ** 2; if (dd < bd) { bd = dd; best = h; } }
    return best;
  };
  c.addEventListener("pointerdown", (ev) => {
    const h = hit(ev);
    if (h) beginGesture("radius", c, ev, { g: h.g, i: h.i, a: h.a, L: radiiLayout(c) });
  });
  c.addEventListener("pointermove", (ev) => {
    if (state.drag && state.drag.canvas === c) { moveGesture(ev); return; }
    if (state.drag) return;
    const h = hit(ev), key = h ? `${h.g}${h.i}` : null;
    c.style.cursor = h ? "grab" : "";
    if (h) readout(`${h.g === "gear2" ? "gear 2" : "gear 3"} radius ${h.i}: ${(+state.design.train[h.g].radii_mm[h.i]).toFixed(2)} mm (drag to change)`);
    if (key !== c.hover) { c.hover = key; drawRadiiEditor(c); }
  });
  c.addEventListener("pointerup", endGesture); c.addEventListener("pointercancel", endGesture);
}

// ---------------------------------------------------------------- render + animation
function render() {
  const res = state.result;
  if (res && res.mechanism) {
    const t = res.train ? `L1 ${res.train.L1_mm.toFixed(1)} mm, L2 ${res.train.L2_mm.toFixed(1)} mm, a1 ${res.train.a1_mm.toFixed(1)} mm, a2 ${res.train.a2_mm.toFixed(1)} mm`
      : Array.isArray(res.centre_distance_mm) ? `centre distances ${res.centre_distance_mm.map((a) => a.toFixed(2)).join(", ")} mm`
      : (res.centre_distance_mm ? `centre distance ${res.centre_distance_mm.toFixed(2)} mm` : "");
    $("mech-info").textContent = t;
    const n = frameCount(res);
    $("scrub").max = Math.max(0, n - 1);
  }
  const t0 = performance.now();
  drawMechanism();
  const t1 = performance.now();
  teethNote();
  renderChecks();
  const t2 = performance.now();
  renderPlots();
  const t3 = performance.now();
  renderEdit();
  markStale();
  // where a redraw's time goes (ms; window.__dragBreakdown, printed by make bench)
  return { draw_mechanism: t1 - t0, draw_checks: t2 - t1, draw_plots: t3 - t2, draw_edit: performance.now() - t3 };
}

function tick(t) {
  try { step(t); } catch (e) { console.error(e); }
  state.lastT = t;
  requestAnimationFrame(tick);
}

function step(t) {
  if (state.playing && state.result && frameCount(state.result)) {
    if (state.lastT !== null) {
      // one carrier turn in 4 s at 1x
      const n = frameCount(state.result);
      state.phase = ((state.phase || 0) + (t - state.lastT) / 4000 * state.speed * n) % n;
      state.frame = Math.floor(state.phase);
      $("scrub").value = state.frame;
      drawMechanism();
      if (state.frame % 6 === 0) renderPlots();
    }
  }
}

// ---------------------------------------------------------------- optimize
async function refreshProblems() {
  if (!state.design) return;
  const r = await api(`/api/problems?mechanism=${state.design.mechanism}`);
  const sel = $("opt-problem"); sel.innerHTML = "";
  for (const p of r.problems) { const o = document.createElement("option"); o.value = p.name; o.textContent = p.stages > 1 ? `${p.name} (${p.algorithm}, ${p.stages} stages, default ${p.generations} gen per stage × ${p.pop})` : `${p.name} (${p.algorithm}, default ${p.generations} gen × ${p.pop})`; sel.appendChild(o); }
  if (state.design.mechanism === "sugarcane_seeder") sel.value = state.design.train ? "seeder-layer2" : "seeder-layer1";
  // a general train is optimized over the fields its file frees: without them there is
  // nothing to run, and the page says so instead of offering a run that can only fail
  const free = state.design.mechanism !== "planetary" || !!state.design.optimize;
  const none = !r.problems.length;
  const running = !$("opt-cancel").disabled;
  if (!running) $("opt-start").disabled = !free || none;
  const why = none ? `no optimizer problem takes a ${state.design.mechanism} design yet: edit its numbers by hand`
    : (!free ? "this file frees no field: add [optimize.variables] (dotted paths with bounds) to optimize it" : "");
  if (!running && (why || /^(this file frees no field|no optimizer problem)/.test($("opt-status").textContent))) $("opt-status").textContent = why;
}

// Results belong to the design they were computed for: another example or file clears
// them (a running task is cancelled); an edit of the design labels them stale.
function clearTasks() {
  for (const t of [state.optTask, state.gearTask]) if (t && state.running && state.running.has(t)) api(`/api/tasks/${t}/cancel`, {}).catch(() => {});
  state.optTask = null; state.optResult = null; state.optSelected = null; state.optKeys = new Set();
  state.gearTask = null; state.gearKey = null; state.teeth = null; state.gearVerdict = null;
  for (const id of ["opt-status", "opt-changes", "g-status", "g-files", "g-images", "g-verdict", "make-headline"]) $(id).innerHTML = "";
  $("opt-cancel").disabled = true; $("opt-start").disabled = false; $("g-start").disabled = false;
  drawHistory([], [], "generation");
  scatterPlot($("opt-pareto"), { x: [], y: [], empty: "no front yet" });
  markStale();
}

function markStale() {
  // (the design serialized only while there is a result to compare it with)
  const key = state.design && (state.gearKey || state.optKeys.size) ? JSON.stringify(state.design) : null;
  // a run belongs to the design it started from and to the designs loaded from it
  const gStale = !!state.gearKey && state.gearKey !== key, oStale = !!state.optKeys.size && !state.optKeys.has(key);
  $("make-panel").classList.toggle("stale", gStale);
  $("opt-panel").classList.toggle("stale", oStale);
  const g = $("g-stale"), o = $("opt-stale");
  const gt = gStale ? "STALE: these gears were cut for an earlier version of the design (cut again for this one)" : "";
  const ot = oStale ? "STALE: this run started from an earlier version of the design" : "";
  if (g.textContent !== gt) g.textContent = gt;
  if (o.textContent !== ot) o.textContent = ot;
  const h = $("make-headline");
  if (state.gearVerdict) {
    const text = `gears: ${state.gearVerdict.headline}${gStale ? " (for an earlier version)" : ""}`;
    if (h.textContent !== text) { h.textContent = text; h.className = state.gearVerdict.ok && !gStale ? "good" : "bad"; }
  }
}

function intField(id) { const t = $(id).value.trim(); const v = Number(t); return t === "" ? null : (Number.isInteger(v) ? v : t); }

function checksMet(rows) { const req = (rows || []).filter((c) => c.required !== false); return [req.filter((c) => c.ok).length, req.length]; }

async function startOptimize() {
  const body = { design: state.design, problem: $("opt-problem").value, generations: intField("opt-gen"), pop: intField("opt-pop"), seed: intField("opt-seed") };
  for (const id of ["opt-gen", "opt-pop", "opt-seed"]) $(id).classList.remove("invalid");
  try {
    const r = await api("/api/optimize", body);
    state.optTask = r.task; state.optResult = null; state.optSelected = null;
    state.optKeys = new Set([JSON.stringify(body.design)]);
    state.optStart = { design: clone(body.design), checks: state.fullResult ? state.fullResult.checks : null };
    (state.running ||= new Set()).add(r.task);
    $("opt-cancel").disabled = false; $("opt-start").disabled = true; $("opt-changes").innerHTML = "";
    markStale();
    pollOptimize(r.task);
  } catch (e) {
    $("opt-status").innerHTML = `<span class="field-error">${esc(e.message)}</span>`;
    for (const f of (e.data && e.data.fields) || []) { const el = document.querySelector(`#bottom [data-field="${CSS.escape(String(f.field))}"]`); if (el) el.classList.add("invalid"); }
  }
}

// progress in order: a stage is a run of generations under one name; a new name, or the
// generation count starting again, is the next stage (the restarts of a staged job).
// Each stage: its name and the index of its first generation in the history.
function stagesOf(hist) {
  const out = [];
  hist.forEach((h, i) => {
    const prev = i ? hist[i - 1] : null;
    if (!prev || h.stage !== prev.stage || h.generation <= prev.generation) out.push({ name: h.stage, first: i });
  });
  return out;
}

// text from the server (messages, names, files) put into HTML: always through esc, so
// that an error or a name holding markup shows as the text it is
function esc(t) { return String(t).replace(/[&<>"']/g, (c) => ({ "&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;", "'": "&#39;" })[c]); }
const fileUrl = (task, f) => esc(`/api/tasks/${encodeURIComponent(task)}/files/${encodeURIComponent(f)}`);

async function pollOptimize(task) {
  if (!task || task !== state.optTask) return; // another design's run: no longer shown
  let st;
  try { st = await api(`/api/tasks/${task}`); } catch { return; }
  if (task !== state.optTask) return;
  const pr = st.progress;
  const hist = st.history || [];
  if (st.state === "running") {
    const stages = stagesOf(hist);
    const k = stages.length;
    $("opt-status").textContent = pr ? `running ${st.elapsed_s.toFixed(0)} s — stage ${k} (${pr.stage || "optimizer"}): generation ${pr.generation}/${pr.generations}, best violation in this stage ${pr.best_violation.toPrecision(4)}, designs meeting all: ${pr.feasible_in_population}`
      : `starting (${st.elapsed_s.toFixed(0)} s)…`;
    // every stage shaded and named: its best violation starts afresh
    const spans = stages.map((st, j) => ({ from: st.first + 0.5, to: j + 1 < k ? stages[j + 1].first + 0.5 : hist.length + 0.5,
      label: `stage ${j + 1}`, color: j % 2 ? "rgba(37,99,235,0.08)" : "rgba(107,114,128,0.10)" }));
    drawHistory(hist.map((h, i) => i + 1), hist.map((h) => h.best_violation), `generation (all ${k} stage${k === 1 ? "" : "s"} in order; each stage starts afresh)`, spans);
    setTimeout(() => pollOptimize(task), 500);
    return;
  }
  state.running.delete(task);
  $("opt-cancel").disabled = true; $("opt-start").disabled = false;
  if (st.state === "failed") {
    $("opt-status").innerHTML = st.error === "cancelled" ? '<span class="cancelled">cancelled</span> (nothing was kept)'
      : `<span class="field-error">optimization failed: ${esc(st.error)}</span>`;
    return;
  }
  const r = st.result; state.optResult = r;
  // the start and the result counted on the same checks: the run's rows the start has too
  const startRows = state.optStart && state.optStart.checks;
  const named = new Map((startRows || []).map((c) => [c.name, c]));
  const common = (r.result_checks || []).filter((c) => named.has(c.name));
  const after = checksMet(startRows ? common : r.result_checks);
  const before = startRows ? checksMet(common.map((c) => ({ ...named.get(c.name), required: c.required }))) : null;
  const worse = before && after[0] < before[0];
  const counts = before ? `checks met: start ${before[0]}/${before[1]} → result ${after[0]}/${after[1]}` : `checks met by the result: ${after[0]}/${after[1]}`;
  const files = r.files.map((f) => `<a href="${fileUrl(task, f)}" download>${esc(f)}</a>`).join(" ");
  $("opt-status").innerHTML = `${r.feasible ? '<span class="ok">every objective met</span>' : '<span class="fail">not every objective met</span> (closest design kept)'} — ${esc(r.evaluations)} evaluations, ${esc(r.wall_s.toFixed(1))} s. <span class="${worse ? "fail" : ""}" id="opt-counts">${esc(counts)}${worse ? " — WORSE than the start" : ""}</span>
    <ul class="opt-summary">${(r.summary || []).map((l) => `<li>${esc(l)}</li>`).join("")}</ul>Files: ${files}`;
  // what the optimizer changed in the design (the best design against the start)
  const changes = [];
  const walk = (a, b, path) => {
    if (typeof a === "number" && typeof b === "number") { if (Math.abs(a - b) > 1e-9 * Math.max(1, Math.abs(a))) changes.push([path, a, b]); return; }
    if (a && b && typeof a === "object" && typeof b === "object") { for (const k of Object.keys(b)) if (path || !["name", "description"].includes(k)) walk(a[k], b[k], path ? `${path}.${k}` : k); }
    else if (JSON.stringify(a) !== JSON.stringify(b)) changes.push([path, a, b]);
  };
  if (state.optStart) walk(state.optStart.design, r.best_design, "");
  const fmtv = (v) => (typeof v === "number" ? +v.toPrecision(6) : JSON.stringify(v));
  $("opt-changes").innerHTML = changes.length
    ? `<b>changed in the best design (${changes.length})</b><ul>${changes.slice(0, 40).map(([p, a, b]) => `<li data-field="${esc(p)}">${esc(p)}: ${esc(fmtv(a))} → ${esc(fmtv(b))}</li>`).join("")}</ul>${changes.length > 40 ? `… and ${changes.length - 40} more` : ""}`
    : "<b>the best design is the start: nothing changed</b>";
  const h = r.history || {};
  drawHistory(h.generation || [], h.best_violation || [], "generation (last stage of the run)");
  drawPareto();
}

function drawHistory(x, y, xlabel, spans = []) {
  linePlot($("opt-history"), { title: "convergence", xlabel, ylabel: "best total violation", logy: true, spans,
    xmin: x.length ? Math.min(...x) - 0.5 : undefined, xmax: x.length ? Math.max(...x) + 0.5 : undefined,
    series: [{ x, y: y.map((v) => Math.max(v, 1e-6)), color: "#111" }], empty: "no run yet" });
}

function drawPareto() {
  const r = state.optResult; if (!r) return;
  const t = r.tradeoff;
  if (!r.feasible && t && t.agronomic_violation && t.agronomic_violation.length) {
    // nothing meets everything: the run's trade-off archive (tradeoff.csv), 0 = met
    const [a, b] = Object.keys(t);
    scatterPlot($("opt-pareto"), { title: `trade-off (tradeoff.csv, ${t[a].length} designs): nothing meets everything`, x: t[a], y: t[b],
      xlabel: `${a.replaceAll("_", " ")} (0 = met)`, ylabel: `${b.replaceAll("_", " ")} (0 = met)`, selected: null });
    $("opt-pareto").dataset.kind = "tradeoff";
    return;
  }
  $("opt-pareto").dataset.kind = "pareto";
  const names = r.objectives.length ? r.objectives : Object.keys(r.pareto).slice(-2);
  const [a, b] = [names[0], names[1] || names[0]];
  scatterPlot($("opt-pareto"), { title: r.pareto_designs ? "Pareto front (click a point to load it)" : "best design (click to load)", x: r.pareto[a] || [], y: r.pareto[b] || [],
    xlabel: a.replaceAll("_", " "), ylabel: b.replaceAll("_", " "), selected: state.optSelected });
}

function loadFromRun(design, name) {
  loadDesign(design, name, true);
  state.optKeys.add(JSON.stringify(state.design));
  markStale();
}

function pickPareto(ev) {
  const r = state.optResult; if (!r) return;
  if ($("opt-pareto").dataset.kind === "tradeoff") { loadFromRun(r.best_design, `${state.name} (optimized, best)`); return; }
  const i = pickPoint($("opt-pareto"), ev);
  if (i === null) return;
  state.optSelected = i;
  const d = r.pareto_designs ? r.pareto_designs[i] : r.best_design;
  loadFromRun(d, `${state.name} (optimized, point ${i + 1})`);
  drawPareto();
}

// ---------------------------------------------------------------- make (teeth)
function numField(id) { const t = $(id).value.trim(); const v = Number(t); return t === "" ? null : (Number.isFinite(v) ? v : t); }

async function startGears() {
  const body = { design: state.design, module: numField("g-module"), face_width: numField("g-face"), backlash: numField("g-backlash") };
  for (const id of ["g-module", "g-face", "g-backlash"]) $(id).classList.remove("invalid");
  for (const id of ["g-files", "g-images", "g-verdict", "make-headline"]) $(id).innerHTML = "";
  state.gearVerdict = null;
  try {
    const r = await api("/api/gears", body);
    state.gearTask = r.task; state.gearKey = JSON.stringify(body.design); $("g-start").disabled = true;
    (state.running ||= new Set()).add(r.task);
    markStale();
    pollGears(r.task);
  } catch (e) {
    $("g-status").innerHTML = `<span class="field-error">${esc(e.message)}</span>`;
    for (const f of (e.data && e.data.fields) || []) { const el = document.querySelector(`#bottom [data-field="${CSS.escape(String(f.field))}"]`); if (el) el.classList.add("invalid"); }
  }
}

async function pollGears(task) {
  if (!task || task !== state.gearTask) return;
  let st;
  try { st = await api(`/api/tasks/${task}`); } catch { return; }
  if (task !== state.gearTask) return;
  if (st.state === "running") { $("g-status").textContent = `cutting teeth… ${st.elapsed_s.toFixed(0)} s${st.progress ? " (" + st.progress.stage + ")" : ""}`; setTimeout(() => pollGears(task), 700); return; }
  state.running.delete(task);
  $("g-start").disabled = false;
  if (st.state === "failed") { $("g-status").innerHTML = st.error === "cancelled" ? '<span class="cancelled">cancelled</span>' : `<span class="field-error">${esc(st.error)}</span>`; return; }
  const res = st.result, rec = res.record;
  if (res.teeth) {
    const m = rec.gears.length ? rec.gears[0].module_mm.toFixed(3) + " mm" : "?";
    state.teeth = { key: state.gearKey, gears: res.teeth, module: m };
    teethNote(); drawMechanism();
  }
  // the one verdict of verification.json (as `plantmech gears` prints it) and its findings
  const ok = res.verdict.ok === true;
  state.gearVerdict = { ok, headline: res.headline };
  const failed = new Set(res.findings.map((f) => f.gear));
  $("g-verdict").innerHTML = `<div class="${ok ? "ok" : "fail"}" id="g-headline">verdict: ${esc(res.headline)}</div>`
    + (res.findings.length ? `<ol class="findings">${res.findings.map((f) => `<li data-gear="${esc(f.gear)}">${esc(f.text)}</li>`).join("")}</ol>` : "");
  let html = `<table><tr><th>gear</th><th>teeth</th><th>module / mm</th><th>max pressure angle / deg</th><th>undercut</th><th>pointed</th><th>cutter fits</th><th></th></tr>`;
  for (const g of rec.gears) html += `<tr><td>${esc(g.name)}</td><td class="num">${esc(g.teeth)}</td><td class="num">${g.module_mm.toFixed(4)}</td><td class="num">${g.max_pressure_angle_deg.toFixed(1)}</td><td class="${g.undercut ? "fail" : "ok"}">${g.undercut ? "yes" : "no"}</td><td class="${g.pointed ? "fail" : "ok"}">${g.pointed ? "yes" : "no"}</td><td class="${g.cutter_fits ? "ok" : "fail"}">${g.cutter_fits ? "yes" : "no"}</td><td class="${failed.has(g.name) ? "fail" : "ok"}">${failed.has(g.name) ? "FAIL" : "ok"}</td></tr>`;
  html += `</table><table><tr><th>pair in mesh</th><th>interference / mm</th><th>max backlash / mm</th><th></th></tr>`;
  // a pair is judged by the findings (backlash band, interference), as the CLI judges it
  for (const m of rec.mesh) { const bad = failed.has(m.pair) || !m.ok; html += `<tr data-pair="${esc(m.pair)}"><td>${esc(m.pair)}</td><td class="num">${m.max_interference_mm.toFixed(4)}</td><td class="num">${m.max_backlash_mm === null ? "n/a" : m.max_backlash_mm.toFixed(4)}</td><td class="${bad ? "fail" : "ok"}">${bad ? "FAIL" : "meshes"}</td></tr>`; }
  html += "</table>" + (rec.step ? `<p class="hint">STEP not written: ${esc(rec.step)}</p>` : "");
  $("g-status").innerHTML = html;
  const links = res.files.filter((f) => !f.endsWith(".png")).map((f) => `<a href="${fileUrl(task, f)}" download class="${ok ? "" : "not-ok"}"${ok ? "" : ' title="from a set that is not manufacturable: see the findings"'}>${esc(f)}</a>`).join(" ");
  $("g-files").innerHTML = ok ? `Download: ${links}` : `<span class="fail">Download (NOT MANUFACTURABLE as cut — see the findings above):</span> ${links}`;
  $("g-images").innerHTML = res.files.filter((f) => f.endsWith(".png")).map((f) => `<img alt="${esc(f)}" src="${fileUrl(task, f)}">`).join("");
  markStale();
}

// ---------------------------------------------------------------- start
async function saveToml() {
  try {
    const r = await fetch("/api/toml", { method: "POST", headers: { "Content-Type": "application/json" }, body: JSON.stringify({ design: state.design }) });
    if (!r.ok) { const e = await r.json(); setStatus(e.error, true); return; }
    const blob = await r.blob();
    const name = (r.headers.get("Content-Disposition") || "").match(/filename="([^"]+)"/);
    const a = document.createElement("a"); a.href = URL.createObjectURL(blob); a.download = name ? name[1] : "design.toml";
    document.body.appendChild(a); a.click(); a.remove();
  } catch (e) { setStatus(e.message, true); }
}

async function main() {
  const ex = await api("/api/examples");
  for (const n of ex.examples) { const o = document.createElement("option"); o.value = n; o.textContent = n; $("example").appendChild(o); }
  $("example").addEventListener("change", async (e) => {
    if (!e.target.value) return;
    const r = await api(`/api/examples/${encodeURIComponent(e.target.value)}`);
    loadDesign(r.design, r.name);
  });
  $("open").addEventListener("change", async (e) => {
    const f = e.target.files[0]; if (!f) return;
    try { const r = await api("/api/parse", { name: f.name.replace(/\.toml$/, ""), text: await f.text() }); loadDesign(r.design, r.name); }
    catch (err) { setStatus(err.message.split("\n").join(" — "), true); }
    e.target.value = "";
  });
  $("save").addEventListener("click", saveToml);
  $("undo").addEventListener("click", undo);
  $("redo").addEventListener("click", redo);
  document.addEventListener("keydown", (e) => {
    if (e.target.tagName === "INPUT") return;
    if ((e.ctrlKey || e.metaKey) && e.key.toLowerCase() === "z") { e.preventDefault(); if (e.shiftKey) redo(); else undo(); }
    if ((e.ctrlKey || e.metaKey) && e.key === "y") { e.preventDefault(); redo(); }
  });
  $("play").addEventListener("click", () => { state.playing = !state.playing; $("play").textContent = state.playing ? "Pause" : "Play"; });
  $("scrub").addEventListener("input", (e) => { state.frame = +e.target.value; state.phase = state.frame; drawMechanism(); renderPlots(); });
  $("speed").addEventListener("change", (e) => { state.speed = +e.target.value; });
  $("show-gears").addEventListener("change", drawMechanism);
  $("opt-start").addEventListener("click", startOptimize);
  $("opt-cancel").addEventListener("click", async () => { if (state.optTask) await api(`/api/tasks/${state.optTask}/cancel`, {}).catch(() => {}); });
  $("fit").addEventListener("click", fitView);
  $("opt-pareto").addEventListener("click", pickPareto);
  $("g-start").addEventListener("click", startGears);
  setupDrag();
  drawHistory([], [], "evaluations");
  scatterPlot($("opt-pareto"), { x: [], y: [], empty: "no front yet" });
  const init = await api("/api/initial");
  if (init.initial) loadDesign(init.initial.design, init.initial.name);
  else { $("example").value = "sugarcane_seeder"; const r = await api("/api/examples/sugarcane_seeder"); loadDesign(r.design, r.name); }
  requestAnimationFrame(tick);
}

main().catch((e) => setStatus(e.message, true));
