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
