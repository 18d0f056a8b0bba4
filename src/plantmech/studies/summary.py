"""Reading a study directory back (``plantmech report``, a resumed ``plantmech study``):
``study.json``, ``summary.json`` and the CSV files, bounded as every input is
(``plantmech.inputs``), and ``summary.json`` checked against what a report reads from it,
so that a partial, hand-edited or foreign file is refused naming the file and the field
instead of failing half-way through the report. The Parquet chunks are read bounded by
``studies.engine.read_results``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError

from plantmech.studies.engine import StudyStateError

#: largest study.json / summary.json / band.csv / plan.csv (bytes)
MAX_STATE_BYTES = 1_000_000
MAX_SUMMARY_BYTES = 64_000_000
MAX_CSV_BYTES = 64_000_000
#: deepest nesting of summary.json (objectives -> sensitivity -> ranking -> row: 5)
MAX_SUMMARY_NESTING = 12


class _Lax(BaseModel):
    """The fields a report reads; any other field is kept as it is."""

    model_config = ConfigDict(extra="allow", allow_inf_nan=False)


Probability = Annotated[float, Field(ge=0, le=1)]
Count = Annotated[int, Field(ge=0)]
Interval = tuple[Probability, Probability]


class _Rank(_Lax):
    parameter: str
    src: float
    first_order_sigma: float | None = None


class _Sensitivity(_Lax):
    r2: float | None = None
    ranking: list[_Rank]


class _Objective(_Lax):
    name: str
    unit: str = ""
    limit: str = ""
    nominal: float | None = None
    nominal_ok: bool
    probability_ok: Probability
    probability_ok_95: Interval
    first_order_std: float | None = None
    quantiles: dict[str, float] = {}
    sensitivity: _Sensitivity


class _Parameter(_Lax):
    name: str
    distribution: Literal["normal", "uniform", "truncated_normal"]
    std: float
    nominal: float


class _Output(_Lax):
    unit: str
    quantiles: dict[str, float] = {}
    sensitivity: _Sensitivity | None = None
    first_order_rms_contribution_mm: dict[str, float] = {}


class _Run(_Lax):
    total_chunks: Count = 0
    computed_chunks: Count = 0
    skipped_chunks: Count = 0
    evaluations: Count = 0
    failed_chunks: list[dict] = []
    wall_s: float | None = None
    workers: Count = 0
    designs_per_s: float | None = None


class _Summary(_Lax):
    complete: bool | None = None
    run: _Run = _Run()


class ToleranceSummary(_Summary):
    kind: Literal["tolerance"]
    samples: Annotated[int, Field(ge=1)]
    probability_all_ok: Probability
    probability_all_ok_95: Interval
    nominal_met: list[str]
    probability_nominal_met_kept: Probability
    objectives: list[_Objective]
    parameters: list[_Parameter]
    outputs: dict[str, _Output]
    required_probability: Probability | None = None
    requirement_met: bool | None = None
    band_summary: dict[str, float | str] | None = None


class _SweepObjective(_Lax):
    name: str
    fraction_ok: Probability
    min: float | None = None
    max: float | None = None


class _SweepParameter(_Lax):
    name: str


class SweepSummary(_Summary):
    kind: Literal["sweep"]
    samples: Annotated[int, Field(ge=1)]
    fraction_all_ok: Probability
    objectives: list[_SweepObjective]
    parameters: list[_SweepParameter]
    limits: dict[str, str] = {}


class _Best(_Lax):
    rank: Count
    seed: Count
    file: str
    feasible: bool = False
    total_violation: float


class MultiStartSummary(_Summary):
    kind: Literal["multi-start"]
    starts: Annotated[int, Field(ge=1)]
    successes: Count
    best: list[_Best] = []


SUMMARIES = {"tolerance": ToleranceSummary, "sweep": SweepSummary,
             "multi-start": MultiStartSummary}


def _json(path: Path, what: str, max_bytes: int) -> dict:
    from plantmech.inputs import read_input_json

    if not path.exists() and not path.is_symlink():
        raise StudyStateError(f"{path}: not found (is {path.parent} the --out of "
                              "'plantmech study'?)")
    value = read_input_json(path, what, max_bytes, MAX_SUMMARY_NESTING, StudyStateError)
    if not isinstance(value, dict):
        raise StudyStateError(f"{path}: not a {what} (a JSON object is expected, got "
                              f"{type(value).__name__})")
    return value


def read_state(out: str | Path) -> dict:
    """study.json of a study directory (which study it holds)."""
    return _json(Path(out) / "study.json", "study state file (study.json)", MAX_STATE_BYTES)


def read_summary(out: str | Path) -> dict:
    """summary.json of a study directory, checked against what a report reads from it
    (StudyStateError naming the file and the field)."""
    path = Path(out) / "summary.json"
    summary = _json(path, "study summary (summary.json)", MAX_SUMMARY_BYTES)
    kind = summary.get("kind")
    if kind is None:
        raise StudyStateError(f"{path}: no chunk of this study has finished yet: run "
                              "'plantmech study' again with the same --out")
    if not isinstance(kind, str) or kind not in SUMMARIES:
        known = ", ".join(f'"{k}"' for k in SUMMARIES)
        raise StudyStateError(f"{path}: field 'kind' is {str(kind)[:60]!r} (expected one of "
                              f"{known})")
    try:
        SUMMARIES[kind].model_validate(summary)
    except ValidationError as exc:
        from plantmech.design import _format_error

        raise StudyStateError(_format_error(path, exc).replace(
            "invalid design file", "not a summary a report can read")) from None
    return summary


def check_columns(data: dict, summary: dict, out: str | Path) -> None:
    """The result columns a report plots from the chunks are there (StudyStateError
    naming the chunks directory and the first missing column)."""
    kind = summary["kind"]
    if kind == "tolerance":
        need = [o["name"] for o in summary["objectives"]] + list(summary["outputs"])
    elif kind == "sweep":
        need = ([p["name"] for p in summary["parameters"]] + ["path_deviation_mm"]
                + [c for o in summary["objectives"] for c in (o["name"], f"{o['name']}__ok")])
    else:
        need = ["seed", "total_violation", "feasible"]
    missing = [c for c in need if c not in data]
    if missing:
        raise StudyStateError(f"{Path(out) / 'chunks'}: the Parquet chunks have no column "
                              f"{missing[0]!r} that summary.json names; they are not this "
                              "study's results")


def read_csv(path: str | Path, columns: tuple[str, ...]) -> dict:
    """A CSV file a study wrote (band.csv, plan.csv): a header naming at least
    ``columns``, then finite numbers -> {column: array}."""
    import numpy as np

    from plantmech.inputs import read_input_text

    path = Path(path)
    text = read_input_text(path, "study CSV file", MAX_CSV_BYTES, StudyStateError)
    lines = [ln for ln in text.splitlines() if ln.strip()]
    if not lines:
        raise StudyStateError(f"{path}: empty; a header and rows are expected")
    header = [h.strip() for h in lines[0].split(",")]
    missing = [c for c in columns if c not in header]
    if missing:
        raise StudyStateError(f"{path}: no column {missing[0]!r} in its header")
    cells = [ln.split(",") for ln in lines[1:]]
    short = next((k for k, c in enumerate(cells) if len(c) != len(header)), None)
    if short is not None or len(cells) < 2:
        where = f" (row {short + 1} has {len(cells[short])})" if short is not None else ""
        raise StudyStateError(f"{path}: expected rows of {len(header)} numbers, at least 2"
                              + where)
    try:
        rows = np.array([[float(x) for x in c] for c in cells], float)
    except ValueError as exc:
        raise StudyStateError(f"{path}: a cell is not a number ({exc})") from None
    if not np.isfinite(rows).all():
        r = int(np.flatnonzero(~np.isfinite(rows).all(axis=1))[0])
        raise StudyStateError(f"{path}: row {r + 1} holds a value that is not finite")
    return {c: rows[:, header.index(c)] for c in columns}
