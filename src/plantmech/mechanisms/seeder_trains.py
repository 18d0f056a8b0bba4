"""The seeder's train (``seeder_forward.SeederTrain``, seed 000) from a design file: from its
[train] table (``train_from_design``) or from the inverse design of its trajectory
(``inverse_design_of``, ``train_from_inverse``), and a [train] table resampled from an
inverse design (``train_from_inverse_job``, ``with_train``). Units: mm and rad inside, mm and
deg in the design file."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from plantmech.geometry.periodic import RadiusCurve
from plantmech.geometry.trajectory import ClosedTrajectory
from plantmech.mechanisms.seeder_inverse import (
    DwellSpec,
    InverseResult,
    InverseSettings,
    inverse_design,
)

if TYPE_CHECKING:
    from plantmech.design import SeederDesign
    from plantmech.mechanisms.seeder_forward import SeederTrain


def gear_body_angles(res: InverseResult) -> dict[str, np.ndarray]:
    """Contact-point polar angle (rad) of each gear in its own body frame.

    Body frames coincide with the carrier frame at carrier_angle = 0, carrier
    frame x-axis along O -> planet axis. Sun (1) is fixed to the machine frame.
    """
    psi = res.carrier_angle
    off = res.shaft_offset
    shaft = res.a1 * np.array([np.cos(off), np.sin(off)])
    planet = np.array([res.L1, 0.0])
    to_planet = np.arctan2(*(planet - shaft)[::-1])
    to_shaft_from_planet = np.arctan2(*(shaft - planet)[::-1])
    phi0 = res.carrier_abs[0]
    return {
        "sun": (phi0 - psi + off) - phi0,  # fixed frame, measured from the initial carrier line
        "gear2": off + np.pi + res.gear2_angle,
        "gear3": to_planet + res.gear2_angle,
        "planet": to_shaft_from_planet - res.planet_rel_realized,
    }


def train_from_inverse(res) -> SeederTrain:
    """Build the forward model's train from the inverse design's pitch curves.

    With a dwell, gears 2 and 3 have a break at the lock point (their ratio jumps when
    meshing stops and restarts): each is interpolated on one open turn from the lock,
    with the inverse design's exact edge radii as the end nodes.
    """
    from scipy.interpolate import CubicSpline

    from plantmech.mechanisms.seeder_forward import SeederTrain

    ang = gear_body_angles(res)
    ok = np.isfinite(res.r2)
    has_dwell = res.dwell is not None
    if not has_dwell:
        g2 = RadiusCurve.from_samples(ang["gear2"][ok], res.r2[ok], name="gear 2")
        g3 = RadiusCurve.from_samples(ang["gear3"][ok], res.r3[ok], name="gear 3")
    else:
        k_lock = int(np.flatnonzero(~ok)[0])
        edges = res.dwell["edge_pitch_radii"]
        curves = []
        for key, name in (("gear2", "r2"), ("gear3", "r3")):
            lock = float(ang[key][k_lock])
            x = lock + np.mod(ang[key][ok] - lock, 2 * np.pi)
            r = getattr(res, name)[ok]
            order = np.argsort(x)
            x, r = x[order], r[order]
            keep = (x > lock + 1e-9) & (x < lock + 2 * np.pi - 1e-9)
            xs = np.r_[lock, x[keep], lock + 2 * np.pi]
            rs = np.r_[edges["meshing_start"][name], r[keep], edges["meshing_end"][name]]
            curves.append(RadiusCurve(lock, CubicSpline(xs, rs), periodic=False))
        g2, g3 = curves
    return SeederTrain(
        L1=res.L1, L2=res.L2, a1=res.a1, a2=res.a2, gear2=g2, gear3=g3,
        gear2_contact0=float(ang["gear2"][0]), gear3_contact0=float(ang["gear3"][0]),
        carrier0=float(res.carrier_abs[0]), arm0=float(res.arm_angle_realized[0]),
        dwell_start=res.dwell["carrier_start"] if has_dwell else None,
        dwell_theta1=res.dwell["theta1"] if has_dwell else 0.0,
    )


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


def inverse_design_of(design: SeederDesign) -> tuple[ClosedTrajectory, InverseResult]:
    """(planned trajectory, inverse design) of the design file's [trajectory] and
    [gear_train]: the curve through its type-value points, mm."""
    traj = ClosedTrajectory.through(np.asarray(design.trajectory.points, dtype=float))
    return traj, inverse_design(traj, inverse_settings(design))


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


def train_from_inverse_job(job, points: int = 8):
    """A [train] table (the forward model's input) sampled from an inverse design job
    (``workflows.SeederInverseJob``: its result and its design's samples):
    ``train_table_from_inverse``."""
    return train_table_from_inverse(job.result, job.design.trajectory.samples, points)


def train_table_from_inverse(res: InverseResult, samples: int, points: int = 8):
    """A [train] table (the forward model's input) sampled from an inverse design:
    ``points`` radii per intermediate gear at uniform body angles, its L1, L2, a1, a2,
    initial angles and dwell; ``samples`` carrier samples. Closure by ``scale`` keeps
    a1 + a2 = L1 (the resampled curves close at a slightly different size). The section
    points stay located on the trajectory."""
    from plantmech.design import GearPointsSpec, Train, TrainDwell

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
                 samples=samples)


def with_train(design, points: int = 16):
    """The design with a [train]: its own, or one resampled from its inverse design."""
    if design.train is not None:
        return design
    _, res = inverse_design_of(design)
    if not res.feasible:
        raise ValueError("the trajectory's inverse design is infeasible: run layer 1 first")
    d = design.model_copy(deep=True)
    d.train = train_table_from_inverse(res, design.trajectory.samples, points)
    return d.__class__.model_validate(d.model_dump())
