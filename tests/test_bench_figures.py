"""benchmarks/figures.py: the named figures `bench.py --json` writes."""

from __future__ import annotations

import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
import figures  # noqa: E402


def test_figures_are_written_by_name_with_their_verdict(tmp_path, monkeypatch):
    monkeypatch.setattr(figures, "FIGURES", {})
    figures.figure("inverse_design_3600_ms", 12.5, "ms", 10.0)
    figures.figure("seeder_population_720_designs_per_s", 25000, "designs/s", 20000.0,
                   "higher", designs=1000)
    figures.figure("optimize_first_feasible_s", float("inf"), "s", 60.0)
    figures.write_json(tmp_path / "f.json")
    doc = json.loads((tmp_path / "f.json").read_text(),
                     parse_constant=lambda c: (_ for _ in ()).throw(ValueError(c)))
    f = doc["figures"]
    assert f["inverse_design_3600_ms"]["met"] is False  # 12.5 ms against < 10 ms
    assert f["seeder_population_720_designs_per_s"]["met"] is True
    assert f["seeder_population_720_designs_per_s"]["designs"] == 1000
    assert f["optimize_first_feasible_s"]["value"] is None  # never reached: no Infinity
    assert f["optimize_first_feasible_s"]["met"] is False
    assert doc["machine"]["cores"] >= 1


def test_bench_help_and_unknown_options_run_nothing():
    """`bench.py --help` prints its usage and a mistyped option exits 2 naming it, both
    at once (each benchmark run takes minutes)."""
    import subprocess
    import sys
    from pathlib import Path

    bench = Path(__file__).resolve().parents[1] / "benchmarks" / "bench.py"
    r = subprocess.run([sys.executable, str(bench), "--help"], capture_output=True, text=True,
                       timeout=60)
    assert r.returncode == 0 and "usage: bench.py" in r.stdout and "--seeder-population-only" \
        in r.stdout
    r = subprocess.run([sys.executable, str(bench), "--verfy-only"], capture_output=True,
                       text=True, timeout=60)
    assert r.returncode == 2 and "unknown option --verfy-only" in r.stderr
