"""Orchestration of whole jobs (design file -> results -> checks).

No physics here beyond wiring: each step lives in its layer (docs/architecture.md). The
names below the imports that live in lower layers are re-exported so that
``plantmech.workflows.<name>`` keeps working (docs/api.md, examples/api.ipynb).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from plantmech.design import SeederDesign
from plantmech.gears.manufacturability import rules_for
from plantmech.geometry.deviation import trajectory_deviation, trajectory_deviation_batch
from plantmech.geometry.trajectory import ClosedTrajectory
from plantmech.mechanisms.gear_pairs import cut_limits, gear_pairs, tooth_proportions
from plantmech.mechanisms.seeder_trains import (
    inverse_settings,
    train_from_design,
    train_from_inverse,
    train_from_inverse_job,
)
from plantmech.mechanisms.transplanter_design import (
    TRANSPLANTER_PARAMS,
    simulate_transplanter,
    transplanter_travel_speed,
)
from plantmech.objectives.inverse_evaluation import (
    InfeasibleDesign,
    SeederInverseJob,
    run_seeder_inverse,
    seeder_checks,
    seeder_inverse_checks,
)
from plantmech.objectives.layer1 import (
    LAYER1_NAMES,
    inverse_speed_objectives,
    layer1_bounds,
    seeder_inverse_checks_population,
    seeding_point_placement,
)
from plantmech.objectives.seeder import (
    attitude_checks,
    locate_section_points,
)
from plantmech.objectives.seeder_design import (
    SEEDER_PARAMS,
    SeederPopulation,
    evaluate_seeder_population,
    section_angles,
    section_reference_psi,
)
from plantmech.objectives.transplanter_design import (
    evaluate_transplanter_population,
    field_setup,
    transplanter_limits,
    transplanter_population,
)

# the job wiring defined here and, re-exported from their layers, the names that lived here
# before issue 16 (``plantmech.workflows.<name>``: docs/api.md, the notebook, the tests)
__all__ = [
    "InfeasibleDesign", "LAYER1_NAMES", "SEEDER_PARAMS", "SeederForwardJob",
    "SeederInverseJob", "SeederPopulation", "TRANSPLANTER_PARAMS", "TransplanterJob",
    "cut_limits", "evaluate_seeder_population", "evaluate_transplanter_population",
    "field_setup", "gear_pairs", "inverse_settings", "inverse_speed_objectives",
    "layer1_bounds", "locate_section_points", "pitch_curve_findings", "run_gears",
    "run_seeder_forward", "run_seeder_inverse", "run_transplanter", "section_reference_psi",
    "seeder_checks",
    "seeder_inverse_checks", "seeder_inverse_checks_population", "seeding_point_placement",
    "simulate_transplanter", "tooth_proportions", "train_from_design", "train_from_inverse",
    "train_from_inverse_job", "trajectory_deviation", "trajectory_deviation_batch",
    "transplanter_limits", "transplanter_population", "transplanter_travel_speed",
]


@dataclass
class SeederForwardJob:
    """A forward simulation of a seeder train and everything derived from it."""

    design: SeederDesign
    train: object  # SeederTrain
    closure_fixes: list
    result: object  # ForwardResult
    section_psi: dict[str, float]  # rad, clockwise carrier angle from the start
    section_distance_mm: dict[str, float] | None
    travel_m_s: float
    summary: dict
    trajectory: ClosedTrajectory | None = None
    inverse: SeederInverseJob | None = None
    metrics: dict | None = None
    checks: list | None = None




def run_seeder_forward(design: SeederDesign) -> SeederForwardJob:
    """Simulate the train of ``design`` (its [train], or the inverse design of its
    [trajectory] when there is none) and evaluate every section-4.1 objective."""
    from plantmech.mechanisms.seeder_forward import simulate
    from plantmech.outputs.seeder_forward_report import forward_summary

    traj = inv = None
    if design.trajectory is not None:
        traj = ClosedTrajectory.through(np.asarray(design.trajectory.points, dtype=float))
    if design.train is None:
        inv = run_seeder_inverse(design, manufacturability=False)
        if not inv.result.feasible:
            raise InfeasibleDesign(inv)
        train, fixes = train_from_inverse(inv.result), []
        samples = design.trajectory.samples
    else:
        train, fixes = train_from_design(design)
        samples = design.train.samples
    res = simulate(train, samples=samples)
    section_psi, dist = section_angles(design, res, inv, traj)
    job = SeederForwardJob(design, train, fixes, res, section_psi, dist, 0.0, {}, traj, inv)
    _evaluate_forward(job)
    job.summary = forward_summary(job)
    return job


def _evaluate_forward(job: SeederForwardJob) -> None:
    """Every section-4.1 objective and gear check of a simulated train."""
    from plantmech.objectives.seeder import (
        gear_checks,
        ratio_ranges,
        section_objectives,
        speed_checks,
    )

    d, res = job.design, job.result
    vel = res.velocity(d.operation.carrier_speed_deg_s)
    att, zero, speeds, job.travel_m_s = section_objectives(
        res.carrier_angle, np.degrees(res.arm_angle), vel, job.section_psi,
        d.operation.travel_speed_m_s)
    checks = attitude_checks(att, d.attitude) + speed_checks(speeds, d.speed)
    gear_metrics, g_checks = gear_checks(job.train, rules_for(d))
    checks += g_checks
    job.metrics = {"attitude_deg": att, "speeds": speeds, "zero_speed": zero,
                   "ratio_range": ratio_ranges(res), **gear_metrics}
    if job.trajectory is not None:
        job.metrics["deviation_from_trajectory_mm"] = trajectory_deviation(job.trajectory,
                                                                           res.tip)
        job.metrics["return_points"] = _speeds_at_return_points(job, vel)
    job.checks = checks


def _speeds_at_return_points(job: SeederForwardJob, vel: np.ndarray) -> list[dict]:
    """Static and dynamic speed (m/s) where the tip passes the type-value points from e
    to f (seed 000 objective 5 names "the type value points q4-q8";
    ``objectives.seeder.speeds_at_points``)."""
    from plantmech.objectives.seeder import speeds_at_points

    sec = job.design.trajectory.sections
    n = len(job.trajectory.points)
    idx = (sec.e + np.arange((sec.f - sec.e) % n + 1)) % n
    res = job.result
    at = speeds_at_points(res.carrier_angle, res.tip, vel, job.trajectory.points[idx],
                          job.section_psi["e"], job.section_psi["f"], job.travel_m_s)
    return [{"point": f"q{i}", **{k: float(v[j]) for k, v in at.items()}}
            for j, i in enumerate(idx)]


# --- seed 001: rice transplanting mechanisms ------------------------------------------


@dataclass
class TransplanterJob:
    design: object  # TransplanterDesign | KHVDesign
    pair: object  # LobedInternalPair | KHVPair
    motion: object  # TransplanterMotion
    evaluation: object  # TransplanterEvaluation
    perimeter_mm: float
    gearbox_radius_mm: float
    summary: dict


def run_transplanter(design) -> TransplanterJob:
    """Simulate a transplanting mechanism and evaluate objectives (i)-(xii): the population
    evaluation with P = 1, at the design's samples and a 4096-point pitch curve."""
    from plantmech.outputs.transplanter_report import transplanter_summary

    pair, motion, perimeter, box, ev = transplanter_population(
        design, None, design.samples, 4096, True, None)
    job = TransplanterJob(design, pair, motion, ev, float(perimeter[0]), float(box[0]), {})
    job.summary = transplanter_summary(job)
    return job


# --- helpers for the optimizer ----------------------------------------------------------


# --- teeth -------------------------------------------------------------------------------


def pitch_curve_findings(design) -> list[dict]:
    """The failing manufacturability rows of the design's pitch curves
    (``gears.manufacturability`` through the full-resolution model: the seeder's
    cuttable module and working pressure angle of both pairs, the transplanter's tooth fit
    and cuttable-module margin) as ``gears.findings`` findings, so that ``plantmech gears``
    and ``plantmech design`` judge the same rules."""
    from plantmech.kinds import kind_of

    return kind_of(design).hook("pitch_findings")(design)


def objective_findings(design) -> list[dict]:
    """``pitch_curve_findings`` of a kind whose forward job (``kinds`` hook "forward_job")
    reports the manufacturability rules among its objectives (the seeder, the rice
    transplanters)."""
    import re

    from plantmech.gears.findings import finding
    from plantmech.kinds import kind_of

    rows = kind_of(design).hook("forward_job")(design).summary["objectives"]
    names = ("cuttable_module", "working_pressure_angle", "equivalent_teeth",
             "internal_teeth_difference")
    out = []
    for c in rows:
        if c["name"].startswith(names) and not c["ok"]:
            limit = float(re.search(r"[-+]?\d+(?:\.\d+)?(?:e[-+]?\d+)?", c["limit"]).group())
            out.append(finding("pitch curves", c["name"], c["value"], limit,
                               c.get("unit", ""), {}, c.get("note", "") or
                               "the pitch curves fail this manufacturability rule "
                               "(docs/manufacturability.md)"))
    return out


def run_gears(design, out, module: float | None = None, face_width: float = 12.0,
              backlash: float = 0.1, steps: int = 360, tooth: dict | None = None,
              step: bool = False, outlines: dict | None = None,
              method: str = "envelope") -> dict:
    """Generate, check and write every gear of ``design`` into ``out`` (``step``: also
    STEP files, build123d: seconds per gear, docs/manufacturing.md); returns the
    verification record (also written as verification.json) with its ``verdict``, the one
    structure of every command (``outputs.verdict``: status, ok, exit_code, failed: each
    finding as "gear check"; with ``label`` "ok" / "not manufacturable" / "files not
    written", ``text`` the line ``plantmech gears`` prints after "verdict: ", and
    ``caveats``) and ``findings`` (``gears.findings``): every failed check of the pitch
    curves, the cut outlines, the mesh and the written files. ``outlines``: a dict
    to receive each gear's cut outline and pitch polyline, {name: (polygon, (n, 2) mm)},
    both in the gear's body frame about its centre (the app draws the teeth with them).
    ``method``: how the teeth are generated (``gear_pairs``)."""
    from dataclasses import asdict

    from plantmech.gears import findings as fnd
    from plantmech.gears.modules import module_finding
    from plantmech.gears.outline import fold_backs, teeth_on_outline
    from plantmech.gears.teeth import gear_checks, mesh_check, placed
    from plantmech.outputs import gear_files as gf
    from plantmech.outputs.files import write_json

    if tooth is None:  # the design's tooth system ([manufacturing], else the standard one)
        rules = rules_for(design)
        tooth = {"pressure_angle_deg": rules.pressure_angle_deg, "addendum": rules.addendum,
                 "dedendum": rules.dedendum}
    tooth = tooth_proportions(**tooth)
    limits = cut_limits(design)
    record = {"verdict": None, "findings": [], "gears": [], "mesh": [], "files": [],
              "face_width_mm": face_width, "backlash_mm": backlash, "tooth": tooth,
              "limits": asdict(limits), "teeth_method": method, "module_choice": []}
    findings = record["findings"]
    for pair, spec in gear_pairs(design, module, backlash, tooth=tooth, method=method):
        spec = getattr(pair, "spec", spec)  # the cutter sized to the pair
        if getattr(pair, "teeth_note", None):  # a pair's tooth count, said (issue 35)
            record.setdefault("notes", []).append(pair.teeth_note)
        names = pair.name.split("_")
        done = {g["name"] for g in record["gears"]}
        for gname, poly, pitch, z, internal, cut_by, made in (
                (names[0], pair.gear_a, pair.pitch_a, pair.teeth_a, pair.internal, None,
                 getattr(pair, "made_a", None)),
                (names[1], pair.gear_b, pair.pitch_b, pair.teeth_b, False,
                 names[0] if pair.b_cut_by_a else None, getattr(pair, "made_b", None))):
            if gname in done:  # a gear in two meshes (the K-H-V middle) is cut once
                continue
            if outlines is not None:
                outlines[gname] = (poly, np.asarray(pitch.xy, dtype=float))
            c = gear_checks(gname, pitch, spec, z, internal, cut_by)
            c["teeth_made_by"] = made  # envelope or simulated, and why (gears.teeth)
            teeth = teeth_on_outline(poly, pitch.xy, spec.module, spec.addendum, internal)
            c["teeth_on_outline"] = int(len(teeth["angle_deg"]))
            c["min_tip_land_mm"] = float(teeth["tip_land_mm"].min()) \
                if len(teeth["tip_land_mm"]) else None
            findings += fnd.gear_findings(c, teeth, limits)
            spikes = fold_backs(poly)
            c["outline_fold_backs"] = int(len(spikes))
            if len(spikes):
                p0 = spikes[0]
                findings.append(fnd.finding(
                    gname, "fragmented_outline", len(spikes), 0, "fold-back vertices",
                    {"body_angle_deg": round(float(np.degrees(np.mod(np.arctan2(
                        p0[1], p0[0]), 2 * np.pi))), 2)},
                    "the outline folds back on itself (a zero-width spike or slit)"))
            for ext, writer in (("dxf", lambda p, g=poly, n=gname: gf.write_dxf(p, {n: g})),
                                ("svg", lambda p, g=poly, n=gname: gf.write_svg(p, g, n))):
                writer(out / f"{gname}.{ext}")
                record["files"].append(f"{gname}.{ext}")
            stl = gf.write_stl(out / f"{gname}.stl", poly, face_width)
            c["stl"] = stl
            c["stl_watertight"] = bool(stl["written"])
            if stl["written"]:
                record["files"].append(f"{gname}.stl")
            else:
                findings.append(fnd.finding(gname, "stl_one_body", stl["bodies"], 1, "bodies",
                                            {}, stl["why"]))
            if step:
                st = gf.write_step(out / f"{gname}.step", poly, face_width)
                c["step"] = st
                if st["written"]:
                    record["files"].append(f"{gname}.step")
                    if st["slow_import"]:
                        findings.append(fnd.finding(
                            gname, "step_import_time", st["import_cpu_s"], gf.STEP_IMPORT_LIMIT_S,
                            "s", {}, "the STEP file took longer to import back (CPU "
                            "seconds) than a CAD import in seconds allows"))
                elif st.get("skipped"):  # asked for and not written: a finding, never ok
                    if "step" not in record:
                        findings.append(fnd.finding(
                            "STEP files", fnd.NOT_WRITTEN, None, None, "", {},
                            f"--step asked for STEP files and none was written: {st['why']}"))
                    record["step"] = st["why"]
                else:
                    findings.append(fnd.finding(gname, "step_file", st.get("max_deviation_mm"),
                                                st["tolerance_mm"], "mm", {}, st["why"]))
            record["gears"].append(c)
        mesh = mesh_check(pair, steps)
        record["mesh"].append(mesh)
        findings += fnd.mesh_findings(mesh, spec.module, backlash, limits)
        # a module no stock cutter has (gears.modules)
        findings += [f for f in [module_finding(pair.name, spec.module,
                                                design.manufacturing)] if f]
        choice = getattr(pair, "module_choice", None)
        record["module_choice"].append(
            {"pair": pair.name, "module_mm": spec.module,
             "source": ("--module" if module is not None else "default" if choice
                        else getattr(pair, "module_source", None)
                        or "the design's tooth count"), **(choice or {})})
        ga, gb = placed(pair, pair.phi_a[0], pair.phi_b[0])
        gf.plot_pair(out / f"{pair.name}_mesh.png", pair, ga, gb, names)
        record["files"].append(f"{pair.name}_mesh.png")
    record["all_pairs_mesh"] = all(m["ok"] for m in record["mesh"])
    findings += pitch_curve_findings(design)
    from plantmech.outputs.caveats import limits_from_file, with_caveats
    from plantmech.outputs.verdict import verdict

    record["caveats"] = limits_from_file(design)  # the file's limits the verdict rests on
    # the modules and tooth counts the command chose for the user (gears.modules)
    record["caveats"] += [
        {"kind": "choice", "name": f"module of {c['pair']}", "value": c["standard_module_mm"],
         "text": f"module {c['standard_module_mm']:g} mm and {c['teeth']} teeth on "
                 f"{c['pair']} chosen by default (the curve closes at {c['module_mm']:.4f} "
                 "mm; --module or the file's tooth count overrides)"}
        for c in record["module_choice"] if c["source"] == "default"]
    # the verdict as every command's (forward, verify: outputs.verdict), built once: the
    # printed line, the report and the app read it
    v = record["verdict"] = verdict(problems=[f"{f['gear']} {f['check']}" for f in findings])
    v["label"] = fnd.verdict(findings)
    v["text"] = fnd.headline(record)
    with_caveats(v, record["caveats"])
    write_json(out / "verification.json", record)
    return record
