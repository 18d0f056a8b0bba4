"""Study plots (outputs.study_plots): what the histograms show of the limits and of
P(ok)."""

from __future__ import annotations

import numpy as np

from plantmech.outputs.study_plots import (
    histogram_window,
    limit_bounds,
    plot_histograms,
    probability_text,
)
from plantmech.studies.runner import wilson


def test_limit_bounds_reads_the_limit_texts():
    assert limit_bounds("> 320 and < 350 deg") == (320.0, 350.0)
    assert limit_bounds("< 0.5 mm") == (None, 0.5)
    assert limit_bounds("> -2.5e-1 mm") == (-0.25, None)


def test_a_near_limit_is_shown_and_a_far_one_named():
    x = np.linspace(29.0, 29.2, 50)  # spread 0.2
    left, right, out = histogram_window(x, (None, 29.8))  # 3 spreads away: in view
    assert left < 29.0 and right > 29.8 and out == []
    left, right, out = histogram_window(x, (20.0, 30.5))  # 6.5 and 45 spreads away
    assert out == [20.0, 30.5] and 28.9 < left < 29.0 and 29.2 < right < 29.3
    left, right, out = histogram_window(np.full(10, 4.0), (None, 20.0))  # no spread
    assert out == [20.0] and left < 4.0 < right


def test_certain_looking_probabilities_carry_their_bound():
    lo, hi = wilson(3000, 3000)
    assert probability_text(1.0, (lo, hi), 3000) == (
        f"P(ok) = 1: met in all 3000 samples (95 %: >= {lo:.4f})")
    lo, hi = wilson(0, 3000)
    assert ">= " not in probability_text(0.0, (lo, hi), 3000)
    assert f"<= {hi:.4f}" in probability_text(0.0, (lo, hi), 3000)
    assert probability_text(0.388, (0.3707, 0.4056), 3000) == (
        "P(ok) = 0.3880 (95 %: 0.3707-0.4056)")


def test_histograms_render_met_and_not_met(tmp_path):
    rng = np.random.default_rng(0)
    a = rng.normal(29.9, 0.1, 400)
    b = rng.normal(0.45, 0.001, 400)
    data = {"a": a, "a__ok": a < 30.0, "b": b, "b__ok": b > 1.0,
            "tip_deviation_mm": np.abs(rng.normal(size=400))}
    summary = {"samples": 400, "outputs": {"tip_deviation_mm": {"unit": "mm"}},
               "objectives": [
                   {"name": "a", "unit": "deg", "limit": "< 30 deg", "nominal": 29.9,
                    "probability_ok": float((a < 30).mean()),
                    "probability_ok_95": wilson(int((a < 30).sum()), 400)},
                   {"name": "b", "unit": "mm", "limit": "> 1 mm", "nominal": 0.45,
                    "probability_ok": 0.0, "probability_ok_95": wilson(0, 400)}]}
    plot_histograms(tmp_path / "h.png", data, summary)
    assert (tmp_path / "h.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
