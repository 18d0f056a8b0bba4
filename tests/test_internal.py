import numpy as np
import pytest

from plantmech.gears.internal import (
    InternalPairError,
    internal_perimeter,
    lobed_internal_pair,
    solve_internal_centre_distance,
)

PH = np.radians(np.arange(12) * 30.0)
SEED001 = np.array([100, 98.5, 101, 81, 82, 66, 64, 79.5, 83, 95, 98, 99.5])


def test_circular_internal_gear_closes_at_the_analytic_centre_distance():
    # circle R with n lobes: planet radius R/n, centre distance R (1 - 1/n)
    for n in (2, 3, 4, 7):
        pair = lobed_internal_pair(PH, np.full(12, 90.0), n)
        assert pair.a[0] == pytest.approx(90.0 * (1 - 1 / n), rel=1e-12)
        assert np.allclose(pair.planet_radius, 90.0 / n)
        assert pair.closure_error[0] < 1e-12
        assert internal_perimeter(pair)[0] == pytest.approx(2 * np.pi * 90.0, rel=1e-9)


def test_published_curve_closes_to_1e_9_and_planet_turns_once_per_lobe():
    pair = lobed_internal_pair(PH, SEED001, 4, "hermite")
    assert pair.closure_error[0] < 1e-9
    # independent check of the closure by the trapezoid rule on a fine grid
    R = pair.R[0]
    a = pair.a[0]
    f = R / (4 * (R - a))
    h = pair.p[1] - pair.p[0]
    assert np.sum(0.5 * (f[1:] + f[:-1])) * h == pytest.approx(2 * np.pi, abs=1e-6)


def test_centre_distance_solver_is_vectorised_and_monotone():
    rng = np.random.default_rng(0)
    R = 80 + rng.uniform(-10, 10, (5, 512))
    a = solve_internal_centre_distance(R, 4)
    assert np.allclose(np.mean(R / (R - a[:, None]), axis=1), 4, atol=1e-10)
    a5 = solve_internal_centre_distance(R, 5)
    assert np.all(a5 > a)  # a faster planet needs a smaller planet: larger centre distance


def test_planet_that_cannot_mesh_is_refused_naming_the_lobe_phase():
    from plantmech.geometry.periodic import RadiusCurve

    # where the planet is smallest: where the internal curve (same Hermite interpolant,
    # evaluated through RadiusCurve) is smallest
    t = np.radians(np.arange(0, 360, 0.01))
    k = np.argmin(RadiusCurve.from_samples(PH, SEED001, kind="hermite")(t))
    with pytest.raises(InternalPairError) as exc:
        lobed_internal_pair(PH, SEED001, 4, "hermite", min_planet_radius=5.0)
    msg = str(exc.value)
    where = float(msg.split("lobe phase ")[1].split(" deg")[0])
    assert where == pytest.approx(np.degrees(t[k]), abs=0.1)
    assert "cannot mesh" in msg


def test_unclosed_pair_with_a_given_centre_distance_is_refused():
    with pytest.raises(InternalPairError, match="does not close.*closes at 58.203 mm"):
        lobed_internal_pair(PH, SEED001, 4, "hermite", centre_distance=55.0)
    ok = lobed_internal_pair(PH, SEED001, 4, "hermite", centre_distance=58.2034006173)
    assert ok.closure_error[0] < 1e-6


def test_tooth_fit_of_a_circular_pair_is_the_spur_gear_tooth_counts():
    # ring R = 90 with n = 3: planet radius 30, centre distance 60; at m = 2 the ring is a
    # 90-tooth internal gear and the planet a 30-tooth spur gear (z_eq exact), difference 60
    from plantmech.gears.internal import tooth_fit

    pair = lobed_internal_pair(PH, np.full(12, 90.0), 3)
    fit = tooth_fit(pair, 2.0)
    assert fit["internal_min_equivalent_teeth"][0] == pytest.approx(90.0, rel=1e-6)
    assert fit["planet_min_equivalent_teeth"][0] == pytest.approx(30.0, rel=1e-6)
    assert fit["min_equivalent_teeth"][0] == pytest.approx(30.0, rel=1e-6)
    assert fit["min_internal_teeth_difference"][0] == pytest.approx(60.0, rel=1e-6)
    assert fit["max_working_pressure_angle_deg"][0] == pytest.approx(20.0, abs=1e-9)


def test_tooth_fit_flags_the_published_lobe():
    # the published lobe dips 37 mm within 45 deg of the ring: its tightest spans are
    # spur gears of ~2 teeth at m = 2.8 (the generated teeth interfere, tests/test_teeth)
    from plantmech.gears.internal import tooth_fit

    pair = lobed_internal_pair(PH, SEED001, 4, "hermite")
    fit = tooth_fit(pair, 2.8)
    assert fit["min_equivalent_teeth"][0] < 3.0
    assert fit["max_working_pressure_angle_deg"][0] > 80.0
    assert fit["min_internal_teeth_difference"][0] < 10.0
