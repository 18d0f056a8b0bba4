"""`plantmech gears` and `verify` on the general file that `plantmech inverse` writes from
examples/planetary/sugarcane_seeder_dwell_inverse.toml (seed 000's trajectory inverse
design with the sun's toothless dwell: gears 2 and 3 open curves breaking at the lock)
against the dedicated file examples/sugarcane_seeder_dwell.toml through its own code
(`plantmech gears` run here), as tests/test_cli_planetary_dwell.py does for Table 4.

What is the same and what is not (docs/architecture.md, "Train model"): both cut gear 2
from its lock point over one open turn (the last radius its left limit) and the sun as its
partial mate, so gear 2 and the sun get the same tooth counts and the same pitch-curve
findings; the module and gear 3's counts differ because gears/teeth resamples a closed
polyline through the break's 18.9 mm step by a periodic spline whose result depends on
where the gear's body frame puts the break (the general file: at body angle 0, which
gives gear 2's perimeter within 0.14 mm of its exact length, 425.32 mm, arc plus step;
the dedicated file's frame 4.0 mm above it)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from plantmech.interfaces.cli import main
from tests.conftest import EXAMPLES, gears_cut

INVERSE = EXAMPLES / "planetary" / "sugarcane_seeder_dwell_inverse.toml"
DEDICATED = EXAMPLES / "sugarcane_seeder_dwell.toml"


@pytest.fixture(scope="module")
def written(shared):
    """``plantmech inverse`` on the planetary dwell file, once per test run (conftest.Shared):
    the design file it writes."""
    out, code = shared.dir("inverse-sugarcane_seeder_dwell_inverse", lambda p: main(
        ["inverse", str(INVERSE), "--out", str(p / "o"), "--no-plots"]))
    # exit 4: gear 2 cannot lock in this dwell (dwell_lock_radius_jump_mm, 18.9 mm)
    assert code == 4
    return out / "o" / "design.toml"


@pytest.fixture(scope="module")
def gears_dirs(shared, written):
    # --module 6, the module these comparisons were made at (the default module before
    # gears.modules.choose_teeth; the default now keeps the design's 1 mm: some 135 teeth)
    ours, code = gears_cut(shared, "written-sugarcane_seeder_dwell_inverse-module-6", written,
                           "--module", "6")
    theirs, their_code = gears_cut(shared, "sugarcane_seeder_dwell-module-6", DEDICATED,
                                   "--module", "6")
    assert their_code == 4
    return ours, theirs, code


def _record(path):
    return json.loads((path / "verification.json").read_text())


def test_gears_cut_gear_two_and_the_sun_as_the_dedicated_file(gears_dirs):
    """Gear 2 (the general file's "gear1") z = 23 and the sun z = 22, as the dedicated
    file; the module within 1 % (5.8843 against 5.9353 mm: the perimeters, module
    docstring); the sun - gear 2 mesh free of interference in both, its least free play
    within 0.01 mm and its largest (the sun's toothless arc) within 0.2 mm. Not
    manufacturable in both: exit 4."""
    ours, theirs, code = gears_dirs
    assert code == 4
    rec, ded = _record(ours), _record(theirs)
    g = {x["name"]: x for x in rec["gears"]}
    t = {x["name"]: x for x in ded["gears"]}
    assert g["gear1"]["teeth"] == t["gear2"]["teeth"] == 23
    assert g["sun"]["teeth"] == t["sun"]["teeth"] == 22
    assert g["gear1"]["module_mm"] == pytest.approx(t["gear2"]["module_mm"], rel=0.01)
    assert g["gear1"]["module_mm"] * 23 * np.pi == pytest.approx(425.32, abs=0.2)
    mesh = {m["pair"]: m for m in rec["mesh"]}["gear1_sun"]
    their = {m["pair"]: m for m in ded["mesh"]}["gear2_sun"]
    assert mesh["max_interference_mm"] == their["max_interference_mm"] == 0.0
    assert mesh["min_circumferential_backlash_mm"] == pytest.approx(
        their["min_circumferential_backlash_mm"], abs=0.01)
    assert mesh["max_circumferential_backlash_mm"] == pytest.approx(
        their["max_circumferential_backlash_mm"], abs=0.2)
    for name in ("gear1", "sun", "gear1b", "planet"):
        assert (ours / f"{name}.dxf").exists()


def test_pitch_curve_findings_are_the_dedicated_files(gears_dirs):
    """The pitch-curve rules fail where the dedicated file's do, with its values: the
    working pressure angle of sun - gear 2 (102.0 deg) and gear 3 - planet (107.1 deg), and
    both pairs' cuttable module (far below 1 mm: concave spans)."""
    ours, theirs, _ = gears_dirs
    rec, ded = _record(ours), _record(theirs)
    mine = {(f["gear"], f["check"]): f for f in rec["findings"]
            if "pair " in f.get("why", "")}
    pitch = {f["check"]: f for f in ded["findings"] if f["gear"] == "pitch curves"}
    for ours_key, their_key, tol in (
            (("gear1", "working_pressure_angle"), "working_pressure_angle_sun_gear2", 0.2),
            (("gear1b", "working_pressure_angle"), "working_pressure_angle_gear3_planet", 0.2),
            (("sun", "cuttable_module"), "cuttable_module_sun_gear2", 0.01),
            (("gear1b", "cuttable_module"), "cuttable_module_gear3_planet", 0.01)):
        assert mine[ours_key]["value"] == pytest.approx(pitch[their_key]["value"], abs=tol), \
            ours_key
    # the per-gear checks of the cut outlines name the same gears and rules on gear 2 and
    # the sun
    kinds = {(f["gear"], f["check"]) for f in rec["findings"]}
    theirs_kinds = {(f["gear"].replace("gear2", "gear1"), f["check"])
                    for f in ded["findings"]}
    for gear in ("gear1", "sun"):
        assert {k for k in kinds if k[0] == gear and "pair " not in k[1]} >= {
            k for k in theirs_kinds if k[0] == gear and k[1] != "pointed_teeth"}


def test_verify_drives_the_dwell_of_the_written_file(gears_dirs, written, tmp_path):
    """`plantmech verify` on the written file and its gears: the first pair's dwell over
    the dedicated design's carrier angles (75.0-126.0 deg at 0.5 deg steps: 103 steps,
    as `plantmech verify` on the dedicated file gives); the loads through it computed with
    its two ends as impacts (finite figures, the energy balance met between them); not met
    (exit 4), as the dedicated file's."""
    ours, _, _ = gears_dirs
    v = tmp_path / "v"
    assert main(["verify", str(written), "--gears", str(ours), "--out", str(v)]) == 4
    rec = json.loads((v / "verification.json").read_text())
    loads = rec["loads"]
    assert "skipped" not in loads
    starts = [i["carrier_angle_deg"] for i in loads["dwell_impacts"]]
    assert len(starts) == 2
    assert abs(starts[0] - 75.0) <= 0.5 and abs(starts[1] - 126.0) <= 0.5, starts
    assert all(math.isfinite(x) for i in loads["dwell_impacts"] for x in i.values()
               if isinstance(x, float))
    assert {c["name"]: c for c in rec["checks"]}["loads: energy balance error"]["ok"]
    assert rec["dwell"]["steps"] == 103
    assert rec["dwell"]["carrier_angle_deg"] == [75.0, 126.0]
    assert rec["dwell"]["jammed_steps"] == 0


def test_the_scene_draws_the_sun_touching_gear_one_through_the_dwell(written):
    """The app's drawing of the written file: the derived sun (its rolling arc the mate of
    gear 2's open turn, its toothless arc at the lock radius) and gear 2 touch in every
    frame, through the dwell too (within 0.2 mm, as the Table 4 file's)."""
    from plantmech.app.scene import planetary_scene
    from plantmech.design import load_design
    from plantmech.trains.model import simulate
    from plantmech.trains.spec import build_from_design

    d = load_design(written)
    built = build_from_design(d)
    assert np.isfinite(built.drivers[0].r).all()
    scene = planetary_scene(d, simulate(built, 720), frames=72, detail=2880)
    g = {x["role"]: x for x in scene["gears"]}

    def placed(gear, k):
        body = np.asarray(gear["body"], dtype=float) @ np.array([1.0, 1j])
        cx, cy = np.asarray(gear["centre"], dtype=float)[k]
        return complex(cx, cy) + body * np.exp(1j * np.asarray(gear["rot"], dtype=float)[k])

    for k in range(len(np.asarray(g["sun"]["rot"]))):
        gap = np.abs(placed(g["sun"], k)[:, None] - placed(g["gear1"], k)[None, :]).min()
        assert gap < 0.2, (k, gap)


def test_the_written_break_moved_off_the_lock_exits_2(written, tmp_path, capsys):
    """Gear 3 turned 1 deg on gear 2's shaft: its break no longer meets the planet where
    the dwell starts (it would be rolled across while the teeth mesh): exit 2 naming it."""
    import tomllib

    import tomli_w

    doc = tomllib.loads(written.read_text())
    doc["train"]["pairs"][1]["driver"]["phase_deg"] += 1.0
    path = tmp_path / "moved.toml"
    path.write_text(tomli_w.dumps(doc))
    assert main(["forward", str(path), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "train.pairs.1.driver.open" in err and "break" in err, err
