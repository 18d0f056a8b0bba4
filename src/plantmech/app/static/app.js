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
};
window.__plantmech = state; // for the tests and the benchmark
window.__dragTimes = [];
window.__dragBreakdown = []; // per drawn drag answer: where the milliseconds went

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
function pushUndo(before) {
  state.undo.push(before); state.redo = [];
  if (state.undo.length > 200) state.undo.shift();
}

function blurEdit() { if (document.activeElement && document.activeElement.closest?.("#edit")) document.activeElement.blur(); }

function loadDesign(design, name, keepUndo = false) {
  blurEdit();
  if (state.design && keepUndo) pushUndo(clone(state.design));
  if (!keepUndo) { state.undo = []; state.redo = []; }
  state.design = clone(design); state.name = name || design.name || "design";
  state.fullResult = null; state.result = null;
  $("design-name").textContent = `${state.name} — ${design.mechanism}`;
  state.view = null;
  refreshProblems();
  evaluate("full");
}

function undo() {
  if (!state.undo.length) return;
  blurEdit();
  state.redo.push(clone(state.design)); state.design = state.undo.pop(); evaluate("full");
}
function redo() {
  if (!state.redo.length) return;
  blurEdit();
  state.undo.push(clone(state.design)); state.design = state.redo.pop(); evaluate("full");
}

// ---------------------------------------------------------------- edit stream
// Edits travel over one WebSocket (/api/ws): no HTTP request per pointer move (Chromium's
// fetch costs several ms per request on loopback, docs/app.md). If the socket cannot be
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
// server computes the next edit while the page draws (docs/app.md, "How an edit travels").
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
    state.result = res;
    if (quality === "full") state.fullResult = res;
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

function makeView(res, canvas) {
  const [x0, x1, y0, y1] = bounds(res);
  const pad = 30, W = canvas.width, H = canvas.height;
  const s = Math.min((W - 2 * pad) / (x1 - x0 || 1), (H - 2 * pad) / (y1 - y0 || 1));
  const ox = pad + ((W - 2 * pad) - s * (x1 - x0)) / 2 - s * x0;
  const oy = H - pad - ((H - 2 * pad) - s * (y1 - y0)) / 2 + s * y0;
  return { s, ox, oy, toPx: (x, y) => [ox + s * x, oy - s * y], toMM: (px, py) => [(px - ox) / s, (oy - py) / s] };
}

function poly(ctx, v, pts, close = false) {
  ctx.beginPath();
  pts.forEach(([x, y], i) => { const [px, py] = v.toPx(x, y); if (i) ctx.lineTo(px, py); else ctx.moveTo(px, py); });
  if (close) ctx.closePath();
}

function frameCount(res) { return res && res.frames ? res.frames.carrier_angle_deg.length : 0; }

function drawMechanism() {
  const canvas = $("mech"), ctx = canvas.getContext("2d");
  const res = state.result;
  ctx.clearRect(0, 0, canvas.width, canvas.height);
  if (!res) return;
  if (!state.view) state.view = makeView(res, canvas);
  const v = state.view;
  ctx.lineJoin = "round";
  // scale bar
  const bar = [10, 20, 50, 100, 200, 500].find((b) => b * v.s > 60) || 500;
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
  const n = frameCount(res);
  const f = n ? state.frame % n : 0;
  // gears on their pitch curves at this frame
  if (n && $("show-gears").checked) {
    const teeth = currentTeeth();
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
  if (n) {
    res.frames.links.forEach((l, i) => {
      const pts = l.points[f];
      const arm = l.name.startsWith("arm");
      const j = parseInt((l.name.match(/\d+/) || ["1"])[0], 10) - 1;
      ctx.strokeStyle = arm ? (res.tip_paths ? ARM_COLOURS[j] : "#1d4ed8") : "#111";
      ctx.lineWidth = arm ? 4 : 5; ctx.globalAlpha = 0.85;
      poly(ctx, v, pts); ctx.stroke(); ctx.globalAlpha = 1;
      for (const p of pts) { const [px, py] = v.toPx(...p); ctx.fillStyle = "#fff"; ctx.strokeStyle = "#111"; ctx.lineWidth = 1.2; ctx.beginPath(); ctx.arc(px, py, 3.5, 0, 2 * Math.PI); ctx.fill(); ctx.stroke(); }
    });
    const [tx, ty] = v.toPx(...res.frames.tip[f]);
    ctx.fillStyle = "#dc2626"; ctx.beginPath(); ctx.arc(tx, ty, 5, 0, 2 * Math.PI); ctx.fill();
  }
  // type-value points (drag handles) with section letters
  if (res.points && state.design && state.design.trajectory) {
    const sec = res.sections_points || {};
    const letter = {}; for (const [k, i] of Object.entries(sec)) letter[i] = k;
    const pts = state.design.trajectory.points;
    const editable = !state.design.train;
    pts.forEach(([x, y], i) => {
      const [px, py] = v.toPx(x, y);
      const bad = state.fieldErrors.some((e) => e.field.startsWith(`trajectory.points.${i}`) || e.field === "trajectory.points");
      ctx.fillStyle = bad ? "#dc2626" : (letter[i] ? "#f59e0b" : "#fff");
      ctx.strokeStyle = "#111"; ctx.lineWidth = 1.2;
      ctx.beginPath(); ctx.arc(px, py, editable ? 5 : 3, 0, 2 * Math.PI); ctx.fill(); ctx.stroke();
      ctx.fillStyle = "#111"; ctx.font = "10px system-ui";
      ctx.fillText(`q${i}${letter[i] ? " " + letter[i] : ""}`, px + 6, py - 5);
    });
  }
  // reasons of infeasible spans, beside the red span
  ctx.font = "12px system-ui"; ctx.fillStyle = "#b91c1c";
  (res.diagnostics || []).filter((d) => d.severity === "error").slice(0, 3).forEach((d, i) => {
    ctx.fillText(`✖ ${d.message.slice(0, 95)}`, 10, 16 + 15 * i);
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

// ---------------------------------------------------------------- dragging type-value points
function canvasPoint(ev, canvas) {
  const r = canvas.getBoundingClientRect();
  return [(ev.clientX - r.left) * canvas.width / r.width, (ev.clientY - r.top) * canvas.height / r.height];
}

function setupDrag() {
  const canvas = $("mech");
  canvas.addEventListener("pointerdown", (ev) => {
    const d = state.design;
    if (!d || !d.trajectory || d.train || !state.view) return;
    const [px, py] = canvasPoint(ev, canvas);
    let best = -1, bd = 10 * 10;
    d.trajectory.points.forEach(([x, y], i) => { const [qx, qy] = state.view.toPx(x, y); const dd = (qx - px) ** 2 + (qy - py) ** 2; if (dd < bd) { bd = dd; best = i; } });
    if (best < 0) return;
    canvas.setPointerCapture(ev.pointerId);
    state.drag = { index: best, before: clone(d), moved: false };
    ev.preventDefault();
  });
  canvas.addEventListener("pointermove", (ev) => {
    if (!state.drag) return;
    const t0 = performance.now();
    performance.mark("drag-input");
    const [px, py] = canvasPoint(ev, canvas);
    const [x, y] = state.view.toMM(px, py);
    state.design.trajectory.points[state.drag.index] = [Math.round(x * 100) / 100, Math.round(y * 100) / 100];
    state.drag.moved = true;
    drawMechanism(); // the handle follows at once; the mechanism follows the server
    evaluate("drag", t0);
  });
  const end = () => {
    if (!state.drag) return;
    const g = state.drag; state.drag = null;
    if (g.moved) { pushUndo(g.before); evaluate("full"); }
  };
  canvas.addEventListener("pointerup", end);
  canvas.addEventListener("pointercancel", end);
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
      tr.innerHTML = `<td>${c.name.replaceAll("_", " ")}</td><td class="num"></td><td></td><td></td>`;
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

function renderPlots() {
  const res = state.result;
  const p = res && res.plots;
  const marker = res && res.frames ? res.frames.carrier_angle_deg[state.frame % frameCount(res)] : undefined;
  const xl = "carrier angle (clockwise from start) / deg";
  if (!p) { for (const id of ["plot1", "plot2", "plot3"]) linePlot($(id), { series: [], empty: res && !res.feasible ? "infeasible: nothing to plot" : "no data" }); return; }
  if (res.mechanism === "sugarcane_seeder") {
    const spans = sectionSpans(res.sections_deg);
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
    linePlot($("plot3"), { title: "transmission ratios", xlabel: xl, ylabel: "ratio (driven/driver turn)", xmin: 0, xmax: 360, spans, marker,
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
    linePlot($("plot1"), { title: "needle angle A→B (CCW from +x)", xlabel: xl, ylabel: "angle / deg", xmin: 0, xmax: 360, spans, marker,
      series: p.needle_angle_deg.map((y, j) => ({ x, y, color: ARM_COLOURS[j], label: `arm ${j + 1}` })) });
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
  const err = fieldError(path);
  if (err) inp.classList.add("invalid");
  inp.addEventListener("change", () => {
    const before = clone(state.design);
    // text goes to the server as typed: its validation names the field
    setPath(state.design, path, numberOrText(inp.value));
    pushUndo(before);
    evaluate("full");
  });
  wrap.appendChild(inp);
  if (err) { const s = document.createElement("span"); s.className = "field-error"; s.dataset.errorFor = path; s.textContent = err; wrap.appendChild(s); }
  return wrap;
}

function renderEdit() {
  const box = $("edit"); box.innerHTML = "";
  const d = state.design;
  if (!d) return;
  const hint = $("hint");
  if (d.mechanism === "sugarcane_seeder" && !d.train) {
    hint.textContent = "Drag a type-value point q_i (white; section points amber) — live inverse design at the working resolution (360 samples per turn: Table 1, attitude and speed objectives update as you drag; gear checks, greyed, and the forward simulation at the design's own resolution follow on release).";
    const t = document.createElement("table");
    t.innerHTML = "<tr><th>point</th><th>x / mm</th><th>y / mm</th></tr>";
    d.trajectory.points.forEach((_, i) => {
      const tr = document.createElement("tr");
      const td0 = document.createElement("td"); td0.textContent = `q${i}`; tr.appendChild(td0);
      for (const c of [0, 1]) { const td = document.createElement("td"); td.appendChild(inputFor(`trajectory.points.${i}.${c}`)); tr.appendChild(td); }
      t.appendChild(tr);
    });
    const err = fieldError("trajectory.points") || fieldError("trajectory");
    if (err) { const s = document.createElement("div"); s.className = "field-error"; s.dataset.errorFor = "trajectory.points"; s.textContent = err; box.appendChild(s); }
    box.appendChild(t);
  } else if (d.mechanism === "sugarcane_seeder") {
    hint.textContent = "Drag a radius handle of gear 2 or 3 (polar view) or type a radius — live forward simulation.";
    const c = document.createElement("canvas"); c.id = "radii"; c.width = 700; c.height = 300; box.appendChild(c);
    drawRadiiEditor(c);
    setupRadiiDrag(c);
    const res = state.result;
    if (res && res.train_error) { const s = document.createElement("div"); s.className = "field-error"; s.dataset.errorFor = "train"; s.textContent = res.train_error; box.appendChild(s); }
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
      : "Edit the published parameters (limits: the optimizer's search box around the current value).";
    const params = state.parameters || [];
    const lim = (v) => (Math.abs(v) >= 10 ? v.toFixed(1) : `${+v.toPrecision(3)}`);
    const what = d.mechanism === "planetary" && !d.optimize ? "box" : "search box";
    for (const p of params) {
      const row = document.createElement("div"); row.className = "param";
      row.innerHTML = `<span>${p.label}</span>`;
      row.appendChild(inputFor(p.field, p.unit, `${lim(p.min)}–${lim(p.max)} ${p.unit}`));
      row.insertAdjacentHTML("beforeend", `<span>${p.unit}</span><span class="lim">${what} ${lim(p.min)} … ${lim(p.max)}</span>`);
      box.appendChild(row);
    }
    const other = state.fieldErrors.filter((e) => !params.some((p) => e.field === p.field));
    for (const e of other) { const s = document.createElement("div"); s.className = "field-error"; s.dataset.errorFor = e.field; s.textContent = `${e.field}: ${e.message}`; box.appendChild(s); }
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
function drawRadiiEditor(c) {
  const ctx = c.getContext("2d"); ctx.clearRect(0, 0, c.width, c.height);
  const L = radiiLayout(c), d = state.design.train, res = state.result;
  ctx.font = "11px system-ui";
  for (const g of ["gear2", "gear3"]) {
    const [cx, cy] = L.centres[g];
    const tp = res && res.train_points && res.train_points[g];
    ctx.strokeStyle = g === "gear2" ? "#b45309" : "#0f766e"; ctx.lineWidth = 1.5;
    if (tp && tp.curve) { ctx.beginPath(); tp.curve.forEach((r, i) => { const a = tp.theta_deg[i] * Math.PI / 180; const x = cx + L.s * r * Math.cos(a), y = cy - L.s * r * Math.sin(a); if (i) ctx.lineTo(x, y); else ctx.moveTo(x, y); }); ctx.closePath(); ctx.stroke(); }
    const angs = angleList(d[g]);
    d[g].radii_mm.forEach((r, i) => {
      const a = angs[i] * Math.PI / 180, x = cx + L.s * r * Math.cos(a), y = cy - L.s * r * Math.sin(a);
      ctx.strokeStyle = "#ccc"; ctx.beginPath(); ctx.moveTo(cx, cy); ctx.lineTo(x, y); ctx.stroke();
      ctx.fillStyle = fieldError(`train.${g}.radii_mm.${i}`) ? "#dc2626" : "#fff"; ctx.strokeStyle = "#111";
      ctx.beginPath(); ctx.arc(x, y, 5, 0, 2 * Math.PI); ctx.fill(); ctx.stroke();
    });
    ctx.fillStyle = "#111"; ctx.fillText(`${g === "gear2" ? "gear 2" : "gear 3"} pitch curve (body frame), radii in mm`, cx - 110, 12);
  }
}
function setupRadiiDrag(c) {
  let drag = null;
  c.addEventListener("pointerdown", (ev) => {
    const [px, py] = canvasPoint(ev, c), L = radiiLayout(c), d = state.design.train;
    for (const g of ["gear2", "gear3"]) {
      const [cx, cy] = L.centres[g], angs = angleList(d[g]);
      d[g].radii_mm.forEach((r, i) => { const a = angs[i] * Math.PI / 180; if ((cx + L.s * r * Math.cos(a) - px) ** 2 + (cy - L.s * r * Math.sin(a) - py) ** 2 < 64) drag = { g, i, a, before: clone(state.design), L }; });
    }
    if (drag) c.setPointerCapture(ev.pointerId);
  });
  c.addEventListener("pointermove", (ev) => {
    if (!drag) return;
    const t0 = performance.now();
    const [px, py] = canvasPoint(ev, c), [cx, cy] = drag.L.centres[drag.g];
    const r = ((px - cx) * Math.cos(drag.a) - (py - cy) * Math.sin(drag.a)) / drag.L.s;
    state.design.train[drag.g].radii_mm[drag.i] = Math.round(r * 100) / 100;
    drawRadiiEditor(c);
    evaluate("drag", t0);
  });
  const end = () => { if (drag) { pushUndo(drag.before); drag = null; evaluate("full"); } };
  c.addEventListener("pointerup", end); c.addEventListener("pointercancel", end);
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
  if (!state.drag && !document.activeElement.closest?.("#edit")) renderEdit();
  else if (state.design && state.design.train) { const c = $("radii"); if (c) drawRadiiEditor(c); }
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
  const running = !$("opt-cancel").disabled;
  if (!running) $("opt-start").disabled = !free;
  if (!free && !running) $("opt-status").textContent = "this file frees no field: add [optimize.variables] (dotted paths with bounds) to optimize it";
  else if (free && !running && $("opt-status").textContent.startsWith("this file frees no field")) $("opt-status").textContent = "";
}

function intField(id) { const t = $(id).value.trim(); const v = Number(t); return t === "" ? null : (Number.isInteger(v) ? v : t); }

async function startOptimize() {
  const body = { design: state.design, problem: $("opt-problem").value, generations: intField("opt-gen"), pop: intField("opt-pop"), seed: intField("opt-seed") };
  for (const id of ["opt-gen", "opt-pop", "opt-seed"]) $(id).classList.remove("invalid");
  try {
    const r = await api("/api/optimize", body);
    state.optTask = r.task; state.optResult = null; state.optSelected = null;
    $("opt-cancel").disabled = false; $("opt-start").disabled = true;
    pollOptimize();
  } catch (e) {
    $("opt-status").innerHTML = `<span class="field-error">${e.message}</span>`;
    for (const f of (e.data && e.data.fields) || []) { const el = document.querySelector(`#bottom [data-field="${f.field}"]`); if (el) el.classList.add("invalid"); }
  }
}

async function pollOptimize() {
  if (!state.optTask) return;
  const st = await api(`/api/tasks/${state.optTask}`);
  const pr = st.progress;
  const hist = st.history || [];
  if (st.state === "running") {
    $("opt-status").textContent = pr ? `running ${st.elapsed_s.toFixed(0)} s — ${pr.stage}: generation ${pr.generation}/${pr.generations}, best violation ${pr.best_violation.toPrecision(4)}, designs meeting all: ${pr.feasible_in_population}`
      : `starting (${st.elapsed_s.toFixed(0)} s)…`;
    drawHistory(hist.map((h, i) => i + 1), hist.map((h) => h.best_violation), "generation (all stages)");
    setTimeout(pollOptimize, 500);
    return;
  }
  $("opt-cancel").disabled = true; $("opt-start").disabled = false;
  if (st.state === "failed") { $("opt-status").innerHTML = `<span class="field-error">optimization failed: ${st.error}</span>`; return; }
  const r = st.result; state.optResult = r;
  $("opt-status").innerHTML = `${r.feasible ? '<span class="ok">every objective met</span>' : '<span class="fail">not every objective met</span> (closest design kept)'} — ${r.evaluations} evaluations, ${r.wall_s.toFixed(1)} s. ${r.note || ""}
    <a href="/api/tasks/${state.optTask}/files/best.toml" download>best.toml</a> <a href="/api/tasks/${state.optTask}/files/pareto.csv" download>pareto.csv</a> <a href="/api/tasks/${state.optTask}/files/run.json" download>run.json</a>`;
  const h = r.history || {};
  drawHistory(h.generation || [], h.best_violation || [], "generation (last stage of the run)");
  drawPareto();
}

function drawHistory(x, y, xlabel) {
  linePlot($("opt-history"), { title: "convergence", xlabel, ylabel: "best total violation", logy: true,
    series: [{ x, y: y.map((v) => Math.max(v, 1e-6)), color: "#111" }], empty: "no run yet" });
}

function drawPareto() {
  const r = state.optResult; if (!r) return;
  const names = r.objectives.length ? r.objectives : Object.keys(r.pareto).slice(-2);
  const [a, b] = [names[0], names[1] || names[0]];
  scatterPlot($("opt-pareto"), { title: r.pareto_designs ? "Pareto front (click a point to load it)" : "best design (click to load)", x: r.pareto[a] || [], y: r.pareto[b] || [],
    xlabel: a.replaceAll("_", " "), ylabel: b.replaceAll("_", " "), selected: state.optSelected });
}

function pickPareto(ev) {
  const r = state.optResult; if (!r) return;
  const i = pickPoint($("opt-pareto"), ev);
  if (i === null) return;
  state.optSelected = i;
  const d = r.pareto_designs ? r.pareto_designs[i] : r.best_design;
  loadDesign(d, `${state.name} (optimized, point ${i + 1})`, true);
  drawPareto();
}

// ---------------------------------------------------------------- make (teeth)
function numField(id) { const t = $(id).value.trim(); const v = Number(t); return t === "" ? null : (Number.isFinite(v) ? v : t); }

async function startGears() {
  const body = { design: state.design, module: numField("g-module"), face_width: numField("g-face"), backlash: numField("g-backlash") };
  for (const id of ["g-module", "g-face", "g-backlash"]) $(id).classList.remove("invalid");
  $("g-files").innerHTML = ""; $("g-images").innerHTML = "";
  try {
    const r = await api("/api/gears", body);
    state.gearTask = r.task; state.gearKey = JSON.stringify(body.design); $("g-start").disabled = true;
    pollGears();
  } catch (e) {
    $("g-status").innerHTML = `<span class="field-error">${e.message}</span>`;
    for (const f of (e.data && e.data.fields) || []) { const el = document.querySelector(`#bottom [data-field="${f.field}"]`); if (el) el.classList.add("invalid"); }
  }
}

async function pollGears() {
  const st = await api(`/api/tasks/${state.gearTask}`);
  if (st.state === "running") { $("g-status").textContent = `cutting teeth… ${st.elapsed_s.toFixed(0)} s`; setTimeout(pollGears, 700); return; }
  $("g-start").disabled = false;
  if (st.state === "failed") { $("g-status").innerHTML = `<span class="field-error">${st.error}</span>`; return; }
  const rec = st.result.record;
  if (st.result.teeth) {
    const m = rec.gears.length ? rec.gears[0].module_mm.toFixed(3) + " mm" : "?";
    state.teeth = { key: state.gearKey, gears: st.result.teeth, module: m };
    teethNote(); drawMechanism();
  }
  let html = `<table><tr><th>gear</th><th>teeth</th><th>module / mm</th><th>max pressure angle / deg</th><th>undercut</th><th>pointed</th><th>cutter fits</th></tr>`;
  for (const g of rec.gears) html += `<tr><td>${g.name}</td><td class="num">${g.teeth}</td><td class="num">${g.module_mm.toFixed(4)}</td><td class="num">${g.max_pressure_angle_deg.toFixed(1)}</td><td class="${g.undercut ? "fail" : "ok"}">${g.undercut ? "yes" : "no"}</td><td class="${g.pointed ? "fail" : "ok"}">${g.pointed ? "yes" : "no"}</td><td class="${g.cutter_fits ? "ok" : "fail"}">${g.cutter_fits ? "yes" : "no"}</td></tr>`;
  html += `</table><table><tr><th>pair in mesh</th><th>interference / mm</th><th>max backlash / mm</th><th></th></tr>`;
  for (const m of rec.mesh) html += `<tr><td>${m.pair}</td><td class="num">${m.max_interference_mm.toFixed(4)}</td><td class="num">${m.max_backlash_mm === null ? "n/a" : m.max_backlash_mm.toFixed(4)}</td><td class="${m.ok ? "ok" : "fail"}">${m.ok ? "meshes" : "FAIL"}</td></tr>`;
  html += "</table>" + (rec.step ? `<p class="hint">STEP not written: ${rec.step}</p>` : "");
  $("g-status").innerHTML = html;
  $("g-files").innerHTML = "Download: " + st.result.files.filter((f) => !f.endsWith(".png")).map((f) => `<a href="/api/tasks/${state.gearTask}/files/${f}" download>${f}</a>`).join(" ");
  $("g-images").innerHTML = st.result.files.filter((f) => f.endsWith(".png")).map((f) => `<img alt="${f}" src="/api/tasks/${state.gearTask}/files/${f}">`).join("");
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
    if ((e.ctrlKey || e.metaKey) && e.key === "z") { e.preventDefault(); undo(); }
    if ((e.ctrlKey || e.metaKey) && e.key === "y") { e.preventDefault(); redo(); }
  });
  $("play").addEventListener("click", () => { state.playing = !state.playing; $("play").textContent = state.playing ? "Pause" : "Play"; });
  $("scrub").addEventListener("input", (e) => { state.frame = +e.target.value; state.phase = state.frame; drawMechanism(); renderPlots(); });
  $("speed").addEventListener("change", (e) => { state.speed = +e.target.value; });
  $("show-gears").addEventListener("change", drawMechanism);
  $("opt-start").addEventListener("click", startOptimize);
  $("opt-cancel").addEventListener("click", async () => { if (state.optTask) await api(`/api/tasks/${state.optTask}/cancel`, {}); });
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
