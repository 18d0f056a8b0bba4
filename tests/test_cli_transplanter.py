import csv
import json

import pytest

from plantmech.interfaces.cli import main
from tests.conftest import EXAMPLES


def test_rice_example_writes_everything(tmp_path, capsys):
    out = tmp_path / "o"
    assert main(["forward", str(EXAMPLES / "rice_transplanter.toml"), "--out", str(out)]) == 4
    s = json.loads((out / "summary.json").read_text())
    for key in ("objectives", "trajectory_height_mm", "picking_angle_deg", "pushing_angle_deg",
                "angle_difference_deg", "forward_inclination_deg", "hole_width_mm",
                "module_mm", "stages_deg"):
        assert key in s, key
    assert len(s["objectives"]) == 16  # (i)-(xii), the tooth fit (xiii)-(xv), cuttable module
    assert set(s["stages_deg"]) == {"arm_I", "arm_II", "arm_III"}
    assert s["closure_error_rad"] < 1e-9
    assert max(s["arm_phase_deviation_mm"]) < 1e-6
    with (out / "motion.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == 3600 and "arm3_tip_y_mm" in rows[0]
    for png in ("trajectories", "attitude_speed", "ratio", "gears"):
        assert (out / f"{png}.png").stat().st_size > 10_000
    assert "arms repeat each other" in capsys.readouterr().out


def test_khv_example_runs(tmp_path):
    out = tmp_path / "o"
    assert main(["forward", str(EXAMPLES / "rice_transplanter_khv.toml"), "--out", str(out),
                 "--no-plots"]) == 4
    s = json.loads((out / "summary.json").read_text())
    assert s["mechanism"] == "rice_transplanter_khv" and len(s["objectives"]) == 12
    na = [o for o in s["objectives"] if o["value"] is None]
    assert all("not computed" in o["note"] for o in na)


@pytest.mark.parametrize("edit, expected", [
    (("teeth = 80", "teeth = 81"), "not a multiple of lobes"),
    (("speed_ratio = 0.75", "speed_ratio = 0.7"), "whole non-zero number"),
    (("rim_mm = 5", "rim_mm = 5\nmin_planet_radius_mm = 6"), "cannot mesh"),
    (("H1_mm = 80", "H1_mm = 180"), "field 'arm': H1_mm = 180 exceeds S_mm"),
    (("r0..r11 (r11 inferred)", "r0..r11\ncentre_distance_mm = 50"), "does not close"),
    (("radii_mm = [100, 98.5", "radii_mm = [-100, 98.5"), "internal_gear.radii_mm.0"),
])
def test_bad_transplanter_files_are_refused(tmp_path, capsys, edit, expected):
    text = (EXAMPLES / "rice_transplanter.toml").read_text()
    assert edit[0] in text
    p = tmp_path / "t.toml"
    p.write_text(text.replace(edit[0], edit[1], 1))
    rc = main(["forward", str(p), "--out", str(tmp_path / "o"), "--no-plots"])
    assert rc == 2
    err = capsys.readouterr().err
    assert expected in err and "Traceback" not in err
