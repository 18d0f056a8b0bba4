"""The seeder's section-4.1 evaluation of a design file, one design or P variants of its
[train] (seed 000): where the train passes the section points a..f (``section_angles``, the
reference angles a population searches around: ``section_reference_psi``) and the
population evaluation of P variants (``evaluate_seeder_population``: simulated by
``mechanisms.seeder_batch.simulate_population``, judged by
``objectives.seeder_population.evaluate_population``). The forward job
(``workflows.run_seeder_forward``), the optimizer's problems and the studies read them
here. Units: mm, rad inside (deg and m/s in the design file)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from plantmech.design import SeederDesign
from plantmech.gears.manufacturability import rules_for
from plantmech.geometry.trajectory import ClosedTrajectory
from plantmech.mechanisms.seeder_trains import train_from_design
from plantmech.objectives.inverse_evaluation import InfeasibleDesign, run_seeder_inverse


def section_angles(design: SeederDesign, res, inv, traj) -> tuple[dict, dict | None]:
    """Carrier angles (rad) of the section points a..f of a simulated train ``res``
    (``ForwardResult``): the design's ``sections_deg``, else those of the inverse design
    ``inv`` (``SeederInverseJob``) behind it, else located on its tip path near the
    planned trajectory ``traj``'s points (``objectives.seeder.locate_section_points``,
    with the distances it misses them by, mm). Returns (angles, misses or None)."""
    if design.train is not None and design.train.sections_deg is not None:
        return {k: float(np.radians(v))
                for k, v in design.train.sections_deg.model_dump().items()}, None
    if inv is not None:
        pc = inv.result.point_carrier_angle
        return {k: float(pc[i]) for k, i in inv.sections.items()}, None
    from plantmech.objectives.seeder import locate_section_points

    return locate_section_points(res.tip, res.carrier_angle, traj.points,
                                 design.trajectory.sections.model_dump())


@dataclass
class SeederPopulation:
    """A population of variants of one design's [train] (radii of gears 2 and 3)."""

    motion: object  # PopulationMotion
    evaluation: object  # PopulationEvaluation
    section_psi: np.ndarray  # (P, 6) rad


def section_reference_psi(design: SeederDesign) -> np.ndarray:
    """Carrier angles (6,) rad where the design's own train passes the section points
    a..f (the forward job's ``section_psi``: its simulation and ``section_angles``, without
    its objectives; a design with no [train] takes its inverse design's, and raises
    ``InfeasibleDesign`` when that is infeasible): where ``evaluate_seeder_population``
    searches each variant's. Depends on the design only, so it is kept per design
    content (the last 16; a read-only array)."""
    key = design.model_dump_json()
    hit = _REFERENCE_PSI.get(key)
    if hit is not None:
        return hit
    if design.train is None:
        inv = run_seeder_inverse(design, manufacturability=False)
        if not inv.result.feasible:
            raise InfeasibleDesign(inv)
        section_psi, _ = section_angles(design, None, inv, None)
    else:
        from plantmech.mechanisms.seeder_forward import simulate

        train, _ = train_from_design(design)
        traj = (None if design.trajectory is None else
                ClosedTrajectory.through(np.asarray(design.trajectory.points, dtype=float)))
        res = simulate(train, samples=design.train.samples)
        section_psi, _ = section_angles(design, res, None, traj)
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
