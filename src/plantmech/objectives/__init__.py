"""Objectives and checks computed from mechanism results (value, limit, ok)."""

from __future__ import annotations

from dataclasses import dataclass


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
        d = {"name": self.name, "value": self.value, "unit": self.unit,
             "limit": self.limit, "ok": self.ok}
        if self.note:
            d["note"] = self.note
        return d


def range_check(name: str, value: float | None, lo: float | None, hi: float | None,
                unit: str, note: str = "") -> Check:
    """Open-interval check lo < value < hi (either bound optional)."""
    parts = []
    if lo is not None:
        parts.append(f"> {lo:g}")
    if hi is not None:
        parts.append(f"< {hi:g}")
    limit = " and ".join(parts) + (f" {unit}" if unit else "") if parts else "none"
    if value is None:
        return Check(name, None, limit, False, unit, note or "could not be computed")
    ok = (lo is None or value > lo) and (hi is None or value < hi)
    return Check(name, round(float(value), 6), limit, bool(ok), unit, note)
