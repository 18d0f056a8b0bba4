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
file and the field.
"""

from __future__ import annotations

import hashlib
import tomllib
from pathlib import Path
from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

from plantmech.design import _format_error


class StudySpecError(ValueError):
    """A study file could not be read or is invalid (message names file and field)."""


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)


Positive = Annotated[float, Field(gt=0, allow_inf_nan=False)]


class Distribution(_Strict):
    """Distribution of one deviation (in the parameter's unit)."""

    distribution: Literal["normal", "uniform", "truncated_normal"]
    mean: float = 0.0
    sigma: Positive | None = None
    plus_minus: Positive | None = None
    low: float | None = None
    high: float | None = None
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

    low: float
    high: float
    levels: Annotated[int, Field(ge=2, le=1000)] = 5

    @model_validator(mode="after")
    def _order(self):
        if not self.low < self.high:
            raise ValueError(f"'low' ({self.low:g}) must be below 'high' ({self.high:g})")
        return self


class _Common(_Strict):
    chunk: Annotated[int, Field(ge=1, le=100000)] = 1000
    seed: Annotated[int, Field(ge=0)] = 0
    cycle_samples: Annotated[int, Field(ge=90, le=36000)] = 720
    dense: Annotated[int, Field(ge=256, le=65536)] = 2048


class ToleranceSpec(_Common):
    kind: Literal["tolerance"]
    samples: Annotated[int, Field(ge=2, le=100_000_000)]
    parameters: dict[str, Distribution]
    required_probability: Annotated[float, Field(gt=0, le=1)] | None = None

    @model_validator(mode="after")
    def _some(self):
        if not self.parameters:
            raise ValueError("give at least one [parameters.NAME] table")
        return self


class SweepSpec(_Common):
    kind: Literal["sweep"]
    method: Literal["grid", "lhs"] = "grid"
    samples: Annotated[int, Field(ge=2, le=100_000_000)] | None = None
    parameters: dict[str, SweepRange]

    @model_validator(mode="after")
    def _some(self):
        if not self.parameters:
            raise ValueError("give at least one [parameters.NAME] table")
        if self.method == "lhs" and self.samples is None:
            raise ValueError("a Latin-hypercube sweep needs 'samples'")
        return self


class MultiStartSpec(_Strict):
    kind: Literal["multi-start"]
    problem: str
    starts: Annotated[int, Field(ge=1, le=10000)]
    seed: Annotated[int, Field(ge=0)] = 0
    generations: Annotated[int, Field(ge=1, le=10000)] = 10
    pop: Annotated[int, Field(ge=4, le=10000)] = 20
    algorithm: str | None = None
    best: Annotated[int, Field(ge=1, le=1000)] = 3


StudySpec = ToleranceSpec | SweepSpec | MultiStartSpec
KINDS = {"tolerance": ToleranceSpec, "sweep": SweepSpec, "multi-start": MultiStartSpec}


def load_spec(path: str | Path) -> StudySpec:
    """Read and validate a study file; raise StudySpecError naming file and field."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
        raw = tomllib.loads(text)
    except FileNotFoundError:
        raise StudySpecError(f"{path}: no such study file") from None
    except tomllib.TOMLDecodeError as exc:
        raise StudySpecError(f"{path}: not valid TOML: {exc}") from None
    except UnicodeDecodeError:
        raise StudySpecError(f"{path}: not a UTF-8 text file") from None
    kind = raw.get("kind")
    known = ", ".join(f'"{k}"' for k in KINDS)
    if kind not in KINDS:
        what = "is missing" if kind is None else f"is {kind!r}"
        raise StudySpecError(f"{path}: field 'kind' {what} (expected one of {known})")
    try:
        return KINDS[kind].model_validate(raw)
    except ValidationError as exc:
        raise StudySpecError(_format_error(path, exc).replace("invalid design file",
                                                              "invalid study file")) from None


def fingerprint(*texts: str) -> str:
    """SHA-256 of the inputs (design and study file contents): a resumed study must be
    the same study."""
    h = hashlib.sha256()
    for t in texts:
        h.update(t.encode("utf-8"))
        h.update(b"\0")
    return h.hexdigest()
