"""Every command on a planetary file with a toothless dwell (seed 000's Table 4 train,
examples/planetary/sugarcane_table4.toml) against the dedicated seeder file
(examples/sugarcane_table4.toml) through its own code: forward's numbers from
mechanisms/seeder_forward's motion, the teeth of `plantmech gears` from the seeder's
(mechanisms/gear_pairs: gear 2 cut from its lock point, the sun the partial gear), the
pitch-curve checks of `plantmech design`, `study`, `forward --report`, the app's scene;
`plantmech verify` against contact/seeder.py's analysis of the dedicated file's gears."""

from __future__ import annotations

import json

import numpy as np
import pytest

from plantmech.design import load_design
from plantmech.interfaces.cli import main
from tests.conftest import EXAMPLES

PLANETARY = EXAMPLES / "planetary" / "sugarcane_table4.toml"
DEDICATED = EXAMPLES / "sugarcane_table4.toml"


@pytest.fixture(scope="module")
def seeder_motion():
    from plantmech.mechanisms.seeder_forward import simulate
    from plantmech.workflows import train_from_design

    tr, _ = train_from_design(load_design(DEDICATED))
    return tr, simulate(tr, 3600)


def test_forward_objectives_are_the_seeder_motions(tmp_path, seeder_motion):
    """The general objectives of the planetary file computed independently from the
    dedicated model's motion (extent of the tip path, the arm's swing, the static tip
    speed at 360 deg/s)."""
    tr, ref = seeder_motion
    out = tmp_path / "o"
    assert main(["forward", str(PLANETARY), "--out", str(out)]) == 0
    s = json.loads((out / "summary.json").read_text())
    v = s["values"]
    assert v["path_width_mm"] == pytest.approx(np.ptp(ref.tip[:, 0]), abs=1e-6)
    assert v["path_height_mm"] == pytest.approx(np.ptp(ref.tip[:, 1]), abs=1e-6)
    assert v["attitude_range_deg"] == pytest.approx(np.degrees(np.ptp(ref.arm_angle)),
                                                    abs=1e-6)
    speed = ref.speed(360.0)
    assert v["max_tip_speed_m_s"] == pytest.approx(speed.max(), abs=1e-8)
    assert v["min_tip_speed_m_s"] == pytest.approx(speed.min(), abs=1e-8)
    assert v["loops"] == 1.0
    assert s["pairs"][0]["centre_distance_mm"] == pytest.approx(tr.a1, abs=1e-8)
    assert s["pairs"][1]["centre_distance_mm"] == pytest.approx(tr.a2, abs=1e-8)


def test_gear_one_is_cut_from_the_seeders_lock_point():
    """``trains.gearing`` cuts the dwell pair from gear 2's body angle at the lock (the
    contact where the dwell starts) as the seeder does (``seeder_forward.sun_rolling_start``,
    its own integration)."""
    from plantmech.mechanisms.seeder_forward import sun_rolling_start
    from plantmech.trains.spec import build_from_design
    from plantmech.workflows import train_from_design

    tr, _ = train_from_design(load_design(DEDICATED))
    built = build_from_design(load_design(PLANETARY))
    law, gap = built.laws[0], built.toothless[0]
    theta_lock = float(np.ravel(built.train.pairs[0].direction)[0]) - float(gap.lock[0, 0, 0])
    start = float(law.invert(np.array([[law.sense * theta_lock]]))[0, 0])
    expected = sun_rolling_start(tr)
    assert np.angle(np.exp(1j * (start - expected))) == pytest.approx(0.0, abs=1e-8)


@pytest.fixture(scope="module")
def gears_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("g") / "gears"
    code = main(["gears", str(PLANETARY), "--out", str(out)])
    return out, code


@pytest.fixture(scope="module")
def dedicated_gears_dir(tmp_path_factory):
    out = tmp_path_factory.mktemp("d") / "gears"
    assert main(["gears", str(DEDICATED), "--out", str(out)]) == 4
    return out


def test_gears_cut_the_seeders_teeth(gears_dir, dedicated_gears_dir):
    """The teeth of the dedicated file (``plantmech gears examples/sugarcane_table4.toml``,
    run here): gear 2 z = 20 at m = 6.0659 mm, the sun its partial mate with 20 teeth on its
    rolling arc; gear 3 and the planet z = 21 at m = 8.0265 mm; each mesh's interference and
    free play as the dedicated file's. The general file names gear 2 "gear1" (shaft 1),
    gear 3 "gear1b" (the second gear on shaft 1). Not manufacturable, as the dedicated file:
    exit 4."""
    out, code = gears_dir
    assert code == 4
    rec = json.loads((out / "verification.json").read_text())
    ded = json.loads((dedicated_gears_dir / "verification.json").read_text())
    gears = {g["name"]: g for g in rec["gears"]}
    assert gears["gear1"]["teeth"] == 20 and gears["sun"]["teeth"] == 20
    assert gears["gear1"]["module_mm"] == pytest.approx(6.0659, abs=1e-4)
    assert gears["gear1b"]["teeth"] == 21 and gears["planet"]["teeth"] == 21
    assert gears["gear1b"]["module_mm"] == pytest.approx(8.0265, abs=1e-4)
    mesh = {m["pair"]: m for m in rec["mesh"]}
    theirs = {m["pair"]: m for m in ded["mesh"]}
    for ours_name, their_name in (("gear1_sun", "gear2_sun"), ("gear1b_planet", "gear3_planet")):
        for key in ("max_interference_mm", "min_circumferential_backlash_mm",
                    "max_circumferential_backlash_mm"):
            assert mesh[ours_name][key] == pytest.approx(theirs[their_name][key], abs=1e-3), (
                ours_name, key)
    assert mesh["gear1_sun"]["max_interference_mm"] == pytest.approx(0.0, abs=1e-4)
    for name in ("gear1", "sun", "gear1b", "planet"):
        assert (out / f"{name}.dxf").exists()


def test_verify_drives_the_dwell_as_the_seeders_contact_analysis(gears_dir, tmp_path,
                                                                   capsys, dedicated_gears_dir):
    """`plantmech verify` through the dwell equals the dedicated seeder's contact analysis
    (contact/seeder.py on the dedicated file's own gear files): each pair's transmission
    error outside the dwell, gear 2 held by the sun's toothless arc (locked and jammed steps
    through the dwell), the arm's attitude error and tip band. The loads through the dwell
    (its impacts) are skipped with the field named."""
    from plantmech.contact.outlines import read_gear_dxf
    from plantmech.contact.seeder import analyse_seeder, seeder_record, seeder_train

    out, _ = gears_dir
    ded_dir = dedicated_gears_dir
    design = load_design(DEDICATED)
    gears = {n: read_gear_dxf(ded_dir / f"{n}.dxf", n) for n in ("gear2", "sun", "gear3",
                                                                  "planet")}
    limits = {"transmission_error_deg": 0.5, "attitude_error_deg": 1.0, "tip_band_mm": 5.0}
    contact = analyse_seeder(seeder_train(design), gears, steps=720)
    ref = seeder_record(contact, seeder_train(design), limits)
    v = tmp_path / "v"
    assert main(["verify", str(PLANETARY), "--gears", str(out), "--out", str(v)]) == 4
    rec = json.loads((v / "verification.json").read_text())
    assert "train.pairs.0.dwell" in rec["loads"]["skipped"]
    for ours, theirs in zip(rec["pairs"], ref["pairs"], strict=True):
        assert ours["transmission_error_deg"]["max_abs_mid"] == pytest.approx(
            theirs["transmission_error_deg"]["max_abs_mid"], abs=1e-3)
        assert ours["contact_lost_steps"] == theirs["contact_lost_steps"]
        assert ours["interference_steps"] == theirs["interference_steps"]
    for key in ("steps", "locked_steps", "jammed_steps"):
        assert rec["dwell"][key] == ref["dwell"][key], key
    assert rec["dwell"]["carrier_angle_deg"] == ref["dwell"]["carrier_angle_deg"]
    arm, chained = rec["arms"][0], ref["chained"]
    assert arm["arm_attitude_error_deg"]["max_abs"] == pytest.approx(
        chained["arm_attitude_error_deg"]["max_abs"], abs=1e-3)
    assert arm["tip_band_mm"]["max"] == pytest.approx(chained["tip_band_mm"]["max"], abs=0.01)
    # the seeder chains gear 2's play at 0 where it has none (a jam or no contact in the
    # dwell); the general train's chain (as the transplanters') counts those steps as the
    # arm not held
    d = ref["dwell"]
    assert arm["arm_not_held_steps"] == chained["arm_not_held_steps"] + d["steps"] \
        - d["locked_steps"]
    checks = {c["name"]: c for c in rec["checks"]}
    assert checks["dwell: arm held (locked steps)"]["ok"] is False  # 49 of 90, as the seeder
    assert "gear1 held" in capsys.readouterr().out


def test_design_judges_the_pitch_curves_as_the_seeder(tmp_path):
    """`plantmech design` (nothing freed: checked, not optimized): the pitch-curve checks
    the dedicated file fails (`plantmech forward examples/sugarcane_table4.toml`), with its
    values: the sun - gear 2 working pressure angle 50.53 deg, gear 3 - planet's 83.26 deg
    and its cuttable module 0.36 mm."""
    out = tmp_path / "d"
    assert main(["design", str(PLANETARY), "--out", str(out), "--quiet"]) == 4
    s = json.loads((out / "summary.json").read_text())
    rows = {o["name"]: o for o in s["final_checks"]}
    failed = sorted(n for n, o in rows.items() if not o["ok"])
    assert failed == ["cuttable_module_gear1b_planet", "working_pressure_angle_gear1b_planet",
                      "working_pressure_angle_sun_gear1"]
    assert rows["working_pressure_angle_sun_gear1"]["value"] == pytest.approx(50.5286, abs=0.01)
    assert rows["working_pressure_angle_gear1b_planet"]["value"] == pytest.approx(83.2593,
                                                                                 abs=0.01)
    # the module windows from each code's own sampling of the pitch curves (dedicated:
    # 0.3562 and 1.8503 mm)
    assert rows["cuttable_module_gear1b_planet"]["value"] == pytest.approx(0.3562, abs=0.005)
    assert rows["cuttable_module_sun_gear1"]["value"] == pytest.approx(1.8503, abs=0.01)


def test_forward_report_animates_the_dwell(tmp_path):
    out = tmp_path / "r"
    assert main(["forward", str(PLANETARY), "--out", str(out), "--report"]) == 0
    assert (out / "report.html").stat().st_size > 0 and (out / "mechanism.gif").exists()


def test_a_study_moves_the_dwell(tmp_path):
    """A tolerance study of the dwell's start and the arm: one population per chunk."""
    spec = tmp_path / "s.toml"
    spec.write_text('kind = "tolerance"\nsamples = 8\nchunk = 8\nseed = 0\n'
                    'cycle_samples = 360\n'
                    '[parameters."train.pairs.0.dwell.start_deg"]\n'
                    'distribution = "normal"\nsigma = 0.5\n'
                    '[parameters."arm.length_mm"]\ndistribution = "normal"\nsigma = 0.1\n')
    out = tmp_path / "st"
    assert main(["study", str(PLANETARY), "--spec", str(spec), "--out", str(out),
                 "--workers", "1", "--quiet", "--no-plots"]) == 0
    s = json.loads((out / "summary.json").read_text())
    assert s["samples"] == 8


def test_population_of_dwell_variants_equals_single_files():
    """Variants of the file moving the dwell's start (one structure, one population):
    each equals its own P = 1 run (to round-off: 1e-10 mm on a 700 mm path)."""
    from plantmech.trains.model import simulate
    from plantmech.trains.spec import build_from_design, build_from_designs

    d = load_design(PLANETARY)
    variants = []
    for start in (70.0, 74.75, 80.0):
        v = d.model_copy(deep=True)
        v.train.pairs[0].dwell.start_deg = start
        variants.append(v)
    many = simulate(build_from_designs(variants), 720)
    for k, v in enumerate(variants):
        one = simulate(build_from_design(v), 720)
        assert np.abs(one.tip[0] - many.tip[k]).max() < 1e-10
        assert np.abs(one.arm_angle[0] - many.arm_angle[k]).max() < 1e-12


def test_the_scene_draws_the_sun_touching_gear_one_through_the_dwell():
    """The app's drawing (``app.scene.planetary_scene``): in every frame, through the dwell
    too, the drawn sun and gear 1 touch (their placed pitch curves come within a
    fraction of a millimetre and do not cross by more)."""
    from plantmech.app.scene import planetary_scene
    from plantmech.trains.model import simulate
    from plantmech.trains.spec import build_from_design

    d = load_design(PLANETARY)
    scene = planetary_scene(d, simulate(build_from_design(d), 720), frames=72, detail=2880)
    g = {x["role"]: x for x in scene["gears"]}
    sun, gear1 = g["sun"], g["gear1"]

    def placed(gear, k):
        body = np.asarray(gear["body"], dtype=float) @ np.array([1.0, 1j])
        cx, cy = np.asarray(gear["centre"], dtype=float)[k]
        return complex(cx, cy) + body * np.exp(1j * np.asarray(gear["rot"], dtype=float)[k])

    frames = len(np.asarray(sun["rot"]))
    for k in range(frames):
        a, b = placed(sun, k), placed(gear1, k)
        gap = np.abs(a[:, None] - b[None, :]).min()
        assert gap < 0.2, (k, gap)
