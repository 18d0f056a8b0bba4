"""Plots of a general planetary train's motion (matplotlib Figures, no pyplot; units on
every axis)."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

DEG = 180.0 / np.pi


def plot_paths(motion, title: str = "") -> Figure:
    """Tip path of every arm, the planet axis' circle, and the gears of arm 1 at the start
    (pitch curves at their shafts, turned to their start angles)."""
    fig = Figure(figsize=(6.4, 6.4), layout="constrained")
    ax = fig.add_subplot()
    for j in range(motion.tip.shape[1]):
        z = motion.tip[0, j]
        ax.plot(z.real, z.imag, lw=1.4 if j == 0 else 0.8, label=f"arm {j + 1} tip path")
    c = motion.centre[0, 0]
    ax.plot(c.real, c.imag, ":", color="0.5", lw=0.8, label="planet axis")
    from plantmech.trains.placement import place_gears

    for gear in place_gears(motion, [0]):  # every gear of arm 1 at the start, once
        if gear.arm == 0:
            z = gear.outline()[0, 0]  # on the curve's own grid
            ax.plot(np.r_[z.real, z.real[0]], np.r_[z.imag, z.imag[0]], color="tab:gray",
                    lw=0.8)
    t0, c0 = motion.tip[0, 0, 0], motion.centre[0, 0, 0]
    ax.plot([0, c0.real], [0, c0.imag], color="k", lw=1.5)
    ax.plot([c0.real, t0.real], [c0.imag, t0.imag], color="tab:red", lw=2,
            label="arm 1 at start")
    _machine_plane(ax, title or "tip paths and the gears at the start")
    return fig


def _machine_plane(ax, title: str) -> None:
    """Equal axes in mm, grid, legend, and the title wrapped (a design's name may be long:
    not cut off at the figure's edge)."""
    import textwrap

    ax.set_aspect("equal")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_title(textwrap.fill(title, 60))
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="best")


def forward_figures(design, motion) -> list[tuple[str, Figure]]:
    """The plots of a planetary train's forward run, by file name (``forward`` writes
    them, ``design`` and ``--report`` embed them)."""
    return [("trajectories.png", plot_paths(motion, design.name)),
            ("attitude_speed.png", plot_attitude_speed(motion, design.carrier.speed_deg_s)),
            ("ratios.png", plot_ratios(motion))]


def _what_turns(motion) -> str:
    """What psi turns: the carrier, or the driver (the sun) when the carrier is held."""
    held = motion.built is not None and motion.built.train.carrier_held
    return "driver" if held else "carrier"


def _angle_label(motion) -> str:
    return f"{_what_turns(motion)} angle (deg)"


def plot_attitude_speed(motion, carrier_speed_deg_s: float) -> Figure:
    """Arm angle (deg) and tip speed (m/s) of arm 1 over the carrier angle (deg)."""
    fig = Figure(figsize=(7.0, 5.0), layout="constrained")
    a1, a2 = fig.subplots(2, 1, sharex=True)
    psi = motion.carrier_angle * DEG
    a1.plot(psi, motion.arm_angle[0, 0] * DEG)
    a1.set_ylabel("arm angle (deg, CCW from +x)")
    a1.grid(alpha=0.3)
    a2.plot(psi, np.abs(motion.velocity(carrier_speed_deg_s)[0, 0]))
    a2.set_ylabel("tip speed (m/s)")
    a2.set_xlabel(_angle_label(motion))
    a2.grid(alpha=0.3)
    fig.suptitle(f"arm 1 at {_what_turns(motion)} speed {carrier_speed_deg_s:g} deg/s")
    return fig


def plot_ratios(motion) -> Figure:
    """Each pair's transmission ratio r_driver / r_follower over the carrier angle; on a
    toothless dwell (the pair's teeth out of mesh, its follower held) no ratio is drawn
    and the span is shaded."""
    fig = Figure(figsize=(7.0, 3.6), layout="constrained")
    ax = fig.add_subplot()
    psi = motion.carrier_angle * DEG
    meshes = list(motion.meshes or []) + [None] * len(motion.contact_radii)
    shaded = False
    for k, (rd, rf) in enumerate(motion.contact_radii):
        ratio = rd[0, 0] / rf[0, 0]
        if meshes[k] is not None:
            held = ~np.asarray(meshes[k][0, 0], bool)
            ratio = np.where(held, np.nan, ratio)
            edges = np.flatnonzero(np.diff(np.r_[0, held.astype(int), 0]))
            for a, b in zip(edges[::2], edges[1::2], strict=True):
                ax.axvspan(psi[a], psi[b - 1], color="0.85", zorder=0,
                           label=None if shaded else "toothless dwell: follower held")
                shaded = True
        ax.plot(psi, ratio, label=f"pair {k + 1}")
    ax.set_xlabel(_angle_label(motion))
    ax.set_ylabel("ratio r_driver / r_follower (-)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    return fig


def plot_inverse(traj, result, motion=None, title: str = "") -> Figure:
    """A first-order inverse design (``objectives.planetary_inverse``): the planned
    trajectory through its
    type-value points (numbered), the reach circles rho = L + a and |L - a| when the
    lengths are known, the written design's forward tip path (``motion``, when feasible),
    and the sun's pitch curve at the start (mm)."""
    fig = Figure(figsize=(6.4, 6.4), layout="constrained")
    ax = fig.add_subplot()
    u = np.linspace(0.0, traj.period, 2000)
    xy = traj(u)
    ax.plot(xy[:, 0], xy[:, 1], lw=2.5, color="tab:blue", alpha=0.5, label="planned trajectory")
    p = traj.points
    ax.plot(p[:, 0], p[:, 1], "o", ms=4, color="tab:blue", label="type-value points")
    for i, (x, y) in enumerate(p):
        ax.annotate(f"q{i}", (x, y), fontsize=7, xytext=(3, 3), textcoords="offset points")
    t = np.linspace(0, 2 * np.pi, 400)
    if result.centre_distance is not None:
        a, L = result.centre_distance, result.arm_length
        for r, style in ((L + a, ":"), (abs(L - a), ":")):
            ax.plot(r * np.cos(t), r * np.sin(t), style, color="0.5", lw=0.8)
        ax.plot(a * np.cos(t), a * np.sin(t), "--", color="0.6", lw=0.8, label="planet axis")
    if motion is not None:
        z = motion.tip[0, 0]
        ax.plot(z.real, z.imag, color="tab:red", lw=1.0, label="forward tip of design.toml")
        from plantmech.trains.placement import place_gears

        sun = next(p for p in place_gears(motion, [0]) if p.name == "sun")
        g = sun.outline()[0, 0]
        ax.plot(np.r_[g.real, g.real[0]], np.r_[g.imag, g.imag[0]], color="tab:gray", lw=0.8,
                label="sun pitch curve")
    ax.plot([0], [0], "k+", ms=10)
    _machine_plane(ax, title or "first-order inverse design")
    return fig
