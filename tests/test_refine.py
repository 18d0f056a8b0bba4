"""Extremes and crossings refined between samples (geometry/refine.py, issue 34).

Independent expectations: closed forms (a cosine law's zero crossings at 2 pi / 3 and
4 pi / 3 and its minimum -0.5 at pi, between samples; cubics that the Hermite segment
reproduces exactly), and Table 2 as printed, whose refined minimum ratio and window at 0.1
deg samples must equal what a ten times finer grid reads.
"""

from __future__ import annotations

import numpy as np
import pytest

from plantmech.geometry.refine import (
    crossing_between,
    hermite_crossing,
    hermite_extreme,
    minimum_between,
    periodic_law,
    run_of_law,
)


def test_a_cosine_law_between_its_samples():
    n = 361  # pi and the crossings are not samples
    psi = 2 * np.pi * np.arange(n) / n
    law = periodic_law(np.cos(psi) + 0.5)
    below = np.flatnonzero(law(psi) < 0)
    run = run_of_law(law, psi, int(below[0]), int(below[-1]))
    assert run["start"] == pytest.approx(2 * np.pi / 3, abs=1e-7)
    assert run["end"] == pytest.approx(4 * np.pi / 3, abs=1e-7)
    assert run["x_min"] == pytest.approx(np.pi, abs=1e-5)
    assert run["minimum"] == pytest.approx(-0.5, abs=1e-9)
    sampled = (np.cos(psi) + 0.5)[below].min()
    assert sampled - run["minimum"] > 1e-6  # the grid's is not the curve's


def test_scalar_brent_helpers():
    x, v = minimum_between(lambda t: (t - 0.3) ** 2 + 1.0, 0.0, 1.0)
    assert x == pytest.approx(0.3, abs=1e-8) and v == pytest.approx(1.0, abs=1e-14)
    assert crossing_between(np.sin, 3.0, 3.3) == pytest.approx(np.pi, abs=1e-13)
    assert crossing_between(np.sin, 1.0, 2.0) == 1.0  # no sign change: the nearer end


def test_hermite_segments_vectorised():
    # y = s^3: from 0 to 1 with end slopes 0 and 3 (exact); levels 1/8, 27/64
    s = hermite_crossing([0.0, 0.0], [1.0, 1.0], [0.0, 0.0], [3.0, 3.0],
                         [0.125, 27 / 64])
    assert s == pytest.approx([0.5, 0.75], abs=1e-12)
    # y = s - s^2 (max 1/4 at 1/2) and y = s^3 - s (min -2 / (3 sqrt 3) at 1 / sqrt 3)
    s_max, v_max = hermite_extreme(0.0, 0.0, 1.0, -1.0, largest=True)
    assert s_max == pytest.approx(0.5) and v_max == pytest.approx(0.25)
    s_min, v_min = hermite_extreme(0.0, 0.0, -1.0, 2.0, largest=False)
    assert s_min == pytest.approx(1 / np.sqrt(3)) and v_min == pytest.approx(
        -2 / (3 * np.sqrt(3)))
    # an end is the extreme of a monotone segment
    assert hermite_extreme(0.0, 1.0, 1.0, 1.0)[1] == pytest.approx(1.0)


def test_table2_as_printed_minimum_ratio_and_window_are_the_curves():
    """The printed q3 makes the planet turn back: at 0.1 deg samples the refined minimum
    and window equal those a 0.01 deg grid reads (-3.2335, 156.11-160.72 deg), not the 0.1
    deg grid's (-3.224, 156.2-160.7)."""
    from plantmech.design import load_design
    from plantmech.mechanisms.seeder_inverse import InverseSettings, inverse_design
    from plantmech.mechanisms.seeder_trains import inverse_design_of
    from tests.conftest import EXAMPLES

    traj, res = inverse_design_of(load_design(EXAMPLES / "sugarcane_table2_as_printed.toml"))
    d = [x for x in res.diagnostics if x.kind == "ratio_not_positive"]
    assert len(d) == 1
    fine = inverse_design(traj, InverseSettings(samples=36000))
    g = fine.total_ratio
    neg = np.flatnonzero(g < 0)
    lo, hi = np.degrees(fine.carrier_angle[[neg[0], neg[-1]]])
    assert d[0].carrier_angle_deg[0] == pytest.approx(lo, abs=0.01)
    assert d[0].carrier_angle_deg[1] == pytest.approx(hi, abs=0.01)
    assert round(d[0].carrier_angle_deg[0], 1) == 156.1
    reached = float(d[0].message.split("reaches ")[1].split(")")[0])
    assert reached == pytest.approx(g.min(), abs=2e-4)
    assert round(reached, 2) == -3.23


def test_cyclic_extreme_of_a_sampled_circle():
    """y = sin(psi + 0.3) at 36 samples (10 deg) with its exact rate: the largest and
    smallest values are +-1, between the samples, to the Hermite segment's accuracy (the
    samples alone miss by more than 1e-3)."""
    from plantmech.geometry.refine import cyclic_extreme

    psi = 2 * np.pi * np.arange(36) / 36
    y, dy = np.sin(psi + 0.3), np.cos(psi + 0.3)
    assert y.max() < 1 - 1e-3
    top = cyclic_extreme(np.stack([y, 2 * y]), np.stack([dy, 2 * dy]), 2 * np.pi / 36)
    assert top == pytest.approx([1.0, 2.0], rel=2e-6)
    assert cyclic_extreme(y, dy, 2 * np.pi / 36, largest=False) == pytest.approx(-1.0, abs=2e-6)
