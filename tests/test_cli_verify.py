"""``plantmech verify``: input errors name the file / field; on the gear files of a
shipped seeder example every figure is reported and the verdict is honest (exit 4 with
the failing checks located); a sun file turned by half a tooth is caught."""

import json
import shutil

import numpy as np
import pytest

from plantmech.interfaces.cli import main
from tests.conftest import EXAMPLES, gears_cut

SEEDER = EXAMPLES / "sugarcane_table4.toml"
TRANSPLANTER = EXAMPLES / "rice_transplanter_manufacturable.toml"
KHV = EXAMPLES / "rice_transplanter_khv.toml"


@pytest.fixture(scope="module")
def gear_dir(shared):
    # at --module 6 (20 teeth a gear, the former default): the checks here do not depend on
    # the module, and the folder is test_cli_planetary_dwell's, cut once per run (the
    # default, ~140 teeth a gear at a standard 1.5 mm, is tested by tests/test_modules.py)
    return gears_cut(shared, "sugarcane_table4-module-6", SEEDER, "--module", "6")[0]


def test_input_errors(tmp_path, capsys):
    rc = main(["verify", str(SEEDER), "--gears", str(tmp_path / "none"), "--out",
               str(tmp_path / "o")])
    assert rc == 2 and "--gears" in capsys.readouterr().err
    (tmp_path / "g").mkdir()
    rc = main(["verify", str(SEEDER), "--gears", str(tmp_path / "g"), "--out",
               str(tmp_path / "o")])
    err = capsys.readouterr().err
    assert rc == 2 and "gear2.dxf: gear file not found" in err
    rc = main(["verify", str(KHV), "--gears", str(tmp_path / "g"), "--out",
               str(tmp_path / "o")])
    assert rc == 2 and "sun.dxf: gear file not found" in capsys.readouterr().err
    rc = main(["verify", str(TRANSPLANTER), "--gears", str(tmp_path / "g"), "--out",
               str(tmp_path / "o")])
    assert rc == 2 and "internal.dxf: gear file not found" in capsys.readouterr().err
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
    # the seeder's strength table (contact/strength.seeder_contacts): every gear rated,
    # never in the dwell (the locking arcs) nor within 3 deg of its impacts, said so
    st = rec["strength"]
    assert [g["gear"] for g in st["gears"]] == ["gear2", "sun", "planet", "gear3"]
    impacts = [i["carrier_angle_deg"] for i in rec["loads"]["dwell_impacts"]]
    assert impacts == [74.75, 119.75]
    for g in st["gears"]:
        for kind in ("root", "flank"):
            w = g[kind]
            assert w["stress_MPa"] > 0 and 1 <= w["tooth"] <= g["teeth"]
            assert w["safety"] == pytest.approx(w["limit_MPa"] / w["stress_MPa"], rel=2e-3)
            assert all(abs(w["carrier_angle_deg"] - c) > 3.0 for c in impacts)
            if g["gear"] in ("gear2", "sun"):
                assert not 74.75 <= w["carrier_angle_deg"] <= 119.75
    # at module 6 the planet's sharpest span is a replacement gear of ~1 tooth: its root
    # is not rated there (ISO 6336-3's form factors do not hold), said, never a number
    assert len(st["not_rated"]) == 4 and "toothless dwell" in st["not_rated"][2]
    assert st["not_rated"][3].startswith("planet root: ")
    assert "fewer than 5 teeth" in st["not_rated"][3]
    (shaft,) = st["shafts"]
    assert shaft["gear"] == "planet" and shaft["overhang_mm"] == st["face_width_mm"]
    assert shaft["overhang_source"] == "default"
    assert any("taken from the default" in c for c in rec["verdict"]["caveats"])
    assert "strength: gear2 flank safety" in {c["name"] for c in rec["checks"]}
    # the overhang given: the shaft bent over it, said so (no default caveat)
    out2 = tmp_path / "v2"
    main(["verify", str(SEEDER), "--gears", str(gear_dir), "--out", str(out2), "--steps",
          "36", "--no-plots", "--shaft-overhang", "6"])
    rec2 = json.loads((out2 / "verification.json").read_text())
    (sh2,) = rec2["strength"]["shafts"]
    assert (sh2["overhang_mm"], sh2["overhang_source"]) == (6.0, "option")
    assert sh2["bending_MPa"] == pytest.approx(shaft["bending_MPa"] / 2, rel=0.02)
    assert not any("taken from the default" in c for c in rec2["verdict"]["caveats"])
    assert any("from --shaft-overhang" in c for c in rec2["verdict"]["caveats"])
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


@pytest.fixture(params=["module-6", "default-module"])
def toothless_gear_dir(request, shared):
    """The Table 4 gears at --module 6 (20 teeth a gear) and at the default standard
    module (1.5 mm on the sun, 81 teeth: tests/test_teeth.py's shared cut)."""
    if request.param == "module-6":
        return request.getfixturevalue("gear_dir")
    out, code = gears_cut(shared, "sugarcane_table4", SEEDER)
    assert code in (0, 4) and (out / "sun.dxf").is_file()  # written (4: with findings)
    return out


def test_sun_toothless_arc_is_where_the_train_dwells(toothless_gear_dir):
    """The sun's uncut (locking) arc on the written outline sits where gear 2 is held.
    Frame-free: the sun's pitch radius along its rolling arc, measured from the middle of
    the outline's toothless gap, must be the design's a1 - r2 rolled from gear 2's body
    angle in the dwell (the forward model's, integrated here by the trapezoid rule). With
    the gap placed at gear 2's theta0 instead, this profile was 43 deg off (8.6 mm rms).
    At any module: at 1.5 mm (83 tips, pitch 0.066 rad) the outline reader once found a
    tooth 0.04 mm high in the middle of the 0.72 rad locking arc, which split the gap
    (0.617 rad against theta1 - pitch = 0.720); the teeth found are now all on the rolling
    arc, the gap 0.728 rad."""
    gear_dir = toothless_gear_dir
    from plantmech.contact.outlines import read_gear_dxf
    from plantmech.design import load_design
    from plantmech.mechanisms.seeder_forward import simulate
    from plantmech.workflows import train_from_design

    tr, _ = train_from_design(load_design(SEEDER))
    f = simulate(tr, samples=7200)
    g_d = tr.gear2_contact0 + f.gear2_angle[f.in_dwell][0]  # gear 2 held here
    theta1 = tr.dwell_theta1
    # the sun's rolling arc: contact body angle -integral r2 / (a1 - r2) from g_d
    th = np.linspace(0.0, 2 * np.pi, 20001)
    r2 = tr.gear2(g_d + th)
    rate = r2 / (tr.a1 - r2)
    beta = -np.r_[0.0, np.cumsum(0.5 * (rate[1:] + rate[:-1]) * np.diff(th))]
    assert abs(beta[-1] + (2 * np.pi - theta1)) < 1e-3  # the pair closes over 360 - theta1
    # the gap lies between the arc's end and its start (body angle 0): centre theta1 / 2
    v_exp, r_exp = beta - theta1 / 2, tr.a1 - r2

    sun = read_gear_dxf(gear_dir / "sun.dxf", "sun")
    tips = np.sort(sun.tip_angles)
    gaps = np.diff(np.r_[tips, tips[0] + 2 * np.pi])
    k = int(np.argmax(gaps))
    pitch = float(np.median(gaps))
    # the toothless arc spans the dwell's carrier turn theta1 (the sun is fixed, gear 2
    # held): tip to tip, theta1 less about one tooth (the teeth at its ends)
    assert abs(gaps[k] - (theta1 - pitch)) < 0.5 * pitch
    centre = tips[k] + gaps[k] / 2
    # measured: the outline's radius averaged over one tooth angle, against body angle
    ang = np.mod(np.arctan2(sun.ring[:, 1], sun.ring[:, 0]), 2 * np.pi)
    o = np.argsort(ang)
    fine = np.radians(np.arange(0.0, 360.0, 0.05))
    rf = np.interp(fine, ang[o], np.hypot(*sun.ring[o].T), period=2 * np.pi)
    w = int(round(pitch / np.radians(0.05)))
    smooth = np.convolve(np.r_[rf[-w:], rf, rf[:w]], np.ones(w) / w, mode="same")[w:-w]
    # away from the gap's ends (20 deg), up to a constant (tooth shape) offset
    inner = (v_exp < -np.radians(20)) & (v_exp > -2 * np.pi + theta1 + np.radians(20))

    def misfit(shift):
        meas = np.interp(np.mod(centre + v_exp[inner] + shift, 2 * np.pi), fine, smooth,
                         period=2 * np.pi)
        return float(np.std(meas - r_exp[inner]))

    shifts = np.radians(np.arange(-90.0, 90.01, 0.25))
    best = shifts[int(np.argmin([misfit(s) for s in shifts]))]
    assert abs(np.degrees(best)) <= 2.0
    assert misfit(0.0) < 1.5  # mm (the radius varies 53-74 mm along the arc)


def test_loads_not_computed_without_the_extra(gear_dir, tmp_path, capsys, monkeypatch):
    """Without plantmech[loads] (exudyn) the contact is still checked, the loads are
    recorded as not computed with the pip line, and the verdict is not met (exit 4)."""
    from plantmech import extras

    monkeypatch.setitem(extras.EXTRAS, "loads", ("plantmech_no_such_module",))
    out = tmp_path / "v"
    rc = main(["verify", str(SEEDER), "--gears", str(gear_dir), "--out", str(out),
               "--steps", "90"])
    rec = json.loads((out / "verification.json").read_text())
    printed = capsys.readouterr().out
    assert rc == 4 and rec["ok"] is False
    assert "pip install 'plantmech[loads]'" in rec["loads"]["not_computed"]
    check = next(c for c in rec["checks"] if c["name"] == "loads: energy balance error")
    assert check["value"] is None and not check["ok"] and "not computed" in check["note"]
    assert "loads not computed" in printed and "FAIL loads: energy balance error" in printed
    assert rec["pairs"] and not (out / "loads.png").exists()


@pytest.fixture(scope="module")
def transplanter_gear_dir(shared):
    out, code = gears_cut(shared, "rice_transplanter_manufacturable", TRANSPLANTER)
    assert code == 0
    return out


def test_transplanter_gear_files_verified(transplanter_gear_dir, tmp_path, capsys):
    """The shipped manufacturable transplanter's gear files (internal gear, planet),
    every arm's planet driven by the internal gear: every figure reported per arm, the
    verdict honest; the planet file turned by half a tooth fails on every arm."""
    out = tmp_path / "v"
    rc = main(["verify", str(TRANSPLANTER), "--gears", str(transplanter_gear_dir), "--out",
               str(out), "--steps", "72"])
    rec = json.loads((out / "verification.json").read_text())
    assert rc == (0 if rec["ok"] else 4)
    assert len(rec["pairs"]) == 3 and len(rec["arms"]) == 3
    for p, a in zip(rec["pairs"], rec["arms"], strict=True):
        assert p["transmission_error_deg"]["max_abs_mid"] is not None
        assert p["backlash_band_deg"]["median"] > 0
        assert a["tip_band_mm"]["max"] > 0
    assert rec["teeth_found_on_outlines"]["internal"] >= 60
    # the loads of both drives (exudyn), cross-checked by the energy balance
    assert rec["loads"]["energy_balance"]["max_error_fraction_of_energy_range"] < 0.01
    assert set(rec["loads"]["input_torque_N_m"]) >= {"carrier", "internal"}
    assert len(rec["loads"]["tangential_tooth_force_N"]) == 3
    assert "loads: energy balance error" in {c["name"] for c in rec["checks"]}
    for png in ("transmission_error", "tip_band", "loads"):
        assert (out / f"{png}.png").stat().st_size > 10_000
    printed = capsys.readouterr().out
    assert "internal -> planet (arm 3)" in printed
    # the strength table: per gear the worst root and flank stress with its place, the shaft
    st = rec["strength"]
    assert [g["gear"] for g in st["gears"]] == ["planet", "internal"]
    for g in st["gears"]:
        for kind in ("root", "flank"):
            w = g[kind]
            assert w["stress_MPa"] > 0 and w["arm"] in (1, 2, 3)
            assert 1 <= w["tooth"] <= g["teeth"] and 0 <= w["carrier_angle_deg"] < 360
            assert w["safety"] == pytest.approx(w["limit_MPa"] / w["stress_MPa"], rel=2e-3)
            assert f"{g['gear']:<9} {kind:<5}" in printed
    (shaft,) = st["shafts"]
    assert shaft["gear"] == "planet" and shaft["diameter_mm"] > 3 and shaft["wall_mm"] > 0
    assert shaft["torque_N_m"] > 0 and "planet shaft d" in printed
    names = {c["name"] for c in rec["checks"]}
    assert {"strength: planet root safety", "strength: planet shaft safety"} <= names
    # the planet's bore shrunk to 3 mm under the same loads: a finding
    from plantmech.contact.strength import MATERIALS, shaft_rating

    row, checks, found = shaft_rating("planet", 3.0, shaft["torque_N_m"],
                                      shaft["normal_force_N"], st["shaft_overhang"],
                                      MATERIALS["steel"], None)
    assert row["safety"] < 1 and found[0]["check"] == "shaft_strength"
    assert not checks[0]["ok"]

    from plantmech.contact.outlines import read_gear_dxf

    bad = tmp_path / "bad"
    shutil.copytree(transplanter_gear_dir, bad)
    planet = read_gear_dxf(bad / "planet.dxf")
    _turn_dxf(bad / "planet.dxf", np.pi / planet.teeth)
    rc = main(["verify", str(TRANSPLANTER), "--gears", str(bad), "--out",
               str(tmp_path / "v2"), "--steps", "36", "--no-plots", "--no-loads"])
    assert rc == 4
    rec = json.loads((tmp_path / "v2" / "verification.json").read_text())
    for p in rec["pairs"]:
        # each planet sits about half its tooth angle off the pitch-curve law
        assert p["transmission_error_deg"]["max_abs_mid"] > 0.5 * 180.0 / planet.teeth
    assert "FAIL transmission error" in capsys.readouterr().out


def _turn_dxf(path, turn: float) -> None:
    import ezdxf

    doc = ezdxf.readfile(path)
    c, s = np.cos(turn), np.sin(turn)
    for e in doc.modelspace().query("LWPOLYLINE"):
        pts = np.asarray(e.get_points("xy"))
        e.set_points(np.c_[c * pts[:, 0] - s * pts[:, 1], s * pts[:, 0] + c * pts[:, 1]],
                     format="xy")
    doc.saveas(path)


@pytest.fixture(scope="module")
def khv_gear_dir(shared):
    out, code = gears_cut(shared, "rice_transplanter_khv", KHV)
    # the illustrative K-H-V example is not manufacturable (undercut teeth: exit 4), its
    # gear files are written all the same
    assert code == 4
    return out


def test_khv_gear_files_verified(khv_gear_dir, tmp_path, capsys):
    """The K-H-V example's gear files (sun, middle, planet), each arm's middle driven by
    the sun and its planet by the middle: both pairs of both arms follow the pitch-curve
    law (the files' body frames are the ones the analysis assumes: no tooth on tooth at
    the reference pose), every figure reported per pair and arm; the middle file turned
    by half a tooth fails and says where."""
    out = tmp_path / "v"
    rc = main(["verify", str(KHV), "--gears", str(khv_gear_dir), "--out", str(out),
               "--steps", "72"])
    rec = json.loads((out / "verification.json").read_text())
    assert rc == (0 if rec["ok"] else 4)
    assert [p["pair"] for p in rec["pairs"]] == [
        "sun -> middle (arm 1)", "middle -> planet (arm 1)", "sun -> middle (arm 2)",
        "middle -> planet (arm 2)"]
    for p in rec["pairs"]:
        assert p["reference_overlap_steps"] == 0 and p["interference_steps"] == 0
        # well inside the free play (cut backlash 0.1 mm over ~20-36 mm pitch radii:
        # 0.15-0.3 deg)
        assert p["transmission_error_deg"]["max_abs_mid"] < 0.05
        assert 0.1 < p["backlash_band_deg"]["median"] < 0.35
    for a in rec["arms"]:
        assert a["arm_not_held_steps"] == 0 and 0 < a["tip_band_mm"]["max"] < 5
    assert rec["teeth_found_on_outlines"] == {"sun": 20, "middle": 20, "planet": 20}
    assert rec["loads"]["energy_balance"]["max_error_fraction_of_energy_range"] < 0.01
    assert len(rec["loads"]["tangential_tooth_force_N"]) == 4  # 2 pairs x 2 arms
    # the strength table: every gear of both pairs, the sun's worst tooth located
    rows = {g["gear"]: g for g in rec["strength"]["gears"]}
    assert set(rows) == {"sun", "middle", "planet"}
    assert 1 <= rows["sun"]["flank"]["tooth"] <= 20
    assert all(rows[g][k]["safety"] > 0 for g in rows for k in ("root", "flank"))
    assert rec["ok"] and rc == 0
    for png in ("transmission_error", "tip_band", "loads"):
        assert (out / f"{png}.png").stat().st_size > 10_000
    assert "middle -> planet (arm 2)" in capsys.readouterr().out

    from plantmech.contact.outlines import read_gear_dxf

    bad = tmp_path / "bad"
    shutil.copytree(khv_gear_dir, bad)
    middle = read_gear_dxf(bad / "middle.dxf")
    _turn_dxf(bad / "middle.dxf", np.pi / middle.teeth)
    rc = main(["verify", str(KHV), "--gears", str(bad), "--out", str(tmp_path / "v2"),
               "--steps", "36", "--no-plots", "--no-loads"])
    assert rc == 4
    rec = json.loads((tmp_path / "v2" / "verification.json").read_text())
    for p in rec["pairs"]:
        # the middle sits about half its tooth angle off the sun's law; the planet, driven
        # by the middle at its nominal angle, half a tooth off too
        te = p["transmission_error_deg"]
        assert te["max_abs_mid"] > 0.5 * 180.0 / middle.teeth
        assert p["reference_overlap_steps"] == 36
        assert te["max_abs_mid_at"][f"{p['driven']}_tooth"] >= 1
    out = capsys.readouterr().out
    assert "FAIL transmission error" in out
    assert "sun -> middle (arm 1): transmission error max |mid|" in out
    assert "middle tooth" in out  # located: carrier angle and the middle's tooth


def test_khv_design_without_a_train_is_input_error(khv_gear_dir, tmp_path, capsys):
    """A sun whose pitch curve cannot be built (radii under 1 mm): exit 2 naming the
    section, no traceback."""
    text = KHV.read_text().replace("radii_mm = [36.4, 33.94, 28.0, 22.06, 19.6, 22.06, 28.0, "
                                   "33.94]", "radii_mm = [0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, "
                                   "0.5]")
    assert "0.5, 0.5" in text
    bad = tmp_path / "khv_tiny.toml"
    bad.write_text(text)
    rc = main(["verify", str(bad), "--gears", str(khv_gear_dir), "--out",
               str(tmp_path / "v"), "--no-plots"])
    err = capsys.readouterr().err
    assert rc == 2 and "[sun_gear]" in err and "sun pitch radius" in err
