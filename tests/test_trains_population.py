"""The general train model's population path (issue 16, "fast"): the centre-distance solve
(Newton on the mean ratio, trains/pairs.py) against closed forms and the full bisection
it replaced, and a population of P different designs against P single runs, through
``objectives.planetary.population_evaluation`` (sub-populations, derived drivers on first
use) and ``trains.model.forward``."""

from __future__ import annotations

import numpy as np
import pytest

from plantmech.design import load_design
from plantmech.trains.curves import ellipse, fourier, rows_matmul
from plantmech.trains.pairs import (
    _admissible,
    _bisected,
    _ratio,
    pair_law,
    solve_centre_distance,
)
from tests.conftest import EXAMPLES

TWO_PI = 2 * np.pi


@pytest.mark.parametrize("grid", [64, 4096, 16384])
def test_two_identical_ellipses_about_their_foci_close_at_twice_the_semi_major_axis(grid):
    """r_2 = a - r_1 is the same ellipse seen from its other end exactly when a = 2A: the
    mean ratio (1 - e^2) / (1 + e^2 - 2 e cos theta) is then 1 (its uniform mean is exact
    to rounding for these grids: a periodic analytic function). The solve must meet the
    closure to rounding (|mean g - 1| < 1e-14) and land on 2A to 1e-12 relative."""
    A = np.array([25.0, 30.0, 20.0, 55.5])
    e = np.array([0.1, 0.18, 0.3, 0.5])
    curve = ellipse(A, e, grid)
    a = solve_centre_distance("external", curve.r, 1.0)
    assert np.abs(a / (2 * A) - 1).max() < 1e-12
    closure = np.mean(_ratio("external", curve.r, a[:, None]), axis=1) - 1.0
    assert np.abs(closure).max() < 1e-14
    law = pair_law("external", curve, 1.0)
    assert np.abs(law.closure_error).max() < 1e-12


def test_circles_close_where_their_ratio_says_for_every_kind():
    """Circular drivers of radius R: external a = R (1 + 1/q); internal (the driver is the
    ring) R / (R - a) = q, a = R (1 - 1/q); ring follower R / (R + a) = q,
    a = R (1 - q) / q (mm)."""
    R = np.array([[30.0], [45.0], [60.0]]) * np.ones((1, 512))
    cases = {"external": (2.0, lambda R, q: R * (1 + 1 / q)),
             "internal": (3.0, lambda R, q: R * (1 - 1 / q)),
             "internal_ring_follower": (0.25, lambda R, q: R * (1 - q) / q)}
    for kind, (q, closed) in cases.items():
        a = solve_centre_distance(kind, R, q)
        assert np.abs(a - closed(R[:, 0], q)).max() < 1e-12 * R.max(), kind


@pytest.mark.parametrize("kind, q", [("external", 1.0), ("external", 2.0),
                                     ("internal", 2.0), ("internal_ring_follower", 0.5)])
def test_newton_lands_on_the_root_the_full_bisection_finds(kind, q):
    """Wavy Fourier drivers (P = 6, 4096 samples): the bracketed Newton solve equals the
    64-step bisection of the full table (the solve before issue 16's change) to 1e-12
    relative, for every kind."""
    rng = np.random.default_rng(3)
    lobes = 2 if q == 2.0 and kind == "external" else 1  # a driver repeating every 1/q
    cos = np.zeros((6, 4))
    sin = np.zeros((6, 4))
    cos[:, lobes - 1] = rng.uniform(1.0, 6.0, 6)
    sin[:, 2 * lobes - 1] = rng.uniform(-2.0, 2.0, 6)
    r = fourier(rng.uniform(40.0, 60.0, 6), cos, sin, 4096).r
    qq = np.full(6, q)
    lo, hi = _admissible(kind, r, qq)
    reference = _bisected(kind, r, qq, lo, hi)
    a = solve_centre_distance(kind, r, q)
    assert np.abs(a / reference - 1).max() < 1e-12


def test_a_given_centre_distance_that_does_not_close_names_the_one_that_does():
    curve = ellipse(25.0, 0.2, 2048)
    with pytest.raises(ValueError, match=r"it closes at 50\.0000 mm"):
        pair_law("external", curve, 1.0, centre_distance=49.0, name="pair 1")


def test_rows_matmul_is_the_matrix_product_row_by_row():
    rng = np.random.default_rng(0)
    a, b = rng.normal(size=(37, 8)), rng.normal(size=(8, 16384))
    out = rows_matmul(a, b)
    assert np.abs(out - a @ b).max() < 1e-12
    assert np.abs(out[5] - rows_matmul(a[5:6], b)[0]).max() < 1e-12  # P = 1: BLAS's gemv


def _table4_variants(P: int, seed: int = 0) -> list:
    """P variants of the Table 4 file (its dwell kept): gear 2's and gear 3's radii +
    uniform(-2, 2) mm, both centre distances solved."""
    rng = np.random.default_rng(seed)
    base = load_design(EXAMPLES / "planetary" / "sugarcane_table4.toml")
    out = []
    for _ in range(P):
        d = base.model_copy(deep=True)
        p0, p1 = d.train.pairs
        p0.follower.radii_mm = [float(v) for v in np.asarray(p0.follower.radii_mm)
                                + rng.uniform(-2, 2, 8)]
        p1.driver.radii_mm = [float(v) for v in np.asarray(p1.driver.radii_mm)
                              + rng.uniform(-2, 2, 8)]
        p0.centre_distance_mm = p1.centre_distance_mm = None
        d.train.grid = 4096  # small: the test's 41 builds stay quick
        out.append(d)
    return out


def test_a_population_of_different_designs_gives_each_design_its_single_numbers():
    """P = 41 Table 4 variants (a toothless dwell, solved centre distances) evaluated
    as one population cut into sub-populations of ``chunk_designs`` (shrunk to 16 so it
    is cut in three) give every design's rows (objectives, module windows, pressure
    angles) and arm-1 motion as its own P = 1 evaluation, to 1e-12 (each design's Newton
    steps and tables are its own: the numbers do not depend on the others)."""
    from plantmech.objectives import planetary as obj

    designs = _table4_variants(41)
    saved = obj.CHUNK_POINTS
    obj.CHUNK_POINTS = 16 * 4096
    try:
        assert obj.chunk_designs(4096) == 16
        many, motions = obj.structure_population(designs, 720)
        rows_many = obj.population_evaluation(designs, 720)
    finally:
        obj.CHUNK_POINTS = saved
    for i, d in enumerate(designs):
        one, motion = obj.structure_population([d], 720)
        for rows in (many[i], rows_many[i]):
            assert [r["name"] for r in rows] == [r["name"] for r in one[0]]
            for r, s in zip(rows, one[0], strict=True):
                assert r["value"] == pytest.approx(s["value"], rel=1e-12, abs=1e-12)
                assert r["violation"] == pytest.approx(s["violation"], rel=1e-12, abs=1e-12)
                assert r["ok"] == s["ok"]
        for x, y in zip(motions[i], motion[0], strict=True):
            assert np.abs(x - y).max() < 1e-12 * max(1.0, np.abs(y).max())


def test_derived_drivers_on_first_use_equal_the_population_rows():
    """The derived sun (the mate of gear 2 with its toothless arc) is derived when first
    read: for a population it equals each design's own (P = 1): radii to 1e-12 mm,
    slopes to 1e-12 of their largest (its inversion's start, a search over the rows'
    joined tables, moves by rounding with the other rows)."""
    from plantmech.trains.spec import build_from_designs

    designs = _table4_variants(3, seed=1)
    built = build_from_designs(designs)
    assert built.known_drivers[0] is None  # not derived by the build
    sun = built.drivers[0]
    for i, d in enumerate(designs):
        one = build_from_designs([d]).drivers[0]
        assert np.abs(one.r[0] - sun.r[i]).max() < 1e-12
        assert np.abs(one.dr[0] - sun.dr[i]).max() < 1e-12 * np.abs(one.dr[0]).max()


@pytest.mark.filterwarnings("ignore:invalid value encountered in cast")  # NumPy's NaN angle
def test_the_kernels_give_numpys_values_to_the_last_bit(monkeypatch):
    """Above ``curves.KERNEL_POINTS`` angles the Hermite interpolant and the law's
    inversion run in numba (``trains.kernels``): the same values as NumPy's, bit for bit
    (per-row and shared angles, several turns both ways, a NaN angle; inverted at rising,
    falling and scattered targets: the interval walked to or bisected); the mate rolled by
    ``trains.fused.mate_tables`` (Newton on the found interval's cubic, not on the angle)
    to 1e-12 mm (measured 3.6e-14), its slope to 1e-11. (The law's own tables by
    ``trains.fused.pair_laws``: tests/test_trains_fused.py.)"""
    from plantmech.trains import curves
    from plantmech.trains.curves import hermite_periodic

    rng = np.random.default_rng(0)
    curve = fourier(rng.uniform(40, 60, 5), rng.uniform(1, 5, (5, 3)),
                    rng.uniform(-2, 2, (5, 3)), 2048)
    x, shared = rng.uniform(-20, 20, (5, 3000)), rng.uniform(-20, 20, (1, 3000))
    x[2, 7] = np.nan
    target = np.broadcast_to(np.linspace(-10.0, 10.0, 2048), (5, 2048))
    runs = []
    law = pair_law("external", curve, 1.0)  # one law (NumPy's: 5 x 2048 points) for both
    for points in (1, 2**62):  # every table in numba, then none
        monkeypatch.setattr(curves, "KERNEL_POINTS", points)
        runs.append((*hermite_periodic(curve.r, curve.dr, x),
                     *hermite_periodic(curve.r, curve.dr, shared), law.invert(target),
                     law.invert(-target), law.invert(x[:, 2000:]), law.mate()))
    for kernel, numpy_ in zip(runs[0][:-1], runs[1][:-1], strict=True):
        assert np.array_equal(kernel, numpy_, equal_nan=True)
    fused, numpy_ = runs[0][-1], runs[1][-1]
    assert np.abs(fused.r - numpy_.r).max() < 1e-12
    assert np.abs(fused.dr - numpy_.dr).max() < 1e-11
    assert np.isnan(runs[0][0][2, 7]) and np.isfinite(runs[0][0][2, 8])
