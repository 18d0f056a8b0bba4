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
    SeederInverseJob,
    run_seeder_inverse,
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
    section_psi, dist = _section_angles(design, res, inv, traj)
    job = SeederForwardJob(design, train, fixes, res, section_psi, dist, 0.0, {}, traj, inv)
    _evaluate_forward(job)
    job.summary = forward_summary(job)
    return job


def _section_angles(design: SeederDesign, res, inv, traj) -> tuple[dict, dict | None]:
    """Carrier angles (rad) of the section points a..f of a simulated train ``res``: the
    design's ``sections_deg``, else those of the inverse design ``inv`` behind it, else
    located on its tip path (with the distances it misses them by, mm)."""
    if design.train is not None and design.train.sections_deg is not None:
        return {k: float(np.radians(v))
                for k, v in design.train.sections_deg.model_dump().items()}, None
    if inv is not None:
        pc = inv.result.point_carrier_angle
        return {k: float(pc[i]) for k, i in inv.sections.items()}, None
    from plantmech.objectives.seeder import locate_section_points

    return locate_section_points(res.tip, res.carrier_angle, traj.points,
                                 design.trajectory.sections.model_dump())


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


class InfeasibleDesign(Exception):
    """The inverse design behind a forward job is infeasible (see its diagnostics)."""

    def __init__(self, job: SeederInverseJob):
        super().__init__("the inverse design is infeasible")
        self.job = job


@dataclass
class SeederPopulation:
    """A population of variants of one design's [train] (radii of gears 2 and 3)."""

    motion: object  # PopulationMotion
    evaluation: object  # PopulationEvaluation
    section_psi: np.ndarray  # (P, 6) rad


def section_reference_psi(design: SeederDesign) -> np.ndarray:
    """Carrier angles (6,) rad where the design's own train passes the section points
    a..f (the forward job's ``section_psi``: its simulation and section location, without
    its objectives): where ``evaluate_seeder_population`` searches each variant's.
    Depends on the design only, so it is kept per design content (the last 16; a
    read-only array)."""
    key = design.model_dump_json()
    hit = _REFERENCE_PSI.get(key)
    if hit is not None:
        return hit
    if design.train is None:
        section_psi = run_seeder_forward(design).section_psi
    else:
        from plantmech.mechanisms.seeder_forward import simulate

        train, _ = train_from_design(design)
        traj = (None if design.trajectory is None else
                ClosedTrajectory.through(np.asarray(design.trajectory.points, dtype=float)))
        res = simulate(train, samples=design.train.samples)
        section_psi, _ = _section_angles(design, res, None, traj)
    out = np.array([section_psi[k] for k in "abcdef"])
    out.flags.writeable = False
    if len(_REFERENCE_PSI) >= 16:
        _REFERENCE_PSI.pop(next(iter(_REFERENCE_PSI)))
    _REFERENCE_PSI[key] = out
    return out


_REFERENCE_PSI: dict[str, np.ndarray] = {}


# per-design overrides of [train] / [operation] scalars for populations (name -> (P,));
# the names are the design file's fields, "backlash_deg" the train's angular play
SEEDER_PARAMS = ("L1_mm", "L2_mm", "initial_carrier_angle_deg", "initial_arm_angle_deg",
                 "gear2_contact_angle_deg", "gear3_contact_angle_deg", "travel_speed_m_s",
                 "backlash_deg")


def evaluate_seeder_population(design: SeederDesign, radii2=None, radii3=None,
                               samples: int = 720, dense: int = 2048,
                               window_deg: float = 40.0,
                               reference_psi: np.ndarray | None = None,
                               params: dict | None = None) -> SeederPopulation:
    """Simulate and evaluate P variants of ``design``'s train at once.

    radii2, radii3: (P, N) interpolation radii (mm) at the design's angles (default:
    the design's own, P = 1). Centre distances follow the design's closure method
    ("centre_distance" or "scale": solved per design — the two give the same motion, the
    turn depends on r / a only; otherwise as given, unclosed pairs show in
    ``metrics['closure_error_rad']``). Section points: the design's ``sections_deg``,
    or located on each variant's path within +-window of where the base design passes
    them (``reference_psi``: ``section_reference_psi(design)`` if already known).
    ``params``: per-design values (name -> (P,)) of the scalars in ``SEEDER_PARAMS`` (the
    [train] fields L1_mm, L2_mm, initial angles and contact angles of gears 2 and 3 in deg,
    [operation] travel_speed_m_s; backlash_deg: the train's angular play, see
    ``mechanisms.backlash.backlash_offset``), the design's own value otherwise.
    """
    from plantmech.mechanisms.seeder_batch import simulate_population
    from plantmech.objectives.seeder_population import evaluate_population, locate_sections

    t = design.train
    if t is None:
        raise ValueError("population evaluation needs a [train]")
    if (t.gear2.angles_deg or t.gear2.angles()) != (t.gear3.angles_deg or t.gear3.angles()):
        raise ValueError("population evaluation needs gears 2 and 3 at the same angles")
    nodes = np.radians(t.gear2.angles())
    R2 = np.atleast_2d(t.gear2.radii_mm if radii2 is None else radii2).astype(float)
    R3 = np.atleast_2d(t.gear3.radii_mm if radii3 is None else radii3).astype(float)
    solve = t.closure in ("centre_distance", "scale")
    params = params or {}
    unknown = sorted(set(params) - set(SEEDER_PARAMS))
    if unknown:
        raise ValueError(f"unknown population parameter(s) {', '.join(unknown)} (expected "
                         f"{', '.join(SEEDER_PARAMS)})")
    own = {"L1_mm": t.L1_mm, "L2_mm": t.L2_mm,
           "initial_carrier_angle_deg": t.initial_carrier_angle_deg,
           "initial_arm_angle_deg": t.initial_arm_angle_deg,
           "gear2_contact_angle_deg": t.gear2.contact_angle_deg,
           "gear3_contact_angle_deg": t.gear3.contact_angle_deg}
    v = {k: np.asarray(params.get(k, x), dtype=float) for k, x in own.items()}
    c2, c3 = np.radians(t.gear2.contact_angle_deg), np.radians(t.gear3.contact_angle_deg)
    dwell = t.dwell
    motion = simulate_population(
        nodes, R2, R3, v["L1_mm"], v["L2_mm"], None if solve else t.a1_mm,
        None if solve else t.a2_mm, np.radians(v["initial_carrier_angle_deg"]),
        np.radians(v["initial_arm_angle_deg"]),
        contact2_0=np.radians(v["gear2_contact_angle_deg"]),
        contact3_0=np.radians(v["gear3_contact_angle_deg"]), samples=samples, dense=dense,
        kind=t.interpolation, dwell_start=np.radians(dwell.start_deg) if dwell else None,
        dwell_sector=np.radians(dwell.sector_deg) if dwell else 0.0,
        backlash=(np.radians(params["backlash_deg"]) if "backlash_deg" in params else None))
    if t.sections_deg is not None:
        sec = np.radians([getattr(t.sections_deg, k) for k in "abcdef"])
        section_psi = np.broadcast_to(sec, (R2.shape[0], 6))
    else:
        ref = section_reference_psi(design) if reference_psi is None else reference_psi
        pts = np.asarray(design.trajectory.points)[
            [getattr(design.trajectory.sections, k) for k in "abcdef"]]
        section_psi = locate_sections(motion.tip, motion.carrier_angle, pts, ref,
                                      np.radians(window_deg))
    g = dict(nodes=nodes, kind=t.interpolation)
    ev = evaluate_population(
        motion, section_psi, design.operation.carrier_speed_deg_s,
        params.get("travel_speed_m_s", design.operation.travel_speed_m_s), design.attitude,
        design.speed,
        gear2={**g, "radii": R2, "contact0": c2}, gear3={**g, "radii": R3, "contact0": c3},
        rules=rules_for(design))
    return SeederPopulation(motion, ev, section_psi)


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
    import re

    from plantmech.gears.findings import finding

    if design.mechanism == "planetary":
        from plantmech.trains.gearing import pitch_curve_findings as train_findings

        return train_findings(design)
    if design.mechanism == "sugarcane_seeder":
        rows = run_seeder_forward(design).summary["objectives"]
    else:
        rows = run_transplanter(design).summary["objectives"]
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
    verification record (also written as verification.json) with its ``verdict`` ("ok" /
    "not manufacturable") and ``findings`` (``gears.findings``): every failed check of the
    pitch curves, the cut outlines, the mesh and the written files. ``outlines``: a dict
    to receive each gear's cut outline and pitch polyline, {name: (polygon, (n, 2) mm)},
    both in the gear's body frame about its centre (the app draws the teeth with them).
    ``method``: how the teeth are generated (``gear_pairs``)."""
    from dataclasses import asdict

    from plantmech.gears import findings as fnd
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
              "limits": asdict(limits), "teeth_method": method}
    findings = record["findings"]
    for pair, spec in gear_pairs(design, module, backlash, tooth=tooth, method=method):
        spec = getattr(pair, "spec", spec)  # the cutter sized to the pair
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
                elif st.get("skipped"):
                    record["step"] = st["why"]
                else:
                    findings.append(fnd.finding(gname, "step_file", st.get("max_deviation_mm"),
                                                st["tolerance_mm"], "mm", {}, st["why"]))
            record["gears"].append(c)
        mesh = mesh_check(pair, steps)
        record["mesh"].append(mesh)
        findings += fnd.mesh_findings(mesh, spec.module, backlash, limits)
        ga, gb = placed(pair, pair.phi_a[0], pair.phi_b[0])
        gf.plot_pair(out / f"{pair.name}_mesh.png", pair, ga, gb, names)
        record["files"].append(f"{pair.name}_mesh.png")
    record["all_pairs_mesh"] = all(m["ok"] for m in record["mesh"])
    findings += pitch_curve_findings(design)
    record["verdict"] = fnd.verdict(findings)
    write_json(out / "verification.json", record)
    return record
