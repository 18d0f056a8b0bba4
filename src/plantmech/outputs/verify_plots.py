"""Plots of the tooth-contact verification (``plantmech verify``): transmission error
and backlash band per pair, arm attitude error, tip path band. Units on every axis."""

from __future__ import annotations

from pathlib import Path

import numpy as np


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _flank_lines(ax, psi: np.ndarray, fp) -> None:
    """One pair's free-play result on ``ax``: both flanks, the mid band and the steps where
    the teeth interfere (deg)."""
    ax.plot(psi, np.degrees(fp.lo), lw=0.8, label="flank lo (CW contact)")
    ax.plot(psi, np.degrees(fp.hi), lw=0.8, label="flank hi (CCW contact)")
    ax.plot(psi, np.degrees(0.5 * (fp.lo + fp.hi)), "k", lw=0.6, label="mid band")
    if fp.jammed.any():
        ax.plot(psi[fp.jammed], np.zeros(fp.jammed.sum()), "rx",
                label="interference (jammed)")


def _tip_path_panel(ax, nominal, lo, hi, who: str, title: str, model: str) -> None:
    """The pitch-curve model's tip path (legend ``model``) and the toothed train's at both
    ends of ``who``'s free play (mm), the rotation centre marked."""
    ax.plot(*nominal.T, "k", lw=0.8, label=model)
    ax.plot(*lo.T, lw=0.7, label=f"toothed, {who} at lo end of its play")
    ax.plot(*hi.T, lw=0.7, label=f"toothed, {who} at hi end of its play")
    ax.plot(0, 0, "k+", ms=10)
    ax.set_aspect("equal")
    ax.set_xlabel("x / mm")
    ax.set_ylabel("y / mm")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(title)


def _save(plt, fig, path: Path) -> None:
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plot_transmission_error(path: Path, c) -> None:
    """Driven gear's turn off the pitch-curve law (deg) on both flanks, per pair, and
    the arm's (the planet's, through the whole train)."""
    plt = _plt()
    psi = np.degrees(c.psi)
    fig, axes = plt.subplots(3, 1, figsize=(9, 9), sharex=True)
    for ax, fp, title in ((axes[0], c.stage1, "sun -> gear 2 (gear 2's turn)"),
                          (axes[1], c.stage2, "gear 3 -> planet (planet's turn, gear 3 "
                                              "at its nominal angle)")):
        _flank_lines(ax, psi, fp)
        ax.set_ylabel("transmission error / deg")
        ax.set_title(title, fontsize=10)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8, loc="upper right")
    ax = axes[2]
    ax.fill_between(psi, np.degrees(c.planet_lo), np.degrees(c.planet_hi), alpha=0.4,
                    label="arm attitude band (whole train)")
    if c.in_dwell.any():
        ax.axvspan(psi[c.in_dwell][0], psi[c.in_dwell][-1], color="0.85", label="dwell")
    ax.set_ylabel("arm attitude error / deg")
    ax.set_xlabel("carrier angle (clockwise from the start) / deg")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper right")
    _save(plt, fig, path)


def plot_tip_band(path: Path, c) -> None:
    """Tip path of the pitch-curve model and of the toothed train at both ends of its
    free play (mm), and the band's width over the cycle."""
    plt = _plt()
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(13, 5.5),
                                 gridspec_kw={"width_ratios": [1.2, 1]})
    _tip_path_panel(ax, c.tip_nominal, c.tip_lo, c.tip_hi, "arm", "tip path",
                    "pitch-curve model")
    psi = np.degrees(c.psi)
    bx.plot(psi, np.hypot(*(c.tip_hi - c.tip_lo).T), label="band width")
    bx.plot(psi, np.fmax(np.hypot(*(c.tip_hi - c.tip_nominal).T),
                         np.hypot(*(c.tip_lo - c.tip_nominal).T)), lw=0.8,
            label="largest distance from the pitch-curve path")
    bx.set_xlabel("carrier angle / deg")
    bx.set_ylabel("tip / mm")
    bx.grid(alpha=0.3)
    bx.legend(fontsize=8)
    bx.set_title("tip band over the cycle")
    _save(plt, fig, path)


def _dwell_impacts(axes, loads: dict) -> None:
    """Dotted lines at a toothless dwell's impacts (``loads["dwell_impacts"]``) on every
    panel, each labelled with its kinetic-energy jump and the drive's work across it (J)."""
    for k, imp in enumerate(loads.get("dwell_impacts", [])):
        for ax in axes:
            ax.axvline(imp["carrier_angle_deg"], color="0.4", ls=":", lw=1.0,
                       label=None if ax is not axes[0] or k > 0 else
                       "dwell impacts (rigid model)")
        axes[2].annotate(f"kinetic {imp['kinetic_energy_jump_J']:+.2f} J,\nwork "
                         f"{imp['drive_work_J']:+.2f} J", (imp["carrier_angle_deg"], 0.95),
                         xycoords=("data", "axes fraction"), xytext=(3, 0),
                         textcoords="offset points", fontsize=7, ha="left", va="top")


def plot_loads(path: Path, loads: dict) -> None:
    """Input torque and tangential tooth forces over the carrier turn (exudyn), and the
    energy balance (drive work vs change of kinetic + potential energy)."""
    plt = _plt()
    s = loads["series"]
    psi = s["carrier_angle_deg"]
    fig, axes = plt.subplots(3, 1, figsize=(9, 9), sharex=True)
    axes[0].plot(psi, s["input_torque_N_m"], label="input torque on the carrier")
    axes[0].set_ylabel("torque / N m")
    axes[1].plot(psi, s["tooth_force_sun_gear2_N"], label="sun - gear 2")
    axes[1].plot(psi, s["tooth_force_gear3_planet_N"], label="gear 3 - planet")
    axes[1].set_ylabel("tangential tooth force / N")
    axes[2].plot(psi, s["work_J"], label="work of the drive")
    axes[2].plot(psi, s["energy_change_J"], "--", label="kinetic + potential energy change")
    axes[2].set_ylabel("energy / J")
    axes[2].set_xlabel("carrier angle / deg")
    _dwell_impacts(axes, loads)
    for ax in axes:
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    err = 100 * loads["energy_balance"]["max_error_fraction_of_energy_range"]
    axes[0].set_title(f"loads at {loads['inputs']['carrier_speed_deg_s']:g} deg/s, energy "
                      f"balance error {err:.2f} %", fontsize=10)
    _save(plt, fig, path)


def plot_transplanter_transmission_error(path: Path, c) -> None:
    """Each planet's turn off the pitch-curve law (deg) on both flanks against the
    internal gear (one panel per arm; the arm's attitude error is the planet's)."""
    plt = _plt()
    psi = np.degrees(c.psi)
    arms = len(c.arms)
    fig, axes = plt.subplots(arms, 1, figsize=(9, 3 * arms), sharex=True, squeeze=False)
    for j, (ax, fp) in enumerate(zip(axes[:, 0], c.arms, strict=True)):
        _flank_lines(ax, psi, fp)
        lost = ~fp.jammed & (~np.isfinite(fp.lo) | ~np.isfinite(fp.hi))
        if lost.any():
            ax.plot(psi[lost], np.zeros(lost.sum()), "m|", label="contact lost")
        ax.set_ylabel("planet turn error / deg")
        ax.set_title(f"internal gear -> planet of arm {j + 1}", fontsize=10)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8, loc="upper right")
    axes[-1, 0].set_xlabel("carrier angle (clockwise from the start) / deg")
    _save(plt, fig, path)


def plot_transplanter_tip_band(path: Path, c) -> None:
    """Arm 1's tip path of the pitch-curve model and of the toothed train at both ends
    of each planet's free play (mm), and every arm's band width over the cycle
    (differential or K-H-V train)."""
    plt = _plt()
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(13, 5.5),
                                 gridspec_kw={"width_ratios": [1.2, 1]})
    _tip_path_panel(ax, c.tip_nominal[0], c.tip_lo[0], c.tip_hi[0], "planet",
                    "tip path (arm 1)", "pitch-curve model (arm 1)")
    psi = np.degrees(c.psi)
    for j in range(len(c.tip_nominal)):
        bx.plot(psi, np.hypot(*(c.tip_hi[j] - c.tip_lo[j]).T), lw=0.8,
                label=f"arm {j + 1} band width")
    bx.set_xlabel(f"{getattr(c, 'turning', 'carrier')} angle / deg")  # held: the driver's
    bx.set_ylabel("tip band / mm")
    bx.grid(alpha=0.3)
    bx.legend(fontsize=8)
    bx.set_title("tip band over the cycle")
    _save(plt, fig, path)


def plot_khv_transmission_error(path: Path, c) -> None:
    """K-H-V train: each arm's middle gear against the sun and planet against its middle
    (driven gear's turn off the pitch-curve law on both flanks, deg), and each arm's
    attitude band through the whole train (deg)."""
    plt = _plt()
    psi = np.degrees(c.psi)
    arms = len(c.stage1)
    fig, axes = plt.subplots(2 * arms + 1, 1, figsize=(9, 2.6 * (2 * arms + 1)), sharex=True)
    for j in range(arms):
        for ax, fp, title in ((axes[2 * j], c.stage1[j], f"sun -> middle of arm {j + 1} "
                               "(middle's turn)"),
                              (axes[2 * j + 1], c.stage2[j], f"middle -> planet of arm "
                               f"{j + 1} (planet's turn, middle at its nominal angle)")):
            _flank_lines(ax, psi, fp)
            ax.set_ylabel("error / deg")
            ax.set_title(title, fontsize=10)
            ax.grid(alpha=0.3)
            ax.legend(fontsize=7, loc="upper right")
    _attitude_bands(axes[-1], psi, c, "carrier angle (clockwise from the start) / deg")
    _save(plt, fig, path)


def _attitude_bands(ax, psi, c, xlabel: str) -> None:
    """Every arm's attitude band through the whole train (deg): the planet's extreme extra
    turns ``c.planet_lo`` / ``c.planet_hi`` (J, T) rad."""
    for j in range(len(c.planet_lo)):
        ax.fill_between(psi, np.degrees(c.planet_lo[j]), np.degrees(c.planet_hi[j]),
                        alpha=0.4, label=f"arm {j + 1} attitude band (whole train)")
    ax.set_ylabel("arm attitude error / deg")
    ax.set_xlabel(xlabel)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper right")


def plot_train_transmission_error(path: Path, c) -> None:
    """A general planetary train (``contact.planetary.PlanetaryContact``): arm 1's pairs,
    each follower against its driver at the driver's nominal angle (the follower's turn
    off the pitch-curve law on both flanks, deg), and every arm's attitude band through
    the whole train (deg)."""
    plt = _plt()
    psi = np.degrees(c.psi)
    n = len(c.names)
    fig, axes = plt.subplots(n + 1, 1, figsize=(9, 2.6 * (n + 1)), sharex=True)
    for ax, fp, (driver, driven) in zip(axes[:-1], c.pairs[0], c.names, strict=True):
        _flank_lines(ax, psi, fp)
        ax.set_ylabel("error / deg")
        ax.set_title(f"{driver} -> {driven}, arm 1 ({driven}'s turn, {driver} at its nominal "
                     "angle)", fontsize=10)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="upper right")
    _attitude_bands(axes[-1], psi, c, f"{c.turning} angle (from the start, in the "
                    f"{c.turning}'s sense) / deg")
    _save(plt, fig, path)


def plot_transplanter_loads(path: Path, loads: dict, turning: str = "carrier") -> None:
    """A transplanter's (or a general train's) input torque(s) and tangential tooth forces
    over the turn of the carrier (``turning``: of the driver, with the carrier held),
    (exudyn), and the energy balance (drives' work vs change of kinetic + potential
    energy); a held carrier's torque (the frame's, holding the centres) dashed."""
    plt = _plt()
    s = loads["series"]
    psi = s["carrier_angle_deg"]
    fig, axes = plt.subplots(3, 1, figsize=(9, 9), sharex=True)
    for k, v in s.items():
        if k.startswith("input_torque_"):
            axes[0].plot(psi, v, label=k.removeprefix("input_torque_").removesuffix("_N_m")
                         + " drive")
        elif k.startswith("holding_torque_"):
            axes[0].plot(psi, v, "--", label=k.removeprefix("holding_torque_").removesuffix(
                "_N_m") + " holding the fixed centres (no input)")
        elif k.startswith("tooth_force_"):
            axes[1].plot(psi, v, lw=0.8,
                         label=k.removeprefix("tooth_force_").removesuffix("_N"))
    held = any(k.startswith("holding_torque_") for k in s)
    axes[0].set_ylabel("input and holding torque / N m" if held else "input torque / N m")
    axes[1].set_ylabel("tangential tooth force / N")
    axes[2].plot(psi, s["work_J"], label="work of the drives")
    axes[2].plot(psi, s["energy_change_J"], "--", label="kinetic + potential energy change")
    axes[2].set_ylabel("energy / J")
    axes[2].set_xlabel(f"{turning} angle / deg")
    _dwell_impacts(axes, loads)
    for ax in axes:
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    err = 100 * loads["energy_balance"]["max_error_fraction_of_energy_range"]
    axes[0].set_title(f"loads at {turning} speed {loads['inputs']['carrier_speed_deg_s']:g} "
                      f"deg/s, energy balance error {err:.2f} %", fontsize=10)
    _save(plt, fig, path)
