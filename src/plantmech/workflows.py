"""Orchestration of whole jobs (design file -> results -> checks).

No physics here beyond wiring: each step lives in its layer.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from plantmech.design import SeederDesign
from plantmech.gears.manufacturability import rules_for
from plantmech.geometry.trajectory import ClosedTrajectory
from plantmech.mechanisms.seeder_inverse import (
    DwellSpec,
    InverseResult,
    InverseSettings,
    inverse_design,
)
from plantmech.objectives.seeder import attitude_by_section, attitude_checks, planning_checks
from plantmech.outputs.seeder_report import summary


@dataclass
class SeederInverseJob:
    design: SeederDesign
    trajectory: ClosedTrajectory
    result: InverseResult
    summary: dict

    @property
    def sections(self) -> dict[str, int]:
        return self.design.trajectory.sections.model_dump()


def inverse_settings(design: SeederDesign) -> InverseSettings:
    gt = design.gear_train
    sec = design.trajectory.sections.model_dump()
    dwell = None
    if gt.dwell is not None and gt.dwell.enabled:
        dwell = DwellSpec(start=sec[gt.dwell.start], end=sec[gt.dwell.end],
                          anchor=sec[gt.dwell.anchor], edge_radius=gt.dwell.edge_radius_mm)
    return InverseSettings(samples=design.trajectory.samples, a1=gt.a1_mm, a2=gt.a2_mm,
                           split_exponent=gt.split_exponent,
                           min_pitch_radius=gt.min_pitch_radius_mm, dwell=dwell)


def run_seeder_inverse(design: SeederDesign, manufacturability: bool = True) -> SeederInverseJob:
    """Inverse design of the trajectory, Table 1, attitude and (``manufacturability``) the
    manufacturability of the designed pitch curves (``objectives.seeder.gear_checks``)."""
    traj = ClosedTrajectory.through(np.asarray(design.trajectory.points, dtype=float))
    res = inverse_design(traj, inverse_settings(design))
    sections = design.trajectory.sections.model_dump()
    planning = planning_checks(traj, sections, design.planning_limits)
    att = checks = None
    if res.arm_angle is not None:
        arm = res.arm_angle_realized if res.arm_angle_realized is not None else res.arm_angle
        att = attitude_by_section(res.carrier_angle, np.degrees(arm),
                                  res.point_carrier_angle, sections)
        checks = attitude_checks(att, design.attitude)
    summ = summary(res, design, planning, att, checks or [])
    if res.feasible and manufacturability:  # can the designed pitch curves be cut?
        from plantmech.objectives.seeder import gear_checks
        from plantmech.verification import train_from_inverse

        metrics, g_checks = gear_checks(train_from_inverse(res), rules_for(design))
        summ["manufacturing"] = metrics["manufacturing"]
        summ["manufacturing_checks"] = [c.as_dict() for c in g_checks]
    return SeederInverseJob(design, traj, res, summ)


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


def train_from_design(design: SeederDesign):
    """(train, closure fixes) from the design file's [train] table (mm/deg -> mm/rad)."""
    from plantmech.mechanisms.seeder_forward import GearPoints, assemble_train

    t = design.train
    pts = [GearPoints(np.radians(g.angles()), np.asarray(g.radii_mm, dtype=float),
                      float(np.radians(g.contact_angle_deg))) for g in (t.gear2, t.gear3)]
    return assemble_train(
        t.L1_mm, t.L2_mm, t.a1_mm, t.a2_mm, pts[0], pts[1],
        carrier0=float(np.radians(t.initial_carrier_angle_deg)),
        arm0=float(np.radians(t.initial_arm_angle_deg)),
        dwell_start=float(np.radians(t.dwell.start_deg)) if t.dwell else None,
        dwell_sector=float(np.radians(t.dwell.sector_deg)) if t.dwell else 0.0,
        kind=t.interpolation, closure=t.closure,
        tolerance=float(np.radians(t.closure_tolerance_deg)),
        min_radius=t.min_pitch_radius_mm)


def run_seeder_forward(design: SeederDesign) -> SeederForwardJob:
    """Simulate the train of ``design`` (its [train], or the inverse design of its
    [trajectory] when there is none) and evaluate every section-4.1 objective."""
    from plantmech.mechanisms.seeder_forward import simulate
    from plantmech.outputs.seeder_forward_report import forward_summary
    from plantmech.verification import train_from_inverse

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


def _distance_to_closed_polyline(points: np.ndarray, poly: np.ndarray) -> np.ndarray:
    """Distance (mm) of each point to a closed polyline: nearest vertex (k-d tree),
    then the perpendicular foot on its two adjacent segments."""
    from scipy.spatial import cKDTree

    _, k = cKDTree(poly).query(points)
    n = len(poly)
    best = np.hypot(*(points - poly[k]).T)
    for a, b in ((k - 1) % n, k), (k, (k + 1) % n):
        seg = poly[b] - poly[a]
        t = np.einsum("ij,ij->i", points - poly[a], seg) / np.maximum(
            np.einsum("ij,ij->i", seg, seg), 1e-300)
        foot = poly[a] + np.clip(t, 0.0, 1.0)[:, None] * seg
        best = np.minimum(best, np.hypot(*(points - foot).T))
    return best


def trajectory_deviation(traj: ClosedTrajectory, tip: np.ndarray, samples: int = 80000) -> dict:
    """Distances (mm) between a simulated tip path (closed, sampled) and the planned
    curve: largest distance of a tip sample from the curve, and of a curve point from
    the tip path (together the Hausdorff distance), point-to-segment. The second is
    limited by the tip sampling: a chord of the sampled path cuts sharp corners."""
    _, u = traj.arc_length_samples(samples)
    plan = traj(u)
    d1 = _distance_to_closed_polyline(tip, plan)
    d2 = _distance_to_closed_polyline(plan, tip)
    return {"max_tip_to_plan": float(d1.max()), "rms_tip_to_plan": float(np.sqrt(np.mean(d1**2))),
            "max_plan_to_tip": float(d2.max())}


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


# per-design overrides of scalar design values for populations (name -> (P,) array): the
# design file's fields, and three tolerances the file has no field for:
# "carrier_offset_mm" (the planet axis that much farther from O than the pair's centre
# distance: a carrier-length error), "backlash_deg" (the planet's angular play against its
# drive) and "plant_spacing_mm" ([field]: the spacing the machine's travel speed gives)
TRANSPLANTER_PARAMS = ("initial_angle_deg", "initial_phase_deg", "S_mm", "H1_mm", "beta_deg",
                       "box_x_mm", "box_y_mm", "box_inclination_deg", "carrier_offset_mm",
                       "backlash_deg", "plant_spacing_mm")


def _param(design, params, name):
    if params and name in params:
        return np.asarray(params[name], dtype=float)
    return {"initial_angle_deg": lambda: design.carrier.initial_angle_deg,
            "initial_phase_deg": lambda: design.internal_gear.initial_phase_deg,
            "S_mm": lambda: design.arm.S_mm, "H1_mm": lambda: design.arm.H1_mm,
            "beta_deg": lambda: design.arm.beta_deg,
            "box_x_mm": lambda: design.seedling_box.x_mm,
            "box_y_mm": lambda: design.seedling_box.y_mm,
            "box_inclination_deg": lambda: design.seedling_box.inclination_deg,
            "carrier_offset_mm": lambda: 0.0,
            "plant_spacing_mm": lambda: design.field.plant_spacing_mm}[name]()


def transplanter_travel_speed(design) -> float:
    """The machine's travel speed v (m/s) that one plant per arm per carrier turn at the
    design's plant spacing s needs: v = s J omega / 360 (s in mm, J arms, omega the
    carrier speed in deg/s) / 1000."""
    return (design.field.plant_spacing_mm * design.carrier.arms
            * design.drive.carrier_speed_deg_s / 360.0 / 1000.0)


def field_setup(design, params=None):
    from plantmech.objectives.transplanter import FieldSetup

    b, f = design.seedling_box, design.field
    return FieldSetup(
        box_x=_param(design, params, "box_x_mm"), box_y=_param(design, params, "box_y_mm"),
        box_inclination_deg=_param(design, params, "box_inclination_deg"),
        mat_thickness=b.mat_thickness_mm, sample=b.sample_mm, box_length=b.length_mm,
        door_length=b.door_length_mm, floor_thickness=b.floor_thickness_mm,
        planting_depth=f.planting_depth_mm,
        spacing_nominal=_param(design, params, "plant_spacing_mm"),
        spacing_range=tuple(f.spacing_range_mm), check_height=f.check_height_mm,
        carrier_speed_deg_s=design.drive.carrier_speed_deg_s,
        needle_length=design.arm.needle_length_mm,
        outline={k: list(v) for k, v in design.arm.outline.items()} if design.arm.outline
        else None)


def transplanter_limits(design):
    """The design file's limits of objectives (iii)-(xii)."""
    return design.limits


def simulate_transplanter(design, radii=None, samples: int | None = None, dense: int = 4096,
                          params: dict | None = None):
    """(pair, motion, perimeter (P,), gearbox radius (P,)) for ``design`` or for P
    variants of its gear radii (P, N) and of the scalars in ``params`` (name -> (P,),
    names in TRANSPLANTER_PARAMS). A carrier offset or a backlash moves the planet, not
    the gears: the perimeter and the gearbox are the pair's."""
    from plantmech.gears.internal import internal_perimeter, lobed_internal_pair
    from plantmech.mechanisms.transplanter import (
        ArmGeometry,
        khv_pair,
        simulate_differential,
        simulate_khv,
    )

    samples = samples or design.samples
    arm = ArmGeometry(_param(design, params, "S_mm"), _param(design, params, "H1_mm"),
                      np.radians(_param(design, params, "beta_deg")))
    carrier0 = np.radians(_param(design, params, "initial_angle_deg"))
    offset = _param(design, params, "carrier_offset_mm")
    play = (np.radians(params["backlash_deg"]) if params and "backlash_deg" in params
            else None)
    if design.mechanism == "rice_transplanter":
        g = design.internal_gear
        r = np.atleast_2d(g.radii_mm if radii is None else radii).astype(float)
        pair = lobed_internal_pair(np.radians(g.phases()), r, g.lobes, g.interpolation, dense,
                                   g.min_planet_radius_mm, g.centre_distance_mm)
        k = design.drive.speed_ratio
        k = (g.lobes - 1) / g.lobes if k is None else k
        motion = simulate_differential(pair, k, carrier0, arm,
                                       np.radians(_param(design, params, "initial_phase_deg")),
                                       design.carrier.arms, samples, offset, play)
        perimeter = internal_perimeter(pair)
        module = perimeter / (np.pi * g.teeth) if g.teeth else np.zeros_like(perimeter)
        box = pair.R.max(axis=1) + 1.25 * module + g.rim_mm
    else:
        g = design.sun_gear
        r = np.atleast_2d(g.radii_mm if radii is None else radii).astype(float)
        pair = khv_pair(np.radians(g.angles()), r, carrier0, g.interpolation, dense)
        motion = simulate_khv(pair, carrier0, arm, design.carrier.arms, samples, offset, play)
        h = pair.sigma[1] - pair.sigma[0]
        # sun perimeter: polar curve over absolute angle (sigma runs clockwise)
        dr = np.gradient(pair.r_sun, h, axis=1)
        ds = np.sqrt(pair.r_sun**2 + dr**2)
        perimeter = np.sum(0.5 * (ds[:, 1:] + ds[:, :-1]), axis=1) * h
        module = perimeter / (np.pi * g.teeth) if g.teeth else np.zeros_like(perimeter)
        # the carrier box holds the planets at 2a: its reach is 2a + largest planet radius
        box = 2 * pair.a + pair.r_sun.max(axis=1) + 1.25 * module + g.rim_mm
    return pair, motion, perimeter, box


def run_transplanter(design) -> TransplanterJob:
    """Simulate a transplanting mechanism and evaluate objectives (i)-(xii): the population
    evaluation with P = 1, at the design's samples and a 4096-point pitch curve."""
    from plantmech.outputs.transplanter_report import transplanter_summary

    pair, motion, perimeter, box, ev = _transplanter_population(
        design, None, design.samples, 4096, True, None)
    job = TransplanterJob(design, pair, motion, ev, float(perimeter[0]), float(box[0]), {})
    job.summary = transplanter_summary(job)
    return job


def evaluate_transplanter_population(design, radii=None, samples: int = 720,
                                    interference: bool = False, params: dict | None = None,
                                    dense: int = 1024):
    """Simulate and evaluate P variants of the design at once: gear radii (P, N) and
    scalars ``params`` (name -> (P,)): (motion, evaluation). ``dense``: points of the
    pitch curve over one lobe (turn). Interference (exact polygon clearances, compiled)
    is optional: it costs about as much as the rest."""
    _, motion, _, _, ev = _transplanter_population(design, radii, samples, dense,
                                                   interference, params)
    return motion, ev


def _transplanter_population(design, radii, samples, dense, interference, params):
    """(pair, motion, perimeter, gearbox radius, evaluation) of P designs: the one path of
    the single-design job and of populations."""
    from plantmech.objectives.transplanter import evaluate

    pair, motion, perimeter, box = simulate_transplanter(design, radii, samples, dense=dense,
                                                         params=params)
    teeth = (design.internal_gear.teeth if design.mechanism == "rice_transplanter"
             else design.sun_gear.teeth)
    ev = evaluate(motion, field_setup(design, params), transplanter_limits(design), perimeter,
                  teeth, box, interference=interference,
                  gear_fit=_gear_fit(design, pair, perimeter, teeth))
    return pair, motion, perimeter, box, ev


def _gear_fit(design, pair, perimeter, teeth):
    """Manufacturability of the internal/planet pitch curves at the design's module
    (objectives xiii, xiv); None for the K-H-V train (its gear check is `plantmech gears`)."""
    from plantmech.gears.internal import tooth_fit

    if design.mechanism != "rice_transplanter" or not teeth:
        return None
    return tooth_fit(pair, np.asarray(perimeter) / (np.pi * teeth), rules_for(design))


# --- helpers for the optimizer ----------------------------------------------------------


def seeder_inverse_checks(design: SeederDesign, samples: int = 720,
                          pitch_margin_mm: float = 0.0) -> dict:
    """Layer-1 evaluation of one candidate trajectory: Table 1 planning checks, the three
    attitude objectives and the three speed objectives of the inverse-designed train (its
    path is the planned one, its timing the inverse's carrier law — which the path fixes:
    docs/optimization.md). Values NaN and large violations when the inverse design is
    infeasible."""

    d = design.model_copy(deep=True)
    d.trajectory.samples = samples
    # a coarse cycle can miss a narrow dip of a pitch radius: optimizers ask for a margin
    d.gear_train.min_pitch_radius_mm += pitch_margin_mm
    names = list(LAYER1_NAMES)
    try:
        job = run_seeder_inverse(d, manufacturability=False)
    except Exception:  # a candidate whose curve cannot even be fitted
        job = None
    if job is None or not job.result.feasible:
        # graded: errors, plus how much of the cycle they cover (an optimizer needs a slope)
        n_err = 10.0
        if job is not None:
            errs = [x for x in job.result.diagnostics if x.severity == "error"]
            n_err = len(errs) + sum(_span_deg(x) for x in errs) / 30.0
        return {"names": names, "units": [""] * len(names), "limits": [""] * len(names),
                "values": [np.nan] * len(names), "ok": [False] * len(names),
                "violation": [10.0] * len(names), "infeasible": float(max(n_err, 1.0)),
                "objectives": [1e3, 1e3, 1e3], "pitch_tangent_angle": [np.nan, np.nan]}
    res = job.result
    checks = [c for c in job.summary["trajectory_checks"]]
    checks += job.summary["objectives"]
    checks += [c.as_dict() for c in inverse_speed_objectives(job)["checks"]]
    by = {c["name"]: c for c in checks}
    values, ok, viol, units, limits = [], [], [], [], []
    for n in names:
        c = by[n]
        v = np.nan if c["value"] is None else float(c["value"])
        values.append(v)
        ok.append(bool(c["ok"]))
        units.append(c["unit"])
        limits.append(c["limit"])
        viol.append(_check_violation(n, v, design))
    objectives = [values[names.index(n)] for n in ("picking_swing", "seeding_swing",
                                                   "sowing_angle")]
    return {"names": names, "units": units, "limits": limits, "values": values, "ok": ok,
            "violation": viol, "infeasible": 0.0, "objectives": objectives,
            "pitch_tangent_angle": _pitch_tangent_angle_deg(res)}


def _pitch_tangent_angle_deg(res) -> list[float]:
    """Largest pitch tangent angle mu (deg) of the sun-gear 2 and gear 3-planet pairs of a
    single inverse design, as ``seeder_inverse.pitch_tangent_angle`` (samples in a
    toothless dwell, where the radii are NaN, are left out)."""
    from plantmech.mechanisms.seeder_inverse import pitch_tangent_angle

    radii = np.stack([res.r1, res.r2, res.r3, res.r4])[None]
    with np.errstate(invalid="ignore"):
        mu = pitch_tangent_angle(radii, np.array([res.a1]), 2 * np.pi / len(res.r1),
                                 nan_ok=bool(np.isnan(radii).any()))
    return [round(float(np.degrees(v)), 6) for v in mu[0]]


def inverse_speed_objectives(job: SeederInverseJob) -> dict:
    """Section 4.1 objectives 4-5 of a feasible inverse design (seed 000): the tip velocity
    of the realized train (the periodic spline's slopes over the uniform carrier angle
    psi, m/s at the design's carrier speed, deg/s clockwise), the static and dynamic
    (Eq. 17) speed v_A (m/s) per sample, the travel speed v_c (m/s; Eq. 18's zero-speed
    seeding at e when the design gives none) and the three speed checks. The same
    evaluation as ``seeder_inverse_checks`` (the optimizer's layer 1), kept apart so the
    app can show the speed objectives live while a type-value point is dragged."""
    from plantmech.geometry.periodic import periodic_spline_node_slopes
    from plantmech.objectives.seeder import speed_by_section, speed_checks, zero_speed_travel

    res, d = job.result, job.design
    if not res.feasible or res.tip_realized is None:
        raise ValueError("speed objectives need a feasible inverse design")
    psi = res.carrier_angle
    vel = periodic_spline_node_slopes(res.tip_realized, 2 * np.pi / len(psi)) * np.radians(
        d.operation.carrier_speed_deg_s) / 1000.0
    sec = {k: float(res.point_carrier_angle[i]) for k, i in job.sections.items()}
    sowing = job.summary["attitude_deg"]["sowing_angle"]
    zero = zero_speed_travel(psi, vel, sowing, sec["e"])
    travel = (zero["zero_speed_travel_m_s"] if d.operation.travel_speed_m_s is None
              else d.operation.travel_speed_m_s)
    speeds = speed_by_section(psi, vel, travel, sec)
    return {"velocity_m_s": vel, "static_m_s": np.hypot(vel[:, 0], vel[:, 1]),
            "dynamic_m_s": np.hypot(vel[:, 0] - travel, vel[:, 1]), "travel_m_s": travel,
            "speeds": speeds, "checks": speed_checks(speeds, d.speed)}


def _span_deg(diagnostic) -> float:
    """Carrier angle (deg) a diagnostic covers: the backward turn of a carrier that would
    have to turn back, else the clockwise span from its first to its last sample."""
    if not diagnostic.carrier_angle_deg:
        return 0.0
    a, b = diagnostic.carrier_angle_deg
    if diagnostic.kind == "carrier_not_monotonic":
        return abs(b - a)
    return (b - a) % 360.0


def seeding_point_placement(design: SeederDesign, max_shift: int = 4,
                            tolerance: float = 0.01) -> dict:
    """Where the seeding point e can be (docs/optimization.md, "Where the seeding point can
    be"): for e and the next ``max_shift`` type-value points, the least static speed that
    gives the return section's minimum as vertical speed there (``seeding_speed_need`` on
    the inverse design's motion). If e itself allows objectives 4 and 5 together it stays;
    otherwise e (and f with it) moves on to the nearest point whose need is within
    ``tolerance`` of the smallest. Returns {shift, rows, reason}."""
    from plantmech.objectives.seeder import seeding_speed_need

    job = run_seeder_inverse(design, manufacturability=False)
    if not job.result.feasible:
        raise ValueError("the trajectory's inverse design is infeasible: fix it before "
                         "placing the seeding point")
    res, t = job.result, design.trajectory
    n = len(t.points)
    # f moves with e and must stay before a (section order)
    max_shift = max(0, min(max_shift, (t.sections.a - t.sections.f) % n - 1))
    psi = res.carrier_angle
    phi, arm = np.unwrap(res.carrier_abs), np.unwrap(res.arm_angle)
    rows = []
    for k in range(max_shift + 1):
        i = (t.sections.e + k) % n
        x = float(np.mod(res.point_carrier_angle[i], 2 * np.pi))
        ph, th = float(np.interp(x, psi, phi)), float(np.interp(x, psi, arm))
        along, need = seeding_speed_need(res.L1, ph, th, design.operation.carrier_speed_deg_s,
                                         design.speed.return_min_m_s)
        rows.append({"shift": k, "point": f"q{i}",
                     "rho_mm": float(np.hypot(*t.points[i])),
                     "along_arm_m_s": float(along), "arm_deg": float(np.degrees(np.angle(
                         np.exp(1j * th)))), "least_speed_m_s": float(need)})
    limit = design.speed.seeding_max_m_s
    need = np.array([r["least_speed_m_s"] for r in rows])
    if need[0] <= limit:
        return {"shift": 0, "rows": rows, "reason": (
            f"e stays at q{t.sections.e}: a {design.speed.return_min_m_s:g} m/s vertical "
            f"speed there needs {need[0]:.3f} m/s, within the {limit:g} m/s seeding limit")}
    ok = np.flatnonzero((need <= need.min() * (1 + tolerance)) & (need <= limit))
    if not len(ok):
        return {"shift": 0, "rows": rows, "reason": (
            f"e stays at q{t.sections.e}: no point within {max_shift} of it lets a "
            f"{design.speed.return_min_m_s:g} m/s vertical speed stay under {limit:g} m/s")}
    k = int(ok[0])
    return {"shift": k, "rows": rows, "reason": (
        f"seeding point e moved from q{t.sections.e} to {rows[k]['point']} (f with it): at "
        f"q{t.sections.e} a {design.speed.return_min_m_s:g} m/s vertical speed needs "
        f"{need[0]:.3f} m/s, above the {limit:g} m/s seeding limit (objectives 4 and 5 "
        f"exclude each other there); {rows[k]['point']} needs {need[k]:.3f} m/s")}


LAYER1_NAMES = ("small_ring_height", "small_ring_width", "large_ring_height",
                "large_ring_width", "cd_central_angle", "sowing_height_difference",
                "centre_to_trench_bottom", "picking_swing", "seeding_swing", "sowing_angle",
                "seeding_peak_speed", "return_min_speed_static", "return_min_speed_dynamic")


def layer1_bounds(design: SeederDesign) -> list[tuple[str, float | None, float | None, str]]:
    """(name, lower, upper, unit) of every layer-1 check (``LAYER1_NAMES`` order): Table 1,
    section 4.1's attitude and speed objectives (open intervals; None: unbounded)."""
    L, A, S = design.planning_limits, design.attitude, design.speed
    out = []
    for name in LAYER1_NAMES[:7]:
        lim = getattr(L, f"{name}_deg" if name == "cd_central_angle" else f"{name}_mm")
        out.append((name, lim.min, lim.max, "deg" if name == "cd_central_angle" else "mm"))
    out += [("picking_swing", None, A.picking_swing_max_deg, "deg"),
            ("seeding_swing", None, A.seeding_swing_max_deg, "deg"),
            ("sowing_angle", None, A.sowing_angle_max_deg, "deg"),
            ("seeding_peak_speed", None, S.seeding_max_m_s, "m/s"),
            ("return_min_speed_static", S.return_min_m_s, None, "m/s"),
            ("return_min_speed_dynamic", S.return_min_m_s, None, "m/s")]
    return out


def _check_violation(name: str, value: float, design: SeederDesign) -> float:
    """Relative violation of one layer-1 check (0 when met)."""
    from plantmech.objectives import relative_violation

    if not np.isfinite(value):
        return 10.0
    _, lo, hi, _ = next(b for b in layer1_bounds(design) if b[0] == name)
    return float(relative_violation(value, lo, hi))


def seeder_inverse_checks_population(design: SeederDesign, points, samples: int = 360,
                                     pitch_margin_mm: float = 0.0) -> dict:
    """``seeder_inverse_checks`` for P candidate trajectories at once: the design with its
    type-value points replaced by each row of ``points`` (P, N, 2) mm. Inverse design
    (``inverse_population``), Table 1, attitude and speeds as arrays over designs; the
    design must have no toothless dwell (layer 1's trains). Returns names, units, limits
    (lists) and values, ok, violation (P, 13), infeasible (P,) (the inverse design's
    error grading, 0 when feasible), objectives (P, 3)."""
    from plantmech.geometry.trajectory_batch import TrajectoryBatch
    from plantmech.mechanisms.seeder_inverse import _node_slopes, inverse_population
    from plantmech.objectives import limit_text, relative_violation
    from plantmech.objectives.seeder_inverse_population import (
        attitude_values,
        planning_values,
        speed_values,
    )

    gt = design.gear_train
    if gt.dwell is not None and gt.dwell.enabled:
        raise ValueError("the population inverse design has no toothless dwell: evaluate "
                         "dwell designs one by one (seeder_inverse_checks)")
    sections = design.trajectory.sections.model_dump()
    curves = TrajectoryBatch(points)
    inv = inverse_population(curves, samples, gt.a1_mm, gt.a2_mm, gt.split_exponent,
                             gt.min_pitch_radius_mm + pitch_margin_mm)
    plan, _ = planning_values(curves, sections)
    psi = inv.psi
    att = attitude_values(psi, np.degrees(inv.arm_angle_realized), inv.point_carrier_angle,
                          sections)
    vel = _node_slopes(inv.tip_realized, 2 * np.pi / len(psi)) * np.radians(
        design.operation.carrier_speed_deg_s) / 1000.0
    speeds, _ = speed_values(psi, vel, inv.point_carrier_angle, sections,
                             design.operation.travel_speed_m_s)
    raw = np.c_[plan, att, speeds]
    bounds = layer1_bounds(design)
    lo = np.array([np.nan if b[1] is None else b[1] for b in bounds])
    hi = np.array([np.nan if b[2] is None else b[2] for b in bounds])
    with np.errstate(invalid="ignore"):
        ok = (np.isnan(lo) | (raw > lo)) & (np.isnan(hi) | (raw < hi)) & np.isfinite(raw)
    values = np.round(raw, 6)  # as the single-design checks report them
    viol = np.stack([relative_violation(values[:, k], b[1], b[2], nan=10.0)
                     for k, b in enumerate(bounds)], axis=1)
    bad = ~inv.feasible
    values[bad], ok[bad], viol[bad] = np.nan, False, 10.0
    objectives = np.where(bad[:, None], 1e3, values[:, 7:10])
    mu = np.where(bad[:, None], np.nan, np.round(np.degrees(inv.pitch_tangent_angle), 6))
    return {"names": list(LAYER1_NAMES), "units": [b[3] for b in bounds],
            "limits": [limit_text(b[1], b[2], b[3]) for b in bounds], "values": values,
            "ok": ok, "violation": viol, "infeasible": inv.error_score,
            "objectives": objectives, "pitch_tangent_angle": mu}


def trajectory_deviation_batch(design: SeederDesign, tips: np.ndarray,
                               samples: int = 20000, coarse: int = 4) -> np.ndarray:
    """Largest distance (mm) of each design's tip samples (P, S, 2) from the planned
    trajectory, point to segment of the plan at ``samples`` equal arc lengths: the
    nearest vertex of every ``coarse``-th (one k-d tree query for all designs; a small
    tree is ~3x faster to search), then the 2 ``coarse`` plan segments around it."""
    tree, start, seg, length2 = _plan_polyline(tuple(map(tuple, design.trajectory.points)),
                                               samples, coarse)
    P, S, _ = tips.shape
    x, y = tips[..., 0].ravel(), tips[..., 1].ravel()
    _, kc = tree.query(np.c_[x, y])
    rx, ry = x[:, None] - start[0][kc], y[:, None] - start[1][kc]
    sx, sy = seg[0][kc], seg[1][kc]
    t = np.clip((rx * sx + ry * sy) / length2[kc], 0.0, 1.0)
    rx -= t * sx
    ry -= t * sy
    d2 = (rx * rx + ry * ry).min(axis=1)
    return np.sqrt(d2).reshape(P, S).max(axis=1)


@functools.lru_cache(maxsize=8)
def _plan_polyline(points: tuple, samples: int, coarse: int):
    """The planned curve through ``points`` at ``samples`` equal arc lengths, as a k-d
    tree of every ``coarse``-th point and, per tree point, the 2 ``coarse`` segments
    around it (starts and vectors (2, n / coarse, 2 coarse), squared lengths): an
    optimizer asks for the same plan every generation."""
    from scipy.spatial import cKDTree

    traj = ClosedTrajectory.through(np.asarray(points, dtype=float))
    _, u = traj.arc_length_samples(samples)
    plan = traj(u)
    n = len(plan)
    a = (np.arange(0, n, coarse)[:, None] + np.arange(-coarse, coarse)[None, :]) % n
    vec = plan[(a + 1) % n] - plan[a]
    start = np.ascontiguousarray(plan[a].transpose(2, 0, 1))
    seg = np.ascontiguousarray(vec.transpose(2, 0, 1))
    return cKDTree(plan[::coarse]), start, seg, np.maximum((vec * vec).sum(axis=2), 1e-300)


def train_from_inverse_job(job: SeederInverseJob, points: int = 8):
    """A [train] table (the forward model's input) sampled from an inverse design:
    ``points`` radii per intermediate gear at uniform body angles, its L1, L2, a1, a2,
    initial angles and dwell. Closure by ``scale`` keeps a1 + a2 = L1 (the resampled
    curves close at a slightly different size). The section points stay located on the
    trajectory."""
    from plantmech.design import GearPointsSpec, Train, TrainDwell
    from plantmech.verification import train_from_inverse

    res = job.result
    tr = train_from_inverse(res)
    ang = np.arange(points) * 360.0 / points
    gears = {}
    for name, curve, c0 in (("gear2", tr.gear2, tr.gear2_contact0),
                            ("gear3", tr.gear3, tr.gear3_contact0)):
        r = curve(np.radians(ang))
        gears[name] = GearPointsSpec(radii_mm=[float(x) for x in r], angles_deg=list(ang),
                                     contact_angle_deg=float(np.degrees(np.mod(c0, 2 * np.pi))))
    dwell = None
    if res.dwell is not None:
        dwell = TrainDwell(start_deg=float(np.degrees(res.dwell["carrier_start"])),
                           sector_deg=float(np.degrees(res.dwell["theta1"])))
    return Train(L1_mm=res.L1, L2_mm=res.L2, a1_mm=res.a1, a2_mm=res.a2,
                 gear2=gears["gear2"], gear3=gears["gear3"], interpolation="hermite",
                 closure="scale",
                 initial_carrier_angle_deg=float(np.degrees(tr.carrier0)),
                 initial_arm_angle_deg=float(np.degrees(tr.arm0)), dwell=dwell,
                 samples=job.design.trajectory.samples)


# --- teeth -------------------------------------------------------------------------------


def tooth_proportions(pressure_angle_deg: float = 20.0, addendum: float = 1.0,
                      dedendum: float = 1.25) -> dict:
    """Checked tooth proportions (ToothSpec fields): pressure angle (deg), addendum and
    dedendum (x module); the dedendum must exceed the addendum (root clearance)."""
    if not 0.0 < pressure_angle_deg < 45.0:
        raise ValueError(f"pressure angle {pressure_angle_deg:g} deg: must lie between 0 and "
                         "45 deg (standard: 20)")
    if not addendum > 0.0:
        raise ValueError(f"addendum {addendum:g} x module: must be positive (standard: 1.0)")
    if not dedendum > addendum:
        raise ValueError(f"dedendum {dedendum:g} x module must exceed the addendum "
                         f"{addendum:g} (root clearance; standard: 1.25)")
    return {"pressure_angle_deg": float(pressure_angle_deg), "addendum": float(addendum),
            "dedendum": float(dedendum)}


def gear_pairs(design, module: float | None = None, backlash: float = 0.1,
               samples: int = 3000, min_teeth: int = 20, tooth: dict | None = None,
               method: str = "envelope"):
    """Toothed gear pairs of a design: the seeder's sun-gear 2 and gear 3-planet pairs
    (from its [train], or from the inverse design of its trajectory), the transplanter's
    internal gear-planet pair; ``tooth``: tooth proportions (``tooth_proportions``);
    ``method``: "envelope" (rack-cut teeth from the meshing equation's envelope) or
    "simulated" (every gear by the Boolean cut of its cutter's positions).
    Returns [(GearPair, ToothSpec)]."""
    if method not in ("envelope", "simulated"):
        raise ValueError(f"teeth method {method!r}: choose 'envelope' or 'simulated'")
    tooth = tooth_proportions(**(tooth or {}))
    if design.mechanism == "planetary":  # any chain of pairs (trains/gearing.py)
        from plantmech.trains.gearing import gear_pairs as train_gear_pairs

        return train_gear_pairs(design, module, backlash, samples, min_teeth, tooth, method)
    from plantmech.gears.teeth import (
        PitchPolyline,
        ToothSpec,
        check_tooth_counts,
        make_pair,
        standard_module,
        teeth_count,
    )

    out = []
    if design.mechanism == "sugarcane_seeder":
        if design.train is not None:
            tr, _ = train_from_design(design)
        else:
            from plantmech.verification import train_from_inverse

            job = run_seeder_inverse(design, manufacturability=False)
            if not job.result.feasible:
                raise ValueError("the trajectory's inverse design is infeasible: no gears")
            tr = train_from_inverse(job.result)
        from plantmech.mechanisms.seeder_forward import sun_rolling_start

        # the sun's rolling arc starts where gear 2 is held through the toothless dwell,
        # so the arc it never rolls on (its toothless, locking arc) faces gear 2 there
        for name, curve, a, start in (("gear2_sun", tr.gear2, tr.a1, sun_rolling_start(tr)),
                                      ("gear3_planet", tr.gear3, tr.a2, tr.gear3.theta0)):
            th = start + np.linspace(0.0, 2 * np.pi, samples)
            r = curve(th)
            if not curve.periodic and start == curve.theta0:
                # a turn from the lock point (gear 2 of a dwell design steps there): the
                # turn's last radius is the one before the step
                r[-1] = float(curve.spline(curve.theta0 + 2 * np.pi))
            P = PitchPolyline.from_polar(th[:-1], r[:-1], samples).perimeter
            m0 = module or standard_module(P, min_teeth)
            names = name.split("_")
            check_tooth_counts(m0, {names[0]: P})
            z, m = teeth_count(P, m0)
            check_tooth_counts(m, {names[1]: _mate_perimeter(th, r, a, False, samples)})
            spec = ToothSpec(module=m, backlash_mm=backlash, method=method, **tooth)
            bore = _bore(r.min(), spec)
            out.append((make_pair(name, th, r, a, spec, samples=samples, bore_a=bore,
                                  bore_b=_bore((a - r).min(), spec)), spec))
    elif design.mechanism == "rice_transplanter":
        pair, *_ = simulate_transplanter(design, samples=360)
        g = design.internal_gear
        ang, R = pair.internal_polar(0)
        order = np.argsort(np.mod(ang, 2 * np.pi))
        th = np.r_[np.mod(ang, 2 * np.pi)[order], 2 * np.pi + np.mod(ang, 2 * np.pi)[order][0]]
        r = np.r_[R[order], R[order][0]]
        P = PitchPolyline.from_polar(th[:-1], r[:-1], samples).perimeter
        if g.teeth and module is None:
            z, m = g.teeth, P / (np.pi * g.teeth)
            check_tooth_counts(m, {"internal": P}, "internal_gear.teeth")
        else:
            m0 = module or standard_module(P, min_teeth * g.lobes)
            check_tooth_counts(m0, {"internal": P})
            z, m = teeth_count(P, m0, g.lobes)
        a = float(pair.a[0])
        check_tooth_counts(m, {"planet": _mate_perimeter(th, r, a, True, samples)},
                           "internal_gear.teeth" if g.teeth and module is None else "--module")
        spec = ToothSpec(module=m, backlash_mm=backlash, method=method, **tooth)
        out.append((make_pair("internal_planet", th, r, a, spec, internal=True,
                              samples=samples, rim=g.rim_mm + 3.0,
                              bore_b=_bore((r - a).min(), spec)), spec))
    else:  # K-H-V: sun - middle, then middle - planet on the middle cut once
        from plantmech.geometry.periodic import RadiusCurve

        kp, *_ = simulate_transplanter(design, samples=360)
        sig = kp.sigma[:-1]
        th_s = np.radians(design.carrier.initial_angle_deg) - sig
        order = np.argsort(np.mod(th_s, 2 * np.pi))
        th = np.mod(th_s, 2 * np.pi)[order]
        r = kp.r_sun[0, :-1][order]
        th, r = np.r_[th, th[0] + 2 * np.pi], np.r_[r, r[0]]
        a = float(kp.a[0])
        P = PitchPolyline.from_polar(th[:-1], r[:-1], samples).perimeter
        source = "sun_gear.teeth" if design.sun_gear.teeth and module is None else "--module"
        if design.sun_gear.teeth and module is None:
            m = P / (np.pi * design.sun_gear.teeth)
        else:
            m0 = module or standard_module(P, min_teeth)
            check_tooth_counts(m0, {"sun": P})
            z, m = teeth_count(P, m0)
        check_tooth_counts(m, {"sun": P, "middle": _mate_perimeter(th, r, a, False, samples)},
                           source)
        spec = ToothSpec(module=m, backlash_mm=backlash, method=method, **tooth)
        p1 = make_pair("sun_middle", th, r, a, spec, samples=samples,
                       bore_a=_bore(r.min(), spec), bore_b=_bore((a - r).min(), spec))
        # the middle meets the planet half a middle turn from the sun contact
        middle = RadiusCurve.from_samples(p1.phi_b[:-1], (a - r)[:-1], kind="spline")
        th2 = p1.phi_b[0] + np.pi + np.linspace(0.0, 2 * np.pi, len(th))
        check_tooth_counts(m, {"planet": _mate_perimeter(th2, middle(th2), a, False, samples)},
                           source)
        p2 = make_pair("middle_planet", th2, middle(th2), a, p1.spec, samples=samples,
                       gear_a=p1.gear_b, pitch_a=p1.pitch_b, tooth_at_a=p1.tooth_at_b,
                       bore_b=_bore((a - middle(th2)).min(), spec))
        out += [(p1, spec), (p2, spec)]
    return out


def _mate_perimeter(theta, r, a: float, internal: bool, samples: int) -> float:
    """Pitch perimeter (mm) of the gear rolling on the polar curve (theta, r) at centre
    distance a (its contact radii a - r, or r - a inside an internal gear)."""
    from plantmech.gears.teeth import PitchPolyline, polar_contacts

    phib, rb = polar_contacts(theta, r, a, internal)
    span = abs(phib[-1] - phib[0])
    if span < 2 * np.pi * (1 - 1e-4):  # a partial mate: the arc it turns through, closed
        return float(np.sum(np.hypot(np.diff(rb * np.cos(phib)), np.diff(rb * np.sin(phib)))))
    return PitchPolyline.from_polar(phib[:-1], rb[:-1], samples).perimeter


def _bore(min_pitch_radius: float, spec) -> float | None:
    """A bore leaving 1.5 modules of material below the tooth roots; none if < 3 mm."""
    d = 2 * (min_pitch_radius - (spec.dedendum + 1.5) * spec.module)
    return float(min(d, 30.0)) if d >= 3.0 else None


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


def cut_limits(design):
    """The limits the cut gears of ``design`` must meet (``gears.findings.CutLimits``):
    defaults, with the working pressure angle limit the design file gives
    (seeder ``[gear_checks]``, transplanter ``[limits]``)."""
    from plantmech.gears.findings import CutLimits
    from plantmech.gears.manufacturability import rules_for

    # one source for the limit: the pitch-curve rules' (gears.manufacturability.rules_for)
    return CutLimits(max_working_pressure_angle_deg=rules_for(design)
                     .max_working_pressure_angle_deg)


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
