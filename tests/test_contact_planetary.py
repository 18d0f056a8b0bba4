"""A general planetary train's gear files driven tooth on tooth (``contact/planetary.py``,
``plantmech verify`` on ``mechanism = "planetary"``): the rotary transplanter with three
identical ellipses. Independent expectations: the backlash the gears were cut with comes
back as the free play (circumferential backlash = band x the driven gear's contact
radius), the second arm repeats the first half a carrier turn later (fixed sun, planets at
180 deg), and a planet file turned by half a tooth jams and fails the verdict."""

import json

import numpy as np
import pytest

from plantmech.contact.outlines import read_gear_dxf
from plantmech.contact.planetary import analyse_planetary, gear_file_names, planetary_record
from plantmech.design import load_design
from plantmech.interfaces.cli import main
from tests.conftest import EXAMPLES, gears_cut

ELLIPTIC = EXAMPLES / "rotary_transplanter_elliptic.toml"
LIMITS = {"transmission_error_deg": 0.5, "attitude_error_deg": 1.0, "tip_band_mm": 5.0}
STEPS = 120


@pytest.fixture(scope="module")
def gear_dir(shared):
    # module 2: 25 teeth, an odd count, so the three ellipses are one gear turned (the
    # default, 2.5 mm, cuts 20: tests/test_modules.py)
    out, code = gears_cut(shared, "rotary_transplanter_elliptic-backlash-0.1-module-2",
                          ELLIPTIC, "--backlash", "0.1", "--module", "2")
    assert code == 0
    return out


@pytest.fixture(scope="module")
def design():
    return load_design(ELLIPTIC)


def _gears(design, gear_dir):
    return {n: read_gear_dxf(gear_dir / f"{n}.dxf", n) for n in gear_file_names(design)}


def test_the_cut_backlash_comes_back_as_free_play(design, gear_dir):
    from plantmech.trains.gearing import built_train
    from plantmech.trains.model import simulate

    assert gear_file_names(design) == ["sun", "idler1", "planet"]
    c = analyse_planetary(design, _gears(design, gear_dir), steps=STEPS)
    motion = simulate(built_train(design), samples=STEPS)
    for j in range(2):
        for k, fp in enumerate(c.pairs[j]):
            assert not fp.jammed.any() and np.isfinite(fp.lo).all() and np.isfinite(fp.hi).all()
            r_driven = motion.contact_radii[k][1][0, j]
            backlash = (fp.hi - fp.lo) * r_driven  # mm along the pitch curve
            assert 0.09 < np.median(backlash) < 0.115, np.median(backlash)
            # the law is met to a small fraction of the backlash: mid band within 0.02 deg
            assert np.abs(np.degrees(0.5 * (fp.lo + fp.hi))).max() < 0.02
    # the arm's play through the train holds the play of both meshes
    band = c.planet_hi - c.planet_lo
    assert (band >= (c.pairs[0][1].hi - c.pairs[0][1].lo)[None] - 1e-12).all()
    # arm 2 is arm 1 half a carrier turn later
    half = STEPS // 2
    assert np.allclose(np.roll(c.planet_lo[0], -half), c.planet_lo[1], atol=1e-6)
    assert np.allclose(np.roll(c.planet_hi[0], -half), c.planet_hi[1], atol=1e-6)
    rec = planetary_record(c, LIMITS)
    assert rec["ok"] and len(rec["pairs"]) == 4 and len(rec["arms"]) == 2
    # the tip band is the arm's chord over its play: 2 L sin(play / 2), the play's ends
    # symmetric about the law to within the small mid-band error
    L = float(design.arm.length_mm)
    ends = np.stack([c.planet_lo[0], c.planet_hi[0]])
    chord = 2 * L * np.sin(0.5 * (ends[1] - ends[0]))
    assert rec["arms"][0]["tip_band_mm"]["max"] == pytest.approx(chord.max(), rel=1e-9)
    assert rec["arms"][0]["tip_band_mm"]["max"] == pytest.approx(
        L * np.radians(2 * rec["arms"][0]["arm_attitude_error_deg"]["max_abs"]), rel=0.05)


def test_a_planet_turned_half_a_tooth_is_caught(design, gear_dir):
    gears = _gears(design, gear_dir)
    planet = gears["planet"]
    half_tooth = np.pi / planet.teeth  # 7.2 deg on 25 teeth
    gears["planet"] = planet.rotated(half_tooth)
    c = analyse_planetary(design, gears, steps=STEPS)
    rec = planetary_record(c, LIMITS)
    sun_idler, idler_planet = rec["pairs"][0], rec["pairs"][1]
    assert sun_idler["transmission_error_deg"]["max_abs_mid"] < 0.02  # untouched
    # the planet sits half a tooth off the law: its error is that half tooth
    te = idler_planet["transmission_error_deg"]["max_abs_mid"]
    assert te == pytest.approx(np.degrees(half_tooth), abs=0.5)
    assert not rec["ok"]
    failed = {ch["name"] for ch in rec["checks"] if not ch["ok"]}
    assert "transmission error, max |mid band|" in failed and "arm attitude error, max" in failed


def test_verify_command_on_a_planetary_train(gear_dir, tmp_path, capsys):
    out = tmp_path / "v"
    rc = main(["verify", str(ELLIPTIC), "--gears", str(gear_dir), "--out", str(out),
               "--steps", str(STEPS)])
    printed = capsys.readouterr().out
    assert rc == 0, printed
    rec = json.loads((out / "verification.json").read_text())
    assert rec["ok"] and rec["teeth_found_on_outlines"] == {"sun": 25, "idler1": 25,
                                                             "planet": 25}
    assert rec["loads"]["energy_balance"]["max_error_fraction_of_energy_range"] < 0.01
    assert set(rec["loads"]["mesh_torque_N_m"]) == {"sun_idler1_1", "idler1_planet_1",
                                                     "sun_idler1_2", "idler1_planet_2"}
    assert "loads: energy balance error" in [c["name"] for c in rec["checks"]]
    assert "idler1 -> planet (arm 2)" in printed and "input torque" in printed
    for png in ("transmission_error.png", "tip_band.png", "loads.png"):
        assert (out / png).stat().st_size > 10_000
    (tmp_path / "empty").mkdir()
    rc = main(["verify", str(ELLIPTIC), "--gears", str(tmp_path / "empty"), "--out",
               str(tmp_path / "o2")])
    assert rc == 2 and "sun.dxf: gear file not found" in capsys.readouterr().err


def test_loads_of_a_circular_train_are_its_weight(tmp_path):
    """Three equal circles (sun fixed, idler, planet), one arm: every gear turns at a
    constant rate and the planet only translates, so the kinetic energy is constant and
    the carrier's torque is the weight's alone: tau = g cos(phi) (m_idler a + m_planet+arm
    2 a), phi the carrier line's angle (a = 50 mm). The exudyn model of the general train
    (masses from the cut gear files) must give it."""
    from plantmech.contact.loads import G, LoadSpec
    from plantmech.contact.planetary import planetary_loads

    text = ELLIPTIC.read_text().replace("eccentricity = 0.18", "eccentricity = 0.0")
    text = text.replace("arms = 2 ", "arms = 1 ")
    circular = tmp_path / "circular.toml"
    circular.write_text(text)
    gears_dir = tmp_path / "g"
    assert main(["gears", str(circular), "--out", str(gears_dir)]) == 0
    design = load_design(circular)
    assert design.carrier.arms == 1
    loads = planetary_loads(design, _gears(design, gears_dir), LoadSpec(), samples=720,
                            steps=360)
    assert loads["energy_balance"]["max_error_fraction_of_energy_range"] < 1e-3
    m = loads["masses_kg"]
    a = 0.050
    psi = np.radians(loads["series"]["carrier_angle_deg"])
    phi = np.radians(design.carrier.initial_angle_deg) - psi  # clockwise
    expected = G * np.cos(phi) * (m["idler1"] * a + m["planet_arm"] * 2 * a)
    tau = loads["series"]["input_torque_carrier_N_m"]
    assert np.abs(tau - expected).max() < 0.01 * np.abs(expected).max()


def test_loads_of_the_khv_train_as_a_planetary_file_match_the_dedicated_model(shared):
    """Seed 001's K-H-V train written as a planetary file (examples/planetary/) and its
    dedicated model (contact/transplanter_loads.khv_loads), each on its own cut gear
    files: the same input torque and tooth forces within 1 % (the middle gears' masses
    differ by ~4 %: the two files are cut with different modules)."""
    from plantmech.contact.loads import LoadSpec
    from plantmech.contact.planetary import planetary_loads
    from plantmech.contact.transplanter_loads import khv_loads

    general = EXAMPLES / "planetary" / "rice_transplanter_khv.toml"
    dedicated = EXAMPLES / "rice_transplanter_khv.toml"
    # `plantmech gears` on each, once per test run (exit 4: undercut, files written; the
    # dedicated file's cut is the one tests/test_cli_verify.py verifies)
    g_dir, _ = gears_cut(shared, "planetary-rice_transplanter_khv", general)
    d_dir, _ = gears_cut(shared, "rice_transplanter_khv", dedicated)
    dg, dd = load_design(general), load_design(dedicated)
    a = planetary_loads(dg, _gears(dg, g_dir), LoadSpec(), samples=1440, steps=720)
    b = khv_loads(dd, {n: read_gear_dxf(d_dir / f"{n}.dxf", n)
                       for n in ("sun", "middle", "planet")}, LoadSpec(), samples=1440,
                  steps=720)
    ta, tb = a["input_torque_N_m"]["carrier"], b["input_torque_N_m"]["carrier"]
    span = tb["max"] - tb["min"]
    for key in ("min", "max", "rms"):
        assert abs(ta[key] - tb[key]) < 0.01 * span, (key, ta, tb)
    fa = sorted(a["tangential_tooth_force_N"].values())
    fb = sorted(b["tangential_tooth_force_N"].values())
    assert np.allclose(fa, fb, rtol=0.01)
