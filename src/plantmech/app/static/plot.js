// Small canvas plots: lines over x with labelled axes (units), shaded spans, a legend,
// and a scatter with click picking. Draws arrays the server returned; computes nothing.

function niceTicks(lo, hi, n = 5) {
  if (!(hi > lo)) { hi = lo + 1; }
  const raw = (hi - lo) / n;
  const mag = Math.pow(10, Math.floor(Math.log10(raw)));
  const step = [1, 2, 2.5, 5, 10].map((m) => m * mag).find((s) => s >= raw) || raw;
  const out = [];
  for (let k = Math.ceil(lo / step); k * step <= hi + 1e-9 * step; k++) out.push(+(k * step).toFixed(10));
  return out;
}

function fmt(v) {
  const a = Math.abs(v);
  if (a === 0) return "0";
  if (a >= 1000 || a < 0.01) return v.toExponential(1);
  return +v.toPrecision(3) + "";
}

export function linePlot(canvas, opt) {
  const ctx = canvas.getContext("2d");
  const W = canvas.width, H = canvas.height;
  const m = { l: 66, r: 10, t: 18, b: 34 };
  ctx.clearRect(0, 0, W, H);
  ctx.font = "11px system-ui, sans-serif";
  const series = (opt.series || []).filter((s) => s && s.y && s.y.length);
  canvas.seriesY = series.map((s) => s.y); // what was drawn (the tests read it)
  if (!series.length) {
    ctx.fillStyle = "#888";
    ctx.fillText(opt.empty || "no data", m.l, H / 2);
    return;
  }
  let ylo = Infinity, yhi = -Infinity;
  for (const s of series) for (const v of s.y) if (Number.isFinite(v)) { ylo = Math.min(ylo, v); yhi = Math.max(yhi, v); }
  for (const h of opt.hlines || []) { ylo = Math.min(ylo, h.y); yhi = Math.max(yhi, h.y); }
  if (opt.ylim) { [ylo, yhi] = opt.ylim; }
  const pad = (yhi - ylo) * 0.06 || 1; ylo -= pad; yhi += pad;
  const xlo = opt.xmin ?? Math.min(...series[0].x), xhi = opt.xmax ?? Math.max(...series[0].x);
  const X = (x) => m.l + (x - xlo) / (xhi - xlo) * (W - m.l - m.r);
  const logy = !!opt.logy;
  const ty = (v) => (logy ? Math.log10(Math.max(v, 1e-9)) : v);
  const [tlo, thi] = logy ? [ty(Math.max(ylo, 1e-9)), ty(yhi)] : [ylo, yhi];
  const Y = (y) => H - m.b - (ty(y) - tlo) / ((thi - tlo) || 1) * (H - m.t - m.b);
  const labels = [];
  for (const sp of opt.spans || []) {
    ctx.fillStyle = sp.color;
    const a = X(Math.max(sp.from, xlo)), b = X(Math.min(sp.to, xhi));
    ctx.fillRect(a, m.t, b - a, H - m.t - m.b);
    if (sp.label) {
      const w = ctx.measureText(sp.label).width;  // inside the frame, even for a span at its right edge
      labels.push({ text: sp.label, x: Math.max(m.l + 2, Math.min(a + 2, W - m.r - w - 2)), w });
    }
  }
  // span labels in rows: a label that would overlap one already placed goes a row lower
  const rowEnds = [];
  for (const lb of labels.sort((p, q) => p.x - q.x)) {
    let row = rowEnds.findIndex((end) => lb.x >= end + 4);
    if (row < 0) { row = rowEnds.length; rowEnds.push(0); }
    rowEnds[row] = lb.x + lb.w;
    lb.y = m.t + 11 + 12 * row;
    ctx.fillStyle = "rgba(255,255,255,0.75)"; ctx.fillRect(lb.x - 1, lb.y - 9, lb.w + 2, 11);
    ctx.fillStyle = "#444"; ctx.fillText(lb.text, lb.x, lb.y);
  }
  canvas.spanLabels = labels.map((lb) => ({ text: lb.text, x: lb.x, y: lb.y, w: lb.w, h: 11 }));
  ctx.strokeStyle = "#ddd"; ctx.fillStyle = "#333"; ctx.lineWidth = 1;
  for (const t of niceTicks(xlo, xhi, 8)) {
    ctx.beginPath(); ctx.moveTo(X(t), m.t); ctx.lineTo(X(t), H - m.b); ctx.stroke();
    ctx.fillText(fmt(t), X(t) - 8, H - m.b + 12);
  }
  let yt = niceTicks(ylo, yhi, 4);
  if (logy) {  // decades inside the range, else plain ticks of the values
    const dec = [];
    for (let e = Math.ceil(tlo); e <= Math.floor(thi); e++) dec.push(Math.pow(10, e));
    yt = dec.length >= 2 ? dec : yt.filter((t) => t > 0);
  }
  for (const t of yt) {
    ctx.beginPath(); ctx.moveTo(m.l, Y(t)); ctx.lineTo(W - m.r, Y(t)); ctx.stroke();
    ctx.textAlign = "right"; ctx.fillText(fmt(t), m.l - 4, Y(t) + 4); ctx.textAlign = "left";
  }
  ctx.strokeStyle = "#333"; ctx.strokeRect(m.l, m.t, W - m.l - m.r, H - m.t - m.b);
  ctx.fillText(opt.xlabel || "", W / 2 - 60, H - 4);
  ctx.save(); ctx.translate(12, (H - m.b + m.t) / 2); ctx.rotate(-Math.PI / 2);
  ctx.textAlign = "center"; ctx.fillText(opt.ylabel || "", 0, 0); ctx.restore();
  if (opt.title) { ctx.fillText(opt.title, m.l, 12); }
  ctx.save();
  ctx.beginPath(); ctx.rect(m.l, m.t, W - m.l - m.r, H - m.t - m.b); ctx.clip();
  for (const h of opt.hlines || []) {
    ctx.strokeStyle = h.color || "#b91c1c"; ctx.setLineDash([5, 4]);
    ctx.beginPath(); ctx.moveTo(m.l, Y(h.y)); ctx.lineTo(W - m.r, Y(h.y)); ctx.stroke();
    ctx.setLineDash([]);
    if (h.label) { ctx.fillStyle = h.color || "#b91c1c"; ctx.fillText(h.label, W - m.r - 130, Y(h.y) - 3); }
  }
  for (const s of series) {
    ctx.strokeStyle = s.color || "#111"; ctx.lineWidth = s.width || 1.4;
    ctx.beginPath();
    let pen = false, prev = null;
    for (let i = 0; i < s.y.length; i++) {
      const v = s.y[i];
      if (!Number.isFinite(v)) { pen = false; continue; }
      const px = X(s.x[i]), py = Y(v);
      // a jump of the x wrap (360 -> 0) lifts the pen
      if (pen && prev !== null && s.x[i] < prev) pen = false;
      if (pen) ctx.lineTo(px, py); else ctx.moveTo(px, py);
      pen = true; prev = s.x[i];
    }
    ctx.stroke();
  }
  if (opt.marker !== undefined) {
    ctx.strokeStyle = "#7c3aed"; ctx.beginPath();
    ctx.moveTo(X(opt.marker), m.t); ctx.lineTo(X(opt.marker), H - m.b); ctx.stroke();
  }
  ctx.restore();
  // the legend: in the top margin right of the title where it fits, else inside the frame
  // below the span labels' rows (never over them)
  const named = series.filter((s) => s.label);
  const legendW = named.reduce((w, s) => w + 22 + ctx.measureText(s.label).width, 0);
  const titleEnd = m.l + (opt.title ? ctx.measureText(opt.title).width : 0) + 16;
  const inMargin = titleEnd + legendW <= W - m.r;
  let lx = inMargin ? W - m.r - legendW + 6 : m.l + 6;
  const ly = inMargin ? 12 : m.t + 21 + 12 * rowEnds.length;
  canvas.legendBox = named.length ? { x: lx, y: ly - 9, w: legendW - 6, h: 11 } : null;
  for (const s of named) {
    ctx.fillStyle = s.color || "#111"; ctx.fillRect(lx, ly - 5, 12, 3);
    ctx.fillStyle = "#222"; ctx.fillText(s.label, lx + 15, ly);
    lx += 22 + ctx.measureText(s.label).width;
  }
}

export function scatterPlot(canvas, opt) {
  const ctx = canvas.getContext("2d");
  const W = canvas.width, H = canvas.height;
  const m = { l: 66, r: 10, t: 18, b: 34 };
  ctx.clearRect(0, 0, W, H);
  ctx.font = "11px system-ui, sans-serif";
  const xs = opt.x || [], ys = opt.y || [];
  canvas._pts = [];
  if (!xs.length) { ctx.fillStyle = "#888"; ctx.fillText(opt.empty || "no data", m.l, H / 2); return; }
  let [xlo, xhi] = [Math.min(...xs), Math.max(...xs)], [ylo, yhi] = [Math.min(...ys), Math.max(...ys)];
  const px = (xhi - xlo) * 0.08 || Math.abs(xlo) * 0.1 || 1, py = (yhi - ylo) * 0.08 || Math.abs(ylo) * 0.1 || 1;
  xlo -= px; xhi += px; ylo -= py; yhi += py;
  const X = (x) => m.l + (x - xlo) / (xhi - xlo) * (W - m.l - m.r);
  const Y = (y) => H - m.b - (y - ylo) / (yhi - ylo) * (H - m.t - m.b);
  ctx.strokeStyle = "#ddd"; ctx.fillStyle = "#333";
  for (const t of niceTicks(xlo, xhi, 5)) { ctx.beginPath(); ctx.moveTo(X(t), m.t); ctx.lineTo(X(t), H - m.b); ctx.stroke(); ctx.fillText(fmt(t), X(t) - 8, H - m.b + 12); }
  for (const t of niceTicks(ylo, yhi, 4)) { ctx.beginPath(); ctx.moveTo(m.l, Y(t)); ctx.lineTo(W - m.r, Y(t)); ctx.stroke(); ctx.textAlign = "right"; ctx.fillText(fmt(t), m.l - 4, Y(t) + 4); ctx.textAlign = "left"; }
  ctx.strokeStyle = "#333"; ctx.strokeRect(m.l, m.t, W - m.l - m.r, H - m.t - m.b);
  ctx.fillText(opt.xlabel || "", W / 2 - 60, H - 4);
  ctx.save(); ctx.translate(12, (H - m.b + m.t) / 2); ctx.rotate(-Math.PI / 2); ctx.textAlign = "center"; ctx.fillText(opt.ylabel || "", 0, 0); ctx.restore();
  if (opt.title) ctx.fillText(opt.title, m.l, 12);
  for (let i = 0; i < xs.length; i++) {
    const cx = X(xs[i]), cy = Y(ys[i]);
    ctx.fillStyle = i === opt.selected ? "#dc2626" : (opt.colors ? opt.colors[i] : "#2563eb");
    ctx.beginPath(); ctx.arc(cx, cy, i === opt.selected ? 6 : 4, 0, 2 * Math.PI); ctx.fill();
    canvas._pts.push([cx, cy, i]);
  }
}

export function pickPoint(canvas, ev) {
  const r = canvas.getBoundingClientRect();
  const x = (ev.clientX - r.left) * canvas.width / r.width, y = (ev.clientY - r.top) * canvas.height / r.height;
  let best = null, bd = 12 * 12;
  for (const [cx, cy, i] of canvas._pts || []) {
    const d = (cx - x) ** 2 + (cy - y) ** 2;
    if (d < bd) { bd = d; best = i; }
  }
  return best;
}
