"""The fixed-seed fuzz corpus (tests/fuzzing.py, issue 19): mutated examples through the
commands; no traceback, hang, non-finite value written, silently accepted invalid design,
wrong exit status or half-written output."""

import pytest

from tests.fuzzing import corpus, make_case, run_case

CASES = corpus(seed=0, size=120)


def test_corpus_is_deterministic_and_mixed():
    again = corpus(seed=0, size=120)
    assert [c.text for c in again] == [c.text for c in CASES]
    assert {c.command for c in CASES} == {"inverse", "forward", "gears", "optimize"}
    invalid = sum(c.invalid for c in CASES)
    assert 20 < invalid < len(CASES) - 20  # both kinds: refusals and runs


@pytest.mark.parametrize("case", CASES, ids=lambda c: f"{c.index}-{c.command}")
def test_case(case, tmp_path):
    verdict = run_case(case, tmp_path, timeout=60.0)
    assert verdict["kind"] is None, verdict


def test_the_oracle_catches_what_it_should(tmp_path):
    """The oracle is not blind: a NaN in a JSON file, an empty CSV cell and a null
    objective without a reason are found; a documented gap is not."""
    from tests.fuzzing import _non_finite_in

    (tmp_path / "a.json").write_text('{"x": [1.0, NaN]}')
    (tmp_path / "b.json").write_text('{"objectives": [{"name": "s", "value": null, '
                                     '"limit": "> 1", "ok": false}]}')
    (tmp_path / "motion.csv").write_text("t,x,ratio\n0,1,\n1,,2\n")
    (tmp_path / "pitch_curves.csv").write_text("angle_deg,r1_mm,r2_mm\n0,,3\n")
    assert _non_finite_in(tmp_path / "a.json") == "a.json.x[1]"
    assert "null objective" in _non_finite_in(tmp_path / "b.json")
    assert _non_finite_in(tmp_path / "motion.csv") == "motion.csv row 2 column 1 = ''"
    assert _non_finite_in(tmp_path / "pitch_curves.csv") is None
    assert make_case(5, 0).text == make_case(5, 0).text


def test_the_hang_oracle_counts_cpu_or_wall_seconds(tmp_path, monkeypatch):
    """A command spinning the CPU past the limit is a hang on either clock; one blocked
    without using CPU is a hang on the wall clock at once, and on the CPU clock only at
    the 10 x wall backstop. Both clocks are recorded."""
    import time

    import plantmech.interfaces.cli as cli

    case = make_case(5, 0)

    def spin(argv):
        while True:
            pass

    def block(argv):
        time.sleep(30)

    monkeypatch.setattr(cli, "main", spin)
    v = run_case(case, tmp_path, timeout=0.3, clock="cpu")
    assert v["kind"] == "hang" and "CPU" in v["detail"] and v["cpu_s"] >= 0.2
    monkeypatch.setattr(cli, "main", block)
    v = run_case(case, tmp_path, timeout=0.2, clock="wall")
    assert v["kind"] == "hang" and v["wall_s"] < 1.5 and v["cpu_s"] < 0.1
    t0 = time.perf_counter()
    v = run_case(case, tmp_path, timeout=0.2, clock="cpu")
    assert v["kind"] == "hang" and "blocked" in v["detail"]
    assert 1.9 <= time.perf_counter() - t0 < 10
