"""Objectives and checks computed from mechanism results (value, limit, ok)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass
class Check:
    """One named check: value with its unit, the limit it is held to, pass/fail."""

    name: str
    value: float | None
    limit: str
    ok: bool
    unit: str = ""
    note: str = ""

    def as_dict(self) -> dict:
        """The check as a dict; a value that cannot be computed (None, NaN, inf) is written
        as null with a ``not_computable`` reason and is never ok."""
        value = self.value
        computable = value is not None and math.isfinite(value)
        d = {"name": self.name, "value": value if computable else None, "unit": self.unit,
             "limit": self.limit, "ok": bool(self.ok) and computable}
        if not computable:
            d["not_computable"] = self.note or (
                "not computable for this design (the geometry it measures does not exist: "
                "see the diagnostics)")
        if self.note:
            d["note"] = self.note
        return d


def limit_text(lo: float | None, hi: float | None, unit: str) -> str:
    """'> lo and < hi unit' for the open interval (either bound optional)."""
    parts = ([f"> {lo:g}"] if lo is not None else []) + ([f"< {hi:g}"] if hi is not None else [])
    return " and ".join(parts) + (f" {unit}" if unit else "") if parts else "none"


def relative_violation(value, lo: float | None, hi: float | None, scale: float | None = None,
                       nan: float = np.inf):
    """How far values lie outside lo < value < hi, divided by ``scale`` (default: the
    larger bound's magnitude, at least 1); 0 where met, ``nan`` where not computed.
    The measure every optimizer constraint uses."""
    value = np.asarray(value, dtype=float)
    if scale is None:
        scale = max(abs(lo or 0.0), abs(hi or 0.0), 1.0)
    v = np.zeros_like(value)
    if lo is not None:
        v = v + np.maximum(lo - value, 0.0) / scale
    if hi is not None:
        v = v + np.maximum(value - hi, 0.0) / scale
    return np.where(np.isnan(value), nan, v)


def range_check(name: str, value: float | None, lo: float | None, hi: float | None,
                unit: str, note: str = "") -> Check:
    """Open-interval check lo < value < hi (either bound optional)."""
    limit = limit_text(lo, hi, unit)
    if value is None:
        return Check(name, None, limit, False, unit, note or "could not be computed")
    ok = (lo is None or value > lo) and (hi is None or value < hi)
    return Check(name, round(float(value), 6), limit, bool(ok), unit, note)
