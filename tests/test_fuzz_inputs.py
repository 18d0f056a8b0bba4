"""The fixed-seed corpus of the input fuzzer (tests/fuzz_inputs.py, issue 29): study
files, study directories, gears directories, numeric options and ``init --name`` through
the commands; no traceback, hang, non-finite value written, invalid input accepted,
wrong exit status, file left behind or written outside DIR."""

import pytest

from tests.fuzz_inputs import KINDS, input_corpus, make_input_case
from tests.fuzzing import run_case

CASES = input_corpus(seed=0, size=60)


def test_corpus_is_deterministic_and_covers_every_input_kind():
    again = input_corpus(seed=0, size=60)
    assert [(c.command, c.mutations, c.invalid) for c in again] == \
        [(c.command, c.mutations, c.invalid) for c in CASES]
    assert {"study", "report", "verify", "init"} <= {c.command for c in CASES}
    assert {"gears", "optimize", "design", "verify", "study"} & {c.command for c in CASES}
    assert sum(c.invalid for c in CASES) >= 40 and sum(not c.invalid for c in CASES) >= 3
    seen = {make_input_case(i, 0).example for i in range(200)}
    assert {"summary", "chunks"} <= seen and len(KINDS) == 6


@pytest.mark.parametrize("case", CASES, ids=lambda c: f"{c.index}-{c.command}")
def test_case(case, tmp_path):
    verdict = run_case(case, tmp_path, timeout=60.0)
    assert verdict["kind"] is None, verdict
