"""``plantmech verify``: input errors name the file / field; on the gear files of a
shipped seeder example every figure is reported and the verdict is honest (exit 4 with
the failing checks located); a sun file turned by half a tooth is caught."""

import json
import shutil

import numpy as np
import pytest

from plantmech.interfaces.cli import main
from tests.conftest import EXAMPLES

SEEDER = EXAMPLES / "sugarcane_table4.toml"


@pytest.fixture(scope="module")
def gear_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("gears")
    main(["gears", str(SEEDER), "--out", str(out)])
    return out


def test_input_errors(tmp_path, capsys):
    rc = main(["verify", str(SEEDER), "--gears", str(tmp_path / "none"), "--out",
               str(tmp_path / "o")])
    assert rc == 2 and "--gears" in capsys.readouterr().err
    (tmp_path / "g").mkdir()
    rc = main(["verify", str(SEEDER), "--gears", str(tmp_path / "g"), "--out",
               str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert rc == 2 and "gear2.dxf: gear file not found" in err
    rc = main(["verify", str(EXAMPLES / "rice_transplanter.toml"), "--gears",
               str(tmp_path / "g"), "--out", str(tmp_path / "o")])
    assert rc == 2 and "field 'mechanism'" in capsys.readouterr().err
    rc = main(["verify", str(SEEDER), "--gears", str(tmp_path / "g"), "--out",
               str(tmp_path / "g")])
    assert rc == 2


def test_table4_gear_files_verified(gear_dir, tmp_path, capsys):
    out = tmp_path / "v"
    rc = main(["verify", str(SEEDER), "--gears", str(gear_dir), "--out", str(out),
               "--steps", "90"])
    rec = json.loads((out / "verification.json").read_text())
    assert rc == (0 if rec["ok"] else 4)
    assert {c["name"] for c in rec["checks"]} >= {
        "transmission error, max |mid band|", "arm attitude error, max", "tip band, max",
        "loads: energy balance error"}
    for p in rec["pairs"]:
        assert p["transmission_error_deg"]["max_abs_mid"] is not None
        assert p["backlash_band_deg"]["median"] > 0
    assert rec["chained"]["tip_band_mm"]["max"] > 0
    assert rec["loads"]["energy_balance"]["max_error_fraction_of_energy_range"] < 0.01
    assert "dwell" in rec  # Table 4 has a toothless dwell
    for png in ("transmission_error", "tip_band", "loads"):
        assert (out / f"{png}.png").stat().st_size > 10_000
    assert "transmission error" in capsys.readouterr().out


def test_sun_turned_by_half_a_tooth_fails(gear_dir, tmp_path, capsys):
    import ezdxf

    from plantmech.contact.outlines import read_gear_dxf

    bad = tmp_path / "bad"
    shutil.copytree(gear_dir, bad)
    sun = read_gear_dxf(bad / "sun.dxf")
    turn = np.pi / len(sun.tip_angles)
    doc = ezdxf.readfile(bad / "sun.dxf")
    c, s = np.cos(turn), np.sin(turn)
    for e in doc.modelspace().query("LWPOLYLINE"):
        pts = np.asarray(e.get_points("xy"))
        e.set_points(np.c_[c * pts[:, 0] - s * pts[:, 1], s * pts[:, 0] + c * pts[:, 1]],
                     format="xy")
    doc.saveas(bad / "sun.dxf")
    out = tmp_path / "v"
    rc = main(["verify", str(SEEDER), "--gears", str(bad), "--out", str(out), "--steps",
               "90", "--no-loads", "--no-plots"])
    assert rc == 4
    rec = json.loads((out / "verification.json").read_text())
    p1 = rec["pairs"][0]
    # gear 2 sits about half a sun tooth off: its TE is of the order of the sun's half
    # tooth angle x the ratio, far above the limit, and the check says so
    assert p1["transmission_error_deg"]["max_abs_mid"] > 1.0
    te = next(c for c in rec["checks"] if c["name"].startswith("transmission error"))
    assert te["ok"] is False
    assert "FAIL transmission error" in capsys.readouterr().out
