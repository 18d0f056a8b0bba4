"""Named benchmark figures (``benchmarks/bench.py --json PATH`` writes them): each printed
figure is also recorded here under a stable name with its value, unit, target and the
machine's load when it was measured, so runs can be compared by name."""

from __future__ import annotations

import json
import math
import os
import platform
import subprocess
import time
from pathlib import Path

FIGURES: dict[str, dict] = {}


def figure(name: str, value: float, unit: str, target: float | None = None,
           better: str = "lower", **context) -> None:
    """Record one figure. ``target``: the issue's acceptance value (met when the value is
    below it for ``better="lower"``, above it for ``"higher"``)."""
    value = float(value)
    finite = math.isfinite(value)  # inf: never reached (e.g. no feasible design found)
    rec = {"value": value if finite else None, "unit": unit,
           "load_average": round(os.getloadavg()[0], 2)}
    if target is not None:
        rec["target"] = float(target)
        rec["better"] = better
        rec["met"] = finite and bool(value < target if better == "lower" else value >= target)
    rec.update(context)
    FIGURES[name] = rec


def write_json(path: Path) -> None:
    """The recorded figures with the machine and the commit they were measured on."""
    root = Path(__file__).resolve().parents[1]
    try:
        commit = subprocess.run(["git", "rev-parse", "HEAD"], cwd=root, capture_output=True,
                                text=True, timeout=10).stdout.strip() or None
    except (OSError, subprocess.SubprocessError):
        commit = None
    doc = {"commit": commit, "time_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
           "machine": {"cores": os.cpu_count(), "python": platform.python_version(),
                       "platform": platform.platform()},
           "figures": FIGURES}
    Path(path).write_text(json.dumps(doc, indent=2) + "\n", encoding="utf-8")
