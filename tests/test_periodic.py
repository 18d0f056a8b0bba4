import numpy as np
import pytest

from plantmech.geometry.periodic import RadiusCurve, convexity


def test_circle_is_convex_with_its_radius():
    th = np.linspace(0, 2 * np.pi, 12, endpoint=False)
    c = convexity(RadiusCurve.from_samples(th, np.full(12, 40.0)))
    assert c["convex"] and c["concave_spans_deg"] == []
    assert c["min_convex_radius_mm"] == pytest.approx(40.0)


def test_five_lobe_curve_has_five_concave_spans():
    # r = 1 + 0.08 cos 5 phi: concave where r^2 + 2 r'^2 - r r'' < 0, around phi = 36 deg + k 72
    th = np.linspace(0, 2 * np.pi, 720, endpoint=False)
    c = convexity(RadiusCurve.from_samples(th, 1 + 0.08 * np.cos(5 * th)))
    assert not c["convex"]
    assert len(c["concave_spans_deg"]) == 5
    mids = sorted((a + b) / 2 for a, b in c["concave_spans_deg"])
    assert np.allclose(mids, [36, 108, 180, 252, 324], atol=0.5)
    # at phi = 36 deg: r = 0.92, r' = 0, r'' = 2: |rho| = r^3 / (r r'' - r^2) = 0.778688 / 0.9936
    assert c["min_concave_radius_mm"] == pytest.approx(0.778688 / 0.9936, rel=1e-3)
    # at phi = 0: r = 1.08, r'' = -2: rho = r^3 / (r^2 + 2 r) = 1.259712 / 3.3264
    assert c["min_convex_radius_mm"] == pytest.approx(1.259712 / 3.3264, rel=1e-3)


def test_ellipse_about_focus_is_convex():
    A, e = 50.0, 0.35
    t = np.linspace(0, 2 * np.pi, 720, endpoint=False)
    c = convexity(RadiusCurve.from_samples(t, A * (1 - e**2) / (1 - e * np.cos(t))))
    assert c["convex"]


def test_cyclic_runs_wrap_and_edges():
    from plantmech.geometry.periodic import cyclic_runs

    m = np.array([1, 1, 0, 0, 1, 0, 1, 1], dtype=bool)
    assert cyclic_runs(m) == [(4, 4), (6, 1)]  # last run wraps through index 0
    assert cyclic_runs(np.zeros(4, bool)) == []
    assert cyclic_runs(np.ones(4, bool)) == [(0, 3)]


def test_uniform_periodic_spline_slopes_and_integral_match_scipy():
    """The FFT-solved periodic cubic spline (used in the hot inverse-design path) is
    SciPy's CubicSpline(bc_type="periodic"): node slopes and running integral."""
    from scipy.interpolate import CubicSpline

    from plantmech.geometry.periodic import (
        periodic_spline_node_slopes,
        periodic_spline_running_integral,
    )

    rng = np.random.default_rng(0)
    n = 360
    h = 2 * np.pi / n
    x = np.arange(n + 1) * h
    y = np.sin(3 * x[:-1]) + 0.3 * rng.standard_normal(n)
    spl = CubicSpline(x, np.r_[y, y[0]], bc_type="periodic")
    assert np.allclose(periodic_spline_node_slopes(y, h), spl(x[:-1], 1), atol=1e-10)
    assert np.allclose(periodic_spline_running_integral(y, h), spl.antiderivative()(x),
                       atol=1e-12)
    two = rng.standard_normal((n, 2))  # columns at once (tip x, y)
    spl2 = CubicSpline(x, np.vstack([two, two[:1]]), bc_type="periodic")
    assert np.allclose(periodic_spline_node_slopes(two, h), spl2(x[:-1], 1), atol=1e-10)
    # and exact on a trigonometric law it can represent to 4th order: d/dx sin x = cos x
    assert np.allclose(periodic_spline_node_slopes(np.sin(x[:-1]), h), np.cos(x[:-1]),
                       atol=1e-6)


def test_interpolant_rows_equal_the_shared_matrix():
    """Per-design evaluation angles (a per-design phase) give the same interpolant as the
    shared matrix, value and slope, for both kinds and uneven nodes."""
    from plantmech.geometry.periodic import periodic_interpolant_rows, periodic_spline_matrix

    rng = np.random.default_rng(1)
    for nodes in (np.radians(np.arange(16) * 22.5), np.sort(rng.uniform(0, 2 * np.pi, 9))):
        R = 60 + rng.uniform(-5, 5, (3, len(nodes)))
        shift = np.array([0.0, 0.3, -1.1])
        at = 0.7 + shift[:, None] + np.linspace(0, 2 * np.pi, 101)[None, :]
        for kind in ("spline", "hermite"):
            value, slope = periodic_interpolant_rows(nodes, R, at, kind)
            for p in range(3):
                for nu, got in ((0, value), (1, slope)):
                    ref = R[p] @ periodic_spline_matrix(nodes, at[p], nu, kind).T
                    assert np.abs(got[p] - ref).max() < 1e-10


def test_derivatives_are_scipys_values():
    """RadiusCurve.derivatives (one pass in a numba kernel) gives exactly what the three
    SciPy evaluations give: periodic spline and Hermite curves, an open curve with a break
    (the dwell's lock point), angles outside one turn and NaN."""
    from scipy.interpolate import CubicSpline


    rng = np.random.default_rng(4)
    th = np.sort(rng.uniform(0.0, 2 * np.pi, 17))
    r = 60.0 + 15.0 * rng.uniform(-1.0, 1.0, 17)
    curves = [RadiusCurve.from_samples(th, r, kind="spline"),
              RadiusCurve.from_samples(th, r, kind="hermite"),
              RadiusCurve.from_samples(th, r, theta0=th[0] - 0.3),  # theta0 off the nodes
              RadiusCurve(0.4, CubicSpline(np.r_[0.4, th[2:-2], 0.4 + 2 * np.pi],
                                           np.r_[55.0, r[2:-2], 58.0]), periodic=False)]
    angles = np.r_[rng.uniform(-20.0, 20.0, 3000), th, th + 2 * np.pi, np.nan]
    for curve in curves:
        got = curve.derivatives(angles)
        for nu in (0, 1, 2):
            ref = curve(angles, nu)
            assert np.array_equal(got[nu], ref, equal_nan=True), nu


@pytest.mark.parametrize("kernel_points", [1, 2**62])
def test_polar_curvature_radius_is_the_formula_written_out(monkeypatch, kernel_points):
    """The buffered evaluation and the numba kernel (every (P, N) table through it, then
    none) give bitwise the values of the formula as one expression (arrays and numbers for
    phi' and phi'', a zero numerator's inf), and a circle's radius."""
    from plantmech.geometry import periodic
    from plantmech.geometry.periodic import polar_curvature_radius

    monkeypatch.setattr(periodic, "CURVATURE_KERNEL_POINTS", kernel_points)

    def written_out(rho, drho, ddrho, dphi=1.0, ddphi=0.0):
        dphi2 = dphi * dphi
        num = rho * rho * (dphi2 * dphi) + 2 * drho * drho * dphi - rho * ddrho * dphi \
            + rho * drho * ddphi
        speed = np.sqrt(drho * drho + rho * rho * dphi2)
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(num == 0, np.inf, speed * speed * speed
                            / np.where(num == 0, 1.0, num))

    rng = np.random.default_rng(1)
    rho = rng.uniform(10, 80, (5, 1000))
    d, dd = rng.normal(0, 20, (5, 1000)), rng.normal(0, 50, (5, 1000))
    dd[0, :10] = (rho[0, :10] ** 2 + 2 * d[0, :10] ** 2) / rho[0, :10]  # straight: inf
    dphi, ddphi = rng.uniform(0.5, 2, (5, 1000)), rng.normal(0, 1, (5, 1000))
    for extra in ((), (1.0, 0.0), (0.25, 0.0), (dphi, ddphi)):
        assert np.array_equal(polar_curvature_radius(rho, d, dd, *extra),
                              written_out(rho, d, dd, *extra))
    ones, zeros = np.ones_like(rho), np.zeros_like(rho)
    assert np.array_equal(polar_curvature_radius(rho, d, dd),
                          written_out(rho, d, dd, ones, zeros))
    assert np.isinf(polar_curvature_radius(rho, d, dd)[0, :10]).sum() >= 5  # 0 or rounding
    assert np.allclose(polar_curvature_radius(np.full(4, 7.0), np.zeros(4), np.zeros(4)), 7.0)
