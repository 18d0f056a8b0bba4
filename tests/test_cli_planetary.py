"""Design files of the general train (design_planetary.py) and `plantmech forward` on them
(interfaces/planetary_cli.py)."""

from __future__ import annotations

import copy
import csv
import json
import re
import tomllib

import numpy as np
import pytest

from plantmech.design import DesignError, load_design
from plantmech.interfaces.cli import main
from tests.conftest import EXAMPLES, assert_file_refused
from tests.conftest import write_toml as _write

EXAMPLE = EXAMPLES / "rotary_transplanter_elliptic.toml"


def _doc() -> dict:
    return tomllib.loads(EXAMPLE.read_text())




def test_elliptic_example_runs_and_writes_everything(tmp_path, capsys):
    out = tmp_path / "o"
    assert main(["forward", str(EXAMPLE), "--out", str(out)]) == 0
    s = json.loads((out / "summary.json").read_text())
    assert s["mechanism"] == "planetary" and s["verdict"]["status"] == "ok"
    assert [o["name"] for o in s["objectives"]] == ["path_height_mm", "loops"]
    assert all(o["ok"] for o in s["objectives"])
    assert len(s["pairs"]) == 2
    for p in s["pairs"]:
        assert p["centre_distance_mm"] == pytest.approx(50.0, abs=1e-9)  # 2A
        assert abs(p["closure_error_rad"]) < 1e-12
        e = 0.18  # ratio range of two ellipses: (1 - e) / (1 + e) .. (1 + e) / (1 - e)
        assert p["ratio_range"] == pytest.approx([(1 - e) / (1 + e), (1 + e) / (1 - e)],
                                                 abs=1e-6)
        assert p["driver_convex"] and p["follower_convex"]
    assert s["values"]["loops"] == 1.0
    assert s["values"]["arm_phase_deviation_mm"] < 1e-9
    # the shafts on one carrier line: sun, idler at 2A, planet at 4A
    assert np.allclose(s["shafts_mm"], [[0, 0], [50, 0], [100, 0]], atol=1e-9)
    with (out / "motion.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == 3600 and "arm2_tip_y_mm" in rows[0]
    x = np.array([float(r["arm1_tip_x_mm"]) for r in rows])
    assert np.ptp(x) == pytest.approx(s["values"]["path_width_mm"], abs=1e-5)
    with (out / "pitch_curves.csv").open() as fh:
        gears = list(csv.DictReader(fh))
    r = np.array([float(g["pair1_driver_sun_mm"]) for g in gears])
    assert r.max() == pytest.approx(25 * 1.18, abs=1e-6)
    assert r.min() == pytest.approx(25 * 0.82, abs=1e-6)
    for png in ("trajectories", "attitude_speed", "ratios"):
        assert (out / f"{png}.png").stat().st_size > 10_000
    printed = capsys.readouterr().out
    assert "verdict: ok" in printed.splitlines()[-1]


def test_a_limit_not_met_exits_4_and_says_which(tmp_path, capsys):
    doc = _doc()
    doc["limits"]["path_width_mm"] = {"max": 40.0}
    out = tmp_path / "o"
    assert main(["forward", _write(tmp_path, doc), "--out", str(out), "--no-plots"]) == 4
    s = json.loads((out / "summary.json").read_text())
    assert s["verdict"]["failed"] == ["path_width_mm"]
    assert "NOT MET" in capsys.readouterr().out.splitlines()[-1]


def test_no_limits_is_ok_and_says_nothing_else_was_checked(tmp_path, capsys):
    doc = _doc()
    del doc["limits"]
    assert main(["forward", _write(tmp_path, doc), "--out", str(tmp_path / "o"),
                 "--no-plots"]) == 0
    assert "no [limits] given" in capsys.readouterr().out


@pytest.mark.parametrize("edit, field", [
    (lambda d: d["train"]["pairs"][0].pop("driver"),
     r"field .train.: pairs\.0\.driver is missing"),
    (lambda d: d["train"]["pairs"][0]["driver"].update(eccentricity=0.9),
     r"train\.pairs\.0\.driver\.ellipse\.eccentricity"),
    (lambda d: d["train"]["pairs"][0]["driver"].update(eccentricity="0.1"),
     r"train\.pairs\.0\.driver\.ellipse\.eccentricity"),
    (lambda d: d["train"]["pairs"][0]["driver"].update(family="spiral"),
     r"train\.pairs\.0\.driver"),
    (lambda d: d["train"]["pairs"][0].update(
        driver={"family": "eccentric", "radius_mm": 20.0, "offset_mm": 20.0}),
     r"train\.pairs\.0\.driver\.eccentric.*offset_mm = 20 is not below radius_mm"),
    (lambda d: d["train"]["pairs"][0].update(
        driver={"family": "fourier", "mean_radius_mm": 20.0, "cos_mm": [25.0]}),
     r"train\.pairs\.0\.driver\.fourier.*falls to"),
    (lambda d: d["train"]["pairs"][1].update(kind="bevel"), r"train\.pairs\.1\.kind"),
    (lambda d: d["train"].update(pairs=[]), r"train\.pairs"),
    (lambda d: d["train"].update(grid=100), r"train\.grid"),
    (lambda d: d["carrier"].update(arms=2.0), r"carrier\.arms"),
    (lambda d: d["arm"].pop("length_mm"), r"'arm': length_mm is missing"),
    (lambda d: d["limits"].update(loops={"min": 2, "max": 1}), r"limits\.loops"),
])
def test_bad_design_files_name_the_field(edit, field, tmp_path, capsys):
    doc = copy.deepcopy(_doc())
    edit(doc)
    assert_file_refused(doc, field, tmp_path, capsys)


@pytest.mark.parametrize("edit, message", [
    (lambda d: d["train"]["pairs"][0].update(centre_distance_mm=52.0),
     r"train\.pairs\.0: the pair does not close.*closes at 50\.0000 mm"),
    (lambda d: d["train"]["pairs"][0].update(follower_turns=2.0),
     r"train\.pairs\.0: .*does not repeat every 180 deg"),
    (lambda d: d["train"].update(min_pitch_radius_mm=21.0),
     r"train\.pairs\.0\.driver: radius .* is not above 21 mm"),
])
def test_trains_that_cannot_be_built_exit_2_naming_the_pair(edit, message, tmp_path, capsys):
    doc = copy.deepcopy(_doc())
    edit(doc)
    out = tmp_path / "o"
    assert main(["forward", _write(tmp_path, doc), "--out", str(out)]) == 2
    assert not out.exists()
    assert re.search(message, capsys.readouterr().err)


@pytest.mark.parametrize("command, field", [(["optimize", "--problem", "seeder-layered"],
                                             "--problem"),
                                            (["inverse"], "field 'trajectory"),
                                            (["optimize", "--problem", "transplanter"],
                                             "--problem")])
def test_other_commands_refuse_a_planetary_design_by_name(command, field, tmp_path, capsys):
    out = tmp_path / "o"
    argv = [command[0], str(EXAMPLE), "--out", str(out)] + command[1:]
    assert main(argv) == 2
    assert field in capsys.readouterr().err and not out.exists()


def test_gears_report_of_a_planetary_train_is_written(tmp_path, capsys):
    """`gears --report` on a general train: the report holds the gears' checks, their
    drawings and the train animated (`inverse --report` still refuses, by name)."""
    out = tmp_path / "o"
    assert main(["gears", str(EXAMPLE), "--out", str(out), "--report"]) in (0, 4)
    html = (out / "report.html").read_text()
    assert "one carrier turn" in html and (out / "mechanism.gif").exists()
    assert "Gear drawings" in html and html.count("data:image/svg") == 3  # sun, idler, planet


@pytest.mark.parametrize("kind, turns", [("internal", 1.0), ("internal_ring_follower", 2.0)])
def test_follower_turns_that_do_not_fit_the_kind_name_the_field(kind, turns):
    doc = _doc()
    doc["train"]["pairs"][0].update(kind=kind, follower_turns=turns)
    with pytest.raises(DesignError, match=r"train\.pairs\.0': follower_turns"):
        load_design(doc, name="t.toml")


def test_given_driver_and_follower_together_are_refused():
    doc = _doc()
    doc["train"]["pairs"][0]["follower"] = dict(doc["train"]["pairs"][0]["driver"])
    with pytest.raises(DesignError, match=r"pairs\.0: give driver or follower, not both"):
        load_design(doc, name="t.toml")
