"""The main job, ``plantmech design``: from a planned trajectory (or a published parameter set)
to gears a workshop can cut, with one verdict.

Job wiring only (no physics): check the design with the full-resolution model; if anything is
not met, optimize it with every objective and the manufacturability checks required
(``optimize.jobs.optimize``: the seeder's layered problem from a trajectory, its layer 2 from a
[train], the transplanter's staged problem, which chooses the lobe's interpolation and the
tooth system where the file does not fix them: recorded in summary.json's optimize stage and in
design.toml's header); cut the teeth of the final design when its pitch curves
pass the manufacturability checks (``workflows.run_gears``), never for curves that fail them;
write ``design.toml`` (the final design), ``summary.json`` and the subdirectories ``optimize/``
and ``gears/``.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path

from plantmech.outputs.verdict import verdict


@dataclass
class DesignOutcome:
    record: dict
    written: list[Path] = field(default_factory=list)

    @property
    def verdict(self) -> dict:
        return self.record["verdict"]


def problem_for(design) -> str | None:
    """The optimization problem that designs this file's mechanism (``kinds.Kind.
    default_problem``), or None when nothing may move (``Kind.unoptimized_reason``)."""
    from plantmech.kinds import kind_of

    return kind_of(design).default_problem(design)


def _require_planetary_curves(design) -> None:
    """ValueError naming the field when a planetary file gives a [trajectory] (inverse
    design's input) instead of its pitch curves."""
    from plantmech.trains.spec import TrainSpecError, require_curves

    try:
        require_curves(design)
    except TrainSpecError as exc:
        raise ValueError(f"field '{exc}") from None


def _stopped_by_time(record: dict) -> bool:
    """Did a time budget cut any run of this optimization record (layered: either layer)?"""
    recs = [record] + [record[k] for k in ("layer1", "layer2") if isinstance(record.get(k),
                                                                             dict)]
    return any(r.get("settings", {}).get("stopped_by_time_budget") for r in recs)


def _failed(check: dict) -> list[str]:
    return [o["name"] for o in check["objectives"] if not o["ok"] and o.get("required", True)]


def run_design(design, out: Path, design_input: str, seed: int = 0, progress: bool = True,
               generations: int | None = None, module: float | None = None,
               time_limit_s: float | None = None, say=print) -> DesignOutcome:
    """Run the whole job into ``out`` (an existing, empty directory); ``time_limit_s`` bounds
    the optimization's wall time (``optimize.runner.time_budget``: the runs stop at the end
    of the generation that passes it, and the record says so)."""
    from plantmech.optimize.jobs import optimize, verify
    from plantmech.outputs.files import write_json
    from plantmech.outputs.optimization_report import choice_lines, design_toml

    t0 = time.perf_counter()
    stages, written = [], []
    rec = {"name": design.name, "mechanism": design.mechanism, "input": design_input,
           "seed": seed, "stages": stages}

    def stage(name: str, **info):
        info = {"stage": name, "elapsed_s": round(time.perf_counter() - t0, 2), **info}
        stages.append(info)
        return info

    from plantmech.kinds import kind_of

    kind = kind_of(design)
    if kind.has("require_train"):
        kind.hook("require_train")(design)  # ValueError naming the field
    say("[1/3] checking the design at full resolution (objectives and manufacturability)")
    # a trajectory alone is no gear train yet: optimize it
    start = None if kind.trajectory_only(design) else design
    final, check, opt_rec = design, None, {}
    if start is not None:
        check = verify(design, True)
        stage("check", all_met=check["all_met"], failed=_failed(check))
    if check is not None and check["all_met"]:
        say("      every objective and manufacturability check met: no optimization needed")
    elif problem_for(design) is None:
        # nothing the job may move: the file names its free fields, or the design stands
        say(f"      not met: {', '.join(_failed(check))}")
        say(f"[2/3] not optimized: {kind.unoptimized_reason[1]}")
        stage("optimize", skipped=kind.unoptimized_reason[0])
    else:
        name = problem_for(design)
        if check is not None:
            say(f"      not met: {', '.join(_failed(check))}")
        say(f"[2/3] optimizing ({name}, random seed {seed}; every objective and manufacturability "
            "required)")
        opt_dir = out / "optimize"
        opt_dir.mkdir()
        from plantmech.optimize.runner import time_budget

        with time_budget(time_limit_s):
            outcome = optimize(design, name, opt_dir, design_input, seed=seed,
                               generations=generations, progress=progress,
                               manufacturability=True)
        written += outcome.written
        from plantmech.design import load_design

        final = load_design(opt_dir / "best.toml")
        check = outcome.record.get("verified_full_resolution") or verify(final, True)
        cut = _stopped_by_time(outcome.record)
        if cut:
            say(f"      stopped by the time limit ({time_limit_s:g} s)")
        opt_rec = outcome.record
        choices = opt_rec.get("design_choices", {})
        for line in choice_lines(opt_rec):
            say(f"      {line}")
        stage("optimize", problem=name, feasible=outcome.feasible, stopped_by_time_limit=cut,
              design_choices=choices,
              evaluations=outcome.record.get("evaluations"),
              failed=_failed(check), tradeoff=outcome.record.get("tradeoff", {}).get(
                  "conflict"), path_tradeoff=outcome.record.get("layer1_tradeoff", {}).get(
                  "conflict"))
        say(f"      {'met' if outcome.feasible else 'NOT met'} after "
            f"{outcome.record.get('evaluations')} evaluations"
            + ("" if outcome.feasible else f": {', '.join(_failed(check)) or 'see run.json'}"))
        if not outcome.feasible:
            from plantmech.optimize.jobs import tradeoff_lines

            for line in tradeoff_lines(outcome.record, "optimize/"):
                say(f"      {line}")
            if name == "seeder-layered":
                say("      why a seeder path can force uncuttable gears: "
                    "plantmech docs manufacturability")
    final, check, std = _standard_module(final, check, verify)
    if std is not None:
        rec["standard_module"] = std
        if "tried" in std:  # a stage only where the job tried to scale the gears
            stage("standard_module", **{k: v for k, v in std.items() if k != "line"})
        say(f"      {std['line']}")
    header = (f"Design made by `plantmech design` from {design_input} (random seed {seed}); "
              "see summary.json" + "".join(f"\n{line}" for line in choice_lines(opt_rec))
              + (f"\n{std['line']}" if std is not None else ""))
    (out / "design.toml").write_text(design_toml(final, header, Path(design_input)),
                                     encoding="utf-8")
    written.append(out / "design.toml")
    failed = _failed(check)
    cuttable = not any(n.startswith(("cuttable_module", "working_pressure_angle",
                                     "equivalent_teeth", "internal_teeth_difference"))
                       for n in failed)
    gears = None
    if cuttable:
        say("[3/3] cutting the teeth, checking the mesh, writing the workshop files")
        from plantmech.workflows import run_gears

        gdir = out / "gears"
        gdir.mkdir()
        gears = run_gears(final, gdir, module=module)
        written += [gdir / f for f in gears["files"]] + [gdir / "verification.json"]
        gears_ok = gears["verdict"]["ok"]
        stage("gears", ok=gears_ok, files=len(gears["files"]))
        if not gears_ok:
            failed += [f"gears: {f['gear']} {f['check']}" for f in gears["findings"]]
    else:
        say("[3/3] teeth not cut: the pitch curves fail the manufacturability checks")
        stage("gears", ok=False, skipped="the pitch curves fail the manufacturability checks")
        rec["gears_skipped"] = True
    rec["final_checks"] = check["objectives"]
    rec["verdict"] = verdict(problems=failed)
    from plantmech.outputs.caveats import caveats

    # what the verdict rests on: limits from the file, thin margins, the job's changes
    rec["caveats"] = caveats(design, check["objectives"], final,
                             dict(opt_rec, standard_module=rec.get("standard_module")))
    say("      writing the report (report.html, mechanism.gif)")
    written += _report(final, out, rec, gears)
    rec["wall_s"] = round(time.perf_counter() - t0, 2)
    write_json(out / "summary.json", rec)
    written.append(out / "summary.json")
    return DesignOutcome(rec, written)


def _scaled(design, scale: float):
    """The transplanter ``design`` with its gear's pitch curve (and a given centre distance)
    scaled by ``scale``: the same ratio law, the module times ``scale``."""
    from plantmech.design import load_design

    raw = design.model_dump(exclude_none=True, mode="json")
    from plantmech.kinds import kind_of

    gear = raw[kind_of(design).fixed_gear]
    gear["radii_mm"] = [r * scale for r in gear["radii_mm"]]
    if "centre_distance_mm" in gear:
        gear["centre_distance_mm"] *= scale
    return load_design(raw)


def _standard_module(final, check, verify):
    """(design, check, record or None): a transplanter whose gear carries a fixed tooth count
    at a module no stock cutter has (``gears.modules``) and meets every objective is scaled
    to the nearest standard module (series I first), if the scaled design still meets every
    objective at full resolution; the record says what was tried."""
    from plantmech.gears import modules
    from plantmech.kinds import kind_of

    if not kind_of(final).standard_module_scaling or check is None or not check["all_met"]:
        return final, check, None
    row = next((o for o in check["objectives"] if o["name"] == "module"), None)
    if row is None or row["value"] is None:
        return final, check, None
    m, man = float(row["value"]), final.manufacturing
    mods = modules.available(man)
    if modules.is_standard(m, mods):
        return final, check, {"module_mm": round(m, 6), "standard": True, "scale": 1.0,
                              "line": f"standard module: {m:g} mm (ISO 54 series "
                                      f"{modules.series_of(m) or '-'}), no change"}
    if man.special_module:
        return final, check, {"module_mm": round(m, 6), "standard": False, "scale": 1.0,
                              "line": f"module {m:.4f} mm kept: the file allows a special "
                                      "module ([manufacturing] special_module = true)"}
    tried = []
    for m_std, scale in modules.scale_candidates(m, mods, final.limits.min_module_mm):
        # a hair above (the check's module is rounded to 1e-6 mm), so the scaled module is
        # not a rounding below a limit it meets; well inside the cutter tolerance RTOL
        cand = _scaled(final, scale * (1 + 1e-5))
        c = verify(cand, True)
        tried.append({"module_mm": m_std, "scale": round(scale, 6), "all_met": c["all_met"],
                      "failed": _failed(c)})
        if c["all_met"]:
            series = modules.series_of(m_std)
            return cand, c, {
                "module_mm": m_std, "standard": True, "from_module_mm": round(m, 6),
                "scale": round(scale, 6), "tried": tried,
                "line": f"standard module: {m:.4f} -> {m_std:g} mm (ISO 54 series {series}): "
                        f"the gear's pitch curve scaled by {scale:.4f}, every objective "
                        "re-checked at full resolution"}
    why = "; ".join(f"{t['module_mm']:g} mm fails {', '.join(t['failed'])}" for t in tried) \
        or "no standard module within 10 % at or above the smallest module (xi)"
    return final, check, {"module_mm": round(m, 6), "standard": False, "tried": tried,
                          "line": f"module {m:.4f} mm is not standard and was kept: {why}"}


def _report(final, out: Path, rec: dict, gears: dict | None) -> list[Path]:
    """report.html (and mechanism.gif): the final design's objectives, plots and animation,
    the gears' findings and drawings, and the job's verdict."""
    from plantmech.kinds import kind_of
    from plantmech.outputs.report import (
        findings_rows,
        write_report,
    )
    from plantmech.outputs.verdict import verdict_line

    summary, figures, animation = kind_of(final).hook("report_parts")(final)
    drawings = []
    # why an optimization fell short: its trade-off fronts (layer 2's, and the path's own)
    layered = (out / "optimize" / "layer2").is_dir()
    for name in (("optimize/layer2/tradeoff.png", "optimize/layer1/tradeoff.png") if layered
                 else ("optimize/tradeoff.png",)):
        if not rec["verdict"]["ok"] and (out / name).is_file():
            figures.append((name, out / name))
    summary = dict(summary, stages=rec["stages"])
    if gears is not None:
        gdir = out / "gears"
        summary["gear_checks"] = findings_rows(gears)
        figures += [(f, gdir / f) for f in gears["files"] if f.endswith(".png")]
        drawings = [(f, gdir / f) for f in gears["files"] if f.endswith(".svg")]
    v = rec["verdict"]
    summary["caveats"] = [c["text"] for c in rec.get("caveats", [])]
    return write_report(out / "report.html", summary, figures, animation,
                        gear_drawings=drawings, title=f"{final.name}: plantmech design",
                        command="plantmech design",
                        verdict=(v["ok"], verdict_line(v, "every objective and "
                                                          "manufacturability check met, the "
                                                          "gears cut and checked")))


def _job_parts(job):
    from plantmech.outputs.report import job_animation, job_figures

    return job.summary, list(job_figures(job)), job_animation(job)


def _job_parts_seeder(design):
    """(summary, figures, animation) of a seeder's train for the report: its forward run."""
    from plantmech.workflows import run_seeder_forward

    return _job_parts(run_seeder_forward(design))


def _job_parts_transplanter(design):
    """(summary, figures, animation) of a rice transplanter for the report."""
    from plantmech.workflows import run_transplanter

    return _job_parts(run_transplanter(design))


def _animation_seeder(design):
    """The seeder's train animated over one cycle (its forward run)."""
    from plantmech.outputs.report import seeder_forward_animation
    from plantmech.workflows import run_seeder_forward

    return seeder_forward_animation(run_seeder_forward(design))


def _animation_transplanter(design):
    """A rice transplanter (differential or K-H-V) animated over one cycle."""
    from plantmech.outputs.report import transplanter_animation
    from plantmech.workflows import run_transplanter

    return transplanter_animation(run_transplanter(design))


def _animation_planetary(design):
    """A general planetary train animated over one cycle at the file's resolution."""
    from plantmech.outputs.report import planetary_animation
    from plantmech.trains.model import simulate
    from plantmech.trains.spec import build_from_design

    return planetary_animation(design, simulate(build_from_design(design), design.samples))


def _planetary_parts(design):
    """(summary, figures, animation) of a general planetary train for the report: its
    forward run at the file's resolution (as ``plantmech forward``)."""
    from plantmech.objectives.planetary import checks, motion_objectives
    from plantmech.outputs import planetary_plots as pp
    from plantmech.outputs.planetary_report import planetary_summary
    from plantmech.outputs.report import planetary_animation
    from plantmech.trains.model import simulate
    from plantmech.trains.spec import build_from_design

    motion = simulate(build_from_design(design), design.samples)
    values = motion_objectives(motion, design.carrier.speed_deg_s)
    summary = planetary_summary(design, motion, values, checks(values, design.limits))
    return summary, pp.forward_figures(design, motion), planetary_animation(design, motion)
