"""The optimizer's process pool under the ``spawn`` start method (the default on macOS and
Windows, where ``fork`` is missing or unsafe): same results as in one process."""

from __future__ import annotations

import numpy as np

from plantmech.design import load_design
from plantmech.optimize import problems
from tests.conftest import EXAMPLES


def test_layer1_in_spawned_workers_matches_one_process(monkeypatch):
    monkeypatch.setenv("PLANTMECH_START_METHOD", "spawn")
    assert problems.start_method() == "spawn"
    design = load_design(EXAMPLES / "sugarcane_seeder.toml")
    serial = problems.SeederLayer1(design, workers=1)
    pooled = problems.SeederLayer1(design, workers=2)
    rng = np.random.default_rng(3)
    X = rng.uniform(-4.0, 4.0, (6, serial.n_var))
    before = set(problems._POOLS)
    a, b = serial.evaluate_batch(X), pooled.evaluate_batch(X)
    # the two-worker evaluation ran in a spawned pool (created for it)
    new = set(problems._POOLS) - before
    assert new and all(method == "spawn" for _, method in new)
    for key in new:
        assert problems._POOLS[key]._mp_context.get_start_method() == "spawn"
    np.testing.assert_array_equal(a.ok, b.ok)
    np.testing.assert_allclose(a.values, b.values, rtol=1e-12, equal_nan=True)
    np.testing.assert_allclose(a.G, b.G, rtol=1e-12)
