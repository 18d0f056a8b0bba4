"""The general train model (trains/): closed forms, populations (the papers' trains as
design files of it: tests/test_planetary_examples.py).

Closed form of two identical ellipses turning about their foci (docs/architecture.md,
"Train model"): with r_1(theta) = A (1 - e^2) / (1 - e cos theta) (theta from the far end
of the major axis) and centre distance a = 2A, the mate's radius is
r_2 = A (1 + e^2 - 2 e cos theta) / (1 - e cos theta), the ratio
g = r_1 / r_2 = (1 - e^2) / (1 + e^2 - 2 e cos theta), and its integral (the follower's
turn, int d theta / (b - c cos theta) with b = 1 + e^2, c = 2e, b^2 - c^2 = (1 - e^2)^2):

    tan(F / 2) = ((1 + e) / (1 - e)) tan(theta / 2).

The mate is the same ellipse seen from its near end: r_2(phi) = A (1 - e^2) / (1 + e cos phi)
at follower angle phi = -F(theta), whose own law is tan(F_2 / 2) = ((1 - e) / (1 + e))
tan(phi / 2).
"""

from __future__ import annotations

import numpy as np
import pytest

from plantmech.trains.curves import (
    eccentric_circle,
    ellipse,
    fourier,
    hermite_periodic,
    interpolated,
)
from plantmech.trains.model import PairSpec, Train, build, forward, simulate
from plantmech.trains.pairs import PairError, pair_law
from tests.conftest import EXAMPLES

TWO_PI = 2 * np.pi
EXAMPLE = EXAMPLES / "rotary_transplanter_elliptic.toml"


def ellipse_law(theta, e):
    """Closed-form follower turn F(theta) of two identical ellipses about their foci,
    continuous over every turn (the branch of atan shifted by 2 pi per turn)."""
    k = (1 + e) / (1 - e)
    theta = np.asarray(theta, dtype=float)
    return 2 * np.arctan(k * np.tan(theta / 2)) + TWO_PI * np.floor((theta + np.pi) / TWO_PI)


def angle_gap(a, b):
    """Largest |a - b| of two angle arrays, modulo whole turns (rad)."""
    return np.abs(np.angle(np.exp(1j * (np.asarray(a) - np.asarray(b))))).max()


def test_elliptic_pair_against_the_closed_form_for_three_eccentricities_at_once():
    A = np.array([25.0, 30.0, 20.0])
    e = np.array([0.1, 0.18, 0.3])
    law = pair_law("external", ellipse(A, e, 4096), 1.0)
    assert np.allclose(law.a, 2 * A, rtol=0, atol=1e-9)  # solved centre distance = 2A
    assert np.all(np.abs(law.closure_error) < 1e-12)
    theta = np.linspace(-7.0, 7.0, 1001)[None, :]  # two turns, off the grid
    F, g = law.F(theta)
    col = e[:, None]
    assert np.abs(g - (1 - col**2) / (1 + col**2 - 2 * col * np.cos(theta))).max() < 1e-9
    assert np.abs(F - ellipse_law(theta, col)).max() < 1e-9
    mate = law.mate()
    phi = mate.theta[None, :]
    expected = A[:, None] * (1 - col**2) / (1 + col * np.cos(phi))
    assert np.abs(mate.r - expected).max() < 1e-9
    assert np.abs(mate.dr - A[:, None] * (1 - col**2) * col * np.sin(phi)
                  / (1 + col * np.cos(phi)) ** 2).max() < 1e-7


def test_elliptic_example_planet_follows_the_closed_form_through_the_idler():
    from plantmech.design import load_design
    from plantmech.trains.spec import build_from_design

    d = load_design(EXAMPLE)
    e = d.train.pairs[0].driver.eccentricity
    A = d.train.pairs[0].driver.semi_major_mm
    built = build_from_design(d)
    assert np.allclose(built.centre_distances, 2 * A, atol=1e-9)
    m = simulate(built, d.samples)
    # sun relative to the carrier line, then the two closed-form laws: idler = pi + F(theta_0)
    alpha0 = m.gear_angles[0]
    idler = np.pi + ellipse_law(-alpha0, e)
    # the idler's contact with the planet is on the far side (direction 0): theta = -alpha_1,
    # the idler curve is the ellipse seen from its near end, whose law has (1 - e)/(1 + e)
    planet = np.pi + ellipse_law(-idler, -e)
    assert angle_gap(m.gear_angles[1], idler) < 1e-9
    assert angle_gap(m.gear_angles[2], planet) < 1e-9
    # closed-form attitude: beta = carrier + planet (relative) + the start offset
    beta = m.carrier + planet
    beta += np.radians(d.arm.initial_angle_deg) - beta[:, :1, :1]
    assert angle_gap(m.arm_angle, beta) < 1e-9
    # the two planets at 180 deg repeat each other half a turn apart (fixed sun)
    half = d.samples // 2
    assert np.abs(np.roll(m.tip[0, 1], half) - m.tip[0, 0]).max() < 1e-9


def test_circular_idler_train_translates_the_planet():
    """Sun, idler, planet circles with planet = sun: the planet keeps its attitude (the
    classic translating planet), the idler any size."""
    sun = fourier(30.0, [], [], 2048)
    idler = PairSpec("external", sun, phase=0.3, follower_turns=30 / 17)
    m = forward(Train([idler, PairSpec("external", None, follower_turns=17 / 30)],
                      carrier0=0.4, arm_length=150.0, arm_angle=-1.0, arms=3), 720)
    assert np.allclose(m.built.centre_distances, [[47.0, 47.0]], atol=1e-9)
    assert np.abs(m.arm_angle + 1.0).max() < 1e-9
    assert np.abs(m.arm_rate).max() < 1e-9


def test_compound_and_internal_circular_trains_have_constant_ratios():
    """Compound shaft (30/20 then 25/15) and the two internal kinds: the planet's
    relative rate is the product of the pairs' ratios with their senses."""
    sun = fourier(30.0, [], [], 1024)
    pairs = [PairSpec("external", sun, follower_turns=1.5),
             PairSpec("external", fourier(25.0, [], [], 1024), phase=0.7,
                      follower_turns=25 / 15)]
    m = forward(Train(pairs, carrier0=0.0, carrier_sense=-1, arm_length=100.0), 360)
    assert np.allclose(m.built.centre_distances, [[50.0, 40.0]], atol=1e-9)
    # sun relative rate (k - 1) s = +1; two external pairs: (+1)(30/20)(25/15) = 2.5
    assert np.allclose(m.gear_rates[2], 2.5, atol=1e-9)
    psi = m.carrier_angle
    assert np.allclose(m.arm_angle[0, 0] - m.arm_angle[0, 0, 0], 1.5 * psi, atol=1e-9)
    ring = fourier(60.0, [], [], 1024)
    m = forward(Train([PairSpec("internal", ring, follower_turns=3.0)], sun_speed_ratio=0.5,
                      arm_length=80.0), 360)
    assert np.allclose(m.built.centre_distances, 40.0, atol=1e-9)  # planet radius 20
    assert np.allclose(m.gear_rates[1], (0.5 - 1) * -1 * 3.0, atol=1e-9)
    m = forward(Train([PairSpec("internal_ring_follower", fourier(20.0, [], [], 1024),
                                follower_turns=1 / 3)], arm_length=80.0), 360)
    assert np.allclose(m.built.centre_distances, 40.0, atol=1e-9)  # ring radius 60
    assert np.allclose(m.gear_rates[1], 1 / 3, atol=1e-9)


def test_mate_of_a_general_curve_rolls_on_its_driver():
    """A Fourier sun and an eccentric-circle idler: at every simulated contact the two
    radii add up to the centre distance, and the follower's contact angle on its own
    tabulated curve gives the same radius (the mate is the rolled curve)."""
    sun = fourier(30.0, [3.0, 1.0], [0.0, -2.0], 4096)
    pairs = [PairSpec("external", sun), PairSpec("external", eccentric_circle(22.0, 4.0, 4096),
                                                 phase=0.5)]
    m = forward(Train(pairs, arm_length=120.0), 1440)
    for k, law in enumerate(m.built.laws):
        rd, rf = m.contact_radii[k]
        assert np.abs(rd + rf - law.a[0]).max() < 1e-9
        theta_f = law.follower_direction - m.gear_angles[k + 1]  # direction 0
        r_mate, _ = m.built.followers[k](theta_f.reshape(1, -1))
        assert np.abs(r_mate.ravel() - rf.ravel()).max() < 1e-7


def test_population_gives_the_same_numbers_as_single_runs():
    P = 4
    A = np.array([25.0, 24.0, 27.0, 22.0])
    e = np.array([0.18, 0.1, 0.2, 0.15])
    phase = np.array([4.7, 0.0, 1.0, 2.0])
    L = np.array([160.0, 150.0, 170.0, 140.0])
    beta0 = np.array([-1.5, -1.2, -2.0, 0.3])
    C0 = np.array([0.0, 0.5, -0.5, 1.0])

    def train(k):
        s = slice(None) if k is None else slice(k, k + 1)
        return Train([PairSpec("external", ellipse(A[s], e[s], 2048), phase=phase[s]),
                      PairSpec("external", None)], carrier0=C0[s], arm_length=L[s],
                     arm_angle=beta0[s], arms=2)

    from plantmech.objectives.planetary import motion_objectives

    many = forward(train(None), 720)
    obj = motion_objectives(many, 360.0)
    assert many.tip.shape == (P, 2, 720)
    for k in range(P):
        one = forward(train(k), 720)
        assert np.abs(one.tip[0] - many.tip[k]).max() < 1e-12
        assert np.abs(one.arm_angle[0] - many.arm_angle[k]).max() < 1e-12
        assert np.abs(one.tip_rate[0] - many.tip_rate[k]).max() < 1e-12
        single = motion_objectives(one, 360.0)
        for name, values in obj.items():
            assert values[k] == pytest.approx(single[name][0], abs=1e-12), name


def test_tip_rate_is_the_derivative_of_the_tip_path():
    d_train = Train([PairSpec("external", ellipse(25.0, 0.18, 4096), phase=4.7),
                     PairSpec("external", None)], arm_length=160.0, arm_angle=-1.5)
    m = forward(d_train, 7200)
    h = m.carrier_angle[1]
    numeric = (np.roll(m.tip, -1, axis=2) - np.roll(m.tip, 1, axis=2)) / (2 * h)
    assert np.abs(numeric - m.tip_rate).max() < 1e-3 * np.abs(m.tip_rate).max()


def test_self_crossings_of_a_circle_and_a_figure_eight():
    from plantmech.objectives.planetary import self_crossings

    t = np.linspace(0, TWO_PI, 2000, endpoint=False)
    circle = np.exp(1j * t)
    eight = np.sin(t) + 1j * np.sin(2 * t) / 2
    assert list(self_crossings(np.stack([circle, eight]))) == [0, 1]


def _crossings_of_every_pair(z: np.ndarray) -> int:
    """The reference: every pair of non-adjacent segments of one closed polyline tested
    (segments i, j cross properly when each one's ends lie strictly on both sides of the
    other's line)."""
    n = len(z)
    a, d = z, np.roll(z, -1) - z

    def side(p, q):
        return d[q].real * (a[p].imag - a[q].imag) - d[q].imag * (a[p].real - a[q].real)

    count = 0
    for i in range(n):
        for j in range(i + 2, n):
            if i == 0 and j == n - 1:
                continue
            if (side(i, j) * side((i + 1) % n, j) < 0
                    and side(j, i) * side((j + 1) % n, i) < 0):
                count += 1
    return count


def test_self_crossings_equal_the_count_over_every_pair_of_segments():
    """The sweep over bounding boxes finds what testing every pair finds: smooth curves
    with 0 to several loops, a star polygon (5 crossings) and jagged random polylines with
    thousands of crossings, in one population."""
    from plantmech.objectives.planetary import self_crossings

    rng = np.random.default_rng(7)
    t = np.linspace(0, TWO_PI, 180, endpoint=False)
    paths = []
    for _ in range(6):
        u, v, w = rng.uniform(0.2, 3.0, 3)
        paths.append(np.cos(t) + u * np.cos(2 * t + v) + 0.5 * np.sin(3 * t + w)
                     + 1j * (np.sin(t) + 0.7 * np.sin(2 * t) + 0.3 * u * np.cos(5 * t)))
    star = np.exp(1j * TWO_PI * 2 * np.arange(5) / 5)  # the pentagram
    paths.append(np.repeat(star, 36))  # 180 points, repeated vertices: degenerate segments
    for _ in range(3):
        paths.append(rng.normal(size=180) + 1j * rng.normal(size=180))
    P = np.stack(paths)
    expected = [_crossings_of_every_pair(z) for z in P]
    assert expected[6] == 5 and max(expected) > 1000
    assert list(self_crossings(P, samples=180)) == expected


def test_pairs_that_cannot_roll_or_close_are_refused_by_name():
    e = ellipse(25.0, 0.2, 1024, name="sun")
    with pytest.raises(PairError, match=r"closes at 50\.0000 mm"):
        pair_law("external", e, 1.0, centre_distance=52.0, name="train.pairs.0")
    with pytest.raises(PairError, match="not above"):
        pair_law("external", e, 1.0, centre_distance=30.0, name="train.pairs.0")
    with pytest.raises(PairError, match="does not repeat every 180 deg"):
        pair_law("external", e, 2.0, name="train.pairs.0")
    with pytest.raises(PairError, match="q > 1"):
        pair_law("internal", e, 1.0)
    with pytest.raises(ValueError, match="first pair's driver"):
        build(Train([PairSpec("external", None)]))


def test_hermite_periodic_is_exact_for_a_cubic_free_trigonometric_check():
    """The interpolant on N points reproduces sin and its slope to O(h^4)."""
    N = 1024
    th = TWO_PI * np.arange(N) / N
    x = np.linspace(-10, 10, 333)[None, :]
    v, s = hermite_periodic(np.sin(th)[None], np.cos(th)[None], x)
    assert np.abs(v - np.sin(x)).max() < 1e-11
    assert np.abs(s - np.cos(x)).max() < 1e-7


def test_population_of_driven_internal_trains_with_given_followers_equals_single_runs():
    """The other structures population-first too: a driven lobed ring (seed 001's kind)
    with radii, phases and carrier starts per design, and a given-follower pair (the sun
    derived from its follower, seed 000's kind) followed by a compound gear."""
    rng = np.random.default_rng(3)
    P = 3
    ph = np.radians(np.arange(0, 360, 45.0))
    radii = 90 + rng.uniform(-8, 8, (P, 8))
    C0 = rng.uniform(0, 1, P)

    def ring_train(k):
        s = slice(None) if k is None else slice(k, k + 1)
        return Train([PairSpec("internal", interpolated(ph, radii[s], 2048, lobes=4),
                               phase=C0[s] + 0.1, follower_turns=4.0)],
                     carrier0=C0[s], sun_speed_ratio=0.75, arm_length=150.0,
                     arm_angle=C0[s] - 0.7, arms=3)

    g2 = 55 + rng.uniform(-5, 5, (P, 8))
    g3 = 60 + rng.uniform(-5, 5, (P, 8))

    def seeder_like(k):
        s = slice(None) if k is None else slice(k, k + 1)
        return Train([PairSpec("external", follower=interpolated(ph, g2[s], 2048),
                               phase=0.3),
                      PairSpec("external", driver=interpolated(ph, g3[s], 2048),
                               phase=C0[s])], carrier0=C0[s], arm_length=400.0,
                     arm_angle=0.2)

    for make in (ring_train, seeder_like):
        many = forward(make(None), 360)
        for k in range(P):
            one = forward(make(k), 360)
            assert np.abs(one.tip[0] - many.tip[k]).max() < 1e-10
            assert np.abs(one.tip_rate[0] - many.tip_rate[k]).max() < 1e-9
            assert np.allclose(one.built.centre_distances[0], many.built.centre_distances[k],
                               rtol=0, atol=1e-10)
