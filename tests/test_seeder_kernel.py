"""The fused seeder kernels (mechanisms/seeder_kernel.py) against independent computations:
SciPy's spline antiderivative, closed forms, the NumPy single-design manufacturability path
and a direct NumPy evaluation of the section objectives."""

import numpy as np
from scipy.interpolate import CubicSpline

from plantmech.gears.closure import solve_centre_distances
from plantmech.gears.manufacturability import CuttingRules, PairShape, assess_pair, shape_pair
from plantmech.mechanisms.seeder_batch import periodic_spline_matrix
from plantmech.mechanisms.seeder_kernel import (
    _closing_centre_distance,
    _running_integrals,
    spline_factors,
)
from plantmech.objectives.seeder_population import pitch_curve_metrics, section_values

TWO_PI = 2 * np.pi


def test_closing_centre_distance_circle_and_curves():
    # a circle of radius r turning its mate by `turn`: r / (a - r) 2 pi = turn
    r, turn = 37.0, TWO_PI - 0.7
    got = _closing_centre_distance(np.full(1025, r), 1024, turn)
    assert abs(got - r * (1 + TWO_PI / turn)) < 1e-9
    rng = np.random.default_rng(1)
    t = np.linspace(0, TWO_PI, 2049)
    for _ in range(5):
        c = rng.uniform(-1, 1, 4)
        rr = 50 + 8 * c[0] * np.cos(t) + 5 * c[1] * np.sin(2 * t) + 3 * c[2] * np.cos(3 * t + c[3])
        a = _closing_centre_distance(rr, 2048, TWO_PI)
        assert abs(a - solve_centre_distances(rr[None, :-1], TWO_PI)[0]) < 1e-9 * a
        assert abs(np.mean(rr[:-1] / (a - rr[:-1])) - 1.0) < 1e-12  # the pair closes


def test_pitch_curve_metrics_match_the_single_design_path():
    """Module window's upper end, working pressure angle and shape extremes of the fused
    pass against manufacturability.shape_pair / assess_pair on the same samples."""
    rng = np.random.default_rng(2)
    nodes = np.radians(np.arange(8) * 45.0)
    R = 60 + rng.uniform(-9, 9, (6, 8))
    a = np.full(6, 130.0) + rng.uniform(-5, 5, 6)
    rules = CuttingRules()
    for kind in ("hermite", "spline"):
        c0 = np.radians(13.0)
        got = pitch_curve_metrics(nodes, R, a, c0, kind, 720, rules)
        t = c0 + np.linspace(0.0, TWO_PI, 720, endpoint=False)
        r, r1, r2 = (R @ periodic_spline_matrix(nodes, t, nu, kind).T for nu in (0, 1, 2))
        shapes, mu = shape_pair(t, r, r1, r2, a)
        v = assess_pair(PairShape("p", shapes, mu), rules)
        assert np.allclose(got["module_high"], v.module_high, rtol=1e-12, atol=0)
        assert np.allclose(got["working_pressure_angle_deg"], v.working_pressure_angle_deg,
                           rtol=1e-12)
        for key, shape in zip(("gear", "mate"), shapes, strict=True):
            kappa = 1 / shape.curvature_radius
            assert np.allclose(got[key]["min_kappa_r"], (kappa * shape.radius).min(axis=1),
                               rtol=1e-12)
            assert np.allclose(got[key]["min_radius_mm"], shape.radius.min(axis=1))
            concave = kappa < 0
            spans = (concave & ~np.roll(concave, 1, axis=1)).sum(axis=1)
            assert np.array_equal(got[key]["concave_spans"], spans)


def test_section_values_against_direct_numpy():
    rng = np.random.default_rng(4)
    P, S = 5, 360
    psi = np.linspace(0, TWO_PI, S, endpoint=False)
    arm = 0.3 * np.sin(psi[None, :] + rng.uniform(0, 6, (P, 1))) + rng.uniform(-1, 1, (P, 1))
    rate = np.stack([np.cos(2 * psi[None, :] + rng.uniform(0, 6, (P, 1))) * 300,
                     np.sin(psi[None, :] + rng.uniform(0, 6, (P, 1))) * 200], axis=-1)
    sec = np.radians([10.3, 50.7, 120.2, 200.9, 250.4, 330.1])
    scale = np.radians(360.0) / 1000
    got = section_values(psi, arm, sec, rate, np.degrees(1.0), scale)
    rel = np.degrees(arm - arm[:, :1])
    v = rate * scale

    def at(values, x):  # linear periodic interpolation of the samples
        return np.array([np.interp(np.mod(x, TWO_PI), np.r_[psi, TWO_PI], np.r_[row, row[0]])
                         for row in values])

    def inside(a, b):
        return np.mod(psi - a, TWO_PI) <= np.mod(b - a, TWO_PI)

    ab, de, ef = inside(sec[0], sec[1]), inside(sec[3], sec[4]), inside(sec[4], sec[5])
    ref = at(rel, sec[0])
    swing = np.maximum(np.abs(rel - ref[:, None])[:, ab].max(axis=1),
                       np.abs(at(rel, sec[1]) - ref))
    assert np.allclose(got[:, 0], swing, atol=1e-12)
    assert np.allclose(got[:, 2], at(rel, sec[4]), atol=1e-12)
    vx_e = at(v[..., 0], sec[4])
    assert np.allclose(got[:, 3], vx_e) and np.allclose(got[:, 4], vx_e)
    static = np.hypot(v[..., 0], v[..., 1])
    peak = np.maximum(static[:, de].max(axis=1),
                      np.maximum(at(static, sec[3]), at(static, sec[4])))
    assert np.allclose(got[:, 5], peak, atol=1e-12)
    dynamic = np.hypot(v[..., 0] - vx_e[:, None], v[..., 1])
    low = np.minimum(dynamic[:, ef].min(axis=1),
                     np.minimum(at(dynamic, sec[4]), at(dynamic, sec[5])))
    assert np.allclose(got[:, 7], low, atol=1e-12)


def test_spans_of_designs_on_threads_give_the_one_thread_result():
    """The kernels split P designs into spans run on numba's threads (``chunks_for``):
    every design is computed once, whatever the split (1, 3 or 7 spans, bit for bit)."""
    from plantmech.mechanisms import seeder_kernel as K
    from plantmech.mechanisms.seeder_batch import simulate_population

    rng = np.random.default_rng(5)
    P = 70
    nodes = np.radians(np.arange(8) * 45.0)
    R2, R3 = 60 + rng.uniform(-5, 5, (P, 8)), 60 + rng.uniform(-5, 5, (P, 8))
    assert K.chunks_for(P) >= 1 and K.chunks_for(1) == 1
    assert K.kernel_threads() >= 1
    runs = []
    for chunks in (1, 3, 7):
        orig = K.chunks_for
        K.chunks_for = lambda P, c=chunks: c
        try:
            m = simulate_population(nodes, R2, R3, 240.0, 450.0, None, None, 0.3, 0.3,
                                    samples=90, dense=256, kind="hermite")
            ext = pitch_curve_metrics(nodes, R2, m.a1, 0.1, "hermite", 90)
            sec = section_values(m.carrier_angle, m.arm_angle, np.radians(
                [10, 60, 120, 200, 250, 300]), m.tip_rate)
        finally:
            K.chunks_for = orig
        runs.append((m.tip, m.arm_angle, m.a1, m.a2, ext["gear"]["min_kappa_r"], sec))
    for other in runs[1:]:
        for a, b in zip(runs[0], other, strict=True):
            assert np.array_equal(a, b)


def test_sincos_rows_is_numpys_cos_and_sin():
    """The branch-free cos/sin of the simulation against numpy, at random angles, at the
    quadrant boundaries (multiples of pi / 4 and just beside pi / 2 multiples) and at
    several turns."""
    from plantmech.mechanisms.seeder_kernel import sincos_rows

    rng = np.random.default_rng(6)
    x = np.r_[rng.uniform(-40, 40, 20000), np.arange(-40, 41) * np.pi / 4,
              np.arange(-40, 41) * np.pi / 2 + 1e-9, 0.0, -0.0, 1e-300]
    c, s = np.empty_like(x), np.empty_like(x)
    sincos_rows(x, c, s, len(x))
    assert np.abs(c - np.cos(x)).max() < 3e-16
    assert np.abs(s - np.sin(x)).max() < 3e-16


def test_kernel_threads_from_the_environment(monkeypatch):
    """PLANTMECH_KERNEL_THREADS: unset -> one thread (one span whatever P); a bad value is
    refused naming the variable."""
    import pytest

    from plantmech.mechanisms import seeder_kernel as K

    monkeypatch.delenv("PLANTMECH_KERNEL_THREADS", raising=False)
    assert K.kernel_threads() == 1 and K.chunks_for(10_000) == 1
    monkeypatch.setenv("PLANTMECH_KERNEL_THREADS", "2")
    assert 1 <= K.kernel_threads() <= 2
    assert K.chunks_for(10) == 1  # below PARALLEL_MIN_DESIGNS: one span
    for bad in ("0", "two", "-1"):
        monkeypatch.setenv("PLANTMECH_KERNEL_THREADS", bad)
        with pytest.raises(ValueError, match="PLANTMECH_KERNEL_THREADS"):
            K.kernel_threads()


def test_running_integral_split_sweeps_at_every_length():
    """The sweeps run in two halves at once (the second corrected by the first's last
    slope): odd and even lengths, tiny to large, against SciPy's not-a-knot antiderivative."""
    for D in (4, 5, 6, 7, 16, 33, 512, 2047, 2048):
        t = np.linspace(0.0, TWO_PI, D + 1)
        y = 1.0 + 0.3 * np.sin(3 * t) + 0.05 * np.abs(np.sin(t))
        y2 = np.exp(np.cos(t)) + t / 10
        cp, piv = spline_factors(D)
        out, out2 = np.empty(D + 1), np.empty(D + 1)
        _running_integrals(y, y2, D, t[1] - t[0], cp, piv, np.empty(D + 1), np.empty(D + 1),
                           out, out2)
        assert np.abs(out - CubicSpline(t, y).antiderivative()(t)).max() < 1e-12
        assert np.abs(out2 - CubicSpline(t, y2).antiderivative()(t)).max() < 1e-12
        if D >= 512:  # the integral itself: 2 pi + 0.05 * 4 (the |sin| term)
            assert abs(out[-1] - (TWO_PI + 0.2)) < 1e-5
