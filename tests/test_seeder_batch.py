import numpy as np
import pytest

from plantmech.geometry.periodic import RadiusCurve
from plantmech.mechanisms.seeder_batch import periodic_spline_matrix, simulate_population
from plantmech.mechanisms.seeder_forward import SeederTrain, simulate, solve_centre_distance


def test_spline_matrix_reproduces_the_spline():
    nodes = np.radians(np.arange(8) * 45.0)
    r = np.array([55.4, 54.9, 62.0, 74.0, 52.9, 60.9, 58.9, 55.9])
    at = np.linspace(-1, 7, 50)
    curve = RadiusCurve.from_samples(nodes, r)
    assert np.allclose(periodic_spline_matrix(nodes, at) @ r, curve(at), atol=1e-12)


def test_population_matches_single_design_simulation():
    rng = np.random.default_rng(3)
    nodes = np.radians(np.arange(8) * 45.0)
    P = 5
    R2 = 60 + rng.uniform(-5, 5, (P, 8))
    R3 = 60 + rng.uniform(-5, 5, (P, 8))
    a1 = np.array([solve_centre_distance(RadiusCurve.from_samples(nodes, r)) for r in R2])
    a2 = np.array([solve_centre_distance(RadiusCurve.from_samples(nodes, r)) for r in R3])
    L1, L2, c0, arm0 = a1 + a2, rng.uniform(400, 500, P), rng.uniform(0, 1, P), 0.4
    pop = simulate_population(nodes, R2, R3, L1, L2, a1, a2, c0, arm0, samples=720)
    assert pop.tip.shape == (P, 720, 2)
    assert np.all(pop.closure_error < 1e-8)
    for p in range(P):
        tr = SeederTrain(L1=L1[p], L2=L2[p], a1=a1[p], a2=a2[p],
                         gear2=RadiusCurve.from_samples(nodes, R2[p]),
                         gear3=RadiusCurve.from_samples(nodes, R3[p]),
                         gear2_contact0=np.pi, gear3_contact0=0.0, carrier0=c0[p], arm0=arm0)
        single = simulate(tr, samples=720)
        assert np.abs(pop.tip[p] - single.tip).max() < 1e-6
        assert np.abs(pop.tip_rate[p] - single.tip_rate).max() < 1e-4


def test_population_with_hermite_dwell_and_solved_centre_distances():
    from plantmech.mechanisms.seeder_forward import GearPoints, assemble_train

    rng = np.random.default_rng(11)
    nodes = np.radians(np.arange(8) * 45.0)
    P = 4
    R2 = 60 + rng.uniform(-6, 6, (P, 8))
    R3 = 62 + rng.uniform(-6, 6, (P, 8))
    start, sector = np.radians(70.0), np.radians(45.0)
    pop = simulate_population(nodes, R2, R3, 240.0, 498.0, None, None, 0.36, 0.36,
                              contact2_0=5.5, contact3_0=0.2, samples=720, kind="hermite",
                              dwell_start=start, dwell_sector=sector)
    assert np.all(pop.closure_error < 1e-9)
    for p in range(P):
        tr, fixes = assemble_train(240.0, 498.0, 127.0, 127.0, GearPoints(nodes, R2[p], 5.5),
                                   GearPoints(nodes, R3[p], 0.2), 0.36, 0.36, start, sector,
                                   kind="hermite", closure="centre_distance")
        assert pop.a1[p] == pytest.approx(tr.a1, rel=1e-9)
        assert pop.a2[p] == pytest.approx(tr.a2, rel=1e-9)
        single = simulate(tr, samples=720)
        assert np.abs(pop.tip[p] - single.tip).max() < 1e-5
        assert np.abs(pop.tip_rate[p] - single.tip_rate).max() < 1e-3
        assert np.array_equal(pop.in_dwell, single.in_dwell)


def test_hermite_matrix_reproduces_the_hermite_curve():
    nodes = np.radians(np.arange(8) * 45.0)
    r = np.array([55.4, 54.9, 62.0, 74.0, 52.9, 60.9, 58.9, 55.9])
    at = np.linspace(-1, 7, 50)
    curve = RadiusCurve.from_samples(nodes, r, kind="hermite")
    for nu in (0, 1):
        assert np.allclose(periodic_spline_matrix(nodes, at, nu, "hermite") @ r, curve(at, nu),
                           atol=1e-10)
