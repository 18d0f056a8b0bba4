"""outputs/planetary_plots.py: what the ratio plot draws through a toothless dwell."""

from __future__ import annotations

import numpy as np

from plantmech.design import load_design
from plantmech.outputs.planetary_plots import plot_ratios
from plantmech.trains.model import simulate
from plantmech.trains.spec import build_from_design
from tests.conftest import EXAMPLES


def test_the_ratio_of_a_held_pair_is_not_drawn_and_its_span_is_shaded():
    """Table 4 as a planetary file: the first pair's teeth are out of mesh over the dwell
    (45 deg of carrier from 74.75 deg): no ratio is drawn there (a gap, not the lock's
    radii), the span is shaded; elsewhere the line is r_driver / r_follower."""
    d = load_design(EXAMPLES / "planetary" / "sugarcane_table4.toml")
    m = simulate(build_from_design(d), 720)
    fig = plot_ratios(m)
    ax = fig.axes[0]
    pair1 = next(line for line in ax.get_lines() if line.get_label() == "pair 1")
    x, y = pair1.get_xdata(), np.asarray(pair1.get_ydata(), float)
    held = (x > 74.75 + 0.5) & (x < 74.75 + 45.0 - 0.5)
    assert held.sum() > 80 and np.isnan(y[held]).all()
    rd, rf = m.contact_radii[0]
    free = ~np.isnan(y)
    assert free.sum() > 600
    assert np.allclose(y[free], (rd[0, 0] / rf[0, 0])[free])
    spans = [p for p in ax.patches]
    assert len(spans) == 1
    x0, x1 = spans[0].get_x(), spans[0].get_x() + spans[0].get_width()
    assert abs(x0 - 74.75) < 1.0 and abs(x1 - 119.75) < 1.0
