"""Population helpers of the job layer: deviation from the plan, section location."""

import numpy as np
import pytest

from plantmech.design import load_design
from plantmech.geometry.trajectory import ClosedTrajectory
from plantmech.objectives.seeder_population import locate_sections, refine_minimum
from plantmech.workflows import trajectory_deviation, trajectory_deviation_batch

from .conftest import EXAMPLES


def test_deviation_of_a_concentric_circle():
    """Tips on a circle 3 mm outside a circular plan are 3 mm from it; half of them
    pushed out to 7.5 mm: 7.5 mm."""
    design = load_design(EXAMPLES / "sugarcane_seeder.toml")
    t = np.linspace(0, 2 * np.pi, 60, endpoint=False)
    design.trajectory.points = [(450 + 200 * np.cos(a), 200 * np.sin(a)) for a in t]
    s = np.linspace(0, 2 * np.pi, 720, endpoint=False)
    ring = np.c_[450 + 203 * np.cos(s), 203 * np.sin(s)]
    bulge = ring.copy()
    bulge[:360] = np.c_[450 + 207.5 * np.cos(s[:360]), 207.5 * np.sin(s[:360])]
    d = trajectory_deviation_batch(design, np.stack([ring, bulge]))
    assert d == pytest.approx([3.0, 7.5], abs=1e-4)  # the spline through 60 points


def test_deviation_equals_the_single_design_measure():
    design = load_design(EXAMPLES / "sugarcane_seeder_optimized.toml")
    traj = ClosedTrajectory.through(np.asarray(design.trajectory.points))
    rng = np.random.default_rng(4)
    u = np.linspace(0, traj.period, 720, endpoint=False)
    base = traj(u)
    normal = traj(u, 1)[:, ::-1] * [1, -1]
    normal /= np.hypot(*normal.T)[:, None]
    tips = np.stack([base + (rng.uniform(-25, 25) * np.sin(u / traj.period * 2 * np.pi * k)
                             )[:, None] * normal for k in (1, 2, 3, 5)])
    d = trajectory_deviation_batch(design, tips)
    ref = [trajectory_deviation(traj, tip)["max_tip_to_plan"] for tip in tips]
    assert np.allclose(d, ref, atol=1e-4)


def test_section_location_between_samples():
    """A tip circling at 720 samples per turn passes a point at 100.3 samples' angle:
    located to a small fraction of a sample (nearest sample: 0.3 of one off)."""
    psi = np.linspace(0, 2 * np.pi, 720, endpoint=False)
    tip = np.c_[300 * np.cos(psi), 300 * np.sin(psi)][None]
    where = 100.3 * (psi[1] - psi[0])
    point = np.array([[330 * np.cos(where), 330 * np.sin(where)]])
    got = locate_sections(tip, psi, point, np.array([where + 0.1]))
    assert abs(got[0, 0] - where) < 1e-3 * (psi[1] - psi[0])
    # the parabola vertex of samples of a parabola is exact
    x = np.arange(10.0)
    off, low = refine_minimum(((x - 4.3) ** 2 + 2.0)[None], np.array([[4]]), 1.0)
    assert off[0, 0] == pytest.approx(0.3) and low[0, 0] == pytest.approx(2.0)


def test_inverse_speed_objectives_integrate_to_the_path_length():
    """The static tip speed v_A integrated over one carrier turn is the length of the
    realized tip path (mm), and with no travel the dynamic speed (Eq. 17) is the static
    one; with zero-speed seeding (Eq. 18) the dynamic speed at e is the vertical one."""
    from plantmech.workflows import inverse_speed_objectives, run_seeder_inverse

    d = load_design(EXAMPLES / "sugarcane_seeder.toml")
    d.trajectory.samples = 1440
    job = run_seeder_inverse(d, manufacturability=False)
    sp = inverse_speed_objectives(job)
    tip = job.result.tip_realized
    perimeter = np.hypot(*(np.roll(tip, -1, axis=0) - tip).T).sum()
    omega = np.radians(d.operation.carrier_speed_deg_s)  # rad/s
    travelled = sp["static_m_s"].sum() * (2 * np.pi / len(tip)) / omega * 1000.0
    assert travelled == pytest.approx(perimeter, rel=2e-3)
    e = job.sections["e"]
    k = int(np.argmin(np.abs(np.angle(np.exp(1j * (job.result.carrier_angle
                                                   - job.result.point_carrier_angle[e]))))))
    vx, vy = sp["velocity_m_s"][k]
    assert sp["travel_m_s"] == pytest.approx(vx, abs=0.02)
    assert sp["dynamic_m_s"][k] == pytest.approx(abs(vy), abs=0.02)
    assert [c.name for c in sp["checks"]] == ["seeding_peak_speed", "return_min_speed_static",
                                              "return_min_speed_dynamic"]
    d.operation.travel_speed_m_s = 0.0
    still = inverse_speed_objectives(run_seeder_inverse(d, manufacturability=False))
    assert np.allclose(still["dynamic_m_s"], still["static_m_s"])
    assert still["travel_m_s"] == 0.0


def test_inverse_speed_objectives_refuse_an_infeasible_design():
    from plantmech.workflows import inverse_speed_objectives, run_seeder_inverse

    d = load_design(EXAMPLES / "sugarcane_table2_as_printed.toml")
    job = run_seeder_inverse(d, manufacturability=False)
    assert not job.result.feasible
    with pytest.raises(ValueError, match="feasible inverse design"):
        inverse_speed_objectives(job)


def test_one_set_of_seeder_checks_in_every_command():
    """The seeder file's checks are the same 17 in `inverse`, in `design`'s full-resolution
    check (``optimize.jobs.verify``) and in the app: Table 1 (7), attitude (3), speeds (3),
    the pitch curves' manufacturability (4); a [train] with its planned trajectory too."""
    from plantmech.app.server import evaluate
    from plantmech.optimize.jobs import verify
    from plantmech.workflows import run_seeder_inverse, seeder_checks

    d = load_design(EXAMPLES / "sugarcane_seeder.toml")
    inverse = [c["name"] for c in seeder_checks(run_seeder_inverse(d, speeds=True).summary)]
    checked = [c["name"] for c in verify(d, True)["objectives"]]
    app = [c["name"] for c in evaluate(d)["checks"]]
    assert len(inverse) == 17 and len(set(inverse)) == 17
    assert checked == inverse and sorted(app) == sorted(inverse)
    assert [n for n in inverse if "speed" in n] == [
        "seeding_peak_speed", "return_min_speed_static", "return_min_speed_dynamic"]
    train = load_design(EXAMPLES / "sugarcane_seeder_optimized.toml")
    assert sorted(c["name"] for c in verify(train, True)["objectives"]) == sorted(inverse)
