import numpy as np
import pytest

from plantmech.design import load_design
from plantmech.workflows import evaluate_seeder_population, run_seeder_forward

from .conftest import EXAMPLES


def test_population_evaluation_matches_the_single_design_job():
    design = load_design(EXAMPLES / "sugarcane_table4.toml")
    job = run_seeder_forward(design)
    pop = evaluate_seeder_population(design, samples=3600, dense=4096)
    single = {c.name: c for c in job.checks}
    ev = pop.evaluation
    assert np.abs(pop.section_psi[0] - [job.section_psi[k] for k in "abcdef"]).max() < 1e-9
    for name, value, ok in zip(ev.names, ev.values[0], ev.ok[0], strict=True):
        ref = single[name]
        if name.startswith("convex_"):  # continuous margin vs span count
            assert ok == ref.ok
            continue
        # pressure angle: 720 body angles here, 3600 in the job
        tol = 2e-3 if "speed" in name else 0.05 if "pressure" in name else 1e-3
        if name.startswith("cuttable_module"):  # smallest radius of curvature, 720 vs 3600
            assert value == pytest.approx(ref.value, rel=0.02), name
        else:
            assert value == pytest.approx(ref.value, abs=tol), name
        assert ok == ref.ok


def test_population_rows_are_independent_designs():
    design = load_design(EXAMPLES / "sugarcane_table4.toml")
    r2 = np.asarray(design.train.gear2.radii_mm)
    r3 = np.asarray(design.train.gear3.radii_mm)
    rng = np.random.default_rng(2)
    R2 = r2 + rng.uniform(-1.5, 1.5, (6, 8))
    R3 = r3 + rng.uniform(-1.5, 1.5, (6, 8))
    pop = evaluate_seeder_population(design, R2, R3, samples=720)
    for p in (0, 3, 5):
        one = evaluate_seeder_population(design, R2[p:p + 1], R3[p:p + 1], samples=720)
        assert np.allclose(one.evaluation.values[0], pop.evaluation.values[p], atol=1e-9)
    # different radii, different speeds
    assert np.ptp(pop.evaluation.values[:, pop.evaluation.names.index("seeding_peak_speed")]) > 0.01


def _gerono(u):
    """A figure eight x = 100 sin 2u, y = 100 sin u (mm): it crosses itself at the origin,
    passing it at u = 0 along (2, 1) and at u = pi along (2, -1)."""
    return np.c_[100 * np.sin(2 * u), 100 * np.sin(u)]


def test_section_location_keeps_the_points_in_order_on_an_eight():
    """A point beside the crossing of an "8" is nearer the pass at u = 0, but the section
    points around it (a, b before, d, e, f after, u = 2.0 .. 5.8) put it on the pass at
    u = pi: located there without a reference (the ordered choice), and with a reference
    near pi; the angle and the miss are the closest approach of that pass, found on a
    10^6-point grid of the exact curve."""
    from plantmech.objectives.seeder_population import locate_sections

    psi = np.linspace(0, 2 * np.pi, 720, endpoint=False)
    tip = _gerono(psi)[None]
    c = np.array([0.3, 0.05])
    others = _gerono(np.array([2.0, 2.8, 4.0, 5.0, 5.8]))
    points = np.vstack([others[:2], c, others[2:]])
    fine = np.linspace(np.pi - 0.05, np.pi + 0.05, 1_000_001)
    d = np.hypot(*(_gerono(fine) - c).T)
    u_c, miss_c = fine[np.argmin(d)], d.min()
    near_zero = np.linspace(-0.05, 0.05, 1_000_001)
    assert np.hypot(*(_gerono(near_zero) - c).T).min() < miss_c  # the wrong pass is nearer
    angle, miss = locate_sections(tip, psi, points, return_miss=True)
    step = psi[1] - psi[0]
    assert abs(angle[0, 2] - u_c) < 1e-2 * step
    assert miss[0, 2] == pytest.approx(miss_c, abs=1e-3)
    assert np.allclose(angle[0, [0, 1, 3, 4, 5]], [2.0, 2.8, 4.0, 5.0, 5.8], atol=1e-2 * step)
    # points on the curve: the vertex of the squared distances is near 0, its square root
    # no better than the closest sample's distance (an upper bound, never NaN)
    nearest = np.hypot(*(tip[0][:, None] - points[None]).transpose(2, 0, 1)).min(axis=0)
    on = [0, 1, 3, 4, 5]
    assert np.all((miss[0, on] >= 0) & (miss[0, on] <= nearest[on] + 1e-12))
    ref = np.array([2.0, 2.8, np.pi + 0.1, 4.0, 5.0, 5.8])
    assert np.allclose(locate_sections(tip, psi, points, ref), angle, atol=1e-12)
    # a window about the other pass finds that one (u near 0)
    wrong = locate_sections(tip, psi, points, np.r_[ref[:2], 0.1, ref[3:]])
    assert abs(np.angle(np.exp(1j * wrong[0, 2]))) < 0.01


def test_objective_columns_are_the_full_tables():
    """The optimizer's objectives-only section pass gives the same numbers as the full
    table (the swings as magnitudes), at uniform and non-uniform samples."""
    from plantmech.objectives.seeder_population import (
        section_column,
        section_table,
        section_values,
    )

    rng = np.random.default_rng(7)
    for psi in (np.linspace(0, 2 * np.pi, 360, endpoint=False),
                np.r_[0.0, np.sort(rng.uniform(0, 2 * np.pi, 500))]):
        S = len(psi)
        angle = np.cumsum(rng.normal(0, 0.02, (9, S)), axis=1)
        rate = rng.normal(0, 300, (9, S, 2))
        sec = np.sort(rng.uniform(0, 2 * np.pi, (9, 6)), axis=1)
        for travel in (None, 0.4):
            full = section_table(psi, angle, sec, rate, 57.3, 1e-3, travel)
            fast = section_values(psi, angle, sec, rate, 57.3, 1e-3, travel)
            c = section_column
            assert np.array_equal(fast, np.c_[
                np.abs(full[:, c("picking_ab", "swing")]),
                np.abs(full[:, c("seeding_de", "swing")]), full[:, c("seeding_de", "end")],
                full[:, c("vx_e")], full[:, c("travel")], full[:, c("peak_static_de")],
                full[:, c("least_static_ef")], full[:, c("least_dynamic_ef")]])


def test_section_location_rows_are_independent_designs():
    """Three tip paths at once (the eight scaled and turned) locate as each alone."""
    from plantmech.objectives.seeder_population import locate_sections

    psi = np.linspace(0, 2 * np.pi, 720, endpoint=False)
    tips = np.stack([_gerono(psi) * s + o for s, o in ((1.0, 0.0), (1.1, 2.0), (0.9, -3.0))])
    points = _gerono(np.array([0.4, 1.2, 2.8, 4.0, 5.0, 5.8]))
    both = locate_sections(tips, psi, points, return_miss=True)
    for p in range(3):
        one = locate_sections(tips[p:p + 1], psi, points, return_miss=True)
        assert np.array_equal(both[0][p], one[0][0]) and np.array_equal(both[1][p], one[1][0])
