import json

from plantmech.interfaces.cli import main
from tests.conftest import EXAMPLES


def test_feasible_example_writes_everything(tmp_path, capsys):
    out = tmp_path / "o"
    rc = main(["inverse", str(EXAMPLES / "sugarcane_seeder.toml"), "--out", str(out),
               "--verify"])
    # feasible, but a Table 1 check fails and the pitch curves cannot be cut
    assert rc == 4
    s_ = json.loads((out / "summary.json").read_text())
    every = s_["trajectory_checks"] + s_["objectives"] + s_["manufacturing_checks"]
    assert s_["verdict"]["failed"] == [c["name"] for c in every if not c["ok"]]
    assert "cuttable_module_gear3_planet" in s_["verdict"]["failed"]
    assert "verdict: NOT MET" in capsys.readouterr().out.strip().splitlines()[-1]
    s = json.loads((out / "summary.json").read_text())
    assert s["feasible"] is True
    for key in ("L1_mm", "L2_mm", "a1_mm", "a2_mm", "closure_error_rad", "trajectory_checks",
                "attitude_deg", "diagnostics"):
        assert key in s
    assert abs(s["L1_mm"] - 254) < 1 and abs(s["L2_mm"] - 498) < 1
    assert s["round_trip_max_deviation_mm"] < 0.01
    assert set(s["convexity"]) == {"gear2", "gear3"}
    assert isinstance(s["convexity"]["gear2"]["convex"], bool)
    header = (out / "pitch_curves.csv").read_text().splitlines()[0]
    assert header == "angle_deg,r1_mm,r2_mm,r3_mm,r4_mm"
    motion = (out / "motion.csv").read_text().splitlines()
    assert motion[0].startswith("carrier_angle_deg,tip_x_mm,tip_y_mm")
    assert len(motion) == 3601
    traj = (out / "trajectory.csv").read_text().splitlines()
    assert traj[0] == "arc_length_mm,x_mm,y_mm,curvature_1_per_mm,point_index"
    s_col = [float(r.split(",")[0]) for r in traj[1:]]
    assert len(s_col) == 3600 and abs((s_col[2] - s_col[1]) - (s_col[-1] - s_col[-2])) < 1e-3
    for png in ("trajectory", "attitude", "ratios", "pitch_curves"):
        assert (out / f"{png}.png").stat().st_size > 10_000


def test_infeasible_example_exit_3(tmp_path, capsys):
    out = tmp_path / "o"
    rc = main(["inverse", str(EXAMPLES / "sugarcane_table2_as_printed.toml"), "--out",
               str(out), "--no-plots"])
    assert rc == 3
    s = json.loads((out / "summary.json").read_text())
    assert s["feasible"] is False
    assert s["diagnostics"][0]["between_points"] == [3, 4]
    assert s["L1_mm"] > 250
    assert not (out / "pitch_curves.csv").exists()
    assert "between q3 and q4" in capsys.readouterr().out


def test_invalid_file_exit_2(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text('mechanism = "sugarcane_seeder"\n')
    rc = main(["inverse", str(bad), "--out", str(tmp_path / "o")])
    assert rc == 2
    err = capsys.readouterr().err
    assert "field 'trajectory'" in err and "Traceback" not in err


def test_out_dir_never_holds_the_input(tmp_path, capsys):
    design = tmp_path / "d.toml"
    design.write_text((EXAMPLES / "sugarcane_seeder.toml").read_text())
    rc = main(["inverse", str(design), "--out", str(tmp_path)])
    assert rc == 2
    assert "would hold or overwrite the input" in capsys.readouterr().err
    assert design.read_text() == (EXAMPLES / "sugarcane_seeder.toml").read_text()


def test_bad_command_line_numbers_are_refused_by_name(tmp_path, capsys):
    import pytest

    for argv, expected in (
            (["gears", "x.toml", "--out", "o", "--module", "-1"], "--module: -1 must be above 0"),
            (["gears", "x.toml", "--out", "o", "--backlash", "nan"], "--backlash: nan must"),
            (["optimize", "x.toml", "--problem", "transplanter", "--out", "o",
              "--generations", "0"], "--generations: 0 must be at least 1")):
        with pytest.raises(SystemExit) as exc:
            main(argv)
        assert exc.value.code == 2
        assert expected in capsys.readouterr().err


def test_a_reader_that_leaves_does_not_stop_the_job(tmp_path):
    """`plantmech ... | head -1`: the pipe is closed before the job prints. The job still runs
    to its end (files, the exit status it has unpiped), with no traceback."""
    import os
    import subprocess
    import sys

    read_end, write_end = os.pipe()
    os.close(read_end)  # every write the job makes meets a closed pipe
    out = tmp_path / "o"
    proc = subprocess.run(
        [sys.executable, "-m", "plantmech.interfaces.cli", "inverse",
         str(EXAMPLES / "sugarcane_table4.toml"), "--out", str(out)],
        stdout=write_end, stderr=subprocess.PIPE, text=True, timeout=300)
    os.close(write_end)
    assert proc.stderr == ""
    assert proc.returncode == 4  # as unpiped: Table 4's pitch curves cannot be cut
    assert json.loads((out / "summary.json").read_text())["verdict"]["exit_code"] == 4
    assert (out / "motion.csv").stat().st_size > 100_000
