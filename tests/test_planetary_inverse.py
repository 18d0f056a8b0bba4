"""Inverse design of a first-order planetary train (objectives/planetary_inverse.py,
``plantmech inverse``
on a ``mechanism = "planetary"`` [trajectory] file).

Independent expectations: a known train (an elliptic sun about its focus, A = 25 mm,
e = 0.2, fixed; one external pair closing at a = 2A = 50 mm; a 20 mm arm) is run forward;
the inverse design of its tip path must give back the lengths (the path's farthest and
nearest radii are a + L = 70 and a - L = 30 mm) and the sun's pitch curve, an ellipse
r = A (1 - e^2) / (1 - e cos(phi - phi_0)) in the absolute frame; and the written design
file, run by ``plantmech forward``, must pass through every type-value point (round trip).
"""

from __future__ import annotations

import csv
import json
import tomllib

import numpy as np
import pytest

from plantmech.design import load_design
from plantmech.geometry.trajectory import ClosedTrajectory
from plantmech.interfaces.cli import main
from plantmech.objectives.planetary_inverse import ROUND_TRIP_TOLERANCE_MM, first_order_inverse
from plantmech.trains.curves import ellipse
from plantmech.trains.model import PairSpec, Train, forward
from tests.conftest import EXAMPLES
from tests.conftest import write_toml as _write

EXAMPLE = EXAMPLES / "planetary" / "first_order_inverse.toml"
A, E, L, SUN_PHASE = 25.0, 0.2, 20.0, 90.0


def _known_tip(samples: int = 3600) -> np.ndarray:
    tr = Train([PairSpec("external", ellipse(A, E, 8192), phase=np.radians(SUN_PHASE),
                         follower_turns=1.0)],
               carrier0=np.radians(90.0), carrier_sense=-1, arm_length=L,
               arm_angle=np.radians(-90.0))
    return forward(tr, samples).tip[0, 0]


def test_inverse_of_a_known_train_gives_back_its_lengths_and_elliptic_sun():
    tip = _known_tip()[::25]  # 144 type-value points on the known train's path
    traj = ClosedTrajectory.through(np.c_[tip.real, tip.imag])
    res = first_order_inverse(traj, "short", "external", -1, 3600)
    assert res.feasible, res.reasons
    assert res.centre_distance == pytest.approx(2 * A, abs=1e-6)
    assert res.arm_length == pytest.approx(L, abs=1e-6)
    assert res.follower_turns == pytest.approx(1.0, abs=1e-9)
    # the sun in the absolute frame: body angle theta at absolute direction theta + phase
    phi = 2 * np.pi * np.arange(3600) / 3600
    expected = A * (1 - E**2) / (1 - E * np.cos(phi - np.radians(SUN_PHASE)))
    theta = np.mod(phi - np.radians(res.sun_phase_deg), 2 * np.pi)
    found = np.interp(theta, 2 * np.pi * np.arange(3600) / 3600, res.sun_radii,
                      period=2 * np.pi)
    assert np.abs(found - expected).max() < 0.15  # mm; the spline through 144 points
    # the planet turns once per sun turn: its radius is a - r_sun at every contact
    assert np.allclose(res.planet_radii + res.sun_radii, 2 * A)


def test_the_other_link_order_or_the_other_sense_is_refused_with_the_reason():
    tip = _known_tip()[::50]
    traj = ClosedTrajectory.through(np.c_[tip.real, tip.imag])
    long = first_order_inverse(traj, "long", "external", -1, 720)
    assert not long.feasible and "carrier turn once clockwise" in long.reasons[0]
    back = ClosedTrajectory.through(np.c_[tip.real, tip.imag][::-1])
    res = first_order_inverse(back, "short", "external", -1, 720)
    assert not res.feasible and "neither assembly branch" in res.reasons[0]
    internal = first_order_inverse(traj, "short", "internal", -1, 720)
    assert not internal.feasible and "turn the other way" in internal.reasons[0]


def _run(args, capsys):
    code = main(args)
    return code, capsys.readouterr()


def test_cli_round_trip_through_forward(tmp_path, capsys):
    out = tmp_path / "inv"
    code, io = _run(["inverse", str(EXAMPLE), "--out", str(out)], capsys)
    # 24 points leave the sun 2.4 mm off: the error estimate (tests/test_inverse_estimate.py)
    # fails its 1 mm limit, and nothing else does
    assert code == 4, io.out + io.err
    s = json.loads((out / "summary.json").read_text())
    assert s["verdict"]["failed"] == ["error_estimate_pitch_radius_mm", "error_estimate_tip_mm"]
    assert s["feasible"] and s["carrier_arm_mm"] == pytest.approx(50.0, abs=0.01)
    assert s["centre_distances_mm"] == [pytest.approx(50.0, abs=0.01)]
    assert s["arm_length_mm"] == pytest.approx(20.0, abs=0.01)
    designed = load_design(out / "design.toml")
    assert designed.train.pairs[0].driver.family == "radii"
    code, io = _run(["forward", str(out / "design.toml"), "--out", str(tmp_path / "fwd"),
                     "--no-plots"], capsys)
    assert code == 0, io.out + io.err
    # independently: the forward command's tip path (motion.csv) through every point
    with open(tmp_path / "fwd" / "motion.csv") as f:
        rows = list(csv.DictReader(f))
    xcol, ycol = "arm1_tip_x_mm", "arm1_tip_y_mm"
    tip = np.array([float(r[xcol]) + 1j * float(r[ycol]) for r in rows])
    pts = np.array(tomllib.loads(EXAMPLE.read_text())["trajectory"]["points"])
    z = pts[:, 0] + 1j * pts[:, 1]
    a, d = tip, np.roll(tip, -1) - tip
    t = np.clip(((z[:, None] - a) * d.conjugate()).real / np.abs(d) ** 2, 0, 1)
    dist = np.abs(z[:, None] - (a + t * d)).min(axis=1)
    assert dist.max() < ROUND_TRIP_TOLERANCE_MM + 1e-6  # csv rounding: 1e-6 mm
    assert s["objectives"][0]["name"] == "round_trip_point_deviation_mm"
    assert s["objectives"][0]["value"] == pytest.approx(dist.max(), abs=2e-6)


def _doc() -> dict:
    return tomllib.loads(EXAMPLE.read_text())




@pytest.mark.parametrize("change, field", [
    (lambda d: d["train"]["pairs"][0].update(centre_distance_mm=40.0),
     "train.pairs.0.centre_distance_mm"),
    (lambda d: d["arm"].update(length_mm=25.0), "arm.length_mm"),
    (lambda d: d["train"].update(sun_speed_ratio=0.5), "train.sun_speed_ratio"),
    (lambda d: d["train"]["pairs"].extend([{"kind": "external"}] * 2), "train.pairs"),
    (lambda d: d["train"]["pairs"][0].update(driver={"family": "ellipse", "semi_major_mm": 9.0,
                                                     "eccentricity": 0.1}),
     "train.pairs.0"),
    (lambda d: d["trajectory"].update(dwell={"start": 3, "end": 5, "anchor": 4}),
     "trajectory.dwell"),
])
def test_inputs_the_inverse_cannot_take_exit_2_naming_the_field(tmp_path, capsys, change,
                                                                 field):
    doc = _doc()
    change(doc)
    code, io = _run(["inverse", _write(tmp_path, doc), "--out", str(tmp_path / "o")], capsys)
    assert code == 2 and f"field '{field}" in io.err, io.err
    assert not (tmp_path / "o").exists()


def test_infeasible_trajectory_exit_3_with_the_reason(tmp_path, capsys):
    doc = _doc()
    doc["trajectory"]["points"] = doc["trajectory"]["points"][::-1]
    code, io = _run(["inverse", _write(tmp_path, doc), "--out", str(tmp_path / "o"),
                     "--no-plots"], capsys)
    assert code == 3 and "neither assembly branch" in io.err
    s = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert not s["feasible"] and s["verdict"]["status"] == "infeasible"
    assert not (tmp_path / "o" / "design.toml").exists()


def test_a_trajectory_file_is_not_a_train_for_forward(tmp_path, capsys):
    code, io = _run(["forward", str(EXAMPLE), "--out", str(tmp_path / "o")], capsys)
    assert code == 2 and "train.pairs.0.driver" in io.err and "plantmech inverse" in io.err


def test_second_order_seeder_train_from_its_trajectory_follows_the_seeder_model():
    """Seed 000's train designed from its Table 2 trajectory through the general model: the
    written design, run by the general forward model, gives the seeder's own inverse
    design's realized tip (mechanisms/seeder_inverse, a separate pipeline) at every carrier
    sample, and its pitch curves are the seeder's r1 and r3."""
    from plantmech.mechanisms.seeder_inverse import InverseSettings, inverse_design
    from plantmech.objectives.planetary_inverse import run_first_order
    from plantmech.trains.model import simulate
    from plantmech.trains.spec import build_from_design

    design = load_design(EXAMPLES / "planetary" / "sugarcane_seeder_inverse.toml")
    job = run_first_order(design)
    assert job["feasible"], job["result"].reasons
    assert job["rows"][0]["ok"] and job["rows"][0]["value"] < ROUND_TRIP_TOLERANCE_MM
    traj = ClosedTrajectory.through(design.trajectory.points)
    seeder = inverse_design(traj, InverseSettings(samples=3600, min_pitch_radius=5.0))
    assert seeder.feasible
    designed = job["designed"]
    assert [p.centre_distance_mm for p in designed.train.pairs] == pytest.approx(
        [seeder.L1 / 2, seeder.L1 / 2])
    assert designed.arm.length_mm == pytest.approx(seeder.L2)
    motion = simulate(build_from_design(designed), 3600)
    tip = motion.tip[0, 0]
    ref = seeder.tip_realized[:, 0] + 1j * seeder.tip_realized[:, 1]
    assert np.abs(tip - ref).max() < 0.01  # mm, over the whole turn
    # the sun: its radius where it touches gear 2 at carrier angle psi is the seeder's r1
    r_sun = motion.contact_radii[0][0][0, 0]
    # mm: the written curves are 900 control radii of the 3600 samples (periodic spline);
    # gear 3's radius is steep where the ratio falls to 0.077, so a small angle offset of
    # gear 2 there shows as up to 0.12 mm of radius at the same carrier angle
    assert np.abs(r_sun - seeder.r1).max() < 0.02
    r_gear3 = motion.contact_radii[1][0][0, 0]
    assert np.abs(r_gear3 - seeder.r3).max() < 0.15
