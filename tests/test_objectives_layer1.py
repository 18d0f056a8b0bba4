"""objectives/layer1.py: the inverse design's speed objectives from one section table (the
layer-1 checks of P candidate trajectories, a toothless dwell's too, are held to the
one-design path's in tests/test_objectives_seeder_inverse_population.py)."""

from pathlib import Path

import pytest

from plantmech.design import load_design

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


@pytest.mark.parametrize("travel", [None, 0.4])
def test_inverse_speed_objectives_read_one_section_table(monkeypatch, travel):
    """One call of ``seeder_population.section_table`` (it was two: one for Eq. 18's travel
    speed at e, one for the speeds), and the same numbers as those two tables: the travel
    speed from a table of e alone (``zero_speed_travel``), the speeds at that travel speed
    (``speed_by_section``)."""
    from plantmech.objectives import seeder_population
    from plantmech.objectives.inverse_evaluation import run_seeder_inverse
    from plantmech.objectives.layer1 import inverse_speed_objectives
    from plantmech.objectives.seeder import speed_by_section, zero_speed_travel

    d = load_design(EXAMPLES / "sugarcane_seeder.toml")
    d.operation.travel_speed_m_s = travel
    job = run_seeder_inverse(d, manufacturability=False)
    calls = []
    real = seeder_population.section_table
    monkeypatch.setattr(seeder_population, "section_table",
                        lambda *a, **k: calls.append(1) or real(*a, **k))
    sp = inverse_speed_objectives(job)
    assert len(calls) == 1
    monkeypatch.undo()
    res = job.result
    sec = {k: float(res.point_carrier_angle[i]) for k, i in job.sections.items()}
    psi, vel = res.carrier_angle, sp["velocity_m_s"]
    zero = zero_speed_travel(psi, vel, 0.0, sec["e"])["zero_speed_travel_m_s"]
    expected_travel = zero if travel is None else travel
    assert sp["travel_m_s"] == pytest.approx(expected_travel, abs=1e-12)
    expected = speed_by_section(psi, vel, expected_travel, sec)
    assert sp["speeds"].keys() == expected.keys()
    for k, v in expected.items():
        assert sp["speeds"][k] == pytest.approx(v, abs=1e-12), k
