"""Count the calls that climb the layers while a command runs (docs/architecture.md, "The
flow of one design file").

    python scripts/layer_climbs.py forward examples/sugarcane_table4.toml [more files]
    python scripts/layer_climbs.py inverse examples/sugarcane_seeder.toml
    python scripts/layer_climbs.py gears examples/rice_transplanter_khv.toml

Runs ``plantmech COMMAND FILE --out TMP`` under ``sys.setprofile`` and records every call
into a function of src/plantmech together with its nearest plantmech caller (frames of
numpy, scipy or pydantic in between are skipped). A call climbs when the callee's module
ranks above the caller's (the ranks of tests/test_layers.py LAYERS). Printed: the climbing
(caller, callee) function pairs with their number of calls, and the workflows.py
functions that workflows.py functions call (physics still kept in the jobs layer).
"""

from __future__ import annotations

import collections
import contextlib
import io
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))

from test_layers import NAME, layer_of  # noqa: E402


def main(argv: list[str]) -> int:
    command, files = argv[0], argv[1:]
    import plantmech
    from plantmech.interfaces.cli import main as cli

    package = Path(plantmech.__file__).resolve().parent

    def module(code) -> str | None:
        path = Path(code.co_filename)
        if not path.is_relative_to(package):
            return None
        parts = list(path.relative_to(package.parent).with_suffix("").parts)
        return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)

    climbs: collections.Counter = collections.Counter()
    inner: collections.Counter = collections.Counter()
    jobs = NAME.index("jobs")

    def profile(frame, event, arg):
        if event != "call" or frame.f_code.co_name.startswith("<"):
            return
        callee = module(frame.f_code)
        if callee is None:
            return
        back = frame.f_back
        while back is not None and (module(back.f_code) is None
                                    or back.f_code.co_name.startswith("<")):
            back = back.f_back
        if back is None:
            return
        caller = module(back.f_code)
        low, high = layer_of(caller), layer_of(callee)
        if low is None or high is None:
            return
        if high > low:
            climbs[(f"{caller}.{back.f_code.co_name} ({NAME[low]})",
                    f"{callee}.{frame.f_code.co_name} ({NAME[high]})")] += 1
        elif low == high == jobs and caller == callee == "plantmech.workflows":
            inner[f"{back.f_code.co_name} -> {frame.f_code.co_name}"] += 1

    for file in files:
        with tempfile.TemporaryDirectory() as tmp, contextlib.redirect_stdout(io.StringIO()):
            sys.setprofile(profile)
            try:
                status = cli([command, file, "--out", str(Path(tmp) / "out")])
            finally:
                sys.setprofile(None)
        print(f"plantmech {command} {file}: exit {status}")
    print(f"{len(climbs)} climbing (caller, callee) pairs, {sum(climbs.values())} calls")
    for (caller, callee), n in sorted(climbs.items()):
        print(f"  {caller} -> {callee}: {n}")
    print(f"{len(inner)} workflows.py functions called from workflows.py")
    for pair, n in sorted(inner.items()):
        print(f"  {pair}: {n}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
