"""Whole optimization jobs: one problem, or the seeder's two layers in sequence.

Layered (seed 000 §4): layer 1 moves type-value points (attitude, planning limits),
then its best trajectory is inverse-designed, its gears 2 and 3 are resampled at
``points`` interpolation radii (the paper's "second layer" input) and layer 2 tunes
those radii for the speeds. Joint mode puts both layers' variables in one problem.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

PROBLEMS = ("seeder-layer1", "seeder-layer2", "seeder-layered", "seeder-joint", "transplanter")

DEFAULTS = {  # algorithm, generations, population
    "seeder-layer1": ("cmaes", 80, 40),
    "seeder-layer2": ("nsga2", 30, 40),
    "seeder-layered": ("cmaes", 80, 40),
    "seeder-joint": ("cmaes", 80, 40),
    "transplanter": ("nsga2", 30, 40),
}


@dataclass
class JobOutcome:
    feasible: bool
    record: dict
    written: list[Path]


def make_problem(design, name: str, layer2_points: int = 16, tooth_fit: bool = False):
    from plantmech.optimize import problems as P

    if name == "transplanter":
        return P.Transplanter(design, tooth_fit=tooth_fit)
    if design.mechanism != "sugarcane_seeder":
        raise ValueError(f"problem {name!r} needs a sugarcane_seeder design")
    if name == "seeder-layer1":
        if design.trajectory is None:
            raise ValueError("layer 1 moves type-value points: the design needs a [trajectory]")
        return P.SeederLayer1(design)
    if name == "seeder-layer2":
        return P.SeederLayer2(with_train(design, layer2_points))
    if name == "seeder-joint":
        return P.SeederJoint(design, points=layer2_points)
    raise ValueError(f"unknown problem {name!r} (expected one of {', '.join(PROBLEMS)})")


def with_train(design, points: int = 16):
    """The design with a [train]: its own, or one resampled from its inverse design."""
    if design.train is not None:
        return design
    from plantmech.workflows import run_seeder_inverse, train_from_inverse_job

    job = run_seeder_inverse(design)
    if not job.result.feasible:
        raise ValueError("the trajectory's inverse design is infeasible: run layer 1 first")
    d = design.model_copy(deep=True)
    d.train = train_from_inverse_job(job, points)
    return d.__class__.model_validate(d.model_dump())


def optimize(design, name: str, out: Path, design_input: str, seed: int = 0,
             generations: int | None = None, pop: int | None = None,
             algorithm: str | None = None, progress: bool = True,
             layer2_points: int = 16, tooth_fit: bool = False) -> JobOutcome:
    from plantmech.optimize.runner import run
    from plantmech.outputs.optimization_report import write_run

    algo0, gen0, pop0 = DEFAULTS.get(name, ("nsga2", 30, 40))
    user_gen, user_pop = generations, pop
    algorithm, generations, pop = algorithm or algo0, generations or gen0, pop or pop0
    if name != "seeder-layered":
        problem = make_problem(design, name, layer2_points, tooth_fit)
        res = run(problem, algorithm, seed, generations, pop, progress,
                  stop_when_feasible=algorithm != "nsga2")
        written = write_run(out, res, problem, design_input)
        rec = _verified(out, res.record(), tooth_fit)
        return JobOutcome(rec["feasible"], rec, written)
    # layered: layer 1, then layer 2 on the resampled gears of layer 1's best trajectory
    from plantmech.optimize import problems as P

    l1_dir, l2_dir = out / "layer1", out / "layer2"
    l1_dir.mkdir(exist_ok=True)
    l2_dir.mkdir(exist_ok=True)
    p1 = P.SeederLayer1(design)
    r1 = run(p1, algorithm, seed, generations, pop, progress, stop_when_feasible=True)
    written = write_run(l1_dir, r1, p1, design_input)
    d1 = p1.decode(r1.best_x)
    d2 = with_train(d1.model_copy(update={"train": None}), layer2_points)
    p2 = P.SeederLayer2(d2)
    r2 = run(p2, "nsga2", seed, user_gen or DEFAULTS["seeder-layer2"][1],
             user_pop or DEFAULTS["seeder-layer2"][2], progress)
    written += write_run(l2_dir, r2, p2, f"{design_input} (layer 1 best)")
    (out / "best.toml").write_text((l2_dir / "best.toml").read_text(), encoding="utf-8")
    rec = {
        "problem": "seeder-layered",
        "algorithm": f"layer 1: {r1.algorithm}, layer 2: {r2.algorithm}",
        "seed": seed,
        "evaluations": r1.evaluations + r2.evaluations,
        "wall_s": round(r1.wall_s + r2.wall_s, 3),
        "first_feasible_s": (None if r2.first_feasible_s is None
                             else round(r1.wall_s + r2.first_feasible_s, 3)),
        "feasible": bool(r1.feasible and r2.feasible),
        "objectives": r2.record()["objectives"],
        "layer1": r1.record(),
        "layer2": r2.record(),
    }
    rec = _verified(out, rec)
    for f in ("history.csv", "pareto.csv"):
        (out / f).write_text((l2_dir / f).read_text(), encoding="utf-8")
    written += [out / "best.toml", out / "run.json", out / "history.csv", out / "pareto.csv"]
    return JobOutcome(rec["feasible"], rec, written)


def verify(design, tooth_fit: bool = True) -> dict:
    """Re-evaluate a design with the full-resolution single-design model (the optimizer
    works at reduced resolution): {all_met, objectives}. ``tooth_fit`` False: the
    transplanter's tooth-fit objectives (xiii)-(xv) are reported, not required."""
    if design.mechanism != "sugarcane_seeder":
        from plantmech.optimize.problems import Transplanter
        from plantmech.workflows import run_transplanter

        objs = run_transplanter(design).summary["objectives"]
        if not tooth_fit:
            objs = [dict(o, required=False) if o["name"] in Transplanter.TOOTH_FIT else o
                    for o in objs]
    elif design.train is not None:
        from plantmech.workflows import run_seeder_forward

        objs = run_seeder_forward(design).summary["objectives"]
    else:
        from plantmech.workflows import run_seeder_inverse

        s = run_seeder_inverse(design).summary
        objs = s["trajectory_checks"] + s.get("objectives", [])
    return {"all_met": all(o["ok"] for o in objs if o.get("required", True)),
            "objectives": objs}


def _verified(out: Path, record: dict, tooth_fit: bool = True) -> dict:
    from plantmech.design import load_design
    from plantmech.outputs.files import write_json

    v = verify(load_design(out / "best.toml"), tooth_fit)
    record["verified_full_resolution"] = v
    record["feasible"] = bool(record["feasible"] and v["all_met"])
    write_json(out / "run.json", record)
    return record


def summary_lines(record: dict) -> list[str]:
    lines = [f"{record['problem']}: {record['algorithm']}, seed {record['seed']}, "
             f"{record['evaluations']} evaluations, {record['wall_s']:.1f} s"
             + (f" (first design meeting every objective after {record['first_feasible_s']:.1f} s)"
                if record.get("first_feasible_s") is not None else "")]
    from plantmech.outputs.files import check_line

    lines += [check_line(o, 34, 3, 16) for o in record["objectives"]]
    v = record.get("verified_full_resolution")
    if v is not None:
        lines.append("full-resolution re-check of best.toml: " + (
            "every objective met" if v["all_met"] else "FAILS " + ", ".join(
                o["name"] for o in v["objectives"] if not o["ok"])))
    lines.append("every objective met" if record["feasible"]
                 else "NOT every objective met: the closest design is written")
    return lines

