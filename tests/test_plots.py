"""The plots show what they claim (issue 17): figures returned, no backend forced, the dwell
marked only where there is one, the sun's toothless sector explained, the needle angle
without 360-degree jumps, every transplanter arm visible, legends off the data, units."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
from matplotlib.figure import Figure

from plantmech.design import load_design
from plantmech.outputs import seeder_plots as sp
from plantmech.outputs import transplanter_plots as tp
from tests.conftest import EXAMPLES


@pytest.fixture(scope="module")
def table4():
    from plantmech.workflows import run_seeder_forward

    return run_seeder_forward(load_design(EXAMPLES / "sugarcane_table4.toml"))


@pytest.fixture(scope="module")
def seeder_forward():
    """A forward job without a dwell (the inverse design of Table 2, dwell disabled)."""
    from plantmech.workflows import run_seeder_forward

    return run_seeder_forward(load_design(EXAMPLES / "sugarcane_seeder.toml"))


@pytest.fixture(scope="module")
def rice():
    from plantmech.workflows import run_transplanter

    return run_transplanter(load_design(EXAMPLES / "rice_transplanter.toml"))


def _labels(fig):
    return [t.get_text() for ax in fig.axes if ax.get_legend()
            for t in ax.get_legend().get_texts()]


def test_importing_the_plot_modules_keeps_the_backend():
    code = ("import matplotlib; matplotlib.use('pdf'); "
            "import plantmech.outputs.seeder_plots, plantmech.outputs.transplanter_plots, "
            "plantmech.outputs.optimization_report, plantmech.outputs.report; "
            "print(matplotlib.get_backend())")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == "pdf"


def test_inverse_ratios_note_the_dwell_only_with_a_dwell():
    from plantmech.workflows import run_seeder_inverse

    plain = run_seeder_inverse(load_design(EXAMPLES / "sugarcane_seeder.toml")).result
    dwell = run_seeder_inverse(load_design(EXAMPLES / "sugarcane_seeder_dwell.toml")).result
    assert plain.dwell is None and dwell.dwell is not None
    f_plain, f_dwell = sp.plot_ratios(plain), sp.plot_ratios(dwell)
    assert isinstance(f_plain, Figure)
    assert "dwell" not in f_plain.axes[0].get_title()
    assert not any("dwell" in t for t in _labels(f_plain))
    assert "0 in the toothless dwell" in f_dwell.axes[0].get_title()
    assert any("toothless dwell" in t for t in _labels(f_dwell))


def test_speed_plateau_of_the_dwell_is_marked(table4, seeder_forward):
    fig = sp.plot_forward_speed(table4)
    ax = fig.axes[0]
    assert any("toothless dwell" in t for t in _labels(fig))
    hatched = [p for p in ax.patches if p.get_hatch()]
    assert len(hatched) == 1
    # the hatched span is the carrier-angle span of the dwell: Table 4's 45 deg sector
    span = hatched[0]
    assert span.get_width() == pytest.approx(45.0, abs=0.2)
    assert span.get_x() == pytest.approx(table4.design.train.dwell.start_deg, abs=0.2)
    # and the static speed is flat there (the arm turns with the carrier)
    res = table4.result
    v = res.speed(360.0)[res.in_dwell]
    assert np.ptp(v) / v.mean() < 1e-6
    assert not any("dwell" in t for t in _labels(sp.plot_forward_speed(seeder_forward)))


def test_table4_sun_drawn_open_with_the_reason(table4, seeder_forward):
    fig = sp.plot_forward_pitch_curves(table4)
    sector = [t for t in _labels(fig) if "toothless sector" in t]
    assert len(sector) == 1 and "(45.0 deg)" in sector[0] and "dwell" in sector[0]
    assert not any("toothless" in t for t in _labels(sp.plot_forward_pitch_curves(
        seeder_forward)))


def test_needle_angle_is_unwrapped(rice):
    raw = rice.motion.needle_angle[0]
    assert np.abs(np.diff(raw, axis=1)).max() > 300  # the wrap the plot used to show
    for j in range(raw.shape[0]):
        u = tp.needle_angle_unwrapped(raw[j])
        assert np.abs(np.diff(u)).max() < 10
        np.testing.assert_allclose(np.mod(u, 360.0), raw[j], atol=1e-9)
        assert 0 <= u.mean() < 360
    lines = [ln for ln in tp.plot_attitude_speed(rice).axes[0].get_lines()
             if "needle" in ln.get_label()]
    assert len(lines) == raw.shape[0]
    assert all(np.abs(np.diff(ln.get_ydata())).max() < 10 for ln in lines)


def test_transplanter_arms_have_distinct_styles(rice):
    ax = tp.plot_trajectories(rice).axes[0]
    arms = [ln for ln in ax.get_lines() if "tip (relative)" in ln.get_label()]
    assert len(arms) == 3
    styles = {(ln.get_linestyle(), ln.get_linewidth()) for ln in arms}
    assert len(styles) == 3
    # the widest line is drawn first: the narrower ones stay visible on top of it
    widths = [ln.get_linewidth() for ln in arms]
    assert widths == sorted(widths, reverse=True)


@pytest.mark.parametrize("make", ["seeder", "rice"])
def test_legends_are_off_the_data(make, table4, rice):
    figs = ([sp.plot_forward_speed(table4), sp.plot_forward_trajectories(table4),
             sp.plot_forward_attitude(table4)] if make == "seeder"
            else [tp.plot_trajectories(rice), tp.plot_attitude_speed(rice),
                  tp.plot_gears(rice)])
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    for fig in figs:
        FigureCanvasAgg(fig).draw()
        r = fig.canvas.get_renderer()
        for ax in fig.axes:
            leg = ax.get_legend()
            if leg is None:
                continue
            a, b = ax.get_window_extent(r), leg.get_window_extent(r)
            overlap_x = min(a.x1, b.x1) - max(a.x0, b.x0)
            overlap_y = min(a.y1, b.y1) - max(a.y0, b.y0)
            assert overlap_x <= 0 or overlap_y <= 0, ax.get_title()


def test_pareto_axes_have_units_and_csv_single_units():
    from plantmech.outputs.optimization_report import objective_label, variable_column

    assert objective_label("seeding_peak_speed").endswith("/ (m/s)")
    assert objective_label("hole_width").endswith("/ mm")
    assert objective_label("picking_swing").endswith("/ deg")
    assert variable_column("S_mm", "mm") == "S_mm"
    assert variable_column("beta_deg", "deg") == "beta_deg"
    assert variable_column("r3", "mm") == "r3_mm"


class _Run:
    problem, algorithm, seed = "transplanter", "nsga2", 0
    history = [{"evaluations": 8, "best_violation": 2.0},
               {"evaluations": 16, "best_violation": 0.5}]

    def __init__(self, feasible, first):
        self.feasible = feasible
        self.first_feasible_evaluations = first
        self.first_feasible_s = 1.0 if first else None


def test_convergence_says_all_met_only_when_met():
    from plantmech.outputs.optimization_report import convergence_figure

    failed = convergence_figure(_Run(False, None)).axes[0]
    assert "NOT met" in failed.get_title()
    assert not any("met" in t.get_text() for t in failed.get_legend().get_texts())
    met = convergence_figure(_Run(True, 16)).axes[0]
    assert "every objective met" in met.get_title()
    assert any("every objective met" in t.get_text() for t in met.get_legend().get_texts())


def test_speed_plot_marks_a_to_f_and_draws_each_limit_over_its_section(table4):
    """Points a-f labelled at their carrier angles; the seeding peak limit drawn over de
    only and the return minimum over ef only (the sections their checks read)."""
    ax = sp.plot_forward_speed(table4).axes[0]
    psi = {k: np.degrees(v) % 360 for k, v in table4.section_psi.items()}
    marks = {t.get_text(): t.get_position()[0] for t in ax.texts}
    assert set(marks) == set("abcdef")
    for k, x in marks.items():
        assert x == pytest.approx(psi[k])
    lim = table4.design.speed
    spans = {}
    for c in ax.collections:
        label = c.get_label()
        if "checked over" in label:
            (x0, y0), (x1, y1) = c.get_segments()[0]
            spans[label.split("checked over ")[1].rstrip(")")] = (x0, x1, y0)
    assert spans["de"] == pytest.approx((psi["d"], psi["e"], lim.seeding_max_m_s))
    assert spans["ef"] == pytest.approx((psi["e"], psi["f"], lim.return_min_m_s))
