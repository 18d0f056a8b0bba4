"""Atomic output directories and finite outputs (outputs/files.py, issue 19)."""

import json
import math
import os

import numpy as np
import pytest

from plantmech.interfaces.cli import main
from plantmech.outputs.files import (
    SUMMARY_PRECISION,
    NonFiniteOutput,
    OutputError,
    OutputRun,
    write_csv,
    write_json,
)
from tests.conftest import EXAMPLES


def _design(tmp_path, name="d.toml"):
    d = tmp_path / name
    d.write_text((EXAMPLES / "sugarcane_seeder.toml").read_text().replace(
        "samples = 3600", "samples = 360"))
    return d


def test_files_appear_only_when_the_run_has_a_result(tmp_path):
    d = _design(tmp_path)
    out = tmp_path / "o"
    with OutputRun(out, [d]) as run:
        (run.path / "a.txt").write_text("x")
        assert not out.exists() and run.path.parent == tmp_path
        assert run.final(run.path / "a.txt") == out / "a.txt"
        run.exit_code = 3
    assert (out / "a.txt").read_text() == "x"
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".plantmech")] == []


@pytest.mark.parametrize("code", [2, None])
def test_failed_run_leaves_nothing_and_keeps_the_old_results(tmp_path, code):
    d = _design(tmp_path)
    out = tmp_path / "o"
    out.mkdir()
    (out / "old.csv").write_text("old")
    with OutputRun(out, [d], force=True) as run:
        (run.path / "new.csv").write_text("new")
        run.exit_code = code
    assert sorted(p.name for p in out.iterdir()) == ["old.csv"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["d.toml", "o"]


def test_exception_and_interrupt_leave_nothing(tmp_path):
    d = _design(tmp_path)
    for exc in (RuntimeError("boom"), KeyboardInterrupt()):
        with pytest.raises(type(exc)), OutputRun(tmp_path / "o", [d]) as run:
            (run.path / "half.csv").write_text("1,")
            raise exc
        assert sorted(p.name for p in tmp_path.iterdir()) == ["d.toml"]


def test_force_replaces_old_results_as_a_whole(tmp_path):
    d = _design(tmp_path)
    out = tmp_path / "o"
    out.mkdir()
    (out / "motion.csv").write_text("stale")
    with pytest.raises(OutputError, match="already holds 1 entries .*motion.csv.*--force"):
        OutputRun(out, [d])
    with OutputRun(out, [d], force=True) as run:
        (run.path / "summary.json").write_text("{}")
        run.exit_code = 0
    assert sorted(p.name for p in out.iterdir()) == ["summary.json"]


def test_links_onto_the_input_are_refused_by_identity(tmp_path):
    d = _design(tmp_path)
    before = d.read_text()
    out = tmp_path / "o"
    out.mkdir()
    os.symlink(d, out / "summary.json")
    with pytest.raises(OutputError, match="link to it"):
        OutputRun(out, [d], force=True)
    out2 = tmp_path / "o2"
    out2.mkdir()
    os.link(d, out2 / "motion.csv")
    with pytest.raises(OutputError, match="link to it"):
        OutputRun(out2, [d], force=True)
    # the design given through a path inside --out
    with pytest.raises(OutputError, match="would hold or overwrite the input"):
        OutputRun(out, [out / "summary.json"], force=True)
    assert d.read_text() == before


def test_unusable_out_paths_are_clear_errors(tmp_path):
    d = _design(tmp_path)
    f = tmp_path / "file"
    f.write_text("x")
    for out, pattern in (("", "empty"), (f / "sub", "file, not a directory"),
                         (f, "not a directory"), (tmp_path / ("x" * 300), "longer than 255"),
                         ("/proc/x", "cannot|not writable")):
        with pytest.raises(OutputError, match=pattern):
            with OutputRun(out, [d]) as run:
                run.exit_code = 0


def test_cli_refuses_existing_results_without_force(tmp_path, capsys):
    d = _design(tmp_path)
    out = tmp_path / "o"
    assert main(["inverse", str(d), "--out", str(out), "--no-plots"]) == 4  # feasible, not cuttable
    first = (out / "summary.json").read_text()
    assert main(["inverse", str(d), "--out", str(out), "--no-plots"]) == 2
    err = capsys.readouterr().err
    assert "already holds" in err and "summary.json" in err and "--force" in err
    assert (out / "summary.json").read_text() == first
    assert main(["inverse", str(d), "--out", str(out), "--no-plots", "--force"]) == 4


def test_cli_input_error_creates_nothing(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text('mechanism = "sugarcane_seeder"\n[trajectory]\npoints = 3\n')
    assert main(["forward", str(bad), "--out", str(tmp_path / "o")]) == 2
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.toml"]
    assert "trajectory.points" in capsys.readouterr().err


def test_non_finite_values_are_never_written(tmp_path):
    with pytest.raises(NonFiniteOutput, match=r"a\.b\[1\]"):
        write_json(tmp_path / "x.json", {"a": {"b": [1.0, math.nan]}})
    with pytest.raises(NonFiniteOutput, match="column y row 2"):
        write_csv(tmp_path / "x.csv", {"x": np.array([1.0, 2.0]), "y": np.array([0, np.inf])})
    # a documented gap (the sun's toothless sector) is an empty cell, inf never
    write_csv(tmp_path / "g.csv", {"a": np.array([1.0, 2.0]), "r1_mm": np.array([1.0, np.nan])},
              gaps=("r1_mm",))
    assert (tmp_path / "g.csv").read_text().splitlines() == ["a,r1_mm", "1.000000,1.000000",
                                                             "2.000000,"]
    with pytest.raises(NonFiniteOutput):
        write_csv(tmp_path / "g.csv", {"r1_mm": np.array([np.inf])}, gaps=("r1_mm",))


def test_a_check_without_a_value_says_why_and_is_not_ok():
    from plantmech.objectives import Check

    d = Check("ring", math.nan, "> 1 mm", True, "mm").as_dict()
    assert d["value"] is None and d["ok"] is False and "not computable" in d["not_computable"]
    json.dumps(d, allow_nan=False)


def test_objectives_without_a_value_are_reported_not_computable(tmp_path):
    write_json(tmp_path / "r.json", {"objectives": [
        {"name": "ring", "value": math.nan, "unit": "mm", "limit": "> 1 mm", "ok": True},
        {"name": "speed", "value": None, "unit": "m/s", "limit": "> 1", "ok": False,
         "not_computable": "no return section"},
        {"name": "swing", "value": 3.0, "unit": "deg", "limit": "< 30 deg", "ok": True}]})
    objs = json.loads((tmp_path / "r.json").read_text())["objectives"]
    assert objs[0]["value"] is None and objs[0]["ok"] is False
    assert "not computable" in objs[0]["not_computable"]
    assert objs[1]["not_computable"] == "no return section"
    assert objs[2] == {"name": "swing", "value": 3.0, "unit": "deg", "limit": "< 30 deg",
                       "ok": True}


def test_run_command_ctrl_c_and_not_computable_leave_nothing(tmp_path, capsys):
    """The helper every command goes through: Ctrl-C returns 130, a value refused at
    writing returns 3; in both cases nothing is left and an old --out is untouched."""
    from argparse import Namespace

    from plantmech.interfaces.cli import run_command

    d = _design(tmp_path)
    out = tmp_path / "o"
    out.mkdir()
    (out / "old.json").write_text("{}")

    def interrupted(args, design, run):
        (run.path / "half.csv").write_text("1,")
        raise KeyboardInterrupt

    def nan_result(args, design, run):
        write_json(run.path / "summary.json", {"L1_mm": math.nan})
        return 0

    def ok(args, design, run):
        write_json(run.path / "summary.json", {"L1_mm": design.trajectory.samples})
        return 4

    args = Namespace(design=str(d), out=str(out), force=True)
    assert run_command(args, interrupted) == 130
    assert "interrupted" in capsys.readouterr().err
    assert run_command(args, nan_result) == 3
    assert "L1_mm = nan: not computable" in capsys.readouterr().err
    assert sorted(p.name for p in out.iterdir()) == ["old.json"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["d.toml", "o"]
    assert run_command(args, ok) == 4
    assert json.loads((out / "summary.json").read_text()) == {"L1_mm": 360,
                                                              "precision": SUMMARY_PRECISION}
    assert sorted(p.name for p in out.iterdir()) == ["summary.json"]


def test_failed_run_removes_the_parents_it_created(tmp_path):
    d = _design(tmp_path)
    with OutputRun(tmp_path / "a" / "b" / "o", [d]) as run:
        assert (tmp_path / "a" / "b").is_dir()
        run.exit_code = 2
    assert sorted(p.name for p in tmp_path.iterdir()) == ["d.toml"]
    with OutputRun(tmp_path / "a" / "b" / "o", [d]) as run:
        run.exit_code = 0
    assert (tmp_path / "a" / "b" / "o").is_dir()


def test_solid_check_counts_open_fragments_without_networkx():
    """Fuzz case 539 (the K-H-V gears at --module 10): the middle gear's extruded outline
    fell into 26 pieces, and trimesh's split repairs each open piece with networkx (not a
    dependency): a ModuleNotFoundError instead of the refusal. Two closed boxes and a box
    with a face removed are 3 bodies, not watertight."""
    import trimesh

    from plantmech.outputs.gear_files import solid_check

    a = trimesh.creation.box((1, 1, 1))
    b = trimesh.creation.box((1, 1, 1))
    b.apply_translation((3, 0, 0))
    c = trimesh.creation.box((1, 1, 1))
    c.apply_translation((6, 0, 0))
    c = trimesh.Trimesh(c.vertices, c.faces[:-2], process=False)  # one side open
    check = solid_check(trimesh.util.concatenate([a, b, c]))
    assert check["bodies"] == 3 and not check["watertight"]
    one = solid_check(a)
    assert one == {"bodies": 1, "watertight": True, "volume_mm3": pytest.approx(1.0)}


def test_summary_numbers_to_12_significant_digits_and_said(tmp_path):
    data = {"a": 1.0080057938388185, "b": [29.8027, 1 / 3, 123456789.123456789],
            "n": 7, "t": True, "s": "x", "c": {"v": -2.5e-17 / 3}}
    write_json(tmp_path / "summary.json", data)
    got = json.loads((tmp_path / "summary.json").read_text())
    assert got["a"] == 1.00800579384 and got["b"] == [29.8027, 0.333333333333, 123456789.123]
    assert got["c"]["v"] == -8.33333333333e-18 and got["n"] == 7 and got["t"] is True
    assert got["precision"] == "every number to 12 significant digits"
    # every other record keeps full precision
    write_json(tmp_path / "run.json", data)
    assert json.loads((tmp_path / "run.json").read_text()) == data
