"""Files of an optimization run: best.toml, pareto.csv, history.csv, run.json, plots."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from plantmech.outputs.files import write_csv, write_json

# axis labels of the problems' objectives (what is minimized, with its unit)
OBJECTIVE_LABELS = {
    "picking_swing": "picking swing (attitude over ab) / deg",
    "seeding_swing": "seeding swing (attitude over de) / deg",
    "sowing_angle": "sowing angle |at e| / deg",
    "seeding_peak_speed": "seeding peak speed (over de) / (m/s)",
    "neg_return_min_speed_dynamic": "- return minimum dynamic speed (over ef) / (m/s)",
    "seedling_block_skew": "seedling-block skew (vi) / mm",
    "hole_width": "widest hole (ix) / mm",
    "angle_difference_offcentre": "|angle difference (v) - mid-range| / deg",
}


def objective_label(name: str) -> str:
    """Axis label (with unit) of an objective by its name."""
    return OBJECTIVE_LABELS.get(name, name.replace("_", " "))


def variable_column(name: str, unit: str) -> str:
    """CSV column of a variable: its name with the unit appended once (``S_mm`` stays)."""
    return name if not unit or name.endswith(f"_{unit}") else f"{name}_{unit}"


def design_toml(design, header: str = "") -> str:
    """A design as TOML that ``load_design`` reads back (comments of the input are lost;
    ``header`` is written as comment lines)."""
    import tomli_w

    data = design.model_dump(exclude_none=True, mode="json")
    text = tomli_w.dumps(data)
    lines = [f"# {line}" if line else "#" for line in header.splitlines()]
    return ("\n".join(lines) + "\n\n" if lines else "") + text


def write_run(out: Path, result, problem, design_input: str) -> list[Path]:
    """Write every file of one run into ``out`` (created by the caller)."""
    best_design = problem.decode(result.best_x)
    rec = result.record()
    header = (f"Best design of `plantmech optimize --problem {result.problem}` "
              f"(algorithm {result.algorithm}, seed {result.seed}, {result.evaluations} "
              f"evaluations, {result.wall_s:.1f} s)\nfrom {design_input}; every objective "
              f"met: {result.feasible}; see run.json")
    (out / "best.toml").write_text(design_toml(best_design, header), encoding="utf-8")
    write_json(out / "run.json", rec)
    hist = result.history
    write_csv(out / "history.csv", {k: np.array([h[k] for h in hist], dtype=float)
                                    for k in ("generation", "evaluations", "best_violation",
                                              "feasible_in_population", "wall_s")})
    cols = {}
    for i, v in enumerate(problem.variables):
        cols[variable_column(v.name, v.unit)] = result.pareto_x[:, i]
    for i, n in enumerate(problem.objective_names):
        cols[n] = result.pareto_f[:, i]
    write_csv(out / "pareto.csv", cols)
    written = [out / "best.toml", out / "run.json", out / "history.csv", out / "pareto.csv"]
    written += plot_run(out, result, problem)
    return written


def plot_run(out: Path, result, problem) -> list[Path]:
    """Write convergence.png (and pareto.png for two or more objectives); their paths."""
    written = [out / "convergence.png"]
    convergence_figure(result).savefig(written[0], dpi=120)
    fig = pareto_figure(result, problem)
    if fig is not None:
        fig.savefig(out / "pareto.png", dpi=120)
        written.append(out / "pareto.png")
    return written


# the violation axis is logarithmic: a run reaching 0 is drawn at this floor
VIOLATION_FLOOR = 1e-6


def convergence_figure(result):
    """Best total relative violation per evaluation (Figure). The floor line that marks
    'every objective met' is drawn only when a design met them all."""
    from matplotlib.figure import Figure

    hist = result.history
    fig = Figure(figsize=(10, 4.5), layout="constrained")
    ax = fig.subplots()
    ev = [h["evaluations"] for h in hist]
    ax.semilogy(ev, [max(h["best_violation"], VIOLATION_FLOOR) for h in hist], "k.-",
                label="best design so far")
    ax.set_xlabel("evaluations")
    ax.set_ylabel("best total relative violation / -")
    met = bool(result.feasible)
    verdict = ("every objective met" if met
               else "NOT met: the best design misses an objective")
    ax.set_title(f"Convergence: {result.problem}, {result.algorithm}, seed {result.seed} "
                 f"({verdict})")
    if met:
        ax.axhline(VIOLATION_FLOOR, color="tab:green", lw=1, ls=":",
                   label=f"{VIOLATION_FLOOR:g}: violation 0, every objective met")
    if result.first_feasible_evaluations:
        ax.axvline(result.first_feasible_evaluations, color="tab:green", ls="--",
                   label=f"first design meeting every objective ({result.first_feasible_s:.1f} s)")
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0)
    ax.grid(alpha=0.3, which="both")
    return fig


def pareto_figure(result, problem):
    """Final non-dominated objectives, axes with units (Figure), or None for fewer than
    two objectives or points."""
    from matplotlib.figure import Figure

    F = result.pareto_f
    names = problem.objective_names
    if F.ndim != 2 or F.shape[1] < 2 or len(F) < 2:
        return None
    fig = Figure(figsize=(7.5, 5.5), layout="constrained")
    ax = fig.subplots()
    sc = ax.scatter(F[:, 0], F[:, 1], c=F[:, 2] if F.shape[1] > 2 else "tab:blue",
                    cmap="viridis")
    if F.shape[1] > 2:
        fig.colorbar(sc, ax=ax, label=objective_label(names[2]))
    ax.set_xlabel(objective_label(names[0]))
    ax.set_ylabel(objective_label(names[1]))
    ax.set_title("Pareto front (final population, non-dominated; all minimized)")
    ax.grid(alpha=0.3)
    return fig
