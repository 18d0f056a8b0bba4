"""The numba kernels of the single-design inverse design against its NumPy path (the same
model, kept as the reference): every bundled seeder example, at the app's working
resolution and at 3600 samples, gives the same verdict, diagnostics and numbers to 1e-6
(mm, rad)."""

from pathlib import Path

import numpy as np
import pytest

from plantmech.design import load_design
from plantmech.geometry.trajectory import ClosedTrajectory
from plantmech.mechanisms.seeder_inverse import inverse_design
from plantmech.workflows import inverse_settings

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
SEEDERS = sorted(p.name for p in EXAMPLES.glob("sugarcane_*.toml")
                 if load_design(p).trajectory is not None)
ARRAYS = ("u", "tip", "carrier_abs", "arm_angle", "planet_rel", "total_ratio", "stage1_ratio",
          "stage2_ratio", "gear2_angle", "r1", "r2", "r3", "r4", "planet_rel_realized",
          "arm_angle_realized", "tip_realized", "point_carrier_angle")


def test_every_seeder_example_is_covered():
    assert {"sugarcane_seeder.toml", "sugarcane_seeder_dwell.toml",
            "sugarcane_table2_as_printed.toml"} <= set(SEEDERS)


@pytest.mark.parametrize("samples", [360, 3600])
@pytest.mark.parametrize("name", SEEDERS)
def test_kernels_match_the_numpy_path(name, samples):
    design = load_design(EXAMPLES / name)
    traj = ClosedTrajectory.through(np.asarray(design.trajectory.points, dtype=float))
    settings = inverse_settings(design)
    settings.samples = samples
    ref = inverse_design(traj, settings, fused=False)
    new = inverse_design(traj, settings)
    assert new.feasible == ref.feasible
    assert [d.as_dict() for d in new.diagnostics] == [d.as_dict() for d in ref.diagnostics]
    for key in ("L1", "L2", "a1", "a2", "shaft_offset", "u_start"):
        assert getattr(new, key) == getattr(ref, key)
    compared = 0
    for key in ARRAYS:
        a, b = getattr(ref, key), getattr(new, key)
        if a is None:
            assert b is None, key
            continue
        assert np.array_equal(np.isnan(a), np.isnan(b)), key
        ok = ~np.isnan(a)
        assert np.abs(a[ok] - b[ok]).max() < 1e-6, key
        compared += 1
    assert compared >= 6  # every example gets at least as far as the planned motion
    if ref.closure_error:
        assert new.closure_error["stage1"] < 1e-9 and new.closure_error["stage2"] < 1e-9


def test_extreme_radii_kernel_matches_the_numpy_loop():
    from plantmech.geometry.trajectory_batch import TrajectoryBatch
    from plantmech.mechanisms.seeder_inverse import extreme_radii

    pts = np.stack([np.asarray(load_design(EXAMPLES / n).trajectory.points, dtype=float)
                    for n in SEEDERS if len(load_design(EXAMPLES / n).trajectory.points) == 27])
    rng = np.random.default_rng(7)
    moved = pts[rng.integers(0, len(pts), 40)] + rng.normal(0.0, 4.0, (40,) + pts.shape[1:])
    tb = TrajectoryBatch(np.concatenate([pts, moved]))
    ref = extreme_radii(tb, fused=False)
    new = extreme_radii(tb)
    for (u_ref, rho_ref), (u_new, rho_new) in zip(ref, new, strict=True):
        assert np.abs(u_new - u_ref).max() < 1e-9  # mm of chord parameter
        assert np.abs(rho_new - rho_ref).max() < 1e-9  # mm


def test_loop_spans_kernel_matches_the_numpy_loop():
    from plantmech.geometry.trajectory_batch import TrajectoryBatch
    from plantmech.objectives.seeder_inverse_population import loop_spans

    pts = np.asarray(load_design(EXAMPLES / "sugarcane_seeder.toml").trajectory.points,
                     dtype=float)
    rng = np.random.default_rng(11)
    # moved copies: most still an "8" (one crossing), some not (NaN spans)
    moved = pts[None] + rng.normal(0.0, 1.0, (60, 1, 1)) * rng.normal(0.0, 8.0, (60,) +
                                                                    pts.shape)
    a = np.linspace(0.0, 2 * np.pi, len(pts), endpoint=False)
    circle = np.c_[300.0 * np.cos(a), 300.0 * np.sin(a) - 400.0]  # no crossing
    tb = TrajectoryBatch(np.concatenate([pts[None], moved, circle[None]]))
    count_ref, spans_ref = loop_spans(tb, fused=False)
    count_new, spans_new = loop_spans(tb)
    assert np.array_equal(count_ref, count_new)
    assert (count_ref == 1).sum() >= 10 and (count_ref != 1).sum() >= 1
    assert np.array_equal(np.isnan(spans_ref), np.isnan(spans_new))
    ok = ~np.isnan(spans_ref)
    assert np.abs(spans_ref[ok] - spans_new[ok]).max() < 1e-9  # mm of chord parameter


def test_the_kernel_modules_copies_of_np_mod_are_one_function_and_equal_np_mod():
    """Three kernel modules each keep a copy of ``_mod`` (numba's disk cache does not see a
    change in another module's function a kernel inlined): the copies stay the same source,
    and each equals NumPy's np.mod bit for bit, on both sides of every branch."""
    import inspect

    from plantmech.geometry import pitch_kernels, trajectory_kernels
    from plantmech.mechanisms import seeder_inverse_kernel

    copies = [m._mod for m in (pitch_kernels, trajectory_kernels, seeder_inverse_kernel)]
    sources = {inspect.getsource(f.py_func) for f in copies}
    assert len(sources) == 1
    rng = np.random.default_rng(0)
    b = np.array([2 * np.pi, 1.0, 0.1, 7.3])
    for period in b:
        a = np.concatenate([rng.uniform(-5 * period, 5 * period, 400),
                            period * np.array([-2, -1, -0.5, 0, 0.5, 1, 2, 3]),
                            np.nextafter(period * np.array([-1, 0, 1, 2]), -np.inf),
                            np.nextafter(period * np.array([-1, 0, 1, 2]), np.inf)])
        expected = np.mod(a, period)
        for f in copies:
            got = np.array([f(x, period) for x in a])
            assert np.array_equal(got, expected)


def test_the_interval_head_finds_the_piece_as_searchsorted_does():
    """``_interval`` (the piece and offset both spline evaluations of the kernel read, written
    once) against an independent search: u wrapped into the period by floor, the piece i
    with knots[i] <= u < knots[i + 1] (np.searchsorted), clipped to the last; at random
    parameters, at every knot, below 0 and past the period. ``_point`` and
    ``_point_and_derivatives`` give the same position there."""
    from plantmech.geometry.trajectory_batch import TrajectoryBatch
    from plantmech.mechanisms.seeder_inverse_kernel import (
        _interval,
        _point,
        _point_and_derivatives,
    )

    pts = np.asarray(load_design(EXAMPLES / "sugarcane_seeder.toml").trajectory.points,
                     dtype=float)
    tb = TrajectoryBatch(pts[None])
    knots, period, coef = tb.knots[0], float(tb.period[0]), tb.coef[0]
    rng = np.random.default_rng(3)
    us = np.concatenate([rng.uniform(-2 * period, 3 * period, 300), knots,
                         knots - period, knots + period, [np.nextafter(period, 0.0)]])
    for u in us:
        w = u - period * np.floor(u / period)
        i_ref = min(int(np.searchsorted(knots, w, side="right")) - 1, len(knots) - 2)
        i, t = _interval(knots, period, u)
        assert i == i_ref
        assert t == w - knots[i_ref]
        assert 0.0 <= t <= knots[i_ref + 1] - knots[i_ref] + 1e-12
        x, y = _point(coef, knots, period, u)
        v = _point_and_derivatives(coef, knots, period, u)
        assert (x, y) == (v[0], v[1])
