"""Plots of a transplanting mechanism, units on every axis.

Every function returns a :class:`matplotlib.figure.Figure` built without pyplot (no backend
forced; save with :func:`plantmech.outputs.seeder_plots.save`). Legends sit outside the
data. The arms repeat each other after a carrier phase shift, so their relative paths
coincide: each arm has its own line style and width so that none hides another.
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from plantmech.outputs.seeder_plots import legend_outside

DEG = 180.0 / np.pi
COLOURS = ["tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown"]
# arm j: wide solid under narrower dashed/dotted lines, so coincident paths all show
ARM_STYLES = [dict(ls="-", lw=4.0, alpha=0.45), dict(ls="--", lw=2.0), dict(ls=":", lw=1.6),
              dict(ls="-.", lw=1.2), dict(ls=(0, (1, 3)), lw=1.2), dict(ls="-", lw=0.8)]


def arm_style(j: int) -> dict:
    """Colour, line style and width of arm ``j`` (0-based)."""
    return {"color": COLOURS[j % len(COLOURS)], **ARM_STYLES[j % len(ARM_STYLES)]}
STAGE_COLOURS = {"picking": "tab:green", "conveying": "tab:blue", "planting": "tab:red",
                 "return": "0.6"}


def _box_and_ground(ax, job, x_range):
    b = job.design.seedling_box
    u = np.exp(1j * np.radians(b.inclination_deg))
    o = complex(b.x_mm, b.y_mm)
    floor = np.array([o, o + b.length_mm * u])
    top = floor + 1j * u * b.mat_thickness_mm
    ax.plot(floor.real, floor.imag, "k-", lw=2.5, label="seedling box floor")
    ax.fill(np.r_[floor.real, top[::-1].real], np.r_[floor.imag, top[::-1].imag],
            color="tab:olive", alpha=0.4, label="seedling mat")
    g = job.evaluation.metrics["ground_y_mm"][0]
    ax.axhline(g, color="saddlebrown", lw=1.5, label="ground")
    ax.fill_between(x_range, g, g - 40, color="saddlebrown", alpha=0.15)


def plot_trajectories(job) -> Figure:
    """Relative trajectories of every arm tip (frame of the machine) with the box and the
    ground, and absolute trajectories over two carrier turns (mm)."""
    m = job.motion
    fig = Figure(figsize=(18, 8), layout="constrained")
    axes = fig.subplots(1, 2, gridspec_kw={"width_ratios": [1, 1.6]})
    ax = axes[0]
    J = m.B.shape[1]
    for j in range(J):
        ax.plot(m.B[0, j].real, m.B[0, j].imag, **arm_style(j),
                label=f"arm {j + 1} tip (relative)")
    for k in range(0, m.B.shape[-1], m.B.shape[-1] // 12):
        for j in range(J):
            pts = np.array([m.centre[0, j, k], m.A[0, j, k], m.B[0, j, k]])
            ax.plot(pts.real, pts.imag, "-", color=COLOURS[j], lw=0.4, alpha=0.5)
    t = np.linspace(0, 2 * np.pi, 200)
    r = job.gearbox_radius_mm
    ax.plot(r * np.cos(t), r * np.sin(t), "k:", lw=1, label="gearbox outline")
    xr = np.array([m.B[0].real.min() - 40, m.B[0].real.max() + 40])
    _box_and_ground(ax, job, xr)
    ax.set_aspect("equal")
    ax.set_xlabel("x / mm")
    ax.set_ylabel("y / mm")
    ax.set_title("Relative trajectories (frame of the machine)")
    ax.grid(alpha=0.3)
    legend_outside(ax)
    ax = axes[1]
    d = job.design
    J = m.B.shape[1]
    sign = job.evaluation.metrics["forward_sign"][0]
    advance = d.field.plant_spacing_mm * J  # mm per carrier turn
    S = m.B.shape[-1]
    for turn in range(2):
        for j in range(J):
            x = m.B[0, j].real * sign + advance * (turn + np.arange(S) / S)
            ax.plot(x, m.B[0, j].imag, **arm_style(j),
                    label=f"arm {j + 1}" if turn == 0 else None)
    g = job.evaluation.metrics["ground_y_mm"][0]
    ax.axhline(g, color="saddlebrown", lw=1.5, label="ground")
    ax.set_aspect("equal")
    ax.set_xlabel("x along the travel direction / mm")
    ax.set_ylabel("y / mm")
    ax.set_title(f"Absolute trajectories, plant spacing {d.field.plant_spacing_mm:g} mm "
                 f"(two carrier turns)")
    ax.grid(alpha=0.3)
    legend_outside(ax)
    return fig


def plot_attitude_speed(job) -> Figure:
    """Needle angle (unwrapped, deg) and relative tip speed (m/s) of every arm, with
    arm 1's stages."""
    m = job.motion
    deg = m.carrier_angle * DEG
    fig = Figure(figsize=(13, 8), layout="constrained")
    axes = fig.subplots(2, 1, sharex=True)
    stages = job.summary["stages_deg"]["arm_I"]
    for ax in axes:
        for name, span in stages.items():
            if span is None:
                continue
            a, b = span
            spans = [(a, b)] if b >= a else [(a, 360.0), (0.0, b)]
            for i, (lo, hi) in enumerate(spans):
                ax.axvspan(lo, hi, color=STAGE_COLOURS[name], alpha=0.12,
                           label=f"arm 1 {name}" if (i == 0 and ax is axes[0]) else None)
    speed = np.abs(m.velocity(job.design.drive.carrier_speed_deg_s)[0])
    for j in range(m.B.shape[1]):
        axes[0].plot(deg, needle_angle_unwrapped(m.needle_angle[0, j]), **arm_style(j),
                     label=f"arm {j + 1} needle angle")
        axes[1].plot(deg, speed[j], **arm_style(j), label=f"arm {j + 1} tip speed")
    axes[0].set_ylabel("needle angle A->B / deg (CCW from +x, unwrapped)")
    axes[1].set_ylabel("tip speed (relative) / (m/s)")
    axes[1].set_xlabel("carrier angle (clockwise from start) / deg")
    axes[1].set_xlim(0, 360)
    for ax in axes:
        ax.grid(alpha=0.3)
        legend_outside(ax)
    return fig


def needle_angle_unwrapped(angle_deg: np.ndarray) -> np.ndarray:
    """A needle angle sampled over the cycle (deg, in [0, 360)) made continuous: no
    jump of 360 deg between samples, shifted by whole turns so that its mean lies in
    [0, 360) (arms that repeat each other then share one band)."""
    a = np.degrees(np.unwrap(np.radians(np.asarray(angle_deg, dtype=float))))
    return a - 360.0 * np.floor(a.mean() / 360.0)


def plot_ratio(job) -> Figure:
    """Planet turn per carrier turn seen by arm 1 (relative to the carrier, -)."""
    m = job.motion
    fig = Figure(figsize=(10, 4.5), layout="constrained")
    ax = fig.subplots()
    ax.plot(m.carrier_angle * DEG, m.planet_rate[0, 0], "k")
    ax.set_xlabel("carrier angle (clockwise from start) / deg")
    ax.set_ylabel("planet turn per carrier turn (relative to the carrier)")
    ax.set_title("Transmission ratio seen by arm 1")
    ax.set_xlim(0, 360)
    ax.grid(alpha=0.3)
    return fig


def plot_gears(job) -> Figure:
    """The gear pair(s) drawn in mesh at the start (pitch curves, mm)."""
    m = job.motion
    fig = Figure(figsize=(9.5, 7.5), layout="constrained")
    ax = fig.subplots()
    c0 = np.radians(job.design.carrier.initial_angle_deg)
    if getattr(job.design, "internal_gear", None) is not None:  # the differential's pair
        pair = job.pair
        ang, R = pair.internal_polar(0)
        phase0 = np.radians(job.design.internal_gear.initial_phase_deg)
        # internal body angle 0 at lobe phase 0; the start contact (phase0) lies on phi_H0
        rot = c0 + phase0 / pair.lobes
        z = R * np.exp(1j * (ang + rot))
        ax.plot(np.r_[z.real, z[0].real], np.r_[z.imag, z[0].imag], "k", lw=1.5,
                label="internal gear (pitch)")
        pa, pr = pair.planet_polar(0)
        for j in range(m.B.shape[1]):
            # planet body angle -Q; oriented by the motion: x-axis at phi_2
            zc = m.centre[0, j, 0]
            phi2 = m.planet_angle[0, j, 0]
            # the planet's contact with body angle -(Q(p) - Q(0)) lies along the carrier line
            q0 = np.interp(phase0 % (2 * np.pi), pair.p, pair.Q[0])
            zz = zc + pr * np.exp(1j * (pa + q0 + phi2))
            ax.plot(zz.real, zz.imag, color=COLOURS[j], label=f"planet {j + 1}")
            ax.plot([0, zc.real], [0, zc.imag], "k-", lw=0.6)
        ax.set_title(f"Internal gear ({pair.lobes:g} lobes) and planets at the start, "
                     f"a = {pair.a[0]:.2f} mm")
    else:
        pair = job.pair
        z = pair.r_sun[0] * np.exp(1j * (c0 - pair.sigma))
        ax.plot(z.real, z.imag, "k", lw=1.5, label="sun (fixed)")
        for j in range(m.B.shape[1]):
            zc = m.centre[0, j, 0]
            ax.plot([0, zc.real], [0, zc.imag], "-o", color=COLOURS[j], lw=0.8, ms=3,
                    label=f"carrier line {j + 1}")
        ax.set_title(f"K-H-V sun gear, a = {pair.a[0]:.2f} mm")
    ax.plot(0, 0, "k+", ms=12)
    ax.set_aspect("equal")
    ax.set_xlabel("x / mm")
    ax.set_ylabel("y / mm")
    ax.grid(alpha=0.3)
    legend_outside(ax)
    return fig
