"""``plantmech study``: exit codes, errors naming the file and field, files written."""

from __future__ import annotations

import json
from pathlib import Path

from plantmech.interfaces.cli import main

ROOT = Path(__file__).resolve().parents[1]
SEEDER = str(ROOT / "examples" / "sugarcane_seeder_optimized.toml")


def _write(path: Path, text: str) -> str:
    path.write_text(text, encoding="utf-8")
    return str(path)


TOL = """kind = "tolerance"
samples = 40
chunk = 20
cycle_samples = 180
dense = 512
[parameters.L2_mm]
distribution = "normal"
sigma = 0.1
"""


def test_invalid_spec_names_file_and_field(tmp_path, capsys):
    spec = _write(tmp_path / "s.toml", TOL.replace('sigma = 0.1', 'plus_minus = 0.1'))
    assert main(["study", SEEDER, "--spec", spec, "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "s.toml" in err and "parameters.L2_mm" in err and "sigma" in err
    spec = _write(tmp_path / "k.toml", TOL.replace('"tolerance"', '"montecarlo"'))
    assert main(["study", SEEDER, "--spec", spec, "--out", str(tmp_path / "o")]) == 2
    assert "field 'kind'" in capsys.readouterr().err


def test_unknown_or_impossible_parameter_is_refused(tmp_path, capsys):
    spec = _write(tmp_path / "s.toml", TOL.replace("L2_mm", "L9_mm"))
    assert main(["study", SEEDER, "--spec", spec, "--out", str(tmp_path / "o")]) == 2
    assert "L9_mm" in capsys.readouterr().err
    spec = _write(tmp_path / "c.toml", TOL.replace("L2_mm", "L1_mm"))
    assert main(["study", SEEDER, "--spec", spec, "--out", str(tmp_path / "o2")]) == 2
    assert "collinear" in capsys.readouterr().err


def test_out_may_not_hold_the_inputs(tmp_path, capsys):
    spec = _write(tmp_path / "s.toml", TOL)
    assert main(["study", SEEDER, "--spec", spec, "--out", str(tmp_path)]) == 2
    assert "overwrite the input" in capsys.readouterr().err
    assert Path(spec).read_text(encoding="utf-8") == TOL


def test_sweep_runs_and_another_study_cannot_reuse_its_out(tmp_path, capsys):
    spec = _write(tmp_path / "w.toml", """kind = "sweep"
method = "grid"
chunk = 3
cycle_samples = 180
dense = 512
[parameters.L2_mm]
low = 485.0
high = 495.0
levels = 3
[parameters.backlash_deg]
low = 0.0
high = 0.4
levels = 2
""")
    out = tmp_path / "out"
    # stopped after one chunk: exit 4, the finished chunk summarised and marked partial
    assert main(["study", SEEDER, "--spec", spec, "--out", str(out), "--workers", "1",
                 "--quiet", "--max-chunks", "1"]) == 4
    s = json.loads((out / "summary.json").read_text())
    assert s["complete"] is False and s["samples"] == 3
    assert "INCOMPLETE" in capsys.readouterr().err
    assert main(["study", SEEDER, "--spec", spec, "--out", str(out), "--workers", "1",
                 "--quiet"]) == 0
    assert "1 computed, 1 already done" in capsys.readouterr().out
    s = json.loads((out / "summary.json").read_text())
    assert s["complete"] is True
    assert s["samples"] == 6 and (out / "sweep.png").stat().st_size > 10000
    assert sorted({round(v["low"], 3) for v in s["parameters"]}) == [0.0, 485.0]
    # the same command again resumes: nothing left to compute
    assert main(["study", SEEDER, "--spec", spec, "--out", str(out), "--quiet"]) == 0
    assert "0 computed, 2 already done" in capsys.readouterr().out
    # its report: the fraction meeting each objective, as in the summary
    assert main(["report", str(out)]) == 0
    page = (out / "report.html").read_text(encoding="utf-8")
    assert 'id="sweep-table"' in page and page.count("data:image/png;base64,") == 1
    for o in s["objectives"]:
        assert f"{o['fraction_ok']:.4f}</td>" in page, o["name"]
    capsys.readouterr()
    other = _write(tmp_path / "t.toml", TOL)
    assert main(["study", SEEDER, "--spec", other, "--out", str(out)]) == 2
    assert "another design or study file" in capsys.readouterr().err


def test_multi_start_reports_successes(tmp_path, capsys):
    spec = _write(tmp_path / "m.toml", """kind = "multi-start"
problem = "seeder-layer2"
starts = 2
generations = 1
pop = 4
best = 1
""")
    out = tmp_path / "ms"
    code = main(["study", SEEDER, "--spec", spec, "--out", str(out), "--workers", "1",
                 "--quiet"])
    s = json.loads((out / "summary.json").read_text())
    assert s["starts"] == 2 and code == (0 if s["successes"] else 4)
    assert (out / "best_1.toml").exists() and (out / "multistart.png").exists()
    assert s["best"][0]["seed"] in (0, 1)
    assert main(["report", str(out)]) == code  # the report's verdict is the study's
    assert 'id="best-table"' in (out / "report.html").read_text(encoding="utf-8")
