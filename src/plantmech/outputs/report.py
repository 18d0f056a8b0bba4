"""A self-contained HTML report of one job, and an animated GIF of the mechanism.

:func:`write_report` takes the job's summary dict (as written to ``summary.json`` /
``run.json`` / ``verification.json``), its figures (matplotlib Figures or image files) and
an :class:`Animation` of the mechanism over one cycle, and writes one HTML file that needs
no network: plots are embedded as base64 PNG, gear drawings as base64 SVG, and the
mechanism is an inline SVG moved by a small inline script (play / pause, frame slider).
:func:`write_gif` writes the same animation as an animated GIF for slides (matplotlib's
``PillowWriter``). Nothing here computes physics: the animations are built from a job's
simulated positions (mm).
"""

from __future__ import annotations

import base64
import datetime as _dt
import html
import io
import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

FRAMES = 72  # one frame per 5 deg of carrier angle (the GIF keeps every other one)


@dataclass
class Animation:
    """A mechanism over one cycle, in the machine frame (mm, y up).

    ``links``: moving polylines, each ``{"label", "color", "width", "points": (F, n, 2)}``;
    ``joints``: moving dots, each ``{"label", "color", "points": (F, 2)}``;
    ``traces``: fixed polylines (paths, box, ground), ``{"label", "color", "width",
    "dash", "points": (n, 2)}``; ``frame_labels``: one text per frame (e.g. the carrier
    angle)."""

    title: str
    links: list[dict]
    joints: list[dict] = field(default_factory=list)
    traces: list[dict] = field(default_factory=list)
    frame_labels: list[str] = field(default_factory=list)
    fps: float = 18.0
    origin: str = "carrier axis O"  # the dot at (0, 0)

    @property
    def frames(self) -> int:
        return int(np.asarray(self.links[0]["points"]).shape[0])

    def bounds(self, margin: float = 0.06) -> tuple[float, float, float, float]:
        """(xmin, xmax, ymin, ymax) of everything drawn, with a relative margin (mm)."""
        pts = [np.asarray(x["points"], float).reshape(-1, 2)
               for x in self.links + self.joints + self.traces]
        allp = np.concatenate(pts)
        allp = allp[np.isfinite(allp).all(axis=1)]
        lo, hi = allp.min(axis=0), allp.max(axis=0)
        pad = margin * float(max(hi - lo))
        return lo[0] - pad, hi[0] + pad, lo[1] - pad, hi[1] + pad


def _hex(colour) -> str:
    """A matplotlib colour ('tab:blue', '0.6', '#123456') as #rrggbb for SVG."""
    from matplotlib.colors import to_hex

    return to_hex(colour)


def _frame_index(n_samples: int, frames: int) -> np.ndarray:
    return np.round(np.linspace(0, n_samples, frames, endpoint=False)).astype(int) % n_samples


def seeder_animation(carrier_angle: np.ndarray, carrier_abs: np.ndarray, tip: np.ndarray,
                     L1: float, planned: np.ndarray | None = None,
                     title: str = "Seeder over one carrier turn",
                     frames: int = FRAMES) -> Animation:
    """Carrier O->B (length L1, mm) and arm B->A (the cane tip A) of the sugarcane seeder.

    ``carrier_angle``: (S,) rad, clockwise from the start; ``carrier_abs``: (S,) rad,
    absolute direction of O->B; ``tip``: (S, 2) mm; ``planned``: the planned trajectory
    (n, 2) mm, drawn fixed."""
    k = _frame_index(len(carrier_angle), frames)
    b = L1 * np.c_[np.cos(carrier_abs[k]), np.sin(carrier_abs[k])]
    o = np.zeros_like(b)
    tip = np.asarray(tip, float)
    links = [{"label": "carrier OB (L1)", "color": "#444444", "width": 6,
              "points": np.stack([o, b], axis=1)},
             {"label": "arm BA (L2)", "color": "#1f77b4", "width": 4,
              "points": np.stack([b, tip[k]], axis=1)}]
    traces = []
    if planned is not None:
        traces.append({"label": "planned trajectory", "color": "#cccccc", "width": 6,
                       "dash": "", "points": np.asarray(planned, float)})
    traces.append({"label": "tip path (gear train)", "color": "#d62728", "width": 1.5,
                   "dash": "", "points": tip})
    joints = [{"label": "planet axis B", "color": "#444444", "points": b},
              {"label": "cane tip A", "color": "#d62728", "points": tip[k]}]
    labels = [f"carrier angle {np.degrees(carrier_angle[i]):5.1f} deg" for i in k]
    return Animation(title, links, joints, traces, labels)


def seeder_forward_animation(job, frames: int = FRAMES) -> Animation:
    """:func:`seeder_animation` of a :class:`plantmech.workflows.SeederForwardJob`."""
    res, tr = job.result, job.train
    planned = None
    if job.trajectory is not None:
        planned = job.trajectory(np.linspace(0, job.trajectory.period, 1500))
    return seeder_animation(res.carrier_angle, tr.carrier0 - res.carrier_angle, res.tip,
                            tr.L1, planned, f"{job.design.name}: one carrier turn", frames)


def seeder_inverse_animation(job, frames: int = FRAMES) -> Animation:
    """:func:`seeder_animation` of a feasible :class:`plantmech.workflows.SeederInverseJob`
    (the gear train's tip, or the planned one where the train is not built)."""
    res = job.result
    tip = res.tip_realized if res.tip_realized is not None else res.tip
    planned = job.trajectory(np.linspace(0, job.trajectory.period, 1500))
    return seeder_animation(res.carrier_angle, res.carrier_abs, tip, res.L1, planned,
                            f"{job.design.name}: one carrier turn", frames)


def transplanter_animation(job, frames: int = FRAMES) -> Animation:
    """Every arm of a transplanter (carrier line O->planet axis, arm to the break point A,
    needle A->B) with the tips' relative paths, the seedling box floor and the ground."""
    from plantmech.outputs.transplanter_plots import COLOURS

    m = job.motion
    k = _frame_index(m.B.shape[-1], frames)

    def xy(z):
        return np.stack([np.real(z), np.imag(z)], axis=-1)

    links, joints, traces = [], [], []
    for j in range(m.B.shape[1]):
        c = COLOURS[j % len(COLOURS)]
        pts = np.stack([np.zeros(len(k), complex), m.centre[0, j, k], m.A[0, j, k],
                        m.B[0, j, k]], axis=1)
        links.append({"label": f"arm {j + 1}", "color": c, "width": 4, "points": xy(pts)})
        joints.append({"label": f"needle tip {j + 1}", "color": c, "points": xy(m.B[0, j, k])})
        traces.append({"label": f"tip path {j + 1}", "color": c, "width": 1,
                       "dash": "4 3" if j else "", "points": xy(m.B[0, j])})
    b = job.design.seedling_box
    u = np.exp(1j * np.radians(b.inclination_deg))
    o = complex(b.x_mm, b.y_mm)
    traces.append({"label": "seedling box floor", "color": "#000000", "width": 3, "dash": "",
                   "points": xy(np.array([o, o + b.length_mm * u]))})
    g = float(job.evaluation.metrics["ground_y_mm"][0])
    x0, x1 = float(np.real(m.B[0]).min()) - 40, float(np.real(m.B[0]).max()) + 40
    traces.append({"label": "ground", "color": "#8b4513", "width": 2, "dash": "",
                   "points": np.array([[x0, g], [x1, g]])})
    labels = [f"carrier angle {np.degrees(m.carrier_angle[i]):5.1f} deg" for i in k]
    return Animation(f"{job.design.name}: one carrier turn", links, joints, traces, labels)


def planetary_animation(design, motion, frames: int = FRAMES) -> Animation:
    """A general planetary train (``trains.model.TrainMotion``, P = 1) over one carrier
    turn: every gear's pitch curve at its centre and angle (``trains.placement``: the sun
    once, followers, idlers, compound and derived drivers of every arm), the carrier's
    line of shafts and the arm of every arm, the tips' paths. With the carrier held (a pair
    on fixed centres) nothing turns there: the turn is the driver's (the sun's), the line
    of shafts the frame's."""
    from plantmech.outputs.transplanter_plots import COLOURS
    from plantmech.trains.curves import TWO_PI
    from plantmech.trains.placement import place_gears

    built = motion.built
    k = _frame_index(motion.tip.shape[-1], frames)
    th = TWO_PI * np.arange(181) / 180

    def xy(z):
        return np.stack([np.real(z), np.imag(z)], axis=-1)

    links, joints, traces = [], [], []
    shafts = built.shafts[0]
    placed = place_gears(motion, k)
    held = bool(built.train.carrier_held)
    turning, line = ("driver", "frame (fixed centres)") if held else ("carrier", "carrier")
    for j in range(motion.tip.shape[1]):
        c = COLOURS[j % len(COLOURS)]
        turn = np.exp(1j * motion.carrier[0, j, k])
        for gear in (g for g in placed if g.arm == j):
            links.append({"label": "", "color": "#6b7280", "width": 1,
                          "points": xy(gear.outline(th)[0])})  # a pitch curve: no legend
        chain = np.c_[shafts[None, :] * turn[:, None], motion.tip[0, j, k]]
        links.append({"label": f"{line} and arm {j + 1}", "color": c, "width": 3,
                      "points": xy(chain)})
        joints.append({"label": f"tip {j + 1}", "color": c, "points": xy(motion.tip[0, j, k])})
        traces.append({"label": f"tip path {j + 1}", "color": c, "width": 1,
                       "dash": "4 3" if j else "", "points": xy(motion.tip[0, j])})
    labels = [f"{turning} angle {np.degrees(motion.carrier_angle[i]):5.1f} deg" for i in k]
    return Animation(f"{design.name}: one {turning} turn", links, joints, traces, labels,
                     origin="driver axis O (fixed)" if held else "carrier axis O")


# --- GIF ------------------------------------------------------------------------------


def write_gif(animation: Animation, path: str | Path, size_in: float = 5.5,
              dpi: int = 80, max_frames: int = 36) -> Path:
    """The animation as an animated GIF (matplotlib Agg frames written by Pillow), at most
    ``max_frames`` frames (every k-th frame, same cycle time); returns the path."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure
    from PIL import Image

    x0, x1, y0, y1 = animation.bounds()
    aspect = (y1 - y0) / max(x1 - x0, 1e-9)
    fig = Figure(figsize=(size_in, max(2.5, min(size_in * aspect, 2 * size_in)) + 0.6))
    FigureCanvasAgg(fig)
    ax = fig.subplots()
    for t in animation.traces:
        p = np.asarray(t["points"], float)
        ax.plot(p[:, 0], p[:, 1], color=t["color"], lw=t["width"] * 0.6,
                ls="--" if t.get("dash") else "-")
    lines = [ax.plot([], [], "-", color=lk["color"], lw=lk["width"] * 0.6,
                     solid_capstyle="round")[0] for lk in animation.links]
    dots = [ax.plot([], [], "o", color=jt["color"], ms=4)[0] for jt in animation.joints]
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_aspect("equal")
    ax.set_xlabel("x / mm")
    ax.set_ylabel("y / mm")
    ax.grid(alpha=0.3)
    title = ax.set_title(animation.title, fontsize=9)
    title.set_text(f"{animation.title}\n{(animation.frame_labels or [''])[0]}")
    fig.tight_layout()

    # blitting: the axes, ticks and fixed paths are drawn once; each frame redraws only
    # the moving links over that background (drawing the text again per frame cost ~0.3 s)
    canvas = fig.canvas
    for art in lines + dots + [title]:
        art.set_animated(True)
    canvas.draw()
    background = canvas.copy_from_bbox(fig.bbox)
    step = max(1, animation.frames // max_frames)
    images = []
    for f in range(0, animation.frames, step):
        for ln, lk in zip(lines, animation.links, strict=True):
            p = np.asarray(lk["points"][f], float)
            ln.set_data(p[:, 0], p[:, 1])
        for d, jt in zip(dots, animation.joints, strict=True):
            p = np.asarray(jt["points"][f], float)
            d.set_data([p[0]], [p[1]])
        if animation.frame_labels:
            title.set_text(f"{animation.title}\n{animation.frame_labels[f]}")
        canvas.restore_region(background)
        for art in lines + dots + [title]:
            fig.draw_artist(art)
        rgba = np.asarray(canvas.buffer_rgba())
        images.append(Image.fromarray(rgba[..., :3].copy()).quantize(colors=64))
    path = Path(path)
    images[0].save(path, save_all=True, append_images=images[1:], loop=0,
                   duration=int(round(1000 * step / animation.fps)), optimize=False)
    return path


# --- HTML -----------------------------------------------------------------------------


def _points_attr(p: np.ndarray) -> str:
    """SVG ``points`` of a polyline in the machine frame (y flipped to SVG's y down)."""
    p = np.asarray(p, float)
    p = p[np.isfinite(p).all(axis=1)]
    return " ".join(f"{x:.2f},{-y:.2f}" for x, y in p)


def _svg_animation(a: Animation) -> str:
    x0, x1, y0, y1 = a.bounds()
    w, h = x1 - x0, y1 - y0
    unit = max(w, h) / 400.0  # stroke widths in pixels of a 400-px drawing
    out = [f'<svg id="mechanism" xmlns="http://www.w3.org/2000/svg" '
           f'viewBox="{x0:.2f} {-y1:.2f} {w:.2f} {h:.2f}" data-frame="0" '
           f'data-frames="{a.frames}" role="img" aria-label="{html.escape(a.title)}">']
    out.append('<g stroke-linecap="round" stroke-linejoin="round" fill="none">')
    for t in a.traces:
        dash = (f' stroke-dasharray="{" ".join(str(float(v) * unit) for v in t["dash"].split())}"'
                if t.get("dash") else "")
        out.append(f'<polyline points="{_points_attr(t["points"])}" stroke="{_hex(t["color"])}" '
                   f'stroke-width="{t["width"] * unit:.3f}"{dash}>'
                   f'<title>{html.escape(t["label"])}</title></polyline>')
    for i, lk in enumerate(a.links):
        out.append(f'<polyline id="link-{i}" class="link" '
                   f'points="{_points_attr(lk["points"][0])}" stroke="{_hex(lk["color"])}" '
                   f'stroke-width="{lk["width"] * unit:.3f}" opacity="0.85">'
                   f'<title>{html.escape(lk["label"])}</title></polyline>')
    out.append("</g>")
    for i, jt in enumerate(a.joints):
        x, y = np.asarray(jt["points"][0], float)
        out.append(f'<circle id="joint-{i}" cx="{x:.2f}" cy="{-y:.2f}" r="{4 * unit:.3f}" '
                   f'fill="{_hex(jt["color"])}"><title>{html.escape(jt["label"])}</title></circle>')
    out.append(f'<circle cx="0" cy="0" r="{3 * unit:.3f}" fill="#000"><title>'
               f'{html.escape(a.origin)}</title></circle>')
    out.append("</svg>")
    return "\n".join(out)


def _animation_data(a: Animation) -> str:
    data = {"fps": a.fps, "n": a.frames, "labels": a.frame_labels,
            "links": [[_points_attr(p) for p in np.asarray(lk["points"], float)]
                      for lk in a.links],
            "joints": [[[round(float(x), 2), round(float(-y), 2)]
                        for x, y in np.asarray(jt["points"], float)] for jt in a.joints]}
    # JSON inside <script>: no "</" can end the element early
    return json.dumps(data, separators=(",", ":")).replace("</", "<\\/")


_SCRIPT = """
(function () {
  var data = JSON.parse(document.getElementById("animation-data").textContent);
  var svg = document.getElementById("mechanism");
  var label = document.getElementById("frame-label");
  var slider = document.getElementById("frame-slider");
  var button = document.getElementById("play");
  var links = data.links.map(function (_, i) { return document.getElementById("link-" + i); });
  var joints = data.joints.map(function (_, i) { return document.getElementById("joint-" + i); });
  var frame = 0, playing = true, last = null;
  function show(k) {
    frame = k;
    for (var i = 0; i < links.length; i++) links[i].setAttribute("points", data.links[i][k]);
    for (var j = 0; j < joints.length; j++) {
      joints[j].setAttribute("cx", data.joints[j][k][0]);
      joints[j].setAttribute("cy", data.joints[j][k][1]);
    }
    svg.setAttribute("data-frame", String(k));
    slider.value = String(k);
    label.textContent = data.labels[k] || ("frame " + k);
  }
  function tick(t) {
    if (playing && (last === null || t - last >= 1000 / data.fps)) {
      last = t;
      show((frame + 1) % data.n);
    }
    window.requestAnimationFrame(tick);
  }
  button.addEventListener("click", function () {
    playing = !playing;
    button.textContent = playing ? "Pause" : "Play";
  });
  slider.addEventListener("input", function () {
    playing = false;
    button.textContent = "Play";
    show(parseInt(slider.value, 10));
  });
  show(0);
  window.requestAnimationFrame(tick);
})();
"""

_STYLE = """
body { font: 15px/1.45 system-ui, sans-serif; margin: 0 auto; max-width: 1200px;
       padding: 1em 2em; color: #222; }
h1 { font-size: 1.5em; margin-bottom: 0.2em; } h2 { margin-top: 1.6em; }
.meta { color: #666; margin-top: 0; }
.verdict { font-size: 1.25em; font-weight: 600; padding: 0.6em 1em; border-radius: 6px; }
.verdict.ok { background: #e3f4e1; color: #1b5e20; border: 1px solid #66bb6a; }
.verdict.fail { background: #fdecea; color: #8e1c1c; border: 1px solid #e57373; }
.verdict.none { background: #f1f1f1; color: #333; border: 1px solid #9e9e9e; }
table { border-collapse: collapse; width: 100%; font-size: 0.92em; }
th, td { border-bottom: 1px solid #ddd; padding: 0.3em 0.5em; text-align: left;
         vertical-align: top; }
td.num { text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap; }
.ok { color: #1b5e20; font-weight: 600; } .fail { color: #b71c1c; font-weight: 700; }
.info { color: #555; }
figure { margin: 1em 0; } figure img { max-width: 100%; border: 1px solid #eee; }
figcaption { color: #555; font-size: 0.9em; }
#mechanism { width: 100%; max-height: 70vh; background: #fcfcfc; border: 1px solid #ddd; }
.controls { display: flex; gap: 1em; align-items: center; margin: 0.4em 0; }
.controls input { flex: 1; }
.legend span { margin-right: 1.2em; white-space: nowrap; }
.legend i { display: inline-block; width: 1.6em; height: 0.35em; vertical-align: middle;
            margin-right: 0.3em; }
.gears { display: flex; flex-wrap: wrap; gap: 1em; }
.gears figure { flex: 1 1 280px; } .gears img { width: 100%; background: #fff; }
pre { background: #f6f6f6; padding: 1em; overflow: auto; font-size: 0.8em; }
"""


def _figure_png(fig, dpi: int = 90) -> bytes:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=dpi)
    return buf.getvalue()


def _img_tag(item, alt: str) -> str:
    """<img> with the figure or image file embedded as a data URI."""
    if isinstance(item, str | Path):
        p = Path(item)
        mime = {".png": "image/png", ".svg": "image/svg+xml", ".gif": "image/gif",
                ".jpg": "image/jpeg", ".jpeg": "image/jpeg"}[p.suffix.lower()]
        from plantmech.inputs import read_input_bytes

        raw = read_input_bytes(p, "image file", 256_000_000)  # never a FIFO or a device
    else:
        mime, raw = "image/png", _figure_png(item)
    b64 = base64.b64encode(raw).decode("ascii")
    return f'<img alt="{html.escape(alt)}" src="data:{mime};base64,{b64}">'


def check_rows(summary: dict) -> list[dict]:
    """Every objective and check of a summary: the lists of dicts that carry a verdict
    (``ok``), in the summary's order, each with the list's key as ``group``."""
    rows = []

    def walk(obj, where):
        if isinstance(obj, dict):
            for k, v in obj.items():
                walk(v, f"{where}.{k}" if where else k)
        elif isinstance(obj, list) and obj and all(isinstance(c, dict) and "ok" in c
                                                   for c in obj):
            rows.extend(dict(c, group=where) for c in obj)

    walk(summary, "")
    return rows


def summary_verdict(summary: dict) -> tuple[bool | None, str]:
    """(everything met, one sentence) from a job summary: infeasible designs, objectives
    and checks that are required (``required`` not False) and not ok, meshes that fail;
    None when the summary holds no objective or check at all (a gear pair's forward run):
    nothing was checked, which is not "met"."""
    if summary.get("feasible") is False:
        return False, "INFEASIBLE: no gear train can produce this trajectory (see diagnostics)"
    rows = [r for r in check_rows(summary) if r.get("required", True) is not False]
    bad = [r.get("name") or r.get("pair") or "?" for r in rows if not r["ok"]]
    if summary.get("all_pairs_mesh") is False and not bad:
        bad = ["mesh"]
    if bad:
        shown = ", ".join(dict.fromkeys(str(b) for b in bad))
        return False, f"NOT MET: {len(bad)} of {len(rows)} checks fail ({shown})"
    if not rows:
        return None, ("nothing checked beyond the train closing and running: no objective "
                      "and no limit applies (the file gives no [limits] and its train no "
                      "objective set); see the figures")
    return True, f"every objective and check met ({len(rows)} of {len(rows)})"


def _value(v) -> str:
    if v is None:
        return "n/a"
    if isinstance(v, float):
        return f"{v:.4g}"
    return html.escape(str(v))


def _checks_table(summary: dict) -> str:
    rows = check_rows(summary)
    if not rows:
        return "<p>This job reports no objectives or checks.</p>"
    out = ['<table id="checks-table"><thead><tr><th>status</th><th>group</th><th>name</th>'
           '<th>value</th><th>limit</th><th>note</th></tr></thead><tbody>']
    for r in rows:
        if r.get("required", True) is False:
            status, cls = "info", "info"
        else:
            status, cls = ("ok", "ok") if r["ok"] else ("FAIL", "fail")
        name = r.get("name") or r.get("pair") or ""
        unit = r.get("unit", "")
        val = _value(r.get("value")) + (f" {html.escape(unit)}" if unit and
                                        r.get("value") is not None else "")
        if "value" not in r and "max_interference_mm" in r:
            val = f"interference {_value(r['max_interference_mm'])} mm"
        out.append(f'<tr><td class="{cls}">{status}</td><td>{html.escape(r["group"])}</td>'
                   f'<td>{html.escape(str(name))}</td><td class="num">{val}</td>'
                   f'<td>{html.escape(str(r.get("limit", "")))}</td>'
                   f'<td>{html.escape(str(r.get("note", "") or ""))}</td></tr>')
    out.append("</tbody></table>")
    return "\n".join(out)


def _legend(a: Animation) -> str:
    items = [(t["label"], t["color"]) for t in a.traces] + [(lk["label"], lk["color"])
                                                             for lk in a.links]
    items = [(lab, c) for lab, c in items if lab]  # unlabelled parts (gears) stay out
    return '<p class="legend">' + "".join(
        f'<span><i style="background:{_hex(c)}"></i>{html.escape(lab)}</span>'
        for lab, c in items) + "</p>"


def build_report(summary: dict, figures=(), animation: Animation | None = None,
                 gear_drawings=(), title: str | None = None, command: str = "",
                 verdict: tuple[bool | None, str] | None = None,
                 gif: str | Path | None = None) -> str:
    """The report as one HTML string (no external resource).

    ``summary``: the job's summary dict; ``figures``: (caption, Figure or image path)
    pairs; ``animation``: the mechanism over one cycle; ``gear_drawings``: (caption, SVG or
    PNG path) pairs; ``verdict``: (ok, text), default :func:`summary_verdict`; ``gif``:
    the GIF's file name, mentioned for slides."""
    from plantmech import __version__

    ok, text = verdict if verdict is not None else summary_verdict(summary)
    name = summary.get("name") or summary.get("design", {}).get("name", "")
    title = title or f"plantmech report: {name}"
    when = _dt.datetime.now(_dt.UTC).strftime("%Y-%m-%d %H:%M UTC")
    parts = ["<!doctype html>", '<html lang="en"><head><meta charset="utf-8">',
             '<meta name="viewport" content="width=device-width, initial-scale=1">',
             f"<title>{html.escape(title)}</title><style>{_STYLE}</style></head><body>",
             f"<h1>{html.escape(title)}</h1>",
             f'<p class="meta">{html.escape(command)} &middot; plantmech {__version__} '
             f"&middot; {when}</p>",
             f'<div id="verdict" class="verdict '
             f'{"none" if ok is None else "ok" if ok else "fail"}">'
             f'{"&#8211;" if ok is None else "&#10003;" if ok else "&#10007;"} '
             f'{html.escape(text)}</div>']
    if summary.get("caveats"):  # what the verdict rests on (outputs/caveats.py)
        parts.append('<ul id="caveats" class="meta">' + "".join(
            f"<li>caveat: {html.escape(str(c['text'] if isinstance(c, dict) else c))}</li>"
            for c in summary["caveats"]) + "</ul>")
    if animation is not None:
        parts += [f'<h2 id="animation">{html.escape(animation.title)}</h2>',
                  _legend(animation), _svg_animation(animation),
                  '<div class="controls"><button id="play" type="button">Pause</button>'
                  f'<input id="frame-slider" type="range" min="0" max="{animation.frames - 1}"'
                  ' value="0" aria-label="frame"><span id="frame-label"></span></div>',
                  f'<script type="application/json" id="animation-data">'
                  f"{_animation_data(animation)}</script>"]
        if gif:
            parts.append(f"<p class=\"meta\">For slides: <code>{html.escape(str(gif))}</code>"
                         " (animated GIF) next to this file.</p>")
    diags = summary.get("diagnostics") or []
    if diags:
        parts.append('<h2 id="diagnostics">Diagnostics</h2><ul>')
        for d in diags:
            where = ""
            if d.get("between_points"):
                where += " between q{} and q{}".format(*d["between_points"][:2])
            if d.get("carrier_angle_deg"):
                where += " (carrier angle {:.1f}-{:.1f} deg)".format(*d["carrier_angle_deg"][:2])
            parts.append(f"<li><b>{html.escape(str(d.get('severity', '')).upper())}</b> "
                         f"[{html.escape(str(d.get('kind', '')))}]{html.escape(where)}: "
                         f"{html.escape(str(d.get('message', '')))}</li>")
        parts.append("</ul>")
    parts += ['<h2 id="checks">Objectives and checks</h2>', _checks_table(summary)]
    if figures:
        parts.append('<h2 id="plots">Plots</h2>')
        for cap, item in figures:
            parts.append(f"<figure>{_img_tag(item, cap)}<figcaption>{html.escape(cap)}"
                         "</figcaption></figure>")
    if gear_drawings:
        parts.append('<h2 id="gear-drawings">Gear drawings</h2><div class="gears">')
        for cap, item in gear_drawings:
            parts.append(f"<figure>{_img_tag(item, cap)}<figcaption>{html.escape(cap)}"
                         "</figcaption></figure>")
        parts.append("</div>")
    from plantmech.outputs.files import _clean

    js = json.dumps(_clean(summary), indent=1, default=str)
    parts += ['<h2 id="summary">Everything computed</h2>',
              f"<details><summary>summary ({len(js)} characters of JSON)</summary>"
              f"<pre>{html.escape(js)}</pre></details>"]
    if animation is not None:
        parts.append(f"<script>{_SCRIPT}</script>")
    parts.append("</body></html>")
    return "\n".join(parts)


def write_report(path: str | Path, summary: dict, figures=(), animation: Animation | None = None,
                 gear_drawings=(), title: str | None = None, command: str = "",
                 verdict: tuple[bool, str] | None = None,
                 gif: bool | str | Path = True) -> list[Path]:
    """Write the HTML report and, with an animation, the animated GIF (``gif``: True for
    ``mechanism.gif`` beside the report, a path, or False for none); returns the files
    written. Other arguments as :func:`build_report`."""
    path = Path(path)
    written = []
    gif_path = None
    if animation is not None and gif:
        target = path.with_name("mechanism.gif") if gif is True else Path(gif)
        gif_path = write_gif(animation, target)
        written.append(gif_path)
    text = build_report(summary, figures, animation, gear_drawings, title, command, verdict,
                        gif_path.name if gif_path else None)
    path.write_text(text, encoding="utf-8")
    return [path] + written


def findings_rows(rec: dict) -> list[dict]:
    """The gears record's findings (``gears.findings``) as report rows, one failed check
    each, and one passed row per gear and pair without a finding."""
    from plantmech.gears.findings import describe

    rows = [{"name": f"{f['gear']}: {f['check']}", "ok": False, "value": f["value"],
             "unit": f["unit"], "limit": f["limit"], "note": describe(f)}
            for f in rec["findings"]]
    failed = {f["gear"] for f in rec["findings"]}
    for name in [g["name"] for g in rec["gears"]] + [m["pair"] for m in rec["mesh"]]:
        if name not in failed:
            rows.append({"name": f"{name}: every check", "ok": True, "value": None,
                         "unit": "", "limit": "no finding"})
    return rows


# --- a job's figures and animation (for the API and the reports) ----------------------


def job_figures(job) -> list[tuple[str, object]]:
    """(file name, matplotlib Figure) of every plot of a job: a seeder inverse job
    (``run_seeder_inverse``), a seeder forward job (``run_seeder_forward``) or a
    transplanter job (``run_transplanter``). The names are those the CLI writes."""
    if hasattr(job, "motion"):
        from plantmech.outputs import transplanter_plots as tp

        return [("trajectories.png", tp.plot_trajectories(job)),
                ("attitude_speed.png", tp.plot_attitude_speed(job)),
                ("ratio.png", tp.plot_ratio(job)), ("gears.png", tp.plot_gears(job))]
    from plantmech.outputs import seeder_plots as sp

    if hasattr(job, "section_psi"):
        return [("trajectories.png", sp.plot_forward_trajectories(job)),
                ("speed.png", sp.plot_forward_speed(job)),
                ("attitude.png", sp.plot_forward_attitude(job)),
                ("pitch_curves.png", sp.plot_forward_pitch_curves(job))]
    res = job.result
    figs = [("trajectory.png", sp.plot_trajectory(job.trajectory, res, job.sections))]
    if res.arm_angle_realized is not None and res.feasible:
        figs += [("attitude.png", sp.plot_attitude(res, job.sections)),
                 ("ratios.png", sp.plot_ratios(res)),
                 ("pitch_curves.png", sp.plot_pitch_curves(res))]
    return figs


def job_animation(job, frames: int = FRAMES) -> Animation | None:
    """The mechanism of a job over one cycle (None: an infeasible inverse design)."""
    if hasattr(job, "motion"):
        return transplanter_animation(job, frames)
    if hasattr(job, "section_psi"):
        return seeder_forward_animation(job, frames)
    if job.result.feasible and job.result.tip_realized is not None:
        return seeder_inverse_animation(job, frames)
    return None


def job_report(job, path: str | Path, gif: bool | str | Path = True) -> list[Path]:
    """:func:`write_report` of a job with all its figures and its animation."""
    return write_report(path, job.summary, job_figures(job), job_animation(job), gif=gif)
