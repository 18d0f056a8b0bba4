import csv
import json

import numpy as np
import pytest

from plantmech.interfaces.cli import main
from tests.conftest import EXAMPLES

TRAIN = """mechanism = "sugarcane_seeder"
name = "test train"
[train]
L1_mm = 254.0
L2_mm = 498.0
a1_mm = 127.0
a2_mm = 127.0
closure = "{closure}"
initial_carrier_angle_deg = 20.0
initial_arm_angle_deg = 20.0
min_pitch_radius_mm = {minr}
[train.gear2]
radii_mm = {r2}
{angles}
[train.gear3]
radii_mm = [63.5, 63.5, 63.5, 63.5]
[train.sections_deg]
a = 0
b = 50
c = 80
d = 130
e = 160
f = 210
"""


def write(tmp_path, closure="check", r2="[63.5, 63.5, 63.5, 63.5]", angles="", minr=5.0):
    p = tmp_path / "t.toml"
    p.write_text(TRAIN.format(closure=closure, r2=r2, angles=angles, minr=minr))
    return p


def test_table4_example_writes_everything(tmp_path, capsys):
    out = tmp_path / "o"
    rc = main(["forward", str(EXAMPLES / "sugarcane_table4.toml"), "--out", str(out)])
    assert rc == 4  # Table 4's gears fail the manufacturability checks
    s = json.loads((out / "summary.json").read_text())
    for key in ("max_speed_seeding_m_s", "min_speed_return_static_m_s",
                "min_speed_return_dynamic_m_s", "zero_speed_travel_m_s", "closure_error_rad",
                "convexity"):
        assert key in s, key
    names = {o["name"] for o in s["objectives"]}
    assert {"picking_swing", "seeding_swing", "sowing_angle", "seeding_peak_speed",
            "return_min_speed_static", "return_min_speed_dynamic"} <= names
    assert all(set(o) >= {"name", "value", "limit", "ok"} for o in s["objectives"])
    assert s["closure_error_rad"]["stage1"] < 1e-9 and s["closure_error_rad"]["stage2"] < 1e-9
    fixes = {f["pair"]: f for f in s["closure_restoration"]}
    assert fixes["gear 3 - planet"]["centre_distance_mm"] == pytest.approx(155.586, abs=1e-3)
    with (out / "motion.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == 3600
    for col in ("carrier_angle_deg", "tip_x_mm", "tip_y_mm", "vx_m_s", "vy_m_s", "speed_m_s",
                "dynamic_speed_m_s", "arm_angle_deg", "ratio", "stage1_ratio", "stage2_ratio"):
        assert col in rows[0], col
    # zero-speed seeding: the dynamic horizontal velocity vanishes at e
    e = s["section_carrier_angle_deg"]["e"]
    k = int(round(e / 0.1)) % 3600
    vx = float(rows[k]["vx_m_s"])
    assert vx == pytest.approx(s["travel_speed_used_m_s"], abs=0.02)
    speed = np.array([float(r["speed_m_s"]) for r in rows])
    assert speed.max() == pytest.approx(s["speeds_m_s"]["max_speed_static_m_s"], rel=1e-5)
    for png in ("trajectories", "speed", "attitude", "pitch_curves"):
        assert (out / f"{png}.png").stat().st_size > 10_000
    assert "closure of gear 3 - planet" in capsys.readouterr().out


def test_forward_of_a_trajectory_simulates_its_inverse_design(tmp_path):
    out = tmp_path / "o"
    assert main(["forward", str(EXAMPLES / "sugarcane_seeder.toml"), "--out", str(out),
                 "--no-plots"]) == 4
    s = json.loads((out / "summary.json").read_text())
    assert s["source"] == "inverse design of the trajectory"
    assert s["deviation_from_trajectory_mm"]["max_tip_to_plan"] < 0.01


def test_circular_train_file_runs(tmp_path):
    out = tmp_path / "o"
    assert main(["forward", str(write(tmp_path)), "--out", str(out), "--no-plots"]) == 4
    s = json.loads((out / "summary.json").read_text())
    # equal circles: the arm keeps its orientation, the tip speed is L1 omega everywhere
    assert s["speeds_m_s"]["max_speed_static_m_s"] == pytest.approx(0.254 * 2 * np.pi, rel=1e-6)
    assert s["speeds_m_s"]["min_speed_static_m_s"] == pytest.approx(0.254 * 2 * np.pi, rel=1e-6)
    assert s["convexity"]["gear2"]["convex"] is True
    # circles of 63.5 mm can be cut (module up to 2 r / 17.1 = 7.43 mm), the constant
    # 1.596 m/s tip speed breaks the seeding peak limit (1.5 m/s): exit 4 names it
    assert "seeding_peak_speed" in s["verdict"]["failed"]
    assert not any(n.startswith(("cuttable", "working_pressure")) for n in s["verdict"]["failed"])
    cut = {c["name"]: c["value"] for c in s["objectives"]}
    assert cut["cuttable_module_sun_gear2"] == pytest.approx(2 * 63.5 / 17.097, rel=1e-3)


@pytest.mark.parametrize("kwargs, expected", [
    (dict(r2="[60.0, 60.0, 60.0, 60.0]"), "do not close"),
    (dict(r2="[60.0, 60.0, -60.0, 60.0]"), "train.gear2.radii_mm.2"),
    (dict(angles="angles_deg = [0, 90, 80, 270]"), "must increase"),
    (dict(angles="angles_deg = [0, 150, 300, 400]"), "cross itself"),
    (dict(r2="[63.5, 63.5, nan, 63.5]"), "train.gear2.radii_mm.2"),
    (dict(closure="centre_distance", r2="[58.0, 63.5, 85.0, 63.5]", minr=55.0),
     "sun (gear 1): pitch radius"),
    (dict(closure="centre_distance", r2="[53.0, 63.5, 75.0, 63.5]", minr=55.0),
     "gear 2: pitch radius"),
])
def test_bad_trains_are_refused_with_the_place(tmp_path, capsys, kwargs, expected):
    rc = main(["forward", str(write(tmp_path, **kwargs)), "--out", str(tmp_path / "o"),
               "--no-plots"])
    assert rc == 2
    err = capsys.readouterr().err
    assert expected in err and "Traceback" not in err
    assert not (tmp_path / "o" / "summary.json").exists()
