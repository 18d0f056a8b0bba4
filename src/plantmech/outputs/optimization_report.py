"""Files of an optimization run: best.toml, pareto.csv, history.csv, run.json, plots."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from plantmech.outputs.files import write_csv, write_json


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
        cols[f"{v.name}_{v.unit}"] = result.pareto_x[:, i]
    for i, n in enumerate(problem.objective_names):
        cols[n] = result.pareto_f[:, i]
    write_csv(out / "pareto.csv", cols)
    written = [out / "best.toml", out / "run.json", out / "history.csv", out / "pareto.csv"]
    written += plot_run(out, result, problem)
    return written


def plot_run(out: Path, result, problem) -> list[Path]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    hist = result.history
    fig, ax = plt.subplots(figsize=(8, 4.5))
    ev = [h["evaluations"] for h in hist]
    ax.semilogy(ev, [max(h["best_violation"], 1e-6) for h in hist], "k.-")
    ax.set_xlabel("evaluations")
    ax.set_ylabel("best total relative violation (1e-6 = all met)")
    ax.set_title(f"Convergence: {result.problem}, {result.algorithm}, seed {result.seed}")
    if result.first_feasible_evaluations:
        ax.axvline(result.first_feasible_evaluations, color="tab:green", ls="--",
                   label=f"first design meeting every objective ({result.first_feasible_s:.1f} s)")
        ax.legend(fontsize=8)
    ax.grid(alpha=0.3, which="both")
    fig.tight_layout()
    fig.savefig(out / "convergence.png", dpi=120)
    plt.close(fig)
    written = [out / "convergence.png"]
    F = result.pareto_f
    names = problem.objective_names
    if F.shape[1] >= 2 and len(F) > 1:
        fig, ax = plt.subplots(figsize=(6.5, 5.5))
        sc = ax.scatter(F[:, 0], F[:, 1], c=F[:, 2] if F.shape[1] > 2 else "tab:blue",
                        cmap="viridis")
        if F.shape[1] > 2:
            fig.colorbar(sc, ax=ax, label=names[2])
        ax.set_xlabel(names[0])
        ax.set_ylabel(names[1])
        ax.set_title("Pareto front (final population, non-dominated)")
        ax.grid(alpha=0.3)
        fig.tight_layout()
        fig.savefig(out / "pareto.png", dpi=120)
        plt.close(fig)
        written.append(out / "pareto.png")
    return written
