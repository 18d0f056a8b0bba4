"""Multi-start optimization: the same ``plantmech optimize`` problem from N seeds, one Dask
task per start (each start evaluates its populations through the population API), so the
spread of the optimizer's outcome over seeds, and the best designs, are seen at once."""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np

from plantmech.studies.engine import (
    RunStats,
    claim_out_dir,
    done_chunks,
    read_results,
    run_chunks,
)
from plantmech.studies.spec import MultiStartSpec, StudySpecError

#: the problems that move type-value points (and so need a [trajectory])
TRAJECTORY_PROBLEMS = ("seeder-layer1", "seeder-layered")


def check_problem(design, spec: MultiStartSpec, source: str = "study file") -> None:
    """StudySpecError naming ``source`` and the field when ``spec.problem`` cannot optimize
    ``design`` (before a start is sent: every start would fail the same way)."""
    from plantmech.kinds import KINDS, kind_of

    if spec.problem not in kind_of(design).problems:
        takes = " or ".join(k.name for k in KINDS.values() if spec.problem in k.problems)
        raise StudySpecError(f"{source}: field 'problem': {spec.problem!r} optimizes a "
                             f"{takes} design, and {design.name!r} is a {design.mechanism}")
    trajectory = spec.problem in TRAJECTORY_PROBLEMS
    if trajectory and getattr(design, "trajectory", None) is None:
        raise StudySpecError(f"{source}: field 'problem': {spec.problem!r} moves type-value "
                             f"points: the design {design.name!r} needs a [trajectory]")


def start_task(shared, payload):
    """Worker task: one optimization run -> (one-row columns, its best design file)."""
    from plantmech.optimize.jobs import optimize

    design, spec, design_input = shared
    index, seed = payload
    with tempfile.TemporaryDirectory() as tmp:
        res = optimize(design, spec.problem, Path(tmp), design_input, seed=seed,
                       generations=spec.generations, pop=spec.pop, algorithm=spec.algorithm,
                       progress=False)
        best = (Path(tmp) / "best.toml").read_text(encoding="utf-8")
    rec = res.record
    cols = {"start": np.array([index]), "seed": np.array([seed]),
            "feasible": np.array([bool(res.feasible)]),
            "total_violation": np.array([float(rec.get("total_violation", np.nan))]),
            "evaluations": np.array([int(rec.get("evaluations", 0))]),
            "wall_s": np.array([float(rec.get("wall_s", np.nan))]),
            "first_feasible_s": np.array([np.nan if rec.get("first_feasible_s") is None
                                          else float(rec["first_feasible_s"])])}
    for o in rec.get("objectives", []):
        cols[o["name"]] = np.array([np.nan if o["value"] is None else float(o["value"])])
        cols[f"{o['name']}__ok"] = np.array([bool(o["ok"])])
    return cols, {"_files": {f"starts/best_seed{seed}.toml": best}}


def run_multistart(design, spec: MultiStartSpec, out: Path, fingerprint: str,
                   design_input: str, scheduler: str | None = None, workers: int = 2,
                   progress: bool = True, max_chunks: int | None = None):
    from plantmech.studies.runner import StudyOutcome, wilson

    check_problem(design, spec)
    claim_out_dir(out, fingerprint, {"kind": spec.kind, "design": design.name,
                                     "problem": spec.problem})
    (out / "starts").mkdir(exist_ok=True)
    chunks = [(k, (k, spec.seed + k), 1) for k in range(spec.starts)]
    stats: RunStats = run_chunks(out, start_task, (design, spec, design_input), chunks,
                                 scheduler, workers, progress, max_chunks, label="starts")
    summary = {}
    if done_chunks(out):  # a stopped study still summarises the starts it finished
        data = read_results(out)
        n = len(data["seed"])
        ok = data["feasible"].astype(bool)
        order = np.lexsort((data["total_violation"], ~ok))
        best = []
        for rank, k in enumerate(order[:spec.best], start=1):
            seed = int(data["seed"][k])
            src = out / "starts" / f"best_seed{seed}.toml"
            dst = out / f"best_{rank}.toml"
            dst.write_text(src.read_text(encoding="utf-8"), encoding="utf-8")
            best.append({"rank": rank, "seed": seed, "file": dst.name,
                         "feasible": bool(ok[k]),
                         "total_violation": float(data["total_violation"][k]),
                         "evaluations": int(data["evaluations"][k]),
                         "wall_s": float(data["wall_s"][k])})
        ffs = data["first_feasible_s"][np.isfinite(data["first_feasible_s"])]
        summary = {"kind": "multi-start", "problem": spec.problem, "starts": n,
                   "generations": spec.generations, "pop": spec.pop,
                   "successes": int(ok.sum()), "success_rate": float(ok.mean()),
                   "success_rate_95": wilson(int(ok.sum()), n),
                   "seeds_succeeded": [int(s) for s in data["seed"][ok]],
                   "first_feasible_s_median": float(np.median(ffs)) if len(ffs) else None,
                   "evaluations_total": int(data["evaluations"].sum()),
                   "best": best, "complete": stats.complete}
    summary["run"] = stats.as_dict()
    return StudyOutcome(stats, summary)
