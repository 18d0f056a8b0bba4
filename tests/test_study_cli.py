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


ELLIPTIC = str(ROOT / "examples" / "rotary_transplanter_elliptic.toml")


def test_a_general_planetary_train_is_studied_by_its_fields(tmp_path, capsys):
    """Study parameters of a planetary file are its numeric fields by dotted path. A
    sweep of the arm's length: every variant's tip is the nominal's moved along the arm by
    the change (the arm turns as before), so the largest tip deviation is |dL| exactly and
    the attitude is untouched; the path height grows with the arm. A tolerance study of
    the sun's eccentricity runs; a field that is not there, or is a count, is refused."""
    import pyarrow.parquet as pq

    spec = _write(tmp_path / "w.toml", """kind = "sweep"
method = "grid"
chunk = 3
cycle_samples = 720
[parameters."arm.length_mm"]
low = 150.0
high = 170.0
levels = 3
""")
    out = tmp_path / "sweep"
    assert main(["study", ELLIPTIC, "--spec", spec, "--out", str(out), "--workers", "1",
                 "--quiet"]) == 0
    rows = pq.read_table(out / "chunks" / "chunk_00000.parquet").to_pydict()
    assert rows["arm.length_mm"] == [150.0, 160.0, 170.0]
    for length, dev, att in zip(rows["arm.length_mm"], rows["tip_deviation_mm"],
                                rows["attitude_error_deg"], strict=True):
        assert abs(dev - abs(length - 160.0)) < 1e-9 and att < 1e-9
    h = rows["path_height_mm"]
    assert h[0] < h[1] < h[2] and all(rows["all_ok"])
    capsys.readouterr()
    tol = _write(tmp_path / "t.toml", """kind = "tolerance"
samples = 40
chunk = 20
cycle_samples = 360
[parameters."train.pairs.0.driver.eccentricity"]
distribution = "normal"
sigma = 0.002
""")
    assert main(["study", ELLIPTIC, "--spec", tol, "--out", str(tmp_path / "tol"),
                 "--workers", "1", "--quiet"]) == 0
    s = json.loads((tmp_path / "tol" / "summary.json").read_text())
    assert s["samples"] == 40 and {o["name"] for o in s["objectives"]} >= {
        "path_height_mm", "working_pressure_angle_sun_idler1"}
    for bad, said in (("train.pairs.0.driver.shape", "not a field"),
                      ("carrier.arms", "a count")):
        spec = _write(tmp_path / "b.toml", TOL.replace("[parameters.L2_mm]",
                                                       f'[parameters."{bad}"]'))
        assert main(["study", ELLIPTIC, "--spec", spec, "--out", str(tmp_path / "b")]) == 2
        err = capsys.readouterr().err
        assert bad in err and said in err


def test_multi_start_of_a_planetary_train(tmp_path, capsys):
    """`problem = "planetary"`: the fields a file frees in [optimize.variables], here to
    lift the tip path from 239 mm to at least 270 mm."""
    import tomllib

    import tomli_w

    doc = tomllib.loads(Path(ELLIPTIC).read_text())
    doc["limits"]["path_height_mm"] = {"min": 270.0}
    doc["optimize"] = {"variables": {"train.pairs.0.driver.eccentricity": [0.1, 0.3],
                                     "arm.length_mm": [150.0, 200.0]}}
    design = tmp_path / "d.toml"
    design.write_text(tomli_w.dumps(doc))
    spec = _write(tmp_path / "m.toml", """kind = "multi-start"
problem = "planetary"
starts = 1
generations = 3
pop = 8
""")
    out = tmp_path / "ms"
    assert main(["study", str(design), "--spec", spec, "--out", str(out), "--workers", "1",
                 "--quiet"]) == 0
    from plantmech.design import load_design
    from plantmech.objectives.planetary import design_evaluation

    best = load_design(out / "best_1.toml")
    rows = {r["name"]: r for r in design_evaluation(best)}
    assert rows["path_height_mm"]["ok"] and rows["path_height_mm"]["value"] > 270.0


def test_variants_outside_the_file_rules_are_counted_not_a_traceback(tmp_path, capsys):
    """A tolerance wide enough that some variants break a field rule (the ellipses'
    eccentricity must lie in [0, 0.8]): those variants cannot be built, so they count as
    not met and stay out of the tip-path band; band.csv has no NaN; the number the summary
    gives is the number of sampled eccentricities outside [0, 0.8] (counted here from the
    samples); before, band.csv refused its NaN with a traceback."""
    import numpy as np

    from plantmech.studies.engine import read_results

    tol = _write(tmp_path / "t.toml", """kind = "tolerance"
samples = 40
chunk = 20
cycle_samples = 180
[parameters."train.pairs.0.driver.eccentricity"]
distribution = "uniform"
plus_minus = 0.9
""")
    out = tmp_path / "tol"
    assert main(["study", ELLIPTIC, "--spec", tol, "--out", str(out), "--workers", "1",
                 "--quiet", "--no-plots"]) == 0
    io = capsys.readouterr()
    s = json.loads((out / "summary.json").read_text())
    e = 0.18 + read_results(out)["d_train.pairs.0.driver.eccentricity"]
    outside = int(((e < 0) | (e > 0.8)).sum())
    assert 0 < outside < 40 and s["variants_not_moved"] == outside
    assert f"{outside} of 40 variants could not be built" in io.out
    band = np.loadtxt(out / "band.csv", delimiter=",", skiprows=1)
    assert np.isfinite(band).all() and len(band) == 180
    assert s["probability_all_ok"] <= 1 - outside / 40


def test_a_band_with_no_variant_that_moved_is_an_input_error(monkeypatch):
    import numpy as np
    import pytest

    from plantmech.studies import runner
    from plantmech.studies.parameters import StudyInputError

    empty = {"sum": np.zeros(4), "sumsq": np.zeros(4), "min": np.full(4, np.inf),
             "max": np.full(4, -np.inf), "count": np.array([0]), "variants": np.array([7])}
    monkeypatch.setattr(runner, "read_extras", lambda out: [empty, empty])
    with pytest.raises(StudyInputError, match="none of the 14 variants"):
        runner.band_statistics(Path("."))


def test_a_sweep_past_a_field_rule_says_how_many_variants_were_not_built(tmp_path, capsys):
    spec = _write(tmp_path / "w.toml", """kind = "sweep"
method = "grid"
chunk = 3
cycle_samples = 180
[parameters."train.pairs.0.driver.eccentricity"]
low = 0.1
high = 0.95
levels = 3
""")
    out = tmp_path / "sw"
    assert main(["study", ELLIPTIC, "--spec", spec, "--out", str(out), "--workers", "1",
                 "--quiet"]) == 0
    s = json.loads((out / "summary.json").read_text())
    assert s["variants_not_moved"] == 1  # e = 0.95 > 0.8; 0.1 and 0.525 are built
    assert "1 could not be built" in capsys.readouterr().out and (out / "sweep.png").exists()


def test_a_khv_file_is_studied_and_reported_with_its_uncomputable_objectives(tmp_path, capsys):
    """The K-H-V example (issue 28: studied and reported as the papers' machines): its tip
    never passes through the seedling mat, so the picking angle (iii) and the objectives
    read from it cannot be computed. The tolerance study says so - nominal None where
    ``plantmech forward`` reports None, never met by a variant - and writes its summary
    and report (it refused with "objectives[0].nominal = nan" before)."""
    khv = str(ROOT / "examples" / "rice_transplanter_khv.toml")
    assert main(["forward", khv, "--out", str(tmp_path / "f"), "--no-plots"]) == 4
    forward = {o["name"]: o["value"] for o in json.loads(
        (tmp_path / "f" / "summary.json").read_text())["objectives"]}
    spec = _write(tmp_path / "t.toml", """kind = "tolerance"
samples = 24
chunk = 12
seed = 0
cycle_samples = 180
[parameters.S_mm]
distribution = "normal"
sigma = 0.1
""")
    out = tmp_path / "s"
    assert main(["study", khv, "--spec", spec, "--out", str(out), "--workers", "1",
                 "--quiet", "--no-plots", "--report"]) == 0
    s = json.loads((out / "summary.json").read_text())
    missing = {o["name"] for o in s["objectives"] if o["nominal"] is None}
    assert missing == {n for n, v in forward.items() if v is None} and "picking_angle" in missing
    for o in s["objectives"]:
        if o["name"] in missing:
            assert o["probability_ok"] == 0.0 and o["first_order_std"] is None
    assert "not computable" in capsys.readouterr().out
    assert 'n/a' in (out / "report.html").read_text(encoding="utf-8")
