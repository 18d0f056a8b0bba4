"""The HTML report of a study directory (outputs.study_report, ``plantmech report``):
its numbers against the study's own Parquet rows, its verdict and exit status, the plots
a --no-plots study skipped, and the files it refuses to overwrite."""

from __future__ import annotations

import html
import json
import re
from pathlib import Path

import numpy as np
import pytest

from plantmech.interfaces.cli import main
from plantmech.outputs.study_report import build_study_report, study_verdict
from plantmech.studies.engine import read_results
from plantmech.studies.runner import wilson

ROOT = Path(__file__).resolve().parents[1]
RICE = str(ROOT / "examples" / "rice_transplanter_manufacturable.toml")
SPEC = """kind = "tolerance"
samples = 60
chunk = 30
seed = 2
cycle_samples = 180
required_probability = {req}
[parameters.box_inclination_deg]
distribution = "normal"
sigma = 0.3
[parameters.carrier_length_mm]
distribution = "uniform"
plus_minus = 0.05
[parameters.backlash_deg]
distribution = "uniform"
low = 0.0
high = 0.2
"""


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    """A transplanter tolerance study stopped after one chunk, then resumed (no plots)."""
    tmp = tmp_path_factory.mktemp("study")
    spec = tmp / "tol.toml"
    spec.write_text(SPEC.format(req=0.5), encoding="utf-8")
    out = tmp / "out"
    args = ["study", RICE, "--spec", str(spec), "--out", str(out), "--workers", "1",
            "--quiet", "--no-plots"]
    first = main(args + ["--max-chunks", "1"])
    partial = json.loads((out / "summary.json").read_text(encoding="utf-8"))
    partial_report = build_study_report(out)
    second = main(args + ["--report"])
    return {"out": out, "spec": spec, "first": first, "second": second, "partial": partial,
            "partial_report": partial_report}


def test_a_stopped_study_reports_incomplete(study):
    assert study["first"] == 4 and study["partial"]["complete"] is False
    style, text = study_verdict(study["partial"])
    assert style == "fail" and text.startswith("INCOMPLETE")
    assert 'class="verdict fail"' in study["partial_report"]
    assert "the 30 finished samples only" in study["partial_report"]


def test_report_numbers_are_the_rows(study, capsys):
    out = study["out"]
    assert study["second"] == 0 and (out / "report.html").exists()
    assert main(["report", str(out)]) == 0
    assert "report:" in capsys.readouterr().out
    page = (out / "report.html").read_text(encoding="utf-8")
    data = read_results(out)
    N = len(data["sample"])
    assert N == 60
    # the verdict: P(every objective met) from the rows, with its interval
    p = data["all_ok"].astype(bool).mean()
    lo, hi = wilson(int(data["all_ok"].sum()), N)
    assert f"P(every objective met) = {p:.4f} (95 %: {lo:.4f}-{hi:.4f})" in html.unescape(page)
    assert 'class="verdict ok"' in page and "required 0.5: met" in page
    # one row per objective: its status word from the rows' ok column
    table = page.split('id="probability-table"')[1].split("</table>")[0]
    rows = re.findall(r'<tr><td class="(\w+)">([\w ]+)</td><td>(\w+)<span', table)
    names = [c[:-4] for c in data if c.endswith("__ok")]
    assert [r[2] for r in rows] == names
    for cls, word, name in rows:
        ok = data[f"{name}__ok"].astype(bool)
        want = "holds" if ok.all() else "fails" if not ok.any() else "at risk"
        assert word == want, name
        assert cls == {"holds": "ok", "fails": "fail", "at risk": "risk"}[want]
        if 0 < ok.mean() < 1:
            assert f"{ok.mean():.4f} (95 %:" in table
    # the transplanter has no planned trajectory: the band is said to be around its path
    assert "Tip-path band around the nominal path" in page
    assert "beyond the pair's centre distance" in html.unescape(page)
    # the three plots the --no-plots study skipped are drawn and embedded
    for name in ("histograms.png", "sensitivity.png", "band.png"):
        assert (out / name).read_bytes()[:4] == b"\x89PNG"
    assert page.count('src="data:image/png;base64,') == 3


def test_an_unmet_requirement_is_not_met(study, tmp_path):
    s = json.loads((study["out"] / "summary.json").read_text(encoding="utf-8"))
    s["required_probability"], s["requirement_met"] = 0.999, False
    style, text = study_verdict(s)
    assert style == "fail" and text.startswith("NOT MET: required P(every objective met)")
    target = tmp_path / "copy"
    target.mkdir()
    for f in ("study.json", "band.csv"):
        (target / f).write_bytes((study["out"] / f).read_bytes())
    (target / "chunks").mkdir()
    for f in (study["out"] / "chunks").iterdir():
        (target / "chunks" / f.name).write_bytes(f.read_bytes())
    (target / "summary.json").write_text(json.dumps(s), encoding="utf-8")
    assert main(["report", str(target)]) == 4
    assert 'class="verdict fail"' in (target / "report.html").read_text(encoding="utf-8")


def test_no_study_and_foreign_files_are_refused(study, tmp_path, capsys):
    assert main(["report", str(tmp_path)]) == 2
    assert "study.json" in capsys.readouterr().err
    mine = tmp_path / "notes.html"
    mine.write_text("my notes", encoding="utf-8")
    assert main(["report", str(study["out"]), "--out", str(mine)]) == 2
    assert "not a report" in capsys.readouterr().err
    assert mine.read_text(encoding="utf-8") == "my notes"


def test_an_objective_no_tolerance_moves_has_no_fit(study):
    """The module is the gear's: the box, the carrier bore and the play leave it alone.
    Its regression has no R² (None in summary.json, which holds no NaN), not a crash."""
    s = json.loads((study["out"] / "summary.json").read_text(encoding="utf-8"))
    module = next(o for o in s["objectives"] if o["name"] == "module")
    assert module["std"] == 0.0 and module["sensitivity"]["r2"] is None
    assert module["probability_ok"] == 1.0
    data = read_results(study["out"])
    assert np.ptp(data["module"]) == 0.0
