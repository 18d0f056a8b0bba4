"""``plantmech optimize --problem planetary`` (optimize/planetary_problem.py): the free
fields of a planetary design file against its [limits] and the pitch-curve
manufacturability rules, with the runner's record and the full-resolution re-check."""

from __future__ import annotations

import json
import tomllib

import numpy as np
import pytest

from plantmech.design import DesignError, load_design
from plantmech.interfaces.cli import main
from tests.conftest import EXAMPLES
from tests.conftest import write_toml as _write

EXAMPLE = EXAMPLES / "rotary_transplanter_elliptic.toml"
VARIABLES = {"train.pairs.0.driver.eccentricity": [0.1, 0.4], "arm.length_mm": [140.0, 200.0]}


def _doc(height_min: float = 270.0) -> dict:
    d = tomllib.loads(EXAMPLE.read_text())
    d["limits"]["path_height_mm"] = {"min": height_min}
    d["optimize"] = {"variables": dict(VARIABLES)}
    return d




def test_a_small_run_meets_a_limit_the_start_misses(tmp_path, capsys):
    path = _write(tmp_path, _doc())
    # the starting design misses the height (239 mm with a 160 mm arm)
    assert main(["forward", path, "--out", str(tmp_path / "f0"), "--no-plots"]) == 4
    out = tmp_path / "o"
    code = main(["optimize", path, "--problem", "planetary", "--out", str(out), "--quiet",
                 "--pop", "8", "--generations", "6", "--seed", "1"])
    text = capsys.readouterr().out
    assert code == 0, text
    rec = json.loads((out / "run.json").read_text())
    assert rec["problem"] == "planetary" and rec["algorithm"] == "de" and rec["feasible"]
    assert rec["verified_full_resolution"]["all_met"]
    assert rec["evaluations"] > 0 and rec["wall_s"] > 0
    assert [v["name"] for v in rec["settings"]["variables"]] == list(VARIABLES)
    names = [o["name"] for o in rec["objectives"]]
    assert names == ["path_height_mm", "loops", "cuttable_module_sun_idler1",
                     "working_pressure_angle_sun_idler1", "cuttable_module_idler1_planet",
                     "working_pressure_angle_idler1_planet"]
    e, L = rec["best_x"]
    assert 0.1 <= e <= 0.4 and 140.0 <= L <= 200.0
    best = load_design(out / "best.toml")  # a valid design file with the variables applied
    assert best.train.pairs[0].driver.eccentricity == pytest.approx(e)
    assert best.arm.length_mm == pytest.approx(L)
    # independently: the forward command on best.toml meets every limit
    assert main(["forward", str(out / "best.toml"), "--out", str(tmp_path / "f1"),
                 "--no-plots"]) == 0
    s = json.loads((tmp_path / "f1" / "summary.json").read_text())
    assert s["values"]["path_height_mm"] > 270.0
    # the working pressure angle of the ellipses: 20 + atan(e / sqrt(1 - e^2)) deg
    wpa = next(o for o in rec["objectives"] if o["name"] == "working_pressure_angle_sun_idler1")
    assert wpa["value"] == pytest.approx(20 + np.degrees(np.arctan(e / np.sqrt(1 - e * e))),
                                         abs=0.05)
    for f in ("best.toml", "history.csv", "pareto.csv", "convergence.png"):
        assert (out / f).exists()


def test_limits_out_of_reach_exit_4_with_an_honest_record(tmp_path, capsys):
    """A 1000 mm high path with an arm of at most 200 mm: no design meets it."""
    out = tmp_path / "o"
    code = main(["optimize", _write(tmp_path, _doc(1000.0)), "--problem", "planetary",
                 "--out", str(out), "--quiet", "--pop", "6", "--generations", "2"])
    assert code == 4
    rec = json.loads((out / "run.json").read_text())
    assert not rec["feasible"] and rec["verdict"]["failed"] == ["path_height_mm"]
    assert "NOT every objective met" in (out / "best.toml").read_text().splitlines()[2]


def test_manufacturability_is_a_constraint_unless_reported_only():
    from plantmech.optimize.planetary_problem import PlanetaryProblem

    doc = _doc(200.0)
    doc["optimize"]["variables"] = {"train.pairs.0.driver.eccentricity": [0.1, 0.8]}
    d = load_design(doc, name="t.toml")
    X = np.array([[0.18], [0.6]])  # 0.6: working pressure angle 56.9 deg > 45
    b = PlanetaryProblem(d).evaluate_batch(X)
    assert b.feasible.tolist() == [True, False]
    k = b.names.index("working_pressure_angle_sun_idler1")
    assert b.G[1, k] == pytest.approx((20 + np.degrees(np.arctan(0.75)) - 45) / 45, rel=1e-3)
    assert b.F[:, 0] == pytest.approx([20 + np.degrees(np.arctan(0.18 / np.sqrt(1 - 0.0324))),
                                       20 + np.degrees(np.arctan(0.75))], abs=0.05)
    loose = PlanetaryProblem(d, manufacturability=False).evaluate_batch(X)
    assert loose.feasible.tolist() == [True, True] and loose.G[1, k] == 0.0


@pytest.mark.parametrize("variables, message", [
    ({"train.pairs.0.driver.eccentricity": [0.1, 0.9]}, r"bound 0\.9 makes the file invalid"),
    ({"train.pairs.5.driver.eccentricity": [0.1, 0.2]}, r"no item 5"),
    ({"carrier.direction": [0.0, 1.0]}, r"not a number"),
    ({"samples": [100.0, 200.0]}, r"samples: Input should be a valid integer"),
    ({"arm.length_mm": [200.0, 100.0]}, r"lower < upper"),
    ({"optimize.samples": [100.0, 200.0]}, r"not design variables"),
])
def test_bad_variables_are_refused_naming_them(variables, message):
    doc = _doc()
    doc["optimize"]["variables"] = variables
    with pytest.raises(DesignError, match=message):
        load_design(doc, name="t.toml")


def test_wrong_problem_or_missing_table_exit_2(tmp_path, capsys):
    out = tmp_path / "o"
    path = _write(tmp_path, _doc())
    assert main(["optimize", path, "--problem", "transplanter", "--out", str(out)]) == 2
    assert "--problem planetary" in capsys.readouterr().err and not out.exists()
    seeder = EXAMPLES / "sugarcane_table4.toml"
    assert main(["optimize", str(seeder), "--problem", "planetary", "--out", str(out)]) == 2
    assert "planetary" in capsys.readouterr().err and not out.exists()


def test_a_generation_is_one_population_equal_to_single_evaluations():
    """The candidates of a generation are built and simulated as ONE population; every
    candidate's checks equal its own single-design evaluation (P = 1) to 1e-12, a candidate
    whose train cannot be built (a pitch radius below the minimum) is found among them and
    the others still evaluated, and a candidate breaking a file rule is graded, not
    evaluated."""
    from plantmech.objectives import planetary as obj
    from plantmech.optimize.planetary_problem import PlanetaryProblem
    from plantmech.trains import spec

    doc = _doc()
    doc["optimize"]["variables"]["train.pairs.0.driver.semi_major_mm"] = [2.0, 40.0]
    design = load_design(doc, name="t.toml")
    problem = PlanetaryProblem(design)
    X = np.array([[0.15, 150.0, 25.0], [0.3, 190.0, 22.0], [0.25, 170.0, 2.05],
                  [0.38, 145.0, 30.0], [0.12, 199.0, 27.5]])
    builds = []
    real = spec.build_from_designs
    spec.build_from_designs = lambda ds, *a, **k: builds.append(len(ds)) or real(ds, *a, **k)
    try:
        batch = problem.evaluate_batch(X)
    finally:
        spec.build_from_designs = real
    assert builds[0] == 5  # the whole generation at once, then halved round the refused one
    assert sum(1 for b in builds if b == 1) <= 3
    for i, x in enumerate(X):
        single = obj.design_evaluation(problem.decode(x), problem.samples)
        if i == 2:  # the 2.05 mm ellipse: its mate falls below the minimum pitch radius
            assert all(r["value"] is None and r["violation"] == np.inf for r in single)
            assert "cannot be built" in single[0]["note"]
            assert np.all(np.isnan(batch.values[i])) and np.all(np.isinf(batch.G[i]))
            continue
        for k, r in enumerate(single):
            assert batch.names[k] == r["name"]
            assert batch.values[i, k] == pytest.approx(r["value"], rel=1e-12, abs=1e-12)
            assert batch.G[i, k] == pytest.approx(r["violation"], rel=1e-12, abs=1e-12)
            assert batch.ok[i, k] == r["ok"]
    # a candidate that breaks a file rule (an eccentric circle's offset beyond its radius)
    doc = _doc()
    doc["train"]["pairs"][0]["driver"] = {"family": "eccentric", "radius_mm": 25.0,
                                          "offset_mm": 3.0, "phase_deg": 270.0}
    doc["optimize"]["variables"] = {"train.pairs.0.driver.offset_mm": [0.0, 20.0],
                                    "train.pairs.0.driver.radius_mm": [15.0, 30.0]}
    problem = PlanetaryProblem(load_design(doc, name="t.toml"))
    designs, refusals = problem.candidates(np.array([[3.0, 25.0], [18.0, 16.0]]))
    assert designs[0] is not None and refusals[0] is None
    assert designs[1] is None and "offset_mm" in refusals[1]
    batch = problem.evaluate_batch(np.array([[3.0, 25.0], [18.0, 16.0]]))
    assert np.all(np.isinf(batch.G[1])) and np.all(np.isfinite(batch.G[0]))



def test_default_variables_shape_every_given_curve_and_the_arm_within_ten_percent():
    """A file without [optimize.variables] frees its pitch curves' lengths and shape
    numbers and the arm length, +-10 % of each value; a bound the file refuses on its own
    is drawn halfway towards the value (the elliptic example's eccentricity 0.18 is free to
    +-0.018; an eccentricity of 0.78 below the file's limit 0.8: 0.78 + 0.078 refused,
    0.78 + 0.039 refused, 0.78 + 0.0195 taken)."""
    from plantmech.optimize.planetary_problem import PlanetaryProblem, default_variables

    design = load_design(EXAMPLE)
    free = default_variables(design)
    assert "arm.length_mm" in free
    for path, (lo, hi) in free.items():
        node = design
        for part in path.split("."):
            node = node[int(part)] if part.isdigit() else getattr(node, part)
        assert lo == pytest.approx(0.9 * node) and hi == pytest.approx(1.1 * node)
    assert free["train.pairs.0.driver.eccentricity"] == pytest.approx([0.162, 0.198])
    doc = tomllib.loads(EXAMPLE.read_text())
    doc["train"]["pairs"][0]["driver"]["eccentricity"] = 0.78
    lo, hi = default_variables(load_design(doc, name="e.toml"))[
        "train.pairs.0.driver.eccentricity"]
    assert lo == pytest.approx(0.702) and hi == pytest.approx(0.78 + 0.0195)
    khv = load_design(EXAMPLES / "planetary" / "rice_transplanter_khv.toml")
    problem = PlanetaryProblem(khv)
    assert [v.name for v in problem.variables] == [
        f"train.pairs.0.driver.radii_mm.{i}" for i in range(8)] + ["arm.length_mm"]
    assert problem.design_choices()["variables"]["set_by"].startswith("default")


def test_khv_file_optimizes_with_its_default_variables_and_report(tmp_path, capsys):
    """The K-H-V train as a general file (no [optimize] table) optimizes, and --report
    writes the HTML report with the best design animated."""
    out = tmp_path / "o"
    khv = EXAMPLES / "planetary" / "rice_transplanter_khv.toml"
    rc = main(["optimize", str(khv), "--problem", "planetary", "--out", str(out),
               "--generations", "2", "--pop", "6", "--seed", "1", "--quiet", "--report"])
    assert rc in (0, 4)
    rec = json.loads((out / "run.json").read_text())
    assert rec["design_choices"]["variables"]["set_by"].startswith("default")
    html = (out / "report.html").read_text()
    assert "<svg" in html and (out / "mechanism.gif").stat().st_size > 1000
    best = load_design(out / "best.toml")
    for i, r in enumerate(load_design(khv).train.pairs[0].driver.radii_mm):
        assert 0.9 * r - 1e-9 <= best.train.pairs[0].driver.radii_mm[i] <= 1.1 * r + 1e-9
