"""Safe writing of output files: nothing the user gave is overwritten."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np


class OutputError(RuntimeError):
    """An output directory cannot be used."""


def prepare_out_dir(out: str | Path, inputs: list[Path]) -> Path:
    """Create ``out``; refuse if it is one of the inputs or contains them."""
    out = Path(out)
    for p in inputs:
        p = Path(p).resolve()
        if out.resolve() == p or out.resolve() in p.parents:
            raise OutputError(f"--out {out} would hold or overwrite the input {p}; "
                              "choose another directory")
    if out.exists() and not out.is_dir():
        raise OutputError(f"--out {out} exists and is not a directory")
    out.mkdir(parents=True, exist_ok=True)
    return out


def _clean(obj):
    if isinstance(obj, dict):
        return {k: _clean(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_clean(v) for v in obj]
    if isinstance(obj, np.generic):
        obj = obj.item()
    if isinstance(obj, float) and not np.isfinite(obj):
        return None
    return obj


def write_json(path: Path, data: dict) -> None:
    path.write_text(json.dumps(_clean(data), indent=2) + "\n", encoding="utf-8")


def write_csv(path: Path, columns: dict[str, np.ndarray], fmt: str = "%.6f") -> None:
    """Columns of equal length; NaN written as an empty cell."""
    names = list(columns)
    data = [np.asarray(columns[k], dtype=float) for k in names]
    with path.open("w", newline="", encoding="utf-8") as fh:
        w = csv.writer(fh)
        w.writerow(names)
        for row in zip(*data, strict=True):
            w.writerow(["" if not np.isfinite(v) else fmt % v for v in row])


def check_line(c: dict, name_width: int = 26, digits: int = 2, value_width: int = 14) -> str:
    """One objective/check dict as a console line: status (ok, FAIL, or info for a check
    reported but not required), name, value with unit, limit."""
    val = "n/a" if c["value"] is None else f"{c['value']:.{digits}f} {c['unit']}"
    status = "info" if c.get("required", True) is False else ("ok  " if c["ok"] else "FAIL")
    return (f"  {status} {c['name']:<{name_width}} "
            f"{val:>{value_width}}   limit {c['limit']}")
