"""Layer-1 checks for a population of trajectories against the single-design checks."""

import numpy as np
import pytest

from plantmech.design import load_design
from plantmech.objectives.seeder import attitude_by_section, speed_by_section
from plantmech.objectives.seeder_inverse_population import attitude_values, speed_values
from plantmech.workflows import seeder_inverse_checks, seeder_inverse_checks_population

from .conftest import EXAMPLES


@pytest.mark.parametrize("name", ["sugarcane_seeder.toml", "sugarcane_seeder_optimized.toml",
                                  "sugarcane_seeder_dwell.toml"])
def test_population_checks_equal_single_design_checks(name):
    """Every candidate's layer-1 checks equal the one-design path's (``seeder_inverse_checks``,
    the inverse design P = 1), a toothless dwell's design (seed 000's sector over cd) too."""
    design = load_design(EXAMPLES / name)
    pts = np.asarray(design.trajectory.points)
    rng = np.random.default_rng(5)
    amp = np.where(np.arange(10) % 2, 4.0, 1.0)[:, None, None]  # feasible and not
    X = pts[None] + amp * rng.uniform(-1.0, 1.0, (10,) + pts.shape)
    X[0] = pts
    b = seeder_inverse_checks_population(design, X, 360, 1.5)
    assert 3 <= (b["infeasible"] == 0).sum() <= 10
    for p in range(len(X)):
        d = design.model_copy(deep=True)
        d.trajectory.points = [tuple(x) for x in X[p]]
        c = seeder_inverse_checks(d, 360, 1.5)
        assert c["names"] == b["names"]
        assert c["infeasible"] == pytest.approx(b["infeasible"][p], abs=1e-9)
        if c["infeasible"]:
            assert np.isnan(b["values"][p]).all() and not b["ok"][p].any()
            continue
        assert c["units"] == b["units"] and c["limits"] == b["limits"]
        # values as reported (6 decimals); the angles agree to ~1e-8 rad
        assert np.allclose(c["values"], b["values"][p], atol=2e-6, rtol=0)
        assert c["ok"] == b["ok"][p].tolist()
        assert np.allclose(c["violation"], b["violation"][p], atol=1e-6)
        assert np.allclose(c["objectives"], b["objectives"][p], atol=2e-6)
        assert np.allclose(c["pitch_tangent_angle"], b["pitch_tangent_angle"][p], atol=2e-6)


def test_a_dwell_design_is_evaluated_with_its_dwell():
    """The population path takes a toothless dwell (it refused one before): the dwell
    design's checks are its own, not those of the same trajectory without the sector."""
    design = load_design(EXAMPLES / "sugarcane_seeder_dwell.toml")
    pts = np.asarray(design.trajectory.points)[None]
    with_dwell = seeder_inverse_checks_population(design, pts, 360)
    plain = design.model_copy(deep=True)
    plain.gear_train.dwell.enabled = False
    without = seeder_inverse_checks_population(plain, pts, 360)
    assert with_dwell["infeasible"][0] == 0 and without["infeasible"][0] == 0
    # the attitude over cd (the dwell's section) changes; Table 1 (the path) does not
    assert np.array_equal(with_dwell["values"][0, :7], without["values"][0, :7])
    assert not np.allclose(with_dwell["values"][0, 7:], without["values"][0, 7:], atol=1e-3)


def test_attitude_of_a_known_law():
    """arm = 10 + 20 sin(psi) deg with sections at 0, 60, ..., 300 deg: the single-design
    function and the population agree, and the swings are the analytic ones."""
    psi = np.linspace(0, 2 * np.pi, 360, endpoint=False)
    arm = np.stack([10 + 20 * np.sin(psi), -5 + 30 * np.cos(psi)])
    pts = np.radians([0, 60, 120, 180, 240, 300])
    sections = dict(a=0, b=1, c=2, d=3, e=4, f=5)
    got = attitude_values(psi, arm, np.stack([pts, pts]), sections)
    for p in range(2):
        att = attitude_by_section(psi, arm[p], pts, sections)
        assert got[p].tolist() == [abs(att["picking_ab"]["swing_from_start"]),
                                   abs(att["seeding_de"]["swing_from_start"]),
                                   abs(att["sowing_angle"])]
    # ab from 0 to 60 deg: 20 sin rises to 17.32; de from 180 to 240: 20 sin falls to -17.32
    assert got[0, 0] == pytest.approx(20 * np.sin(np.radians(60)), abs=1e-4)
    assert got[0, 1] == pytest.approx(20 * np.sin(np.radians(60)), abs=1e-4)
    assert got[0, 2] == pytest.approx(20 * np.sin(np.radians(60)), abs=1e-4)


def test_speeds_of_a_known_velocity():
    psi = np.linspace(0, 2 * np.pi, 720, endpoint=False)
    vel = np.stack([np.c_[1.2 * np.cos(psi), 0.8 * np.sin(psi)],
                    np.c_[0.5 + 0.0 * psi, 1.3 * np.cos(2 * psi)]])
    pts = np.radians([0, 60, 120, 180, 240, 300])
    sections = dict(a=0, b=1, c=2, d=3, e=4, f=5)
    got, travel = speed_values(psi, vel, np.stack([pts, pts]), sections)
    for p in range(2):
        sec = {k: pts[i] for k, i in sections.items()}
        ref = speed_by_section(psi, vel[p], travel[p], sec)
        assert got[p] == pytest.approx([ref["max_speed_seeding_m_s"],
                                        ref["min_speed_return_static_m_s"],
                                        ref["min_speed_return_dynamic_m_s"]], abs=1e-12)
    # zero-speed seeding at e (240 deg): travel = x velocity there
    assert travel[0] == pytest.approx(1.2 * np.cos(np.radians(240)), abs=1e-12)
    # the second row's speed over de (180..240 deg) peaks at d, where cos(2 psi) = 1
    assert got[1, 0] == pytest.approx(np.hypot(0.5, 1.3), abs=1e-12)
