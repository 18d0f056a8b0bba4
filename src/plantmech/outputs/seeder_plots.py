"""Plots of a seeder design (inverse and forward), units on every axis.

Every function returns a :class:`matplotlib.figure.Figure` built without pyplot, so no
backend is forced (a notebook shows it; the CLI saves it with :func:`save`). Legends sit
outside the data.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from plantmech.mechanisms.seeder_trains import gear_body_angles

DEG = 180.0 / np.pi
SECTION_COLOURS = {"picking_ab": "tab:green", "transport_bc": "tab:blue",
                   "transport_cd": "tab:purple", "seeding_de": "tab:red",
                   "return_efca": "0.6"}
SECTION_BOUNDS = {"picking_ab": ("a", "b"), "transport_bc": ("b", "c"),
                  "transport_cd": ("c", "d"), "seeding_de": ("d", "e"),
                  "return_efca": ("e", "a")}


def save(fig: Figure, path: Path, dpi: int = 110) -> Path:
    """Write ``fig`` to ``path`` (PNG, or the format of the suffix)."""
    fig.savefig(path, dpi=dpi)
    return Path(path)


def legend_outside(ax, **kw) -> None:
    """The axes' legend to their right, off the data."""
    ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0,
              fontsize=kw.pop("fontsize", 7), **kw)


def _section_spans(res, sections):
    pp = {k: res.point_carrier_angle[v] for k, v in sections.items()}
    for name, (s, e) in SECTION_BOUNDS.items():
        yield name, pp[s], pp[e]


def _mask(psi, p0, p1):
    return np.mod(psi - p0, 2 * np.pi) <= np.mod(p1 - p0, 2 * np.pi)


def _runs(mask):
    """(start, end) index pairs of the True runs of a boolean array."""
    m = np.r_[False, np.asarray(mask, bool), False].astype(int)
    d = np.diff(m)
    return list(zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1) - 1, strict=True))


def plot_trajectory(traj, res, sections: dict[str, int]) -> Figure:
    """Planned trajectory (type-value points q_i, section points a-f) and, when the
    inverse design is feasible, the gear train's tip path per section (mm)."""
    fig = Figure(figsize=(10, 8), layout="constrained")
    ax = fig.subplots()
    uu = np.linspace(0, traj.period, 3000)
    ax.plot(*traj(uu).T, color="0.8", lw=6, label="planned trajectory", zorder=1)
    if res is not None and res.tip_realized is not None:
        psi = res.carrier_angle
        for name, p0, p1 in _section_spans(res, sections):
            m = _mask(psi, p0, p1)
            ax.plot(*res.tip_realized[m].T, ".", ms=1.5, color=SECTION_COLOURS[name],
                    label=f"{name.replace('_', ' ')} (gear train)")
        b = res.L1 * np.c_[np.cos(res.carrier_abs[0]), np.sin(res.carrier_abs[0])][0]
        ax.plot([0, b[0], res.tip[0, 0]], [0, b[1], res.tip[0, 1]], "k-o", ms=4,
                label="carrier OB and arm BA at start")
    pts = traj.points
    ax.plot(pts[:, 0], pts[:, 1], "ko", ms=3, label="type-value points q_i")
    for i, p in enumerate(pts):
        ax.annotate(f"q{i}", p, textcoords="offset points", xytext=(4, 4), fontsize=7)
    for letter, idx in sections.items():
        ax.annotate(letter, pts[idx], textcoords="offset points", xytext=(-12, -12),
                    fontsize=12, color="tab:red", weight="bold")
    ax.plot(0, 0, "k+", ms=12)
    ax.set_aspect("equal")
    ax.set_xlabel("x / mm")
    ax.set_ylabel("y / mm")
    ax.set_title("Tip trajectory (origin: carrier axis O)")
    ax.grid(alpha=0.3)
    legend_outside(ax)
    return fig


def plot_attitude(res, sections) -> Figure:
    """Cane attitude (arm angle) relative to the start, planned and realized (deg)."""
    psi = res.carrier_angle * DEG
    fig = Figure(figsize=(11, 4.5), layout="constrained")
    ax = fig.subplots()
    ref = res.arm_angle[0] * DEG
    ax.plot(psi, res.arm_angle * DEG - ref, color="0.6", lw=3, label="planned")
    ax.plot(psi, res.arm_angle_realized * DEG - ref, "k", lw=1, label="gear train")
    for name, p0, p1 in _section_spans(res, sections):
        a, b = p0 * DEG, p1 * DEG
        spans = [(a, b)] if b >= a else [(a, 360), (0, b)]
        for k, (lo, hi) in enumerate(spans):
            ax.axvspan(lo, hi, color=SECTION_COLOURS[name], alpha=0.15,
                       label=name.replace("_", " ") if k == 0 else None)
    _mark_dwell(ax, psi, _inverse_dwell_mask(res))
    ax.set_xlabel("carrier angle (clockwise from start) / deg")
    ax.set_ylabel("cane attitude change / deg")
    ax.set_xlim(0, 360)
    ax.grid(alpha=0.3)
    legend_outside(ax)
    ax.set_title("Cane seed attitude relative to the initial attitude")
    return fig


def _inverse_dwell_mask(res):
    """Carrier angles inside the inverse design's toothless dwell (None: no dwell)."""
    if res.dwell is None or "carrier_start" not in res.dwell:
        return None
    return _mask(res.carrier_angle, res.dwell["carrier_start"], res.dwell["carrier_end"])


def _mark_dwell(ax, deg, in_dwell, note: str = "toothless dwell") -> None:
    """Hatch the carrier-angle spans of the toothless dwell (if any) and label them."""
    if in_dwell is None or not np.any(in_dwell):
        return
    for k, (i, j) in enumerate(_runs(in_dwell)):
        ax.axvspan(deg[i], deg[j], facecolor="none", edgecolor="0.3", hatch="//", lw=0,
                   label=note if k == 0 else None)


def plot_ratios(res) -> Figure:
    """Ratio laws 1/i0, 1/i1, 1/i2 of the second-order train (relative to the carrier)."""
    psi = res.carrier_angle * DEG
    fig = Figure(figsize=(11, 4.5), layout="constrained")
    ax = fig.subplots()
    with np.errstate(divide="ignore"):
        for v, lab in ((res.total_ratio, "total 1/i0 = dpsi4/dpsi"),
                       (res.stage1_ratio, "stage 1 1/i1 = dpsi2/dpsi"),
                       (res.stage2_ratio, "stage 2 1/i2 = dpsi4/dpsi2")):
            ax.plot(psi, v, label=lab)
    dwell = _inverse_dwell_mask(res)
    _mark_dwell(ax, psi, dwell, "toothless dwell (ratios 0: gear 2 and the planet "
                "held to the carrier)")
    ax.set_xlabel("carrier angle / deg")
    ax.set_ylabel("speed ratio (relative to the carrier) / -")
    ax.set_xlim(0, 360)
    ax.grid(alpha=0.3)
    legend_outside(ax)
    ax.set_title("Ratio laws of the second-order train"
                 + (" (0 in the toothless dwell)" if dwell is not None and dwell.any() else ""))
    return fig


def plot_pitch_curves(res) -> Figure:
    """The four pitch curves drawn at their centres in the initial configuration (mm)."""
    ang = gear_body_angles(res)
    off = res.shaft_offset
    centres = {"sun": (0.0, 0.0), "gear2": (res.a1 * np.cos(off), res.a1 * np.sin(off)),
               "gear3": (res.a1 * np.cos(off), res.a1 * np.sin(off)),
               "planet": (res.L1, 0.0)}
    fig = Figure(figsize=(12, 5.5), layout="constrained")
    ax = fig.subplots()
    for key, r, col in (("sun", res.r1, "tab:orange"), ("gear2", res.r2, "tab:blue"),
                        ("gear3", res.r3, "tab:green"), ("planet", res.r4, "tab:red")):
        ok = np.isfinite(r)
        a = ang[key][ok]
        order = np.argsort(np.mod(a, 2 * np.pi))
        a, rr = np.mod(a, 2 * np.pi)[order], r[ok][order]
        cx, cy = centres[key]
        ls = "--" if key == "gear3" else "-"
        ax.plot(cx + rr * np.cos(a), cy + rr * np.sin(a), ls, color=col,
                label=f"{key} ({np.nanmin(r):.1f}-{np.nanmax(r):.1f} mm)")
        ax.plot(cx, cy, "+", color=col)
    if res.dwell is not None and res.dwell.get("edge_radius") is not None:
        th = off - np.linspace(res.dwell["carrier_end"], res.dwell["carrier_start"], 50)
        e = res.dwell["edge_radius"]
        ax.plot(e * np.cos(th), e * np.sin(th), ":", color="tab:orange", lw=2,
                label=f"sun toothless sector, R2 = {e:.1f} mm (no teeth: the dwell)")
    ax.set_aspect("equal")
    ax.set_xlabel("carrier frame x / mm")
    ax.set_ylabel("carrier frame y / mm")
    ax.grid(alpha=0.3)
    legend_outside(ax, fontsize=8)
    ax.set_title("Pitch curves at the initial position (gear 3 dashed, on gear 2's shaft)")
    return fig


# --- forward simulation -----------------------------------------------------------


def _forward_spans(section_psi):
    for name, (s, e) in SECTION_BOUNDS.items():
        yield name, section_psi[s], section_psi[e]


def _shade_sections(ax, section_psi):
    for name, p0, p1 in _forward_spans(section_psi):
        a0, a1 = p0 * DEG, p1 * DEG
        spans = [(a0, a1)] if a1 >= a0 else [(a0, 360.0), (0.0, a1)]
        for k, (lo, hi) in enumerate(spans):
            ax.axvspan(lo, hi, color=SECTION_COLOURS[name], alpha=0.15,
                       label=name.replace("_", " ") if k == 0 else None)


def _wrapped_spans(p0: float, p1: float) -> list[tuple[float, float]]:
    """The carrier-angle spans (deg, within 0-360) of the section from p0 to p1 (rad)."""
    a0, a1 = (p0 * DEG) % 360.0, (p1 * DEG) % 360.0
    return [(a0, a1)] if a1 >= a0 else [(a0, 360.0), (0.0, a1)]


def _span_line(ax, p0: float, p1: float, y: float, label: str, **kw) -> None:
    """A horizontal limit line drawn only over the section from p0 to p1 (rad)."""
    for k, (lo, hi) in enumerate(_wrapped_spans(p0, p1)):
        ax.hlines(y, lo, hi, lw=1.5, label=label if k == 0 else None, **kw)


def _mark_points(ax, section_psi: dict) -> None:
    """The section points a-f as labelled vertical lines at their carrier angles."""
    for letter, p in section_psi.items():
        x = (p * DEG) % 360.0
        ax.axvline(x, color="0.35", lw=0.7)
        ax.text(x, 1.0, letter, transform=ax.get_xaxis_transform(), ha="center",
                va="bottom", fontsize=11, weight="bold", color="tab:red")


def plot_forward_trajectories(job) -> Figure:
    """Static trajectory (mechanism frame) and dynamic trajectory (over the ground), mm."""
    res = job.result
    speed = job.design.operation.carrier_speed_deg_s
    fig = Figure(figsize=(16, 7), layout="constrained")
    axes = fig.subplots(1, 2)
    ax = axes[0]
    if job.trajectory is not None:
        uu = np.linspace(0, job.trajectory.period, 3000)
        ax.plot(*job.trajectory(uu).T, color="0.85", lw=6, label="planned trajectory")
    psi = res.carrier_angle
    for name, p0, p1 in _forward_spans(job.section_psi):
        m = _mask(psi, p0, p1)
        ax.plot(*res.tip[m].T, ".", ms=1.5, color=SECTION_COLOURS[name],
                label=name.replace("_", " "))
    if res.in_dwell is not None and res.in_dwell.any():
        ax.plot(*res.tip[res.in_dwell].T, "-", color="k", lw=2.5, alpha=0.5,
                label="toothless dwell (arm locked to the carrier)")
    for letter, p in job.section_psi.items():
        k = int(np.argmin(np.abs(np.angle(np.exp(1j * (psi - p))))))
        ax.annotate(letter, res.tip[k], textcoords="offset points", xytext=(-12, -12),
                    fontsize=12, color="tab:red", weight="bold")
    tr = job.train
    b = tr.L1 * np.array([np.cos(tr.carrier0), np.sin(tr.carrier0)])
    ax.plot([0, b[0], res.tip[0, 0]], [0, b[1], res.tip[0, 1]], "k-o", ms=4,
            label="carrier and arm at start")
    ax.set_aspect("equal")
    ax.set_xlabel("x / mm")
    ax.set_ylabel("y / mm")
    ax.set_title("Static trajectory (origin: carrier axis)")
    ax.grid(alpha=0.3)
    legend_outside(ax)
    ax = axes[1]
    # two turns so the ground path shows how consecutive cycles sit
    period = 360.0 / speed
    for cycle in range(2):
        dyn = res.dynamic_tip(speed, job.travel_m_s)
        dyn[:, 0] -= job.travel_m_s * 1000.0 * period * cycle
        ax.plot(*dyn.T, "-", lw=1, color="tab:blue" if cycle == 0 else "tab:cyan",
                label=f"cycle {cycle + 1}")
        k = int(np.argmin(np.abs(np.angle(np.exp(1j * (psi - job.section_psi["e"]))))))
        ax.plot(*dyn[k], "rv", ms=7, label="seeding point e" if cycle == 0 else None)
    ax.set_aspect("equal")
    ax.set_xlabel("x over ground / mm")
    ax.set_ylabel("y / mm")
    ax.set_title(f"Dynamic trajectory, travel v_c = {job.travel_m_s:.3f} m/s (Eq. 17)")
    ax.grid(alpha=0.3)
    legend_outside(ax)
    return fig


def plot_forward_speed(job) -> Figure:
    """Static and dynamic tip speed (m/s) with the sections, the limits and the dwell."""
    res = job.result
    speed = job.design.operation.carrier_speed_deg_s
    lim = job.design.speed
    fig = Figure(figsize=(12, 5), layout="constrained")
    ax = fig.subplots()
    _shade_sections(ax, job.section_psi)
    deg = res.carrier_angle * DEG
    ax.plot(deg, res.speed(speed), color="k", label="static speed")
    ax.plot(deg, res.speed(speed, job.travel_m_s), color="tab:orange",
            label=f"dynamic speed (v_c = {job.travel_m_s:.3f} m/s)")
    _mark_dwell(ax, deg, res.in_dwell, "toothless dwell: arm locked to the carrier, "
                "static speed = w |OA| (plateau)")
    # each limit drawn over the section its check reads (objectives 4-5): the seeding peak
    # over de, the return minimum over ef (after f the tip may slow down: not checked)
    psi = job.section_psi
    _span_line(ax, psi["d"], psi["e"], lim.seeding_max_m_s, color="tab:red", ls="--",
               label=f"seeding peak limit {lim.seeding_max_m_s:g} m/s (checked over de)")
    _span_line(ax, psi["e"], psi["f"], lim.return_min_m_s, color="0.2", ls=":",
               label=f"return minimum limit {lim.return_min_m_s:g} m/s (checked over ef)")
    _mark_points(ax, psi)
    ax.set_xlim(0, 360)
    ax.set_xlabel("carrier angle (clockwise from start) / deg")
    ax.set_ylabel("tip speed / (m/s)")
    ax.set_title(f"Tip speed at {speed:g} deg/s carrier speed (section points a-f marked)",
                 pad=16)
    ax.grid(alpha=0.3)
    legend_outside(ax)
    return fig


def plot_forward_attitude(job) -> Figure:
    """Cane attitude (arm angle from the initial one, deg) over the carrier turn."""
    res = job.result
    fig = Figure(figsize=(12, 5), layout="constrained")
    ax = fig.subplots()
    _shade_sections(ax, job.section_psi)
    deg = res.carrier_angle * DEG
    ax.plot(deg, (res.arm_angle - res.arm_angle[0]) * DEG, "k",
            label="cane attitude (from the initial attitude)")
    _mark_dwell(ax, deg, res.in_dwell, "toothless dwell (attitude turns with the carrier)")
    ax.set_xlim(0, 360)
    ax.set_xlabel("carrier angle (clockwise from start) / deg")
    ax.set_ylabel("attitude / deg")
    ax.set_title("Cane attitude vs carrier angle")
    ax.grid(alpha=0.3)
    legend_outside(ax)
    return fig


def plot_forward_pitch_curves(job) -> Figure:
    """Both pairs drawn in mesh at the start (carrier angle 0): gear 2 (3) about the
    origin, the sun (planet) about (-a, 0), touching on the line of centres (mm). With a
    toothless dwell the sun's rolling curve spans 360 deg - theta1 only: the rest is the
    toothless sector, drawn dotted."""
    from plantmech.objectives.seeder import mate_curves

    tr = job.train
    mates = mate_curves(tr)
    t = np.linspace(0, 2 * np.pi, 4097)
    fig = Figure(figsize=(15, 6.5), layout="constrained")
    axes = fig.subplots(1, 2)
    for ax, (gear, mate, curve, c0, a) in zip(axes, (
            ("gear 2", "sun (1)", tr.gear2, tr.gear2_contact0, tr.a1),
            ("gear 3", "planet (4)", tr.gear3, tr.gear3_contact0, tr.a2)), strict=True):
        r = curve(c0 + t)
        # the gear point that reaches the contact after a turn t starts at angle pi + t
        ax.plot(r * np.cos(np.pi + t), r * np.sin(np.pi + t), "tab:blue", label=gear)
        key = "sun" if mate.startswith("sun") else "planet"
        ang, rm = mates[key]
        # the mate turns the other way: its point meeting the contact after the gear's
        # turn t starts at angle -ang(t) about its own centre
        ax.plot(-a + rm * np.cos(-ang), rm * np.sin(-ang), "tab:red", label=mate)
        gap = 2 * np.pi - float(ang[-1])
        if key == "sun" and tr.dwell_start is not None and tr.dwell_theta1 > 0 and gap > 1e-6:
            th = np.linspace(-ang[-1], -2 * np.pi, 60)
            rr = np.linspace(rm[-1], rm[0], th.size)
            ax.plot(-a + rr * np.cos(th), rr * np.sin(th), ":", color="tab:red", lw=2,
                    label=f"sun toothless sector ({np.degrees(gap):.1f} deg): open on "
                    "purpose, the dwell over cd")
        ax.plot([0, -a], [0, 0], "k+", ms=10)
        ax.plot([-r[0]], [0], "ko", ms=4, label="contact at the start")
        ax.set_aspect("equal")
        ax.set_title(f"{mate} - {gear}, centre distance {a:.2f} mm")
        ax.set_xlabel("x / mm")
        ax.set_ylabel("y / mm")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.12), ncol=2)
    fig.suptitle("Pitch curves in mesh at carrier angle 0 (carrier frame, line of centres "
                 "along x)")
    return fig
