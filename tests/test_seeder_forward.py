import numpy as np
import pytest

from plantmech.geometry.periodic import PitchCurveError, RadiusCurve
from plantmech.geometry.trajectory import ClosedTrajectory
from plantmech.mechanisms.seeder_forward import SeederTrain, simulate
from plantmech.mechanisms.seeder_inverse import InverseSettings, inverse_design
from plantmech.verification import train_from_inverse


def circular_train(r2=60.0, r3=60.0, a=120.0, L1=240.0, L2=400.0):
    th = np.linspace(0, 2 * np.pi, 8, endpoint=False)
    return SeederTrain(L1=L1, L2=L2, a1=a, a2=a,
                       gear2=RadiusCurve.from_samples(th, np.full(8, r2)),
                       gear3=RadiusCurve.from_samples(th, np.full(8, r3)),
                       gear2_contact0=np.pi, gear3_contact0=0.0, carrier0=0.4, arm0=1.0)


def test_circular_train_is_the_analytic_epicycle():
    # equal circles: the planet turns +psi relative to the carrier, the arm keeps its
    # absolute orientation: tip = L1 e^{i(phi0 - psi)} + L2 e^{i arm0}
    tr = circular_train()
    f = simulate(tr, samples=720)
    psi = f.carrier_angle
    exp = np.c_[240 * np.cos(0.4 - psi) + 400 * np.cos(1.0),
                240 * np.sin(0.4 - psi) + 400 * np.sin(1.0)]
    assert np.abs(f.tip - exp).max() < 1e-9
    assert f.closure_error["stage1"] < 1e-12 and f.closure_error["stage2"] < 1e-12


def test_unequal_circles_do_not_close():
    f = simulate(circular_train(r2=50.0), samples=90)
    assert f.closure_error["stage1"] > 0.1


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_round_trip_three_trajectories(seed):
    rng = np.random.default_rng(seed)
    t = np.linspace(0, 2 * np.pi, 16, endpoint=False)
    A, B = rng.uniform(0.1, 0.35), rng.uniform(-0.15, 0.15)
    L1, L2 = rng.uniform(80, 200), rng.uniform(300, 500)
    c = 0.3 - t
    a = c + t + A * np.sin(t) + B * np.sin(2 * t) + rng.uniform(0, 6)
    pts = np.c_[L1 * np.cos(c) + L2 * np.cos(a), L1 * np.sin(c) + L2 * np.sin(a)]
    res = inverse_design(ClosedTrajectory.through(pts), InverseSettings(samples=3600))
    assert res.feasible
    fwd = simulate(train_from_inverse(res), samples=3600)
    assert np.hypot(*(fwd.tip - res.tip).T).max() < 0.01


def test_radius_curve_refuses_bad_input():
    th = np.linspace(0, 2 * np.pi, 8, endpoint=False)
    with pytest.raises(PitchCurveError, match="not positive"):
        RadiusCurve.from_samples(th, np.r_[np.ones(7), -1.0], name="gear 2")
    with pytest.raises(PitchCurveError, match="share the angle"):
        RadiusCurve.from_samples(np.r_[th[:7], th[0]], np.ones(8))


def test_velocity_matches_finite_differences():
    rng = np.random.default_rng(5)
    th = np.linspace(0, 2 * np.pi, 8, endpoint=False)
    g2 = RadiusCurve.from_samples(th, 60 + rng.uniform(-6, 6, 8), kind="hermite")
    g3 = RadiusCurve.from_samples(th, 60 + rng.uniform(-6, 6, 8))
    from plantmech.mechanisms.seeder_forward import solve_centre_distance

    a1, a2 = solve_centre_distance(g2), solve_centre_distance(g3)
    tr = SeederTrain(L1=a1 + a2, L2=450.0, a1=a1, a2=a2, gear2=g2, gear3=g3,
                     gear2_contact0=np.pi, gear3_contact0=0.0, carrier0=0.3, arm0=0.3)
    n = 7200
    f = simulate(tr, samples=n)
    assert f.closure_error["stage1"] < 1e-9 and f.closure_error["stage2"] < 1e-9
    h = 2 * np.pi / n
    fd = (np.roll(f.tip, -1, axis=0) - np.roll(f.tip, 1, axis=0)) / (2 * h)
    assert np.abs(fd - f.tip_rate).max() / np.abs(f.tip_rate).max() < 1e-5
    # m/s at 360 deg/s: one carrier turn per second
    v = f.velocity(360.0)
    assert np.allclose(v, f.tip_rate * 2 * np.pi / 1000)
    assert np.allclose(f.speed(360.0, 0.5), np.hypot(v[:, 0] - 0.5, v[:, 1]))


def test_centre_distance_of_circles_and_ellipse():
    from plantmech.mechanisms.seeder_forward import solve_centre_distance

    th = np.linspace(0, 2 * np.pi, 16, endpoint=False)
    assert solve_centre_distance(RadiusCurve.from_samples(th, np.full(16, 40.0))) == \
        pytest.approx(80.0, rel=1e-10)
    # a 3:2 circular pair: mate turns 2/3 turn per turn of a 40 mm gear -> mate r = 60
    assert solve_centre_distance(RadiusCurve.from_samples(th, np.full(16, 40.0)),
                                 turn=2 * np.pi * 2 / 3) == pytest.approx(100.0, rel=1e-10)
    # ellipse about its focus meshing with its twin: a = 2 * semi-major axis
    A, e = 50.0, 0.35
    t = np.linspace(0, 2 * np.pi, 720, endpoint=False)
    r = A * (1 - e**2) / (1 - e * np.cos(t))
    a = solve_centre_distance(RadiusCurve.from_samples(t, r))
    assert a == pytest.approx(2 * A, rel=1e-6)


def test_unequal_circular_gears_give_the_epicyclic_path_and_speed():
    # sun 70 / gear 2 50 (a1 = 120), gear 3 40 / planet 80 (a2 = 120): the planet turns
    # (r1 / r2)(r3 / r4) = 0.7 of the carrier's turn relative to the carrier.
    th = np.linspace(0, 2 * np.pi, 8, endpoint=False)
    L1, L2, phi0, arm0 = 240.0, 400.0, 0.4, 1.0
    tr = SeederTrain(L1=L1, L2=L2, a1=120.0, a2=120.0,
                     gear2=RadiusCurve.from_samples(th, np.full(8, 50.0)),
                     gear3=RadiusCurve.from_samples(th, np.full(8, 40.0)),
                     gear2_contact0=0.0, gear3_contact0=0.0, carrier0=phi0, arm0=arm0)
    f = simulate(tr, samples=720)
    psi = f.carrier_angle
    k = 0.7
    arm = arm0 - (1 - k) * psi
    exp = np.c_[L1 * np.cos(phi0 - psi) + L2 * np.cos(arm),
                L1 * np.sin(phi0 - psi) + L2 * np.sin(arm)]
    assert np.abs(f.tip - exp).max() < 1e-8
    assert np.allclose(f.total_ratio, k, atol=1e-12)
    # speed at 360 deg/s (omega = 2 pi rad/s): |d tip/dt| from the two rotating phasors
    w = 2 * np.pi
    v = np.abs(-1j * L1 * w * np.exp(1j * (phi0 - psi))
               - 1j * (1 - k) * L2 * w * np.exp(1j * arm)) / 1000.0
    assert np.allclose(f.speed(360.0), v, rtol=1e-9)


def test_assemble_train_refuses_bad_pitch_curves():
    from plantmech.gears.closure import ClosureError
    from plantmech.mechanisms.seeder_forward import GearPoints, assemble_train

    th = np.radians(np.arange(8) * 45.0)
    ok = GearPoints(th, np.full(8, 60.0))
    with pytest.raises(ClosureError, match="gear 2"):
        assemble_train(240, 400, 120, 120, GearPoints(th, np.full(8, 55.0)), ok, 0, 0)
    spiky = GearPoints(th, np.array([60, 60, 60, 118, 60, 60, 60, 60.0]))
    with pytest.raises(PitchCurveError, match=r"sun \(gear 1\).*body angle 135.00 deg"):
        # closure tolerance opened wide so that the positivity check is what refuses
        assemble_train(240, 400, 120, 120, spiky, ok, 0, 0, tolerance=100.0, min_radius=5.0)
    with pytest.raises(ValueError, match="carrier cannot hold the shafts"):
        assemble_train(300, 400, 120, 120, ok, ok, 0, 0)


def test_sun_rolling_start_is_where_gear2_is_held_in_the_dwell():
    # independent: the forward model's own gear-2 angle over the dwell's samples
    from plantmech.design import load_design
    from plantmech.mechanisms.seeder_forward import sun_rolling_start
    from plantmech.workflows import train_from_design
    from tests.conftest import EXAMPLES

    tr, _ = train_from_design(load_design(EXAMPLES / "sugarcane_table4.toml"))
    f = simulate(tr, samples=7200)
    held = np.mod(tr.gear2_contact0 + f.gear2_angle[f.in_dwell], 2 * np.pi)
    assert np.ptp(held) < 1e-12
    start = sun_rolling_start(tr)
    assert abs(np.angle(np.exp(1j * (start - held[0])))) < 1e-9
    # Table 4: gear 2 dwells at body angle 57.15 deg, not at its curve's theta0 (0 deg)
    assert abs(np.degrees(start) - 57.15) < 0.01
    # no dwell: the curve's theta0
    assert sun_rolling_start(circular_train()) == circular_train().gear2.theta0


def test_hermite_form_is_the_curve_itself():
    # the kernel's input (knots, values, slopes) re-evaluated as cubic Hermite pieces must
    # reproduce the interpolant (periodic spline, periodic Hermite, open spline with a break)
    from scipy.interpolate import CubicHermiteSpline, CubicSpline

    from plantmech.mechanisms.seeder_forward import hermite_form

    th = np.radians([0, 40, 95, 150, 210, 260, 320.0])
    r = np.array([60, 55, 66, 58, 61, 52, 63.0])
    curves = [RadiusCurve.from_samples(th, r, kind) for kind in ("spline", "hermite")]
    xs = np.radians(np.r_[0, 40, 95, 150, 210, 260, 320.0, 360.0] + 10.0)
    curves.append(RadiusCurve(xs[0], CubicSpline(xs, np.r_[r, 70.0]), periodic=False))
    for curve in curves:
        x, v, s = hermite_form(curve)
        assert x[0] == curve.theta0 and x[-1] == pytest.approx(curve.theta0 + 2 * np.pi)
        u = curve.theta0 + np.linspace(0, 2 * np.pi, 2001)[:-1]
        assert np.abs(CubicHermiteSpline(x, v, s)(u) - curve(u)).max() < 1e-10
    assert v[-1] == pytest.approx(70.0) and v[0] == pytest.approx(60.0)  # the break


def test_open_curve_with_a_break_follows_the_closed_form_rolling():
    # gear 2 a linear ramp r = r0 + k (u - theta0) over its turn (radius steps back at
    # theta0, the lock), gear 3 a circle of a2 / 2 (planet turns with gear 3: psi_4 = psi_2).
    # Closed form: G(u) = int r / (a - r) = -(u - theta0) - (a / k) ln((a - r(u)) / (a - r0));
    # the dwell starts where the break reaches the sun and closes the turn:
    # theta_1 = 2 pi - G(theta0 + 2 pi). Expected gear-2 turns by root finding on it.
    from scipy.interpolate import CubicSpline
    from scipy.optimize import brentq

    a1, r0, r1, theta0, c0 = 150.0, 40.0, 62.0, 0.3, 2.0
    k = (r1 - r0) / (2 * np.pi)
    xs = theta0 + np.linspace(0, 2 * np.pi, 9)
    g2 = RadiusCurve(theta0, CubicSpline(xs, r0 + k * (xs - theta0)), periodic=False)
    g3 = RadiusCurve.from_samples(np.linspace(0, 2 * np.pi, 8, endpoint=False), np.full(8, 60.0))

    def G(u):
        return -(u - theta0) - a1 / k * np.log((a1 - r0 - k * (u - theta0)) / (a1 - r0))

    total = G(theta0 + 2 * np.pi)
    tb = np.mod(theta0 - c0, 2 * np.pi)  # gear-2 turn at which the break reaches the sun

    def F(t):  # sun's turn while gear 2 turns t from c0
        return (G(c0 + t) - G(c0) if t < tb else total - G(c0) + G(theta0 + t - tb))

    start, theta1 = F(tb), 2 * np.pi - total
    assert 0 < theta1 < np.pi and 0 < start < 2 * np.pi - theta1
    tr = SeederTrain(L1=240.0, L2=400.0, a1=a1, a2=120.0, gear2=g2, gear3=g3,
                     gear2_contact0=c0 - 0.0, gear3_contact0=0.5, carrier0=0.4, arm0=1.0,
                     dwell_start=start, dwell_theta1=theta1)
    f = simulate(tr, samples=720)
    m = np.where(f.carrier_angle >= start + theta1, f.carrier_angle - theta1,
                 np.minimum(f.carrier_angle, start))
    exp = np.array([tb if d else brentq(lambda t, mm=mm: F(t) - mm, 0, 2 * np.pi, xtol=1e-14)
                    for mm, d in zip(m, f.in_dwell, strict=True)])
    assert np.abs(f.gear2_angle - exp).max() < 1e-9
    assert np.abs(f.planet_rel - exp).max() < 1e-9  # planet turns with gear 3 (ratio 1)
    arm = 1.0 - f.carrier_angle + exp
    tip = np.c_[240 * np.cos(0.4 - f.carrier_angle) + 400 * np.cos(arm),
                240 * np.sin(0.4 - f.carrier_angle) + 400 * np.sin(arm)]
    assert np.abs(f.tip - tip).max() < 1e-6
    assert f.closure_error["stage1"] < 1e-9
    assert np.all(f.total_ratio[f.in_dwell] == 0)
