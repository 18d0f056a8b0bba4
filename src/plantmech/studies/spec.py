"""Study specification files (TOML): what to vary, how, and how finely to evaluate.

Three kinds (``kind``):

* ``tolerance``: Monte Carlo over manufacturing and assembly deviations, each parameter
  with a distribution (``normal`` with ``sigma``; ``uniform`` with ``plus_minus`` about
  ``mean`` or ``low``/``high``; ``truncated_normal`` with ``sigma`` cut at ``mean +-
  limit``); deviations are added to the design's nominal value of the parameter;
* ``sweep``: a ``grid`` (``levels`` per parameter) or ``lhs`` (Latin hypercube,
  ``samples``) over absolute parameter values ``low``..``high``;
* ``multi-start``: one ``plantmech optimize`` problem from ``starts`` seeds.

Parameter names and their meaning per mechanism: ``studies.parameters``. Errors name the
file and the field. A study file is read as a design file is (``plantmech.inputs``: a
regular file of at most 1 MB, nested at most 8 levels), and a study is bounded by what
one machine holds: at most :data:`MAX_DESIGNS` designs in at most :data:`MAX_CHUNKS`
chunks (the error says how large the study is), deviations and sweep values within
+-:data:`MAX_DEVIATION`, seeds of 32 bits.
"""

from __future__ import annotations

import hashlib
import math
from pathlib import Path
from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

from plantmech.design import MAX_FILE_BYTES, MAX_NESTING, _format_error
from plantmech.inputs import parse_toml, read_input_text
from plantmech.optimize import ALGORITHMS, PROBLEMS

#: most designs (samples, grid points, Latin-hypercube samples) one study evaluates: its
#: result rows are held in memory for the summary (about 1 kB a design).
MAX_DESIGNS = 1_000_000
#: most chunks (Dask tasks, Parquet files) of one study.
MAX_CHUNKS = 100_000
#: largest deviation, distribution parameter or swept value (in the parameter's unit:
#: mm, deg, m/s; no planting mechanism is 10 m across).
MAX_DEVIATION = 10_000.0
#: largest random seed (32 bits, as NumPy's and pymoo's).
MAX_SEED = 2**32 - 1
#: most parameters one study varies.
MAX_PARAMETERS = 100


class StudySpecError(ValueError):
    """A study file could not be read or is invalid (message names file and field)."""


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)


Positive = Annotated[float, Field(gt=0, le=MAX_DEVIATION, allow_inf_nan=False)]
Value = Annotated[float, Field(ge=-MAX_DEVIATION, le=MAX_DEVIATION, allow_inf_nan=False)]
Seed = Annotated[int, Field(ge=0, le=MAX_SEED)]


class Distribution(_Strict):
    """Distribution of one deviation (in the parameter's unit)."""

    distribution: Literal["normal", "uniform", "truncated_normal"]
    mean: Value = 0.0
    sigma: Positive | None = None
    plus_minus: Positive | None = None
    low: Value | None = None
    high: Value | None = None
    limit: Positive | None = None

    @model_validator(mode="after")
    def _complete(self):
        d = self.distribution
        if d in ("normal", "truncated_normal") and self.sigma is None:
            raise ValueError(f"a {d} distribution needs 'sigma' (> 0)")
        if d == "truncated_normal" and self.limit is None:
            raise ValueError("a truncated_normal distribution needs 'limit' (> 0): the "
                             "deviation is cut at mean +- limit")
        if d == "uniform":
            if self.plus_minus is None and (self.low is None or self.high is None):
                raise ValueError("a uniform distribution needs 'plus_minus' (about 'mean') or "
                                 "'low' and 'high'")
            if self.plus_minus is not None and (self.low is not None or self.high is not None):
                raise ValueError("give either 'plus_minus' or 'low'/'high', not both")
            if self.plus_minus is None and not self.low < self.high:
                raise ValueError(f"'low' ({self.low:g}) must be below 'high' ({self.high:g})")
        return self


class SweepRange(_Strict):
    """Absolute values of one parameter from ``low`` to ``high``; ``levels`` grid points."""

    low: Value
    high: Value
    levels: Annotated[int, Field(ge=2, le=1000)] = 5

    @model_validator(mode="after")
    def _order(self):
        if not self.low < self.high:
            raise ValueError(f"'low' ({self.low:g}) must be below 'high' ({self.high:g})")
        return self


def _check_size(designs: int, chunk: int, what: str) -> None:
    """A study of ``designs`` designs in chunks of ``chunk``: within MAX_DESIGNS and
    MAX_CHUNKS, else ValueError saying how large it is."""
    if designs > MAX_DESIGNS:
        raise ValueError(f"{what} makes {designs:,} designs; a study is at most "
                         f"{MAX_DESIGNS:,} designs (split it into several studies)")
    chunks = math.ceil(designs / chunk)
    if chunks > MAX_CHUNKS:
        raise ValueError(f"{designs:,} designs in chunks of {chunk} make {chunks:,} chunks; "
                         f"a study is at most {MAX_CHUNKS:,} chunks (a larger 'chunk')")


class _Common(_Strict):
    chunk: Annotated[int, Field(ge=1, le=100000)] = 1000
    seed: Seed = 0
    cycle_samples: Annotated[int, Field(ge=90, le=36000)] = 720
    dense: Annotated[int, Field(ge=256, le=65536)] = 2048


class ToleranceSpec(_Common):
    kind: Literal["tolerance"]
    samples: Annotated[int, Field(ge=2, le=MAX_DESIGNS)]
    parameters: Annotated[dict[str, Distribution], Field(max_length=MAX_PARAMETERS)]
    required_probability: Annotated[float, Field(gt=0, le=1)] | None = None

    @model_validator(mode="after")
    def _some(self):
        if not self.parameters:
            raise ValueError("give at least one [parameters.NAME] table")
        _check_size(self.samples, self.chunk, f"samples = {self.samples}")
        return self


class SweepSpec(_Common):
    kind: Literal["sweep"]
    method: Literal["grid", "lhs"] = "grid"
    samples: Annotated[int, Field(ge=2, le=MAX_DESIGNS)] | None = None
    parameters: Annotated[dict[str, SweepRange], Field(max_length=MAX_PARAMETERS)]

    @model_validator(mode="after")
    def _some(self):
        if not self.parameters:
            raise ValueError("give at least one [parameters.NAME] table")
        if self.method == "lhs":
            if self.samples is None:
                raise ValueError("a Latin-hypercube sweep needs 'samples'")
            _check_size(self.samples, self.chunk, f"samples = {self.samples}")
        else:
            levels = [r.levels for r in self.parameters.values()]
            _check_size(math.prod(levels), self.chunk,
                        "the grid of " + " x ".join(map(str, levels)) + " levels")
        return self

    @property
    def designs(self) -> int:
        if self.method == "lhs":
            return self.samples
        return math.prod(r.levels for r in self.parameters.values())


class MultiStartSpec(_Strict):
    kind: Literal["multi-start"]
    problem: Literal[PROBLEMS]
    starts: Annotated[int, Field(ge=1, le=10000)]
    seed: Seed = 0
    generations: Annotated[int, Field(ge=1, le=10000)] = 10
    pop: Annotated[int, Field(ge=4, le=2000)] = 20
    algorithm: Literal[ALGORITHMS] | None = None
    best: Annotated[int, Field(ge=1, le=1000)] = 3

    @model_validator(mode="after")
    def _seeds(self):
        if self.seed + self.starts - 1 > MAX_SEED:
            raise ValueError(f"the starts' seeds {self.seed}..{self.seed + self.starts - 1} "
                             f"pass {MAX_SEED} (2^32 - 1): a smaller 'seed'")
        return self


StudySpec = ToleranceSpec | SweepSpec | MultiStartSpec
KINDS = {"tolerance": ToleranceSpec, "sweep": SweepSpec, "multi-start": MultiStartSpec}


def load_spec(path: str | Path) -> StudySpec:
    """Read and validate a study file; raise StudySpecError naming file and field."""
    path = Path(path)
    if str(path) in ("", "."):
        raise StudySpecError("option --spec: the study file name is empty")
    text = read_input_text(path, "study file", MAX_FILE_BYTES, StudySpecError)
    raw = parse_toml(text, str(path), MAX_NESTING, StudySpecError,
                     "a study file needs at most 3")
    kind = raw.get("kind")
    known = ", ".join(f'"{k}"' for k in KINDS)
    if not isinstance(kind, str) or kind not in KINDS:
        what = "is missing" if kind is None else f"is {str(kind)[:60]!r}"
        raise StudySpecError(f"{path}: field 'kind' {what} (expected one of {known})")
    try:
        return KINDS[kind].model_validate(raw)
    except ValidationError as exc:
        raise StudySpecError(_format_error(path, exc).replace("invalid design file",
                                                              "invalid study file")) from None
    except RecursionError:
        raise StudySpecError(f"{path}: nested too deeply") from None


def fingerprint(*texts: str) -> str:
    """SHA-256 of the inputs (design and study file contents): a resumed study must be
    the same study."""
    h = hashlib.sha256()
    for t in texts:
        h.update(t.encode("utf-8"))
        h.update(b"\0")
    return h.hexdigest()
