"""Plots of design studies: histograms with the limits, sensitivity ranking, the tip-path
band over the planned trajectory, sweep responses, multi-start outcomes."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def limit_bounds(text: str) -> tuple[float | None, float | None]:
    """(lower, upper) from a limit text such as '> 320 and < 350 deg', '< 30 deg'."""
    lo = re.search(r">\s*(-?[\d.eE+-]+)", text or "")
    hi = re.search(r"<\s*(-?[\d.eE+-]+)", text or "")
    return (float(lo.group(1)) if lo else None, float(hi.group(1)) if hi else None)


def _grid(n: int, width: int = 4):
    cols = min(width, n)
    rows = int(np.ceil(n / cols))
    return rows, cols


def probability_text(p: float, interval, n: int) -> str:
    """P(ok) with its 95 % interval: a probability of 0 or 1 from n samples is a bound,
    not a certainty."""
    lo, hi = interval if interval is not None else (float("nan"), float("nan"))
    if p >= 1.0:
        return f"P(ok) = 1: met in all {n} samples (95 %: >= {lo:.4f})"
    if p <= 0.0:
        return f"P(ok) = 0: met in none of {n} samples (95 %: <= {hi:.4f})"
    return f"P(ok) = {p:.4f} (95 %: {lo:.4f}-{hi:.4f})"


def histogram_window(x: np.ndarray, bounds) -> tuple[float, float, list]:
    """The x range of a histogram: the samples' range, widened to the limits that lie
    within four times that range of it (a limit farther out would squash the
    distribution into one bar); returns (left, right, the limits left out of view)."""
    lo, hi = float(np.min(x)), float(np.max(x))
    spread = hi - lo if hi > lo else max(abs(hi), 1.0) * 1e-3
    left, right = lo - 0.08 * spread, hi + 0.08 * spread
    outside = []
    for b in bounds:
        if b is None:
            continue
        if lo - 4 * spread <= b <= hi + 4 * spread:
            left, right = min(left, b - 0.05 * spread), max(right, b + 0.05 * spread)
        else:
            outside.append(b)
    return left, right, outside


def plot_histograms(path: Path, data: dict, summary: dict) -> None:
    """One histogram per objective and per band output: samples that meet the objective
    in blue, those that do not in red, the limits as red lines (a limit far from every
    sample is named at the edge, with its distance, instead of squashing the
    histogram), the nominal value dashed, P(ok) with its 95 % interval in the title."""
    plt = _plt()
    N = int(summary["samples"])
    items = [(o["name"], o["unit"], o["limit"], o["nominal"],
              probability_text(o["probability_ok"], o.get("probability_ok_95"), N))
             for o in summary["objectives"]]
    items += [(n, v["unit"], "", None, None) for n, v in summary["outputs"].items()]
    rows, cols = _grid(len(items))
    fig, axes = plt.subplots(rows, cols, figsize=(4.2 * cols, 3.1 * rows), squeeze=False)
    for ax, (name, unit, limit, nominal, ptext) in zip(axes.ravel(), items, strict=False):
        x = np.asarray(data[name], float)
        ok = (np.asarray(data[f"{name}__ok"], bool) if f"{name}__ok" in data
              else np.ones(len(x), bool))
        finite = np.isfinite(x)
        bounds = limit_bounds(limit)
        if finite.any():
            xf = x[finite]
            left, right, outside = histogram_window(
                np.r_[xf, [nominal] if nominal is not None and np.isfinite(nominal) else []],
                bounds)
            bins = np.linspace(left, right, 61)
            ax.hist([x[finite & ok], x[finite & ~ok]], bins=bins, stacked=True,
                    color=["#4a7ab0", "#d9534f"], alpha=0.9,
                    label=["objective met", "objective not met"])
            ax.set_xlim(left, right)
            for b in outside:  # name the far limit at the edge it lies beyond
                side = "right" if b > right else "left"
                gap = b - xf.max() if side == "right" else xf.min() - b
                ax.annotate(f"limit {b:g} {unit}\n{gap:.3g} {unit} beyond\nevery sample "
                            + ("->" if side == "right" else "<-"),
                            xy=(0.98 if side == "right" else 0.02, 0.6),
                            xycoords="axes fraction", ha=side, fontsize=7, color="red")
        else:
            ax.text(0.5, 0.5, "not computed in any sample", ha="center",
                    transform=ax.transAxes, fontsize=8)
        for b in bounds:
            if b is not None and finite.any() and left <= b <= right:
                ax.axvline(b, color="red", lw=1.5, label="limit")
        if nominal is not None and np.isfinite(nominal):
            ax.axvline(nominal, color="k", ls="--", lw=1, label="nominal design")
        missing = int((~finite).sum())
        title = name if ptext is None else f"{name}  ({limit})\n{ptext}"
        if missing:
            title += f"\n{missing} samples not computed (not met)"
        ax.set_title(title, fontsize=8)
        ax.set_xlabel(f"{name} ({unit})" if unit else name, fontsize=8)
        ax.set_ylabel("samples", fontsize=8)
        ax.tick_params(labelsize=7)
        ax.ticklabel_format(axis="x", useOffset=False)
    for ax in axes.ravel()[len(items):]:
        ax.axis("off")
    seen = {}
    for ax in axes.ravel()[:len(items)]:
        for h, lab in zip(*ax.get_legend_handles_labels(), strict=True):
            seen.setdefault(lab, h)
    if seen:
        fig.legend(list(seen.values()), list(seen), loc="upper right", fontsize=8)
    fig.suptitle(f"Tolerance study: {N} samples", fontsize=10)
    fig.tight_layout(rect=(0, 0, 0.9, 1))
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_sensitivity(path: Path, summary: dict) -> None:
    """Per objective (and the band): parameters ranked by first-order contribution
    |d output / d parameter| x std (bars, in the output's unit) with the Monte Carlo
    standardized regression coefficient printed beside each bar."""
    plt = _plt()
    items = [(o["name"], o["unit"], o["sensitivity"]) for o in summary["objectives"]]
    band = summary["outputs"]["path_deviation_mm"].get("first_order_rms_contribution_mm")
    rows, cols = _grid(len(items) + (1 if band else 0), 3)
    fig, axes = plt.subplots(rows, cols, figsize=(5.2 * cols, 2.6 * rows), squeeze=False)
    for ax, (name, unit, sens) in zip(axes.ravel(), items, strict=False):
        rank = sens["ranking"][::-1]
        vals = [r.get("first_order_sigma", 0.0) for r in rank]
        ax.barh([r["parameter"] for r in rank], vals, color="#c0793a")
        for y, r in enumerate(rank):
            ax.text(vals[y], y, f" SRC {r['src']:+.2f}", va="center", fontsize=6)
        r2 = sens.get("r2")
        fitted = r2 is not None and r2 == r2
        still = not fitted and not any(vals)
        ax.set_title(f"{name} (R² of linear fit {r2:.2f})" if fitted else
                     f"{name}{' (unaffected by these parameters)' if still else ''}",
                     fontsize=8)
        ax.set_xlabel(f"first-order |d/dx| x std ({unit or '-'})", fontsize=7)
        ax.tick_params(labelsize=6)
        ax.margins(x=0.3)
    if band:
        ax = axes.ravel()[len(items)]
        names = list(band)[::-1]
        ax.barh(names, [band[n] for n in names], color="#5a9a5a")
        ax.set_title("tip-path band: rms over the cycle of each parameter's share", fontsize=8)
        ax.set_xlabel("first-order normal deviation x std (mm, rms)", fontsize=7)
        ax.tick_params(labelsize=6)
    for ax in axes.ravel()[len(items) + (1 if band else 0):]:
        ax.axis("off")
    fig.suptitle("Sensitivity ranking (bars: first-order x std; text: Monte Carlo SRC)",
                 fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_band(path: Path, summary: dict, plan: np.ndarray | None = None) -> None:
    """Left: the planned trajectory, the nominal tip path and the Monte Carlo envelope
    (min/max of the deviation along the path's normal), the band magnified so it can be
    seen (factor in the legend). Right: the deviation along the normal over the cycle:
    min/max, mean +- 3 std and the first-order +- 3 std."""
    plt = _plt()
    b = summary["band"]
    tip, nrm = np.asarray(b["nominal_tip_mm"]), np.asarray(b["normal"])
    lo, hi = np.asarray(b["mc_min_mm"]), np.asarray(b["mc_max_mm"])
    width = float(np.max(hi - lo)) if len(hi) else 0.0
    span = float(np.ptp(tip, axis=0).max())
    mag = 1.0
    if width > 0:  # the largest 1-2-5 factor that keeps the band under ~6 % of the path
        target = 0.06 * span / width
        steps = [m * 10.0**e for e in range(0, 6) for m in (1, 2, 5)]
        mag = max([1.0] + [m for m in steps if m <= target])
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(13, 5.5))
    if plan is not None:
        a1.plot(plan[:, 0], plan[:, 1], color="0.6", lw=1, label="planned trajectory")
    a1.plot(np.r_[tip[:, 0], tip[:1, 0]], np.r_[tip[:, 1], tip[:1, 1]], "k-", lw=0.8,
            label="nominal tip path")
    for k, v in enumerate((lo, hi)):
        p = tip + nrm * (mag * v)[:, None]
        p = np.r_[p, p[:1]]  # closed cycle
        a1.plot(p[:, 0], p[:, 1], color="tab:red", lw=0.8,
                label=f"Monte Carlo min - max, deviation x {mag:g}" if k else None)
    a1.fill(np.r_[tip[:, 0] + mag * lo * nrm[:, 0], (tip[:, 0] + mag * hi * nrm[:, 0])[::-1]],
            np.r_[tip[:, 1] + mag * lo * nrm[:, 1], (tip[:, 1] + mag * hi * nrm[:, 1])[::-1]],
            color="tab:red", alpha=0.15, lw=0)
    a1.set_aspect("equal")
    a1.set_xlabel("x (mm)")
    a1.set_ylabel("y (mm)")
    a1.legend(fontsize=8, loc="best")
    a1.set_title(f"tip-path band over the cycle (band magnified x {mag:g})", fontsize=9)
    ang = np.asarray(b["carrier_angle_deg"])
    m, s, fo = np.asarray(b["mc_mean_mm"]), np.asarray(b["mc_std_mm"]), np.asarray(
        b["first_order_std_mm"])
    a2.fill_between(ang, lo, hi, color="tab:red", alpha=0.15, label="Monte Carlo min - max")
    a2.plot(ang, m + 3 * s, "tab:blue", lw=1, label="Monte Carlo mean +- 3 std")
    a2.plot(ang, m - 3 * s, "tab:blue", lw=1)
    fm = np.asarray(b.get("first_order_mean_mm", np.zeros_like(fo)))
    a2.plot(ang, fm + 3 * fo, "k--", lw=1, label="first order mean +- 3 std")
    a2.plot(ang, fm - 3 * fo, "k--", lw=1)
    a2.set_xlabel("carrier angle (deg)")
    a2.set_ylabel("tip deviation along the path normal (mm)")
    a2.legend(fontsize=8)
    a2.set_title(f"{summary['samples']} samples", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_sweep(path: Path, data: dict, summary: dict) -> None:
    """Every objective against every swept parameter (points; met in blue, not in grey),
    limits in red."""
    plt = _plt()
    params = [p["name"] for p in summary["parameters"]]
    objs = [o["name"] for o in summary["objectives"]]
    limits = summary.get("limits", {})
    fig, axes = plt.subplots(len(objs), len(params), squeeze=False,
                             figsize=(max(3.4 * len(params), 5.0), 2.2 * len(objs)))
    # variants that could not be built have no motion: marked on the x axis
    built = np.isfinite(np.asarray(data["path_deviation_mm"], float))
    for i, o in enumerate(objs):
        ok = np.asarray(data[f"{o}__ok"], bool)
        for j, p in enumerate(params):
            ax = axes[i, j]
            x, y = np.asarray(data[p]), np.asarray(data[o])
            ax.scatter(x[~ok], y[~ok], s=4, color="0.6")
            ax.scatter(x[ok], y[ok], s=4, color="tab:blue")
            if (~built).any():
                ax.scatter(x[~built], np.full((~built).sum(), 0.03), s=14, marker="x",
                           color="tab:red", transform=ax.get_xaxis_transform(), clip_on=False)
                pad = 0.05 * max(float(np.ptp(x)), 1e-12)
                ax.set_xlim(float(x.min()) - pad, float(x.max()) + pad)
            lo, hi = limit_bounds(limits.get(o, ""))
            for bnd in (lo, hi):
                if bnd is not None:
                    ax.axhline(bnd, color="red", lw=1)
            if i == len(objs) - 1:
                ax.set_xlabel(p, fontsize=7)
            if j == 0:
                ax.set_ylabel(o, fontsize=7)
            ax.tick_params(labelsize=6)
    fig.suptitle("Sweep: objectives vs parameters\n(blue: met, grey: not met, red line: "
                 "limit, red x: variant not built)", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def plot_multistart(path: Path, data: dict) -> None:
    """Total violation of each start's best design (0: every objective met)."""
    plt = _plt()
    seeds = np.asarray(data["seed"])
    v = np.asarray(data["total_violation"], float)
    ok = np.asarray(data["feasible"], bool)
    fig, ax = plt.subplots(figsize=(7, 3.5))
    ax.bar(seeds[ok], np.maximum(v[ok], 1e-6), color="tab:green", label="met every objective")
    ax.bar(seeds[~ok], v[~ok], color="tab:red", label="not met")
    ax.set_xlabel("seed")
    ax.set_ylabel("total violation of the best design (-)")
    ax.legend(fontsize=8)
    ax.set_title(f"multi-start: {int(ok.sum())} of {len(ok)} starts met every objective")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
