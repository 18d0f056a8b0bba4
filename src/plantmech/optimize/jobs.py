"""Whole optimization jobs: one problem, or the seeder's two layers in sequence.

Layered (seed 000 §4): layer 1 moves type-value points (attitude, planning limits),
then its best trajectory is inverse-designed, its gears 2 and 3 are resampled at
``points`` interpolation radii (the paper's "second layer" input) and layer 2 tunes
those radii for the speeds. Joint mode puts both layers' variables in one problem.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from plantmech.mechanisms.seeder_trains import with_train
from plantmech.optimize import PROBLEMS  # noqa: F401  (re-exported: the problem names)

DEFAULTS = {  # algorithm, generations, population
    "seeder-layer1": ("cmaes", 200, 40),
    "seeder-layer2": ("nsga2", 100, 40),
    "seeder-layered": ("cmaes", 200, 40),
    "seeder-joint": ("cmaes", 80, 40),
    "transplanter": ("nsga2", 30, 40),
    # the transplanter with the tooth fit required: staged CMA-ES (TOOTH_FIT_STAGES),
    # generations per stage
    "transplanter-tooth-fit": ("cmaes", 100, 40),
    "planetary": ("de", 30, 20),
}


def job_defaults(name: str, manufacturability: bool = True) -> tuple[str, int, int, int]:
    """(algorithm, generations, population, tooth-fit stages) ``optimize`` runs for
    problem ``name`` when none are given: the transplanter with manufacturability required
    is the staged tooth-fit job (``TOOTH_FIT_STAGES``, the generations per stage); every
    other problem counts as one stage here."""
    staged = name == "transplanter" and manufacturability
    algorithm, generations, pop = DEFAULTS.get("transplanter-tooth-fit" if staged else name,
                                               ("nsga2", 30, 40))
    return algorithm, generations, pop, len(TOOTH_FIT_STAGES) if staged else 1


@dataclass
class JobOutcome:
    feasible: bool
    record: dict
    written: list[Path]


def make_problem(design, name: str, layer2_points: int = 16, tooth_fit: bool = True):
    from plantmech.optimize import problems as P

    if name == "transplanter":
        return P.Transplanter(design, tooth_fit=tooth_fit)
    if name == "planetary":
        from plantmech.optimize.planetary_problem import PlanetaryProblem

        return PlanetaryProblem(design, manufacturability=tooth_fit)
    _takes(design, name)
    if name == "seeder-layer1":
        _needs_trajectory(design, name)
        return P.SeederLayer1(design)
    if name == "seeder-layer2":
        return P.SeederLayer2(with_train(design, layer2_points), gear_shape=tooth_fit)
    if name == "seeder-joint":
        return P.SeederJoint(design, points=layer2_points, gear_shape=tooth_fit)
    raise ValueError(f"unknown problem {name!r} (expected one of {', '.join(PROBLEMS)})")


def place_seeding_point(design):
    """(design with the seeding point where objectives 4 and 5 can hold together, the
    placement record: ``workflows.seeding_point_placement``)."""
    from plantmech.optimize.problems import shift_seeding_point
    from plantmech.workflows import seeding_point_placement

    try:
        placement = seeding_point_placement(design)
    except ValueError as exc:  # infeasible start: layer 1 has to repair it first
        return design, {"shift": 0, "rows": [], "reason": f"seeding point kept: {exc}"}
    if placement["shift"]:
        design = shift_seeding_point(design, placement["shift"])
    return design, placement


def _takes(design, name: str) -> None:
    """ValueError naming the kinds problem ``name`` takes when the design is of another
    (``kinds.Kind.problems``)."""
    from plantmech.kinds import KINDS, kind_of

    if name not in kind_of(design).problems:
        takes = [k.name for k in KINDS.values() if name in k.problems]
        raise ValueError(f"problem {name!r} needs a {' or '.join(takes) or 'known'} design")


def _taken(design, name: str) -> bool:
    from plantmech.kinds import kind_of

    return name in kind_of(design).problems


def _needs_trajectory(design, name: str) -> None:
    """Layer 1 (alone or layered) moves type-value points: refuse other designs."""
    _takes(design, name)
    if design.trajectory is None:
        raise ValueError("layer 1 moves type-value points: the design needs a [trajectory]")


def optimize(design, name: str, out: Path, design_input: str, seed: int = 0,
             generations: int | None = None, pop: int | None = None,
             algorithm: str | None = None, progress: bool = True,
             layer2_points: int = 16, manufacturability: bool = True,
             seeding_shifts: int = 0, seeding_point: str = "auto") -> JobOutcome:
    """Run one problem; ``manufacturability`` (default) makes the pitch-curve manufacturability
    checks constraints (``--no-manufacturability`` only reports them; recorded in run.json).
    best.toml is written after its full-resolution re-check (``outputs.optimization_report.
    write_run``)."""
    from plantmech.optimize.runner import run
    from plantmech.outputs.optimization_report import run_verdict, write_run

    placement = None
    if (name in ("seeder-layer1", "seeder-layered", "seeder-joint") and seeding_point == "auto"
            and not seeding_shifts and _taken(design, name)
            and design.trajectory is not None):
        design, placement = place_seeding_point(design)
        if progress:
            print(placement["reason"])

    def recheck(path):
        from plantmech.design import DesignError, load_design

        try:
            design_ = load_design(path)
        except DesignError as exc:  # a candidate the optimizer moved past a file check
            return {"all_met": False, "objectives": [
                {"name": "valid_design_file", "value": None, "unit": "", "limit": "valid",
                 "ok": False, "note": str(exc).replace("\n", " ")}]}
        return verify(design_, manufacturability)

    algo0, gen0, pop0, _ = job_defaults(name, manufacturability)
    user_gen, user_pop = generations, pop
    algorithm, generations, pop = algorithm or algo0, generations or gen0, pop or pop0
    extra = {"manufacturability_required": manufacturability}
    if placement is not None:
        extra["seeding_point"] = placement
    if name != "seeder-layered":
        if name == "seeder-layer1":
            _needs_trajectory(design, name)
            problem, res, extra["stages"] = layer1_staged(
                design, algorithm, seed, generations, pop, progress, shifts=seeding_shifts,
                gear_shape=manufacturability)
        elif name == "transplanter" and manufacturability:
            design, extra["design_choices"] = transplanter_choices(design)
            problem, res, extra["stages"] = transplanter_tooth_fit_staged(
                design, algorithm, seed, generations, pop, progress)
            prefer_standard_teeth(problem, res, extra["design_choices"])
        else:
            problem = make_problem(design, name, layer2_points, manufacturability)
            if name == "planetary" and problem.design_choices():
                extra["design_choices"] = problem.design_choices()
                if progress:
                    print("variables: " + problem.design_choices()["variables"]["value"])
            res = run(problem, algorithm, seed, generations, pop, progress,
                      stop_when_feasible=algorithm != "nsga2")
        written, rec = write_run(out, res, problem, design_input, recheck, extra)
        return JobOutcome(rec["feasible"], rec, written)
    # layered: layer 1, then layer 2 on the resampled gears of layer 1's best trajectory
    _needs_trajectory(design, name)
    from plantmech.optimize import problems as P
    from plantmech.outputs.files import write_json

    l1_dir, l2_dir = out / "layer1", out / "layer2"
    l1_dir.mkdir(exist_ok=True)
    l2_dir.mkdir(exist_ok=True)
    # the hand-offs stop layer 1 at the first path whose gears meet every agronomic
    # objective (manufacturability reported); the final layer 2 below requires it
    handoff = Layer2Handoff(seed, layer2_points, False)
    p1, r1, stages = layer1_staged(design, algorithm, seed, generations, pop, progress,
                                   shifts=seeding_shifts, hook=handoff)
    written, rec1 = write_run(l1_dir, r1, p1, design_input, recheck, dict(stages=stages))
    d1 = p1.decode(np.asarray(rec1["best_x"]))
    try:
        d2 = with_train(d1.model_copy(update={"train": None}), layer2_points)
    except ValueError:  # layer 1's best fails its full-resolution inverse design
        rec = dict(rec1, **extra)
        rec["note"] = ("layer 2 not run: layer 1's best trajectory has no feasible inverse "
                       "design at full resolution (layer1/run.json, verified_full_resolution)")
        rec["feasible"] = False
        rec["verdict"] = run_verdict(rec)
        (out / "best.toml").write_text((l1_dir / "best.toml").read_text(), encoding="utf-8")
        write_json(out / "run.json", rec)
        return JobOutcome(False, rec, written + [out / "best.toml", out / "run.json"])
    p2 = P.SeederLayer2(d2, gear_shape=manufacturability)
    r2 = run(p2, "nsga2", seed, user_gen or DEFAULTS["seeder-layer2"][1],
             user_pop or DEFAULTS["seeder-layer2"][2], progress)
    w2, rec2 = write_run(l2_dir, r2, p2, f"{design_input} (layer 1 best)", recheck,
                         source=Path(design_input))
    written += w2
    (out / "best.toml").write_text((l2_dir / "best.toml").read_text(), encoding="utf-8")
    rec = {
        "problem": "seeder-layered",
        "algorithm": f"layer 1: {r1.algorithm}, layer 2: {r2.algorithm}",
        "seed": seed,
        "evaluations": r1.evaluations + r2.evaluations,
        "wall_s": round(r1.wall_s + r2.wall_s, 3),
        "first_feasible_s": (round(handoff.found, 3) if handoff.found is not None
                             else None if r2.first_feasible_s is None
                             else round(r1.wall_s + r2.first_feasible_s, 3)),
        "handoff": handoff.record(),
        # the final design: layer 2 holds every section-4.1 objective (and the deviation
        # bound) as constraints; Table 1 bounds the planned path, i.e. layer 1's design
        "feasible": bool(rec2["feasible"] and _table1_met(r1)),
        "objectives": rec2["objectives"],
        "verified_full_resolution": rec2.get("verified_full_resolution"),
        "layer1": rec1,
        "layer2": rec2,
        **extra,
    }
    if "tradeoff" in rec2:
        rec["tradeoff"] = rec2["tradeoff"]
    if "tradeoff" in rec1:  # the path's own conflict: agronomic vs the pitch tangent angles
        rec["layer1_tradeoff"] = rec1["tradeoff"]
    rec["verdict"] = run_verdict(rec)
    write_json(out / "run.json", rec)
    for f in ("history.csv", "pareto.csv"):
        (out / f).write_text((l2_dir / f).read_text(), encoding="utf-8")
    written += [out / "best.toml", out / "run.json", out / "history.csv", out / "pareto.csv"]
    return JobOutcome(rec["feasible"], rec, written)


# Staged runs: re-centred restarts, each stage searching a box around the previous best
# (the step size of CMA-ES / the spread of NSGA-II restart with the box).
# Layer 1: with ``seeding_shifts`` > 0, first a scouting run (box half-width mm, share of the
# generations) for each place of the seeding point (moved on by 0..seeding_shifts type-value
# points: seed 000 Fig. 6 relabels it g); then stages around the best design so far.
LAYER1_SCOUT = (60.0, 0.3)
LAYER1_STAGES = ((60.0, 1.0), (20.0, 0.75), (12.0, 0.75), (8.0, 0.75))
# Transplanter with the tooth fit required (docs/optimization.md, "The transplanter's tooth
# fit"): stages re-centred on the previous best, each with limits of its own that the next
# tightens: (radius box half-width mm, ring-scale half-width, teeth difference (xv) above the
# file's limit, working pressure angle (xiv) allowed above the file's limit in deg, share of
# the generations). The last stage holds the design file's own limits.
TOOTH_FIT_STAGES = (
    (25.0, 0.10, 0.0, 15.0, 1.0),   # reshape the lobe, pressure angle relaxed
    (10.0, 0.10, 0.0, 15.0, 1.0),
    (10.0, 0.10, 2.0, 15.0, 1.0),   # a margin on the teeth difference for the re-check
    (6.0, 0.10, 0.0, 0.0, 1.0),     # the file's limits
)


def staged(design, build, stages, algorithm: str, seed: int, generations: int, pop: int,
           progress: bool = True, hook=None, final=None):
    """Run ``build(current_design, stage)`` problems one after the other, each starting
    from the previous stage's best (stage[-1] is its share of ``generations``); stop at the
    first design meeting every objective. ``final(k)``: whether stage k's problem holds the
    objectives the job is judged by (default: every stage's does); a stage that does not
    (relaxed limits) hands its best on even when it meets them, and its designs do not
    count as the first meeting every objective. Returns (last problem, its result with
    evaluations, wall time and time to the first feasible design summed over the stages,
    per-stage records)."""
    from plantmech.optimize.runner import _out_of_time as out_of_time
    from plantmech.optimize.runner import run

    current, records, tally = design, [], _Tally(seed)
    for k, stage in enumerate(stages):
        judged = final is None or final(k)
        p = build(current, stage)
        r = run(p, algorithm, seed + k, max(1, int(round(generations * stage[-1]))), pop,
                progress, stop_when_feasible=True, hook=hook,
                stage=f"stage {k + 1}/{len(stages)}" if len(stages) > 1 else None)
        tally.add(r, judged)
        current = p.decode(r.best_x)
        records.append({"stage": list(stage), "generations": r.generations,
                        "evaluations": r.evaluations, "wall_s": round(r.wall_s, 3),
                        "best_violation": float(r.best.violation[0]),
                        "feasible": bool(r.feasible)})
        if ((r.feasible and judged) or getattr(hook, "found", None) is not None
                or out_of_time()):
            break
    return p, tally.onto(r), records


class _Tally:
    """Evaluations, wall time, the first feasible design and the convergence history
    summed over several runs (the stages of one job)."""

    def __init__(self, seed: int):
        self.seed, self.evals, self.wall, self.first = seed, 0, 0.0, None
        self.history, self.stages = [], 0

    def add(self, r, judged: bool = True) -> None:
        """Count run ``r``; its first feasible design only if ``judged`` (its problem
        holds the job's own objectives, not a stage's relaxed ones). Its history joins the
        job's, each row with its stage (1, 2, ... over the job), whether the stage holds
        the job's own limits (``judged``), and the evaluations and wall time from the
        job's start."""
        if judged and r.first_feasible_s is not None and self.first is None:
            self.first = (self.wall + r.first_feasible_s,
                          self.evals + r.first_feasible_evaluations)
        for h in r.history:
            self.history.append(dict(h, evaluations=h["evaluations"] + self.evals,
                                     wall_s=round(h["wall_s"] + self.wall, 3),
                                     stage=self.stages + h.get("stage", 1),
                                     judged=bool(judged and h.get("judged", True))))
        self.stages += max((h.get("stage", 1) for h in r.history), default=1)
        self.evals += r.evaluations
        self.wall += r.wall_s

    def onto(self, r):
        """``r`` with the job's totals, history and seed (its own replaced)."""
        r.evaluations, r.wall_s = self.evals, self.wall
        r.first_feasible_s, r.first_feasible_evaluations = self.first or (None, None)
        r.history, r.seed = self.history, self.seed
        return r


def layer1_staged(design, algorithm: str, seed: int, generations: int, pop: int,
                  progress: bool = True, stages=LAYER1_STAGES, shifts: int = 0, hook=None,
                  gear_shape: bool = False):
    """Seed 000's layer 1: scout ``shifts`` + 1 places of the seeding point
    (``LAYER1_SCOUT``; none when 0), then staged runs (``LAYER1_STAGES``) from the best
    design so far. Stops at the first design meeting every objective. ``gear_shape``: the
    pitch tangent angles of both pairs are constraints (else reported, and in the
    trade-off archive)."""
    from plantmech.optimize.problems import SeederLayer1, shift_seeding_point

    def build(d, stage):
        return SeederLayer1(d, bound_mm=stage[0], gear_shape=gear_shape)

    best, records, tally = None, [], _Tally(seed)
    for k in range(shifts + 1 if shifts else 0):
        d = shift_seeding_point(design, k)
        p, r, rec = staged(d, build, (LAYER1_SCOUT,), algorithm, seed, generations, pop,
                           progress, hook)
        tally.add(r)
        records.append({"seeding_shift": k, "sections": d.trajectory.sections.model_dump(),
                        **rec[0]})
        score = -1.0 if r.feasible or getattr(hook, "found", None) is not None else float(
            r.best.violation[0])
        if best is None or score < best[0]:
            best = (score, p, r)
        if score < 0:
            break
    start = design if best is None else best[1].decode(best[2].best_x)
    if best is None or best[0] >= 0:
        p, r, rec = staged(start, build, stages, algorithm, seed + 100 * bool(shifts),
                           generations, pop, progress, hook)
        tally.add(r)
        records += rec
    else:
        _, p, r = best
    return p, tally.onto(r), records


def transplanter_tooth_fit_staged(design, algorithm: str, seed: int, generations: int,
                                  pop: int, progress: bool = True, stages=TOOTH_FIT_STAGES):
    """The transplanter with the tooth fit required, as staged runs (``staged`` over
    ``TOOTH_FIT_STAGES``): the lobe must change shape far more than the paper's objectives
    need, so the first stages search wide boxes under relaxed tooth-fit limits and each next
    stage starts from the previous best with tighter ones. A relaxed stage that finds a
    design meeting its limits hands it on; only the last stage (the file's limits) stops at
    the first design meeting every objective, as does the time budget
    (``runner.time_budget``). Returns (problem, result, per-stage records); the problem
    holds the file's limits, so its best design is judged against them (a run cut short
    before the last stage is re-evaluated under them)."""
    from plantmech.optimize.problems import Transplanter
    from plantmech.optimize.runner import _row

    own = design.limits.model_copy()

    def build(d, stage):
        box, scale, dz_margin, angle_slack, _ = stage
        d = d.model_copy(deep=True)
        d.limits = stage_limits(own, dz_margin, angle_slack)
        return Transplanter(d, radius_bound_mm=box, tooth_fit=True, ring_scale_bound=scale)

    last = len(stages) - 1
    p, r, records = staged(design, build, stages, algorithm, seed, generations, pop, progress,
                           final=lambda k: k == last)
    for rec in records:
        box, scale, dz_margin, angle_slack, share = rec["stage"]
        lim = stage_limits(own, dz_margin, angle_slack)
        rec["stage"] = {"radius_bound_mm": box, "ring_scale_bound": scale,
                        "min_internal_teeth_difference": lim.min_internal_teeth_difference,
                        "max_working_pressure_angle_deg": lim.max_working_pressure_angle_deg,
                        "share": share}
        rec["feasible_at_stage_limits"] = rec.pop("feasible")
    if p.design.limits != own:  # cut short at a relaxed stage: judge its best by the file
        d = p.decode(r.best_x)
        d.limits = own.model_copy()
        p = Transplanter(d, radius_bound_mm=stages[-1][0], tooth_fit=True,
                         ring_scale_bound=stages[-1][1])
        b = p.evaluate_batch(p.x0[None, :])
        r.best_x, r.best = p.x0, _row(b, 0)
        r.pareto_x, r.pareto_f = p.x0[None, :], b.F
        r.tradeoff = None
    return p, r, records


def stage_limits(own, dz_margin: float, angle_slack: float):
    """The file's limits (``own``) with the teeth difference (xv) raised by ``dz_margin`` and
    the working pressure angle (xiv) allowed ``angle_slack`` deg more."""
    lim = own.model_copy()
    lim.min_internal_teeth_difference = own.min_internal_teeth_difference + dz_margin
    lim.max_working_pressure_angle_deg = own.max_working_pressure_angle_deg + angle_slack
    return lim


STUB_TEETH = {"pressure_angle_deg": 25.0, "addendum": 0.8, "dedendum": 1.0}


def transplanter_choices(design):
    """What the job chooses where the design file does not fix it: the lobe's
    interpolation (the periodic spline, C2, whose radius of curvature - which the tooth
    fit reads - has no jumps at the nodes, against Hermite's C1) and the tooth system
    (stub 25 deg teeth, whose undercut limit is 8.96 equivalent teeth against the full
    depth 20 deg system's 17.10; ``prefer_standard_teeth`` goes back to the standard one if
    the final design passes with it). Returns (design to search, record of each choice)."""
    from plantmech.design import Manufacturing
    from plantmech.optimize.problems import not_transplanter

    if not _taken(design, "transplanter"):
        raise ValueError(not_transplanter(design))
    from plantmech.kinds import kind_of

    d = design.model_copy(deep=True)
    choices = {}
    field = kind_of(design).fixed_gear  # the internal gear, or the K-H-V train's sun
    g = getattr(design, field)
    if "interpolation" in g.model_fields_set:
        choices["interpolation"] = {"value": g.interpolation, "set_by": "design file"}
    else:
        getattr(d, field).interpolation = "spline"
        choices["interpolation"] = {
            "value": "spline", "set_by": "plantmech design (the file does not fix it)",
            "why": "periodic cubic spline (C2): its radius of curvature, which the tooth fit "
                   "(xiii), (xv) and the cuttable module read, is continuous; Hermite (C1) "
                   "jumps at the nodes"}
    if "manufacturing" in design.model_fields_set:
        m = design.manufacturing
        choices["tooth_system"] = {"value": tooth_system_name(m), "set_by": "design file"}
    else:
        d.manufacturing = Manufacturing(**STUB_TEETH)
        choices["tooth_system"] = {
            "value": tooth_system_name(d.manufacturing),
            "set_by": "plantmech design (the file does not fix it)",
            "why": "undercut limit 1.6 / sin^2 25 deg = 8.96 equivalent teeth against "
                   "2 / sin^2 20 deg = 17.10 for full-depth 20 deg teeth; the standard "
                   "system is kept if the final design passes with it too"}
    return d.__class__.model_validate(d.model_dump()), choices


def tooth_system_name(m) -> str:
    alpha = 20.0 if m.pressure_angle_deg is None else m.pressure_angle_deg
    kind = "full depth" if m.addendum == 1.0 else "stub"
    return (f"{kind} {alpha:g} deg (addendum {m.addendum:g} x module, dedendum "
            f"{m.dedendum:g} x module)")


def prefer_standard_teeth(problem, result, choices: dict) -> None:
    """Where the job chose the tooth system: keep the standard full-depth 20 deg system if
    the best design meets every objective with it as well (checked at full resolution);
    recorded in ``choices``."""
    from plantmech.design import Manufacturing

    ts = choices.get("tooth_system", {})
    if ts.get("set_by") == "design file":
        return
    best = problem.decode(result.best_x)
    best.manufacturing = Manufacturing()
    check = verify(best, True)
    ts["standard_20_deg_full_depth"] = {
        "all_met": check["all_met"],
        "fails": [o["name"] for o in check["objectives"]
                  if not o["ok"] and o.get("required", True)]}
    if check["all_met"]:
        problem.design.manufacturing = Manufacturing()
        ts["value"] = tooth_system_name(problem.design.manufacturing)


# Layered seeder: layer 2 is tried from layer 1's best as soon as that meets Table 1 and its
# attitude and speed residual (total relative violation) is at most this, and again each
# time the residual has halved; layer 1 stops when layer 2 meets everything from there.
HANDOFF_VIOLATION = 0.05
HANDOFF_GENERATIONS = 40


class Layer2Handoff:
    """Hook for layer 1's runs: tries a short layer 2 (``HANDOFF_GENERATIONS``) on the
    best layer-1 design when it is close (``HANDOFF_VIOLATION``); ``found``: seconds from
    the start of layer 1 to the first design meeting every objective, if one was."""

    def __init__(self, seed: int, points: int, tooth_fit: bool,
                 max_violation: float = HANDOFF_VIOLATION,
                 generations: int = HANDOFF_GENERATIONS):
        import time

        self.seed, self.points, self.tooth_fit = seed, points, tooth_fit
        self.generations = generations
        self.max_violation, self.last = max_violation, np.inf
        self.t0, self.found, self.attempts = time.perf_counter(), None, []

    def __call__(self, p1) -> bool:
        import time

        from plantmech.optimize.problems import SeederLayer2
        from plantmech.optimize.runner import run

        if self.found is not None:
            return True
        v, ok = getattr(p1, "best_score", np.inf), getattr(p1, "best_ok", None)
        if (ok is None or v <= 0 or v > self.max_violation or v > 0.5 * self.last
                or not _table1_ok(ok)):
            return False
        self.last = v
        attempt = {"at_s": round(time.perf_counter() - self.t0, 3),
                   "layer1_violation": float(v), "evaluations_layer1": p1.evaluations}
        self.attempts.append(attempt)
        try:
            d2 = with_train(p1.decode(p1.best_x).model_copy(update={"train": None}),
                            self.points)
        except ValueError:
            attempt["result"] = "no feasible inverse design at full resolution"
            return False
        p2 = SeederLayer2(d2, gear_shape=self.tooth_fit)
        r2 = run(p2, "nsga2", self.seed, self.generations, DEFAULTS["seeder-layer2"][2],
                 progress=False, stop_when_feasible=True)
        attempt.update(layer2_evaluations=r2.evaluations, layer2_wall_s=round(r2.wall_s, 3),
                       layer2_violation=float(r2.best.violation[0]))
        if r2.feasible:
            check = verify(p2.decode(r2.best_x), self.tooth_fit)
            if check["all_met"]:
                self.found = time.perf_counter() - self.t0
                attempt["result"] = "every objective met: layer 1 stops here"
                return True
            attempt["failed_full_resolution"] = {
                o["name"]: o["value"] for o in check["objectives"]
                if not o["ok"] and o.get("required", True)}
        attempt["result"] = "layer 2 fell short"
        return False

    def record(self) -> dict:
        return {"max_violation": self.max_violation, "layer2_generations": self.generations,
                "found_s": None if self.found is None else round(self.found, 3),
                "attempts": self.attempts}


TABLE1 = ("feasible_inverse", "small_ring_height", "small_ring_width", "large_ring_height",
          "large_ring_width", "cd_central_angle", "sowing_height_difference",
          "centre_to_trench_bottom")


def _table1_ok(ok_by_name: dict) -> bool:
    """A layer-1 path is inverse-designable and meets Table 1 (its attitude and speed
    residuals are layer 2's to remove); ``ok_by_name``: check name -> met."""
    return all(ok_by_name.get(n, True) for n in TABLE1)


def _table1_met(r1) -> bool:
    """Layer 1's best (a run result) passes ``_table1_ok``."""
    return _table1_ok({o["name"]: o["ok"] for o in r1.record()["objectives"]})


def verify(design, tooth_fit: bool = True) -> dict:
    """Re-evaluate a design with the full-resolution single-design model (the optimizer
    works at reduced resolution): {all_met, objectives}. ``tooth_fit`` False: the
    transplanter's tooth-fit objectives (xiii)-(xv) are reported, not required."""
    from plantmech.kinds import kind_of

    return kind_of(design).hook("optimizer_check")(design, tooth_fit)


def _tooth_fit_reported(objs: list[dict], tooth_fit: bool) -> dict:
    """{all_met, objectives}: ``tooth_fit`` False makes the gear-shape checks reported, not
    required."""
    from plantmech.optimize.problems import is_gear_shape_check

    if not tooth_fit:
        objs = [dict(o, required=False) if is_gear_shape_check(o["name"]) else o
                for o in objs]
    return {"all_met": all(o["ok"] for o in objs if o.get("required", True)),
            "objectives": objs}


def _check_transplanter(design, tooth_fit: bool = True) -> dict:
    """``verify`` of a rice transplanter: its forward job's objectives (i)-(xv)."""
    from plantmech.workflows import run_transplanter

    return _tooth_fit_reported(run_transplanter(design).summary["objectives"], tooth_fit)


def _check_seeder(design, tooth_fit: bool = True) -> dict:
    """``verify`` of a seeder: its train's objectives after its path's Table 1, or (a
    trajectory alone) layer 1's checks of the inverse design."""
    if design.train is not None:  # the train's objectives, after its path's Table 1
        from plantmech.objectives.seeder import planning_checks
        from plantmech.workflows import run_seeder_forward

        job = run_seeder_forward(design)
        objs = list(job.summary["objectives"])
        if job.trajectory is not None:
            objs = [c.as_dict() for c in planning_checks(
                job.trajectory, design.trajectory.sections.model_dump(),
                design.planning_limits)] + objs
    else:  # layer 1: Table 1, attitude, speeds and pitch curves of the inverse design
        from plantmech.workflows import run_seeder_inverse, seeder_checks

        job = run_seeder_inverse(design, speeds=True)
        objs = seeder_checks(job.summary)
        errors = [x for x in job.result.diagnostics if x.severity == "error"]
        if not job.result.feasible:
            objs.insert(0, {"name": "feasible_inverse", "value": float(max(len(errors), 1)),
                            "unit": "", "limit": "= 0 errors", "ok": False})
    return _tooth_fit_reported(objs, tooth_fit)


def summary_lines(record: dict) -> list[str]:
    lines = [f"{record['problem']}: {record['algorithm']}, random seed {record['seed']}, "
             f"{record['evaluations']} evaluations, {record['wall_s']:.1f} s"
             + (f" (first design meeting every objective after {record['first_feasible_s']:.1f} s)"
                if record.get("first_feasible_s") is not None else "")]
    from plantmech.outputs.files import check_line

    if record.get("seeding_point"):
        lines.append(record["seeding_point"]["reason"])
    lines += [check_line(o, 34, 3, 16) for o in record["objectives"]]
    v = record.get("verified_full_resolution")
    if v is not None:
        lines.append("full-resolution re-check of best.toml: " + (
            "every objective met" if v["all_met"] else "FAILS " + ", ".join(
                o["name"] for o in v["objectives"] if not o["ok"] and o.get("required", True))))
    if not record["feasible"]:
        lines += tradeoff_lines(record)
    return lines


def tradeoff_lines(record: dict, where: str = "") -> list[str]:
    """What conflicts, from an optimization record's trade-offs (``tradeoff``, and the
    layered run's ``layer1_tradeoff``: the path's own); ``where``: the run directory as the
    reader sees it (e.g. ``optimize/``)."""
    out = []
    # a layered run's trade-off is its layer 2's (the files are in layer2/)
    own = "layer2/tradeoff.csv" if "layer2" in record else "tradeoff.csv"
    for key, what, csv in (("tradeoff", "trade-off", own),
                           ("layer1_tradeoff", "trade-off of the path itself",
                            "layer1/tradeoff.csv")):
        t = record.get(key)
        if t is not None:
            out.append(f"{what} ({where}{csv}): {t['conflict']}")
    return out

