import numpy as np
import pytest

from plantmech.gears.internal import lobed_internal_pair
from plantmech.mechanisms.transplanter import (
    ArmGeometry,
    khv_pair,
    simulate_differential,
    simulate_khv,
)

PH = np.radians(np.arange(12) * 30.0)
SEED001 = np.array([100, 98.5, 101, 81, 82, 66, 64, 79.5, 83, 95, 98, 99.5])
ARM = ArmGeometry(150.0, 80.0, np.radians(-40.0))
PHI0 = np.radians(40.0)


@pytest.mark.parametrize("n, k", [(4, 0.75), (4, 0.5), (3, 2 / 3), (5, 0.6)])
def test_circular_internal_gear_gives_the_analytic_trochoid(n, k):
    """Circle R: planet R/n, a = R (1 - 1/n); the planet turns (1 - k) R / r = m = n (1 - k)
    carrier turns: B = a e^{i(phi0 - psi)} + S e^{i(phi0 - psi + m psi + beta)}
    (m = 1: a circle; m = 2: an ellipse-like hypotrochoid)."""
    pair = lobed_internal_pair(PH, np.full(12, 90.0), n)
    mo = simulate_differential(pair, k, PHI0, ARM, arms=3, samples=720)
    psi = mo.carrier_angle
    m = n * (1 - k)
    a = 90.0 * (1 - 1 / n)
    exp = a * np.exp(1j * (PHI0 - psi)) + 150 * np.exp(1j * (PHI0 - psi + m * psi - np.radians(40)))
    assert np.abs(mo.B[0, 0] - exp).max() < 1e-9
    rate = -1j * a * np.exp(1j * (PHI0 - psi)) + 1j * (m - 1) * 150 * np.exp(
        1j * (PHI0 - psi + m * psi - np.radians(40)))
    assert np.abs(mo.tip_rate[0, 0] - rate).max() < 1e-9
    assert np.allclose(mo.planet_rate, m)


def test_velocity_matches_finite_differences():
    pair = lobed_internal_pair(PH, SEED001, 4, "hermite")
    mo = simulate_differential(pair, 0.75, PHI0, ARM, np.radians(10), samples=7200)
    h = 2 * np.pi / 7200
    B = mo.B[0]
    fd = (np.roll(B, -1, axis=-1) - np.roll(B, 1, axis=-1)) / (2 * h)
    assert np.abs(fd - mo.tip_rate[0]).max() / np.abs(mo.tip_rate).max() < 1e-4


def _phase_deviation(mo):
    from plantmech.outputs.transplanter_report import arm_phase_deviation

    return max(arm_phase_deviation(mo))


@pytest.mark.parametrize("n, identical", [(4, True), (7, True), (5, False), (3, False)])
def test_three_arms_repeat_each_other_only_when_3_divides_n_minus_1(n, identical):
    """With a swinging arm (one lobe per carrier turn, omega_1/omega_2 = (n-1)/n) the
    internal gear turns 120 (n-1)/n deg while the carrier turns 120 deg; the arms repeat
    each other iff that is a whole number of lobes (360/n deg): 3 | n - 1."""
    pair = lobed_internal_pair(PH, SEED001, n, "hermite")
    mo = simulate_differential(pair, (n - 1) / n, PHI0, ARM, np.radians(10), arms=3, samples=720)
    dev = _phase_deviation(mo)
    if identical:
        assert dev < 1e-9
    else:
        assert dev > 1.0
    # with circular gears the paths coincide but identical planets (same arm angle beta on
    # the same body) meet the internal gear (n - 1) 120 j deg out of phase: the arm of arm
    # j is turned by that angle, |B_j - B_0| = 2 S |sin((n - 1) 60 j deg)|
    circ = simulate_differential(lobed_internal_pair(PH, np.full(12, 90.0), n), (n - 1) / n,
                                 PHI0, ARM, arms=3, samples=720)
    expected = max(2 * 150 * abs(np.sin(np.radians((n - 1) * 60 * j))) for j in range(3))
    assert _phase_deviation(circ) == pytest.approx(expected, abs=1e-9)


def test_non_periodic_speed_ratio_is_refused():
    pair = lobed_internal_pair(PH, np.full(12, 90.0), 4)
    with pytest.raises(ValueError, match="whole non-zero number"):
        simulate_differential(pair, 0.7, PHI0, ARM)


def test_khv_with_a_circular_sun_translates_the_arm():
    """Circular sun r: a = 2 r, middle and planet r, the planet turns with the carrier's
    opposite: the arm keeps its orientation, B = 2 a e^{i(phi0 - psi)} + S e^{i(phi0 + beta)}."""
    th = np.radians(np.arange(8) * 45.0)
    pair = khv_pair(th, np.full(8, 30.0), PHI0)
    assert pair.a[0] == pytest.approx(60.0, rel=1e-10)
    mo = simulate_khv(pair, PHI0, ARM, arms=2, samples=720)
    psi = mo.carrier_angle
    exp = 120.0 * np.exp(1j * (PHI0 - psi)) + 150 * np.exp(1j * (PHI0 - np.radians(40)))
    assert np.abs(mo.B[0, 0] - exp).max() < 1e-9
    assert np.allclose(mo.planet_rate, 1.0)


def test_khv_arms_repeat_and_the_planet_closes():
    th = np.radians(np.arange(8) * 45.0)
    r = 28 * (1 + 0.3 * np.cos(th))
    pair = khv_pair(th, r, PHI0)
    mo = simulate_khv(pair, PHI0, ARM, arms=2, samples=720)
    assert _phase_deviation(mo) < 1e-9
    assert mo.closure_error[0] < 1e-6
    assert np.ptp(mo.planet_rate) > 0.1  # a 1-fold sun: the ratio varies


def test_population_rows_match_single_designs():
    rng = np.random.default_rng(4)
    R = SEED001 + rng.uniform(-2, 2, (4, 12))
    pop = simulate_differential(lobed_internal_pair(PH, R, 4), 0.75, PHI0, ARM, samples=360)
    for d in range(4):
        one = simulate_differential(lobed_internal_pair(PH, R[d], 4), 0.75, PHI0, ARM,
                                    samples=360)
        assert np.abs(pop.B[d] - one.B[0]).max() < 1e-9


def test_interp_rows_is_np_interp_row_by_row():
    """The population interpolation used by the K-H-V train against ``np.interp`` per
    row: per-row tables, a shared table, a shared query (P = J on purpose), the ends."""
    from plantmech.geometry.interpolation import interp_rows

    rng = np.random.default_rng(5)
    P, N = 7, 50
    xp = np.cumsum(rng.uniform(0.01, 1.0, (P, N)), axis=1) - 3.0
    fp = rng.standard_normal((P, N))
    x = rng.uniform(-5.0, 50.0, (P, 33))  # beyond both ends too
    x[:, 0], x[:, 1] = xp[:, 0], xp[:, -1]  # exactly on the ends
    want = np.stack([np.interp(x[d], xp[d], fp[d]) for d in range(P)])
    assert np.abs(interp_rows(x, xp, fp) - want).max() < 1e-12
    grid = np.linspace(0.0, 10.0, N)
    want = np.stack([np.interp(x[d], grid, fp[d]) for d in range(P)])
    assert np.abs(interp_rows(x, grid, fp) - want).max() < 1e-12
    q = rng.uniform(0.0, 10.0, (P, 11))  # shared by every row, as many rows as designs
    got = interp_rows(q, grid, fp, shared_x=True)
    assert got.shape == (P, P, 11)
    want = np.stack([np.interp(q, grid, fp[d]) for d in range(P)])
    assert np.abs(got - want).max() < 1e-12
