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
from tests.conftest import EXAMPLES, gears_cut

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


# Both files are cut at --module 6 (gear 2 20 teeth at 6.0659 mm, gear 3 28 at P / (28 pi)):
# there the two code paths' gear files drive alike to 1e-6 deg. At the default modules (81
# and 169 teeth, docs/manufacturing.md) they do not yet: the sun - gear 2 transmission error
# 0.620 against 0.600 deg and the arm's not-held steps 403 against 460 (measured, left to the
# train engine's owners); tests/test_cli_verify.py and tests/test_teeth.py cut the default.
@pytest.fixture(scope="module")
def gears_dir(shared):
    return gears_cut(shared, "planetary-sugarcane_table4-module-6", PLANETARY, "--module", "6")


@pytest.fixture(scope="module")
def dedicated_gears_dir(shared):
    out, code = gears_cut(shared, "sugarcane_table4-module-6", DEDICATED, "--module", "6")
    assert code == 4
    return out


def test_gears_cut_the_seeders_teeth(gears_dir, dedicated_gears_dir):
    """The teeth of the dedicated file (``plantmech gears examples/sugarcane_table4.toml``,
    run here) at --module 6: gear 2 z = round(P / (6 pi)) = 20, the sun its partial mate;
    gear 3 and the planet z = round(P / (6 pi)) = 28; the same teeth and modules as the
    dedicated file's, each mesh's interference and free play as
    the dedicated file's. The general file names gear 2 "gear1" (shaft 1), gear 3 "gear1b"
    (the second gear on shaft 1). Not manufacturable, as the dedicated file: exit 4."""
    out, code = gears_dir
    assert code == 4
    rec = json.loads((out / "verification.json").read_text())
    ded = json.loads((dedicated_gears_dir / "verification.json").read_text())
    gears = {g["name"]: g for g in rec["gears"]}
    theirs_g = {g["name"]: g for g in ded["gears"]}
    for ours, their, m_std in (("gear1", "gear2", 6.0), ("gear1b", "gear3", 6.0)):
        z = round(gears[ours]["perimeter_mm"] / (m_std * np.pi))
        assert gears[ours]["teeth"] == theirs_g[their]["teeth"] == z
        assert gears[ours]["module_mm"] == pytest.approx(gears[ours]["perimeter_mm"]
                                                         / (z * np.pi), rel=1e-9)
        assert gears[ours]["module_mm"] == pytest.approx(theirs_g[their]["module_mm"],
                                                         abs=1e-4)
    assert (gears["gear1"]["teeth"], gears["gear1b"]["teeth"]) == (20, 28)
    assert gears["planet"]["teeth"] == theirs_g["planet"]["teeth"]
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
    through the dwell), the arm's attitude error and tip band; the loads through the dwell
    are written (its two impacts, finite figures, the energy balance met) and the exit
    code is the dedicated file's (4: its contact checks fail)."""
    import math

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
    loads = rec["loads"]
    assert "skipped" not in loads
    assert [i["carrier_angle_deg"] for i in loads["dwell_impacts"]] == [74.75, 119.75]

    def numbers(x):
        if isinstance(x, dict):
            return [v for y in x.values() for v in numbers(y)]
        if isinstance(x, list):
            return [v for y in x for v in numbers(y)]
        return [x] if isinstance(x, float) else []

    assert all(math.isfinite(v) for v in numbers(loads))
    checks = {c["name"]: c for c in rec["checks"]}
    assert checks["loads: energy balance error"]["ok"]
    assert (v / "loads.png").stat().st_size > 10_000
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
    assert checks["dwell: arm held (locked steps)"]["ok"] is False  # 49 of 90, as the seeder
    printed = capsys.readouterr().out
    assert "gear1 held" in printed and "dwell impact at carrier 74.75 deg" in printed


@pytest.fixture(scope="module")
def both_loads(gears_dir, dedicated_gears_dir):
    """The loads of the dedicated file (``loads.seeder_loads`` on its own gear files) and
    of the planetary file (``planetary.planetary_loads`` on its), 1440 steps."""
    from plantmech.contact.loads import LoadSpec, seeder_loads
    from plantmech.contact.outlines import read_gear_dxf
    from plantmech.contact.planetary import gear_file_names, planetary_loads
    from plantmech.contact.seeder import seeder_train
    from plantmech.mechanisms.seeder_forward import simulate

    train = seeder_train(load_design(DEDICATED))
    ded = {n: read_gear_dxf(dedicated_gears_dir / f"{n}.dxf", n)
           for n in ("gear2", "sun", "gear3", "planet")}
    ref = seeder_loads(train, simulate(train, samples=3600), ded, LoadSpec())
    design = load_design(PLANETARY)
    gen = {n: read_gear_dxf(gears_dir[0] / f"{n}.dxf", n) for n in gear_file_names(design)}
    return planetary_loads(design, gen, LoadSpec()), ref


def test_loads_through_the_dwell_are_the_dedicated_seeders(both_loads):
    """The general train's loads through the toothless dwell against the dedicated seeder's
    on Table 4 (each file on its own cut gears): the same bodies (masses and inertias), peak
    and rms input torque, mesh torques, tooth forces, energy balance (checked between the
    impacts), and each impact's kinetic-energy jump, drive work and peak torque.
    Tolerance 1e-5 relative (1e-4 J on the impacts): the two kinematic models differ by
    2e-8 mm at the tip and 1e-11 in the rates, the two cuts' planet masses by 3e-8, and the
    second pair's law is splined through different samples (the seeder's gear-2 angles at
    3600 carrier steps less the dwell's, the general train's 2048 gear angles); measured:
    6e-8 relative on the peaks, 2e-7 J on the impacts. Before: the seeder took gear 3's
    file frame as gear 2's (74.4 deg off on their shaft) and the planet's centroid on the
    arm line (inertias 1.2 % and 4.7 % off), and the general train splined the sun's law
    through 2048 samples instead of the seeder's 3600 (the peak torque at the dwell's start
    -629 instead of -375 N m: a rigid impact's peak is the interpolation's)."""
    gen, ref = both_loads
    rel = 1e-5

    def close(a, b):
        assert a == pytest.approx(b, rel=rel), (a, b)

    close(gen["masses_kg"]["gear1"], ref["masses_kg"]["gears_2_3"])
    close(gen["masses_kg"]["planet_arm"], ref["masses_kg"]["planet_arm_payload"])
    close(gen["inertias_kg_m2"]["gear1_about_centroid"],
          ref["inertias_kg_m2"]["gears_2_3_about_centroid"])
    close(gen["inertias_kg_m2"]["planet_arm_about_centroid"],
          ref["inertias_kg_m2"]["planet_arm_payload_about_com"])
    for key in ("min", "max", "rms"):
        close(gen["input_torque_N_m"]["carrier"][key], ref["input_torque_N_m"][key])
    close(gen["mesh_torque_N_m"]["sun_gear1"], ref["mesh_torque_N_m"]["sun_gear2"])
    close(gen["mesh_torque_N_m"]["gear1b_planet"], ref["mesh_torque_N_m"]["gear3_planet"])
    close(gen["tangential_tooth_force_N"]["sun_gear1_max"],
          ref["tangential_tooth_force_N"]["sun_gear2_max"])
    close(gen["tangential_tooth_force_N"]["gear1b_planet_max"],
          ref["tangential_tooth_force_N"]["gear3_planet_max"])
    eb, rb = gen["energy_balance"], ref["energy_balance"]
    assert eb["checked"] == rb["checked"]
    assert eb["max_error_fraction_of_energy_range"] == pytest.approx(
        rb["max_error_fraction_of_energy_range"], abs=1e-6)
    assert eb["max_error_fraction_of_energy_range"] < 0.01
    close(eb["energy_range_J"], rb["energy_range_J"])
    assert len(gen["dwell_impacts"]) == len(ref["dwell_impacts"]) == 2
    for a, b in zip(gen["dwell_impacts"], ref["dwell_impacts"], strict=True):
        assert a["carrier_angle_deg"] == b["carrier_angle_deg"]
        for key in ("kinetic_energy_jump_J", "energy_change_J", "drive_work_J",
                    "dissipated_J"):
            assert a[key] == pytest.approx(b[key], abs=1e-4), key
        close(a["peak_input_torque_N_m"], b["peak_input_torque_N_m"])
        # the drive's work across an impact covers the energy's change: what is left is
        # the integrator's damping of the unresolved jump, never a gain
        assert a["dissipated_J"] > 0.0


def test_loads_energy_is_the_kinematic_energy_of_the_cut_gears(both_loads, gears_dir):
    """An independent energy: the planetary file's motion (``trains``, 14,400 samples) and
    its gear files' outlines posed at their shafts by their body angles (plates of 12 mm
    steel: area, centroid and polar moment of each outline), the arm a 1 kg rod 498 mm long
    and the 0.5 kg payload at the tip; kinetic energy from the posed centroids' velocities
    and the bodies' angular rates (finite differences), potential from their heights. The
    solver's kinetic + potential energy change equals it to 1e-3 J (of a 21 J swing) more
    than 2 deg from the impacts; each impact's kinetic-energy jump to 1e-3 J."""
    from plantmech.contact.loads import G, LoadSpec, polygon_mass_properties
    from plantmech.contact.outlines import read_gear_dxf
    from plantmech.trains.gearing import built_train
    from plantmech.trains.model import simulate

    gen, _ = both_loads
    spec = LoadSpec()
    design = load_design(PLANETARY)
    built = built_train(design)
    n = 14400
    m = simulate(built, samples=n)
    carrier = m.carrier[0, 0]
    shafts = built.shafts[0] * 1e-3
    dt = (2 * np.pi / np.radians(spec.carrier_speed_deg_s)) / n

    def posed(name, shaft, body):
        g = read_gear_dxf(gears_dir[0] / f"{name}.dxf", name)
        mass, c, j = polygon_mass_properties(g.rings, spec.face_width_mm * 1e-3,
                                             spec.density_kg_m3)
        z = np.exp(1j * carrier) * (shaft + np.exp(1j * body) * complex(*c))
        return mass, j, z, carrier + body

    L = 0.498
    beta = m.arm_angle[0, 0]
    parts = [posed("gear1", shafts[1], m.gear_angles[1][0, 0]),
             posed("gear1b", shafts[1], m.driver_angles[1][0, 0]),
             posed("planet", shafts[2], m.gear_angles[2][0, 0]),
             (spec.arm_mass_kg, spec.arm_mass_kg * L**2 / 12,
              m.centre[0, 0] * 1e-3 + 0.5 * L * np.exp(1j * beta), beta),
             (spec.payload_kg, 0.0, m.tip[0, 0] * 1e-3, beta)]

    def rate(x):
        return np.gradient(x, dt, edge_order=2)

    ke = sum(0.5 * mass * np.abs(rate(z)) ** 2 + 0.5 * j * rate(a) ** 2
             for mass, j, z, a in parts)
    pe = sum(mass * G * z.imag for mass, _, z, _ in parts)
    s = gen["series"]
    psi = np.radians(s["carrier_angle_deg"])
    energy = np.interp(psi, m.carrier_angle, ke + pe, period=2 * np.pi)
    far = np.ones(len(psi), dtype=bool)
    for imp in gen["dwell_impacts"]:
        far &= np.abs(np.angle(np.exp(1j * (psi - np.radians(imp["carrier_angle_deg"]))))) \
            > np.radians(2.0)
    assert np.abs(s["energy_change_J"] - (energy - energy[0]))[far].max() < 1e-3
    kinetic = np.interp(psi, m.carrier_angle, ke, period=2 * np.pi)
    for imp in gen["dwell_impacts"]:
        d = np.angle(np.exp(1j * (psi - np.radians(imp["carrier_angle_deg"]))))
        before = np.flatnonzero(d < -np.radians(1.0))[np.argmax(d[d < -np.radians(1.0)])]
        after = np.flatnonzero(d > np.radians(1.0))[np.argmin(d[d > np.radians(1.0)])]
        assert imp["kinetic_energy_jump_J"] == pytest.approx(kinetic[after] - kinetic[before],
                                                             abs=1e-3)
    # the value of these gear files (--module 6; 2.199 J when gear 3 had 21 teeth at 8.03
    # mm: the gears' masses and inertias set it)
    assert abs(gen["dwell_impacts"][0]["kinetic_energy_jump_J"] - 2.173) < 0.01


def test_loads_of_two_arms_through_the_dwell(both_loads, gears_dir, tmp_path):
    """The same train with two arms (planets at 180 deg): each arm meets the sun's
    toothless arc, the second half a turn after the first (``trains``: the dwell is a
    region of the sun), so four impacts at 74.75, 119.75, 254.75 and 299.75 deg; what the
    drive's work leaves over at each (the integrator's damping of one arm's jump) is the
    one-arm train's at that end, and the balance between the impacts holds."""
    from plantmech.contact.loads import LoadSpec
    from plantmech.contact.outlines import read_gear_dxf
    from plantmech.contact.planetary import gear_file_names, planetary_loads

    one, _ = both_loads
    two = tmp_path / "two.toml"
    text = PLANETARY.read_text()
    assert "\narms = 1\n" in text
    two.write_text(text.replace("\narms = 1\n", "\narms = 2\n"))
    design = load_design(two)
    gears = {n: read_gear_dxf(gears_dir[0] / f"{n}.dxf", n) for n in gear_file_names(design)}
    loads = planetary_loads(design, gears, LoadSpec())
    impacts = loads["dwell_impacts"]
    assert [i["carrier_angle_deg"] for i in impacts] == [74.75, 119.75, 254.75, 299.75]
    for k, imp in enumerate(impacts):
        assert imp["dissipated_J"] == pytest.approx(one["dwell_impacts"][k % 2]["dissipated_J"],
                                                    abs=2e-3)
    assert loads["energy_balance"]["max_error_fraction_of_energy_range"] < 0.01


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
