"""Orchestration of whole jobs (design file -> results -> checks).

No physics here beyond wiring: each step lives in its layer.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from plantmech.design import SeederDesign
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


def run_seeder_inverse(design: SeederDesign) -> SeederInverseJob:
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
    return SeederInverseJob(design, traj, res, summ)
