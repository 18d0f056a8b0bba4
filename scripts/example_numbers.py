"""Every number the command line reports for every bundled example, as the user sees it
(summary.json of `plantmech inverse` and `plantmech forward`), dumped to JSON and compared:
issue 16's acceptance (the same numbers to 1e-6 in their units) checked through the
public interface, whatever moved inside.

    python scripts/example_numbers.py dump OUT.json
    python scripts/example_numbers.py compare OLD.json NEW.json [--tol 1e-6]

Timings, paths and versions are left out. A number compares by absolute difference (every
unit of these files is mm, deg, m/s, s or a ratio, where 1e-6 is far below what matters);
a missing or added key is reported.
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
EX = ROOT / "examples"
SKIP_KEYS = ("time", "elapsed", "seconds", "version", "path", "file", "out", "created")


def _jobs():
    for f in sorted(EX.glob("*.toml")) + sorted((EX / "planetary").glob("*.toml")):
        text = f.read_text()
        if 'mechanism = "sugarcane_seeder"' in text and "[trajectory]" in text:
            yield f, "inverse"
        yield f, "forward"


def _flat(x, prefix="", out=None):
    out = {} if out is None else out
    if isinstance(x, dict):
        for k, v in x.items():
            if any(s in str(k).lower() for s in SKIP_KEYS):
                continue
            _flat(v, f"{prefix}.{k}" if prefix else str(k), out)
    elif isinstance(x, list):
        for i, v in enumerate(x):
            _flat(v, f"{prefix}[{i}]", out)
    else:
        out[prefix] = x
    return out


def dump(path: Path) -> None:
    result = {}
    with tempfile.TemporaryDirectory() as tmp:
        for f, command in _jobs():
            name = f"{f.relative_to(EX)}:{command}"
            out = Path(tmp) / name.replace("/", "_").replace(":", "_")
            proc = subprocess.run([sys.executable, "-m", "plantmech.interfaces.cli", command,
                                   str(f), "--out", str(out)], capture_output=True, text=True)
            entry = {"exit": proc.returncode}
            summary = out / "summary.json"
            if summary.exists():
                entry.update(_flat(json.loads(summary.read_text())))
            result[name] = entry
            print(f"{name}: exit {proc.returncode}, {len(entry) - 1} values", flush=True)
    path.write_text(json.dumps(result, indent=0, sort_keys=True))


def compare(old_path: Path, new_path: Path, tol: float) -> int:
    old, new = json.loads(old_path.read_text()), json.loads(new_path.read_text())
    bad = 0
    for name in sorted(set(old) | set(new)):
        a, b = old.get(name), new.get(name)
        if a is None or b is None:
            print(f"{name}: only in {'new' if a is None else 'old'}")
            bad += 1
            continue
        worst = (0.0, None)
        for key in sorted(set(a) | set(b)):
            if key not in a or key not in b:
                print(f"{name}: {key} only in {'new' if key not in a else 'old'}")
                bad += 1
                continue
            u, v = a[key], b[key]
            if isinstance(u, (int, float)) and isinstance(v, (int, float)) \
                    and not isinstance(u, bool) and not isinstance(v, bool):
                d = abs(u - v)
                if d > worst[0]:
                    worst = (d, key)
                if d > tol:
                    print(f"{name}: {key} {u!r} -> {v!r} (difference {d:.3g})")
                    bad += 1
            elif u != v:
                print(f"{name}: {key} {u!r} -> {v!r}")
                bad += 1
        print(f"{name}: {len(a)} values, largest difference {worst[0]:.3g}"
              + (f" ({worst[1]})" if worst[1] else ""))
    print(f"{bad} differences beyond {tol:g}")
    return 1 if bad else 0


if __name__ == "__main__":
    args = sys.argv[1:]
    if len(args) == 2 and args[0] == "dump":
        dump(Path(args[1]))
    elif len(args) in (3, 5) and args[0] == "compare":
        tol = float(args[4]) if len(args) == 5 and args[3] == "--tol" else 1e-6
        sys.exit(compare(Path(args[1]), Path(args[2]), tol))
    else:
        print(__doc__)
        sys.exit(2)
