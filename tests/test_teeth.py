import numpy as np
import pytest
import shapely

from plantmech.gears.teeth import (
    PitchPolyline,
    ToothSpec,
    cut_gear,
    gear_checks,
    make_pair,
    mesh_check,
    spur_gear_polygon,
)

TH = np.linspace(0, 2 * np.pi, 3001)


def test_circular_pitch_curve_gives_the_standard_involute_gear():
    spec = ToothSpec(module=2.0)
    pitch = PitchPolyline.from_polar(TH[:-1], np.full(3000, 30.0))
    g = cut_gear(pitch, spec)
    # tooth thickness on the pitch circle: pi m / 2 (chord sum / 30 teeth, arc ~ chord)
    circle = shapely.Point(0, 0).buffer(30.0, 2048).exterior
    assert g.intersection(circle).length / 30 == pytest.approx(np.pi, abs=0.02)
    # flanks are involutes of the base circle r_b = r cos 20: compare with the analytic gear
    ref = spur_gear_polygon(30, spec)
    ring = shapely.Point(0, 0).buffer(31.5, 2048).difference(shapely.Point(0, 0).buffer(29.0, 2048))
    assert g.intersection(ring).symmetric_difference(ref.intersection(ring)).area < 1.0
    # addendum circle r + m
    assert np.hypot(*np.asarray(g.exterior.coords).T).max() == pytest.approx(32.0, abs=0.02)


def test_rack_cut_circle_is_the_standard_involute_gear():
    """A rack rolled on a circle generates the involute exactly (the simulated shaper only
    approximately, the shaper's envelope exactly too: tests/test_shaper_envelope.py): same
    thickness and tip, root at r - 1.25 m, flanks closer than the simulated shaper's."""
    spec = ToothSpec(module=2.0, cutter="rack")
    pitch = PitchPolyline.from_polar(TH[:-1], np.full(3000, 30.0))
    g = cut_gear(pitch, spec)
    circle = shapely.Point(0, 0).buffer(30.0, 2048).exterior
    assert g.intersection(circle).length / 30 == pytest.approx(np.pi, abs=0.01)
    rad = np.hypot(*np.asarray(g.exterior.coords).T)
    assert rad.max() == pytest.approx(32.0, abs=0.02) and rad.min() == pytest.approx(27.5,
                                                                                   abs=0.02)
    ref = spur_gear_polygon(30, spec)
    ring = shapely.Point(0, 0).buffer(31.5, 2048).difference(shapely.Point(0, 0).buffer(29.0, 2048))
    rack_err = g.intersection(ring).symmetric_difference(ref.intersection(ring)).area
    shaper = cut_gear(pitch, ToothSpec(module=2.0, method="simulated"))
    shaper_err = shaper.intersection(ring).symmetric_difference(ref.intersection(ring)).area
    assert rack_err < 0.3 and rack_err < 0.6 * shaper_err
    # the shaper's envelope is as close as the rack (what remains is the reference's own
    # polygon: 12 points per flank)
    envelope = cut_gear(pitch, ToothSpec(module=2.0))
    assert envelope.intersection(ring).symmetric_difference(
        ref.intersection(ring)).area < 1.1 * rack_err


def test_a_rack_cannot_cut_an_internal_gear():
    pitch = PitchPolyline.from_polar(TH[:-1], np.full(3000, 40.0))
    with pytest.raises(ValueError, match="internal"):
        cut_gear(pitch, ToothSpec(module=2.0, cutter="rack"), internal=True)


def test_motion_stations_follow_the_relative_motion():
    from plantmech.gears.teeth import motion_stations

    th = np.linspace(0, 2 * np.pi, 3001)
    # a circular 1:1 pair: arc and turn grow evenly, so the stations are evenly spaced
    pa, pb, ra = motion_stations(th, -th, np.full_like(th, 30.0), 2.0, count=100)
    assert np.allclose(np.diff(pa), 2 * np.pi / 100)
    assert np.allclose(pb, -pa) and np.allclose(ra, 30.0)
    # a steep span r' = 30 mm/rad: station density ~ arc / cos(working pressure angle),
    # arc sqrt(r^2 + r'^2) per radian, working pressure angle 20 deg + atan(r' / r)
    r = np.where(th < np.pi, 30.0, 30.0 + 30.0 * (th - np.pi))
    pa, _, _ = motion_stations(th, -th, r, 2.0, spacing=1.0, endpoint=True)
    assert pa[0] == 0 and pa[-1] == pytest.approx(2 * np.pi)
    flat = np.diff(pa[pa < np.pi - 0.1]).mean()
    assert flat == pytest.approx(np.cos(np.radians(20)) / 30.0, rel=0.01)
    rs = 30.0 + 30.0 * (pa[pa > np.pi + 0.1] - np.pi)
    steep = np.diff(pa[pa > np.pi + 0.1])
    alpha_w = np.radians(20) + np.arctan(30.0 / rs[:-1])
    predicted = np.cos(alpha_w) / np.hypot(rs[:-1], 30.0)
    assert steep == pytest.approx(predicted, rel=0.05)


def ellipse_pair(backlash=0.1):
    from scipy.special import ellipe

    e = 0.35
    A = np.pi * 2 * 32 / (4 * ellipe(e**2))  # perimeter = 32 pitches at m = 2
    r = A * (1 - e**2) / (1 - e * np.cos(TH))
    return make_pair("ellipse", TH, r, 2 * A, ToothSpec(module=2.0, backlash_mm=backlash)), A


def test_ellipse_about_its_focus_meshes_with_its_twin():
    pair, A = ellipse_pair()
    assert pair.spec.cutter == "rack"  # convex everywhere: the rack cuts it
    assert pair.teeth_a == 32 and pair.teeth_b == 32
    assert pair.phi_b[-1] == pytest.approx(-2 * np.pi, abs=1e-4)  # closes 1:1
    ratio = np.diff(pair.phi_a) / -np.diff(pair.phi_b)
    assert ratio.min() == pytest.approx(0.4815, abs=2e-3)  # (1 - e) / (1 + e)
    assert ratio.max() == pytest.approx(2.0769, abs=5e-3)  # (1 + e) / (1 - e)
    m = mesh_check(pair, 360)
    assert m["ok"] and m["max_interference_mm"] < 1e-3
    assert 0.0 < m["min_normal_gap_mm"] <= m["max_normal_gap_mm"] < 0.1
    # the free play a designer asked for (0.1 mm on the pitch curve) holds over the cycle
    assert 0.09 < m["min_circumferential_backlash_mm"] <= m["max_circumferential_backlash_mm"] \
        < 0.13


def test_wrong_tooth_phase_is_caught_by_the_mesh_check():
    pair, _ = ellipse_pair()
    from plantmech.gears.teeth import _arc_to_angle

    pair.gear_b = cut_gear(pair.pitch_b, ToothSpec(module=2.0),
                           tooth_at=_arc_to_angle(pair.pitch_b, pair.phi_b[0]))
    m = mesh_check(pair, 90)
    assert not m["ok"] and m["max_interference_mm"] > 0.5


def wavy(cutter_teeth=None):
    from plantmech.gears.closure import solve_centre_distance
    from plantmech.geometry.periodic import RadiusCurve

    r = 1 + 0.08 * np.cos(5 * TH)
    scale = 100 * np.pi * 2 / PitchPolyline.from_polar(TH[:-1], r[:-1]).perimeter
    r = r * scale
    a = solve_centre_distance(RadiusCurve.from_samples(TH[:-1], r[:-1]), turn=5 * np.pi)
    return make_pair("wavy", TH, r, a, ToothSpec(module=2.0, backlash_mm=0.1), samples=4000)


def test_concave_pitch_curve_with_a_shaper_cutter_meshes():
    pair = wavy()
    assert pair.spec.cutter == "shaper"  # concave spans: a shaper small enough for them
    assert pair.teeth_a == 100 and pair.teeth_b == 40
    c = gear_checks("wavy", pair.pitch_a, pair.spec, 100)
    # analytic: r = R0 (1 + 0.08 cos 5t), rho = (r^2 + r'^2)^1.5 / (r^2 + 2 r'^2 - r r'')
    R0 = np.hypot(*pair.pitch_a.xy.T).max() / 1.08
    t = np.linspace(0, 2 * np.pi, 200001)
    r, r1, r2 = (R0 * (1 + 0.08 * np.cos(5 * t)), -0.4 * R0 * np.sin(5 * t),
                 -2.0 * R0 * np.cos(5 * t))
    den = r**2 + 2 * r1**2 - r * r2
    rho = (r**2 + r1**2) ** 1.5 / den
    assert c["min_concave_curvature_radius_mm"] == pytest.approx(-rho[den < 0].max(), rel=5e-3)
    assert c["cutter_fits"]
    m = mesh_check(pair, 360)
    assert m["ok"] and m["max_interference_mm"] < 1e-3
    assert m["max_normal_gap_mm"] < 0.1
    assert 0.08 < m["min_circumferential_backlash_mm"] <= m["max_circumferential_backlash_mm"] \
        < 0.15


def test_a_rack_gouges_the_concave_spans():
    """A rack on a curve with concave spans (the naive whole-rack sweep) removes flank
    material where the curve is concave: the teeth generated that way no longer touch —
    the backlash jumps."""
    pair = wavy()
    rack = ToothSpec(module=2.0, backlash_mm=0.1, cutter="rack")
    assert not gear_checks("wavy", pair.pitch_a, rack, 100)["cutter_fits"]
    from plantmech.gears.teeth import _arc_to_angle

    pair.gear_a = cut_gear(pair.pitch_a, rack, tooth_at=_arc_to_angle(pair.pitch_a, TH[0]))
    m = mesh_check(pair, 360)
    # the fitted shaper's pair keeps its backlash under 0.05 mm (previous test)
    assert m["max_normal_gap_mm"] > 0.2 and m["max_circumferential_backlash_mm"] > 0.4


@pytest.mark.parametrize("backlash", [0.1, 0.3])
def test_circumferential_backlash_of_circular_involute_gears_is_what_was_cut(backlash):
    """Two 30-tooth involute gears cut with a circumferential backlash B (each tooth
    thinner by B / 2 on the pitch circle): the driven gear turns B / r between its two
    flank contacts, everywhere in the cycle; the normal gap on one side at the nominal
    position is B / 2 x cos(alpha) (what used to be reported as "backlash": 0.047 mm)."""
    th = np.linspace(0, 2 * np.pi, 721)
    pair = make_pair("c", th, np.full_like(th, 30.0), 60.0,
                     ToothSpec(2.0, backlash_mm=backlash))
    m = mesh_check(pair, 60)
    assert m["min_circumferential_backlash_mm"] == pytest.approx(backlash, abs=0.003)
    assert m["max_circumferential_backlash_mm"] == pytest.approx(backlash, abs=0.003)
    assert m["max_backlash_mm"] == m["max_circumferential_backlash_mm"]  # the app's name
    gap = backlash / 2 * np.cos(np.radians(20.0))
    assert m["min_normal_gap_mm"] == pytest.approx(gap, abs=0.003)
    assert m["max_normal_gap_mm"] == pytest.approx(gap, abs=0.003)


def test_a_module_leaving_too_few_teeth_is_refused_before_cutting(tmp_path, capsys):
    """--module 200 would cut 1-tooth gears, --module 0.001 ran 400 s and allocated 5 GiB:
    the option's range refuses both (0.5-50 mm), and a module inside it that leaves a gear
    of Table 4 (perimeter 381.1 mm) with 381.1 / (50 pi) = 2.43 teeth is refused by name
    (gear, tooth count, module) with exit 2, nothing written."""
    import time

    from plantmech.interfaces.cli import main
    from tests.conftest import EXAMPLES

    for module in ("200", "0.001"):
        with pytest.raises(SystemExit) as exc:
            main(["gears", str(EXAMPLES / "sugarcane_table4.toml"), "--out",
                  str(tmp_path / "g"), "--module", module])
        assert exc.value.code == 2 and "at least 0.5 and at most 50" in capsys.readouterr().err
    t0 = time.perf_counter()
    rc = main(["gears", str(EXAMPLES / "sugarcane_table4.toml"), "--out",
               str(tmp_path / "g"), "--module", "50"])
    err = capsys.readouterr().err
    assert rc == 2 and time.perf_counter() - t0 < 20
    assert "gear gear2" in err and "module 50" in err and "2.426 teeth" in err
    assert "6..500" in err
    assert not (tmp_path / "g").exists()


def test_undercut_is_flagged_below_17_teeth():
    for z, expected in ((12, True), (30, False)):
        pitch = PitchPolyline.from_polar(TH[:-1], np.full(3000, float(z)))
        assert gear_checks("c", pitch, ToothSpec(module=2.0), z)["undercut"] is expected


def test_dxf_is_closed_and_in_mm_and_stl_is_watertight(tmp_path):
    import ezdxf
    import trimesh

    from plantmech.outputs.gear_files import write_dxf, write_stl, write_svg

    pitch = PitchPolyline.from_polar(TH[:-1], np.full(3000, 30.0))
    g = cut_gear(pitch, ToothSpec(module=2.0), bore=20.0)
    write_dxf(tmp_path / "g.dxf", {"gear": g})
    doc = ezdxf.readfile(tmp_path / "g.dxf")
    assert doc.units == ezdxf.units.MM
    polys = list(doc.modelspace().query("LWPOLYLINE"))
    assert len(polys) == 2 and all(p.closed for p in polys)  # outline and bore
    assert {p.dxf.layer for p in polys} == {"gear"}
    assert write_stl(tmp_path / "g.stl", g, 10.0)
    mesh = trimesh.load(tmp_path / "g.stl")
    assert mesh.is_watertight
    assert mesh.volume == pytest.approx(g.area * 10.0, rel=1e-6)
    write_svg(tmp_path / "g.svg", g)
    assert (tmp_path / "g.svg").read_text().startswith("<svg")


def test_gears_cli_writes_every_file_and_the_verification_record(shared):
    """The published Table 4 gears at the default modules (gears.modules.choose_teeth:
    gear 2 - sun 81 teeth at 1.4977 mm, the largest standard module in their 1-1.84 mm
    window; gear 3 - planet 169 teeth at 0.9974 mm, the design's smallest module where the
    curves allow 0.356): every file written (each STL one body), the sun - gear 2 pair
    turning without interference, the choice printed, and the verdict "not manufacturable"
    with exit 4, naming what cannot be cut: gear 3's concave span (radius of curvature 3.6
    mm) against the shaper's 3.99 mm pitch radius, working pressure angles of 83 deg,
    undercut, and the teeth of gear 3 and the planet overlapping there."""
    import json

    from tests.conftest import EXAMPLES, gears_cut

    # `plantmech gears` on it, once per test run (tests/test_cli_verify.py verifies the files)
    out, rc, printed = gears_cut(shared, "sugarcane_table4", EXAMPLES / "sugarcane_table4.toml",
                                 printed=True)
    rec = json.loads((out / "verification.json").read_text())
    # each mate is cut by its partner, with stations spaced by the relative motion and
    # the partial sun's last position included (docs/validation.md)
    worst = {m["pair"]: m["max_interference_mm"] for m in rec["mesh"]}
    assert worst["gear2_sun"] < 0.005 and worst["gear3_planet"] > 0.05
    teeth = {g["name"]: g["teeth"] for g in rec["gears"]}
    P = {g["name"]: g["perimeter_mm"] for g in rec["gears"]}
    assert teeth["gear2"] == round(P["gear2"] / (1.5 * np.pi)) == 81
    assert teeth["gear3"] == round(P["gear3"] / (1.0 * np.pi)) == 169
    assert "module of gear3_planet: 1 mm (ISO 54 series I), 169 teeth" in printed
    assert [c["standard_module_mm"] for c in rec["module_choice"]] == [1.5, 1.0]
    assert rc == 4 and rec["verdict"]["label"] == "not manufacturable"
    assert printed.strip().splitlines()[-1].startswith("verdict: NOT MET - not manufacturable")
    # the one verdict of every command (outputs.verdict), each finding a reason, printed last
    v = rec["verdict"]
    assert v["status"] == "not met" and v["ok"] is False and v["exit_code"] == rc
    assert v["failed"] == [f"{f['gear']} {f['check']}" for f in rec["findings"]]
    assert printed.strip().splitlines()[-1] == f"verdict: {v['text']}"
    assert "ok   gear3" not in printed and "FAIL gear3" in printed
    found = {(f["gear"], f["check"]): f for f in rec["findings"]}
    cut = found[("gear3", "cutter_fit")]
    assert 3.5 < cut["value"] < cut["limit"] < 4.0 and cut["unit"] == "mm"
    assert set(cut["where"]) >= {"body_angle_deg", "tooth"} and cut["why"]
    assert found[("gear3", "working_pressure_angle")]["value"] > 80
    assert ("planet", "undercut") in found
    # the teeth overlap where gear 3's concave span is sharper than its shaper
    assert ("gear3_planet", "mesh_interference") in found
    for f in rec["findings"]:
        assert set(f) == {"gear", "check", "value", "limit", "unit", "where", "why"}
        assert f"{f['gear']}: {f['check']}" in printed
    assert {g["name"] for g in rec["gears"]} == {"gear2", "sun", "gear3", "planet"}
    for g in rec["gears"]:
        for key in ("teeth", "module_mm", "perimeter_mm", "min_curvature_radius_mm",
                    "undercut", "pointed", "max_pressure_angle_deg"):
            assert key in g
        assert g["stl"]["written"] and g["stl"]["bodies"] == 1  # before: gear 3 4, planet 6
        for ext in ("dxf", "svg", "stl"):
            assert (out / f"{g['name']}.{ext}").stat().st_size > 1000
    assert {m["pair"] for m in rec["mesh"]} == {"gear2_sun", "gear3_planet"}
    for m in rec["mesh"]:
        assert set(m) >= {"pair", "max_interference_mm", "min_circumferential_backlash_mm",
                          "max_circumferential_backlash_mm", "max_normal_gap_mm", "ok"}
    # the sun has a toothless sector: fewer teeth than its perimeter would carry
    sun = next(g for g in rec["gears"] if g["name"] == "sun")
    assert sun["perimeter_mm"] / (np.pi * sun["module_mm"]) > sun["teeth"] + 1
    assert (out / "gear2_sun_mesh.png").exists()


def test_seeder_example_gears_mesh_and_say_why_they_cannot_drive(tmp_path):
    """The bundled seeder example (Table 2's inverse design): its cusped pitch curves
    still carry generated teeth that turn through the cycle without interference, and the
    record says where they fail as gears (working pressure angle over 90 deg: the mesh
    would lock; concave radii far below the cutter)."""
    from plantmech.design import load_design
    from plantmech.workflows import run_gears
    from tests.conftest import EXAMPLES

    # at module 6 (23 and 24 teeth; the default, the design's smallest module 1 mm since
    # the curves allow 0.02 mm, cuts some 140 teeth per gear: tests/test_modules.py)
    rec = run_gears(load_design(EXAMPLES / "sugarcane_seeder.toml"), tmp_path, module=6.0)
    assert [x["teeth"] for x in rec["gears"]][::2] == [23, 24]
    assert rec["all_pairs_mesh"], rec["mesh"]
    g = {x["name"]: x for x in rec["gears"]}
    assert g["gear3"]["max_pressure_angle_deg"] > 90 and not g["gear3"]["cutter_fits"]
    assert g["sun"]["cutter"] == "envelope of gear2"


def test_khv_gear_set_meshes_on_both_pairs_with_one_middle_gear(tmp_path):
    """The middle gear of a K-H-V train is cut once (against the sun) and the planet is
    phased to it; both meshes run clean."""
    import json

    from plantmech.design import load_design
    from plantmech.workflows import run_gears
    from tests.conftest import EXAMPLES

    rec = run_gears(load_design(EXAMPLES / "rice_transplanter_khv.toml"), tmp_path, steps=180)
    assert [g["name"] for g in rec["gears"]] == ["sun", "middle", "planet"]
    assert rec["all_pairs_mesh"], rec["mesh"]
    assert all(m["max_interference_mm"] < 1e-3 for m in rec["mesh"])
    assert json.loads((tmp_path / "verification.json").read_text())["all_pairs_mesh"]


@pytest.mark.parametrize("planet_teeth,clean", [(32, True), (36, False)])
def test_internal_circular_pair_tip_interference_needs_a_tooth_difference(planet_teeth, clean):
    # textbook internal spur pairs (20 deg, full depth): a 40-tooth ring meshes with a
    # 32-tooth planet, but with 36 teeth the tips foul away from the line of centres
    # (objective xv's limit of 8 is this measurement, docs/conventions.md)
    th = np.linspace(0, 2 * np.pi, 721)[:-1]
    m = 2.0
    pair = make_pair("ring_planet", th, np.full_like(th, 40.0), 40.0 - planet_teeth * m / 2,
                     ToothSpec(m, backlash_mm=0.1), internal=True)
    assert (pair.teeth_a, pair.teeth_b) == (40, planet_teeth)
    res = mesh_check(pair, steps=90)
    assert res["ok"] is clean
    if not clean:
        assert res["max_interference_mm"] > 0.1


def test_toothed_transplanter_example_meets_every_objective_but_cannot_be_cut():
    """The transplanter re-optimized with the tooth fit: objectives (i)-(xv) met, but at
    20 deg full-depth teeth its curves allow a module of 1.27 mm against its 2.57 mm
    (docs/manufacturability.md): the cuttable-module margin fails, and only it."""
    from plantmech.design import load_design
    from plantmech.workflows import run_transplanter
    from tests.conftest import EXAMPLES

    path = EXAMPLES / "rice_transplanter_toothed.toml"
    objs = run_transplanter(load_design(path)).summary["objectives"]
    assert len(objs) == 16
    assert [o["name"] for o in objs if not o["ok"]] == ["cuttable_module_margin"]
    margin = next(o["value"] for o in objs if o["name"] == "cuttable_module_margin")
    assert margin == pytest.approx(1.27 - 2.567, abs=0.02)


def test_toothed_transplanter_gears_mesh_but_are_undercut(tmp_path):
    """Its generated ring and planet turn through a full cycle without interference with the
    free play asked for; each STL one body. Its pitch curves bend like spur gears of 8.5
    (ring) and 9.6 (planet) teeth, under the rack's undercut limit of 17.1 at 20 deg
    full-depth teeth: "not manufacturable" (exit 4); the findings are the two undercuts and
    the pitch-curve rule that says the same (cuttable module margin)."""
    import json

    from plantmech.interfaces.cli import main
    from tests.conftest import EXAMPLES

    path = EXAMPLES / "rice_transplanter_toothed.toml"
    out = tmp_path / "g"
    assert main(["gears", str(path), "--out", str(out)]) == 4
    rec = json.loads((out / "verification.json").read_text())
    (mesh,) = rec["mesh"]
    assert mesh["ok"] and mesh["max_interference_mm"] < 0.01 * rec["gears"][0]["module_mm"]
    assert 0.05 < mesh["min_circumferential_backlash_mm"] <= \
        mesh["max_circumferential_backlash_mm"] < 0.25
    assert 0 < mesh["max_normal_gap_mm"] < 0.1
    assert all(g["stl"]["written"] and g["stl"]["bodies"] == 1 for g in rec["gears"])
    assert [g["teeth"] for g in rec["gears"]] == [80, 20]
    assert [g["teeth_on_outline"] for g in rec["gears"]] == [80, 20]
    assert rec["verdict"]["label"] == "not manufacturable"
    # 80 teeth make its module 2.567 mm: no stock cutter (gears/modules.py) either
    assert sorted((f["gear"], f["check"]) for f in rec["findings"]) == [
        ("internal", "undercut"), ("internal_planet", "standard_module"),
        ("pitch curves", "cuttable_module_margin"), ("planet", "undercut")]
    z_eq = {f["gear"]: f["value"] for f in rec["findings"] if f["check"] == "undercut"}
    assert z_eq["internal"] == pytest.approx(8.5, abs=0.1)
    assert z_eq["planet"] == pytest.approx(9.6, abs=0.1)


def test_manufacturable_transplanter_example_meets_everything_and_meshes(shared):
    """The same design optimized with manufacturability required (stub 25 deg teeth, its
    [manufacturing] table): every objective and check met, and `plantmech gears` cuts it with
    no finding (exit 0): no undercut at the stub limit 1.6 / sin^2 25 deg = 8.96."""
    import json

    from plantmech.design import load_design
    from plantmech.workflows import run_transplanter
    from tests.conftest import EXAMPLES, gears_cut

    path = EXAMPLES / "rice_transplanter_manufacturable.toml"
    objs = run_transplanter(load_design(path)).summary["objectives"]
    assert len(objs) == 16 and all(o["ok"] for o in objs), [o for o in objs if not o["ok"]]
    # `plantmech gears` on it, once per test run (tests/test_cli_verify.py verifies the files)
    out, rc = gears_cut(shared, "rice_transplanter_manufacturable", path)
    rec = json.loads((out / "verification.json").read_text())
    assert rc == 0, rec["findings"]
    assert rec["verdict"]["ok"] and rec["findings"] == []
    assert rec["tooth"] == {"pressure_angle_deg": 25.0, "addendum": 0.8, "dedendum": 1.0}
    (mesh,) = rec["mesh"]
    assert mesh["ok"] and mesh["max_interference_mm"] < 0.01 * rec["gears"][0]["module_mm"]
    assert all(g["stl"]["written"] and g["stl"]["bodies"] == 1 for g in rec["gears"])
    assert [g["teeth"] for g in rec["gears"]] == [80, 20]


def test_step_solid_follows_the_outline_within_its_tolerance_and_sits_like_the_stl(tmp_path):
    """STEP (optional extra, ``--step``): one valid solid over z = 0..face width (before:
    -12..0), its outline cubic B-spline edges within the stated 5 um of the cut outline
    (before: splines overshooting by 2.06 mm; then thousands of straight edges, minutes to
    import), area x face width = the STL's volume. Skipped where build123d is not
    installed (CI installs only .[dev])."""
    bd = pytest.importorskip("build123d")
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps

    from plantmech.outputs.gear_files import STEP_TOLERANCE_MM, write_step

    # a ring with a wavy outer edge: 2,400 vertices, curvature everywhere; a 5 mm bore
    t = np.linspace(0, 2 * np.pi, 2400, endpoint=False)
    r = 20 + 1.5 * np.cos(12 * t)
    poly = shapely.Polygon(np.c_[r * np.cos(t), r * np.sin(t)],
                           [shapely.Point(0, 0).buffer(5.0, 64).exterior.coords])
    rec = write_step(tmp_path / "g.step", poly, 8.0)
    assert rec["written"], rec
    (solid,) = bd.import_step(str(tmp_path / "g.step")).solids()
    assert solid.is_valid
    bb = solid.bounding_box()
    assert bb.min.Z == pytest.approx(0.0, abs=1e-6) and bb.max.Z == pytest.approx(8.0, abs=1e-6)
    bottom = min(solid.faces(), key=lambda f: f.center().Z)
    props = GProp_GProps()
    BRepGProp.SurfaceProperties_s(bottom.wrapped, props, 1e-7)
    assert props.Mass() == pytest.approx(poly.area, rel=1e-4)
    # smooth edges, not a polygon: 2 bore halves and a few dozen outer runs at most
    edges = bottom.edges()
    assert len(edges) < 100 and rec["poles"] < len(t) / 5
    assert all(e.geom_type.name == "BSPLINE" for e in edges)
    # independent of the writer's own check: the edges sampled by OCC lie on the outline
    pts = np.array([[p.X, p.Y] for e in edges for p in e.positions(np.linspace(0, 1, 50))])
    d = shapely.distance(poly.boundary, shapely.points(pts))
    assert d.max() <= STEP_TOLERANCE_MM
    assert rec["max_deviation_mm"] <= STEP_TOLERANCE_MM


def test_a_step_file_that_is_off_or_slow_is_a_finding_never_silent(tmp_path, monkeypatch):
    """`gears --step`: a STEP file the writer refused (outline off its tolerance) and one
    that imported too slowly are each a finding naming the gear, and the verdict is not
    ok, on a gear set that otherwise passes (the manufacturable transplanter). The writer is
    replaced by its two outcomes, so this runs without build123d."""
    from plantmech.design import load_design
    from plantmech.outputs import gear_files as gf
    from plantmech.workflows import run_gears
    from tests.conftest import EXAMPLES

    outcomes = {
        "internal.step": {"written": False, "why": "the STEP outline deviates 0.0071 mm from "
                          "the cut outline (> 0.005)", "max_deviation_mm": 0.0071,
                          "tolerance_mm": 0.005, "slow_import": False},
        "planet.step": {"written": True, "why": None, "import_s": 9.0, "import_cpu_s": 7.5,
                        "slow_import": True,
                        "tolerance_mm": 0.005, "max_deviation_mm": 0.0044}}
    monkeypatch.setattr(gf, "write_step", lambda path, poly, width: outcomes[path.name])
    rec = run_gears(load_design(EXAMPLES / "rice_transplanter_manufacturable.toml"),
                    tmp_path, steps=36, step=True)
    found = {(f["gear"], f["check"]): f for f in rec["findings"]}
    assert set(found) == {("internal", "step_file"), ("planet", "step_import_time")}
    assert found[("internal", "step_file")]["value"] == 0.0071
    assert found[("planet", "step_import_time")]["value"] == 7.5
    assert found[("planet", "step_import_time")]["limit"] == gf.STEP_IMPORT_LIMIT_S
    assert rec["verdict"]["label"] == "not manufacturable"
    assert "planet.step" in rec["files"] and "internal.step" not in rec["files"]


def test_tooth_proportions_are_parameters_checked_and_recorded(tmp_path):
    """--pressure-angle / --addendum / --dedendum reach the cutter and the checks: the
    K-H-V set cut at 25 deg meshes, and its working pressure angle is 5 deg higher than at
    20 deg (alpha + atan(|r'| / r)); impossible proportions are refused by name."""
    import json

    from plantmech.interfaces.cli import main
    from plantmech.workflows import tooth_proportions
    from tests.conftest import EXAMPLES

    out = tmp_path / "g"
    # cut and meshed; its sun's 20 teeth make a module no stock cutter has: that alone fails
    assert main(["gears", str(EXAMPLES / "rice_transplanter_khv.toml"), "--out", str(out),
                 "--pressure-angle", "25"]) == 4
    rec = json.loads((out / "verification.json").read_text())
    assert {f["check"] for f in rec["findings"]} == {"standard_module"}
    assert rec["tooth"] == {"pressure_angle_deg": 25.0, "addendum": 1.0, "dedendum": 1.25}
    assert rec["all_pairs_mesh"]
    sun = next(g for g in rec["gears"] if g["name"] == "sun")
    assert sun["max_pressure_angle_deg"] == pytest.approx(38.1 + 5.0, abs=0.1)
    with pytest.raises(ValueError, match="pressure angle"):
        tooth_proportions(pressure_angle_deg=45.0)
    with pytest.raises(ValueError, match="dedendum"):
        tooth_proportions(dedendum=1.0)


def _plain_mesh_check(pair, steps):
    """The mesh check as it was first written (before it was made faster): each gear
    clipped to the window on the 1e-4 mm grid over its whole outline, every overlay made,
    every bisection step asked on the whole outlines. The reference the fast one must
    agree with (same findings; numbers within the grid and the bisection's resolution)."""
    import shapely.affinity

    from plantmech.gears.teeth import _turn_each, motion_stations

    pa, pb, rc = motion_stations(pair.phi_a, pair.phi_b, pair.r_a, pair.module, count=steps,
                                 endpoint=True, pressure_angle=pair.spec.alpha)
    turn_b = np.pi - pb
    r_pitch = np.hypot(*pair.pitch_a.xy.T)
    h = 5 * np.pi * pair.module
    window = shapely.box(r_pitch.min() - 3 * pair.module, -h, r_pitch.max() + 3 * pair.module,
                         h)
    grid, T = 1e-4, len(pa)
    wa = _turn_each(np.full(T, window), pa)
    wb = _turn_each(np.full(T, shapely.affinity.translate(window, xoff=-pair.a)), -turn_b)
    ga = _turn_each(shapely.buffer(shapely.intersection(pair.gear_a, wa, grid_size=grid), 0),
                    -pa)
    gb = _turn_each(shapely.buffer(shapely.intersection(pair.gear_b, wb, grid_size=grid), 0),
                    turn_b, dx=pair.a)
    inter = shapely.intersection(ga, gb, grid_size=grid)
    parts, owner = shapely.get_parts(inter, return_index=True)
    pa_, pl_ = shapely.area(parts), shapely.length(parts)
    depth = np.zeros(T)
    np.maximum.at(depth, owner, np.where(pa_ > 1e-6, 2 * pa_ / np.maximum(pl_, 1e-9), 0.0))
    free = shapely.area(inter) <= 1e-6
    discs = shapely.buffer(shapely.points(rc[free], np.zeros(free.sum())),
                           2.5 * np.pi * pair.module, quad_segs=16)
    gap = shapely.distance(shapely.intersection(shapely.boundary(ga[free]), discs),
                           shapely.intersection(shapely.boundary(gb[free]), discs))
    r_b = np.abs(pair.a - rc[free])
    moved = shapely.transform(gb[free], lambda xy: xy - [pair.a, 0.0])
    play = 0.0
    for sense in (+1, -1):
        lo, hi = np.zeros(free.sum()), np.full(free.sum(), np.pi * pair.module) / r_b
        for _ in range(int(np.ceil(np.log2(np.pi * pair.module / 1e-4)))):
            mid = 0.5 * (lo + hi)
            hit = shapely.intersects(ga[free], _turn_each(moved, sense * mid, dx=pair.a))
            hi, lo = np.where(hit, mid, hi), np.where(hit, lo, mid)
        play = play + r_b * 0.5 * (lo + hi)
    return {"max_interference_mm": depth.max(), "min_normal_gap_mm": gap.min(),
            "max_normal_gap_mm": gap.max(), "min_circumferential_backlash_mm": play.min(),
            "max_circumferential_backlash_mm": play.max(), "backlash_stations": free.sum()}


def test_the_fast_mesh_check_finds_what_the_plain_one_finds_on_sugarcane_table4():
    """Table 4's gears at module 10 (paper 000's published sugarcane seeder; both pairs
    fail the backlash band: gear3-planet's free play reaches several pitches, where the
    planet's teeth are missing) checked at 24 stations by the fast mesh check and by the
    plain overlay above: the same findings, the same stations with free play, the
    numbers within the 1e-4 mm grid and bisection resolution."""
    from pathlib import Path

    from plantmech.design import load_design
    from plantmech.gears.findings import mesh_findings
    from plantmech.workflows import gear_pairs

    design = load_design(Path(__file__).parents[1] / "examples" / "sugarcane_table4.toml")
    pairs = gear_pairs(design, 10.0, 0.1)
    found = {}
    for pair, spec in pairs:
        fast, plain = mesh_check(pair, 24), _plain_mesh_check(pair, 24)
        assert fast["backlash_stations"] == plain["backlash_stations"]
        for k in ("max_interference_mm", "min_normal_gap_mm", "max_normal_gap_mm",
                  "min_circumferential_backlash_mm", "max_circumferential_backlash_mm"):
            assert fast[k] == pytest.approx(plain[k], abs=3e-4), k
        f = mesh_findings(fast, spec.module, 0.1)
        found[pair.name] = sorted(x["check"] for x in f)
        plain_checks = sorted(x["check"] for x in mesh_findings(
            {**fast, **plain, "pair": pair.name}, spec.module, 0.1))
        assert found[pair.name] == plain_checks
    assert found == {"gear2_sun": [], "gear3_planet": ["backlash_max"]}


def test_a_dwell_sun_is_cut_when_its_polyline_wanders_over_the_toothless_arc():
    """Fuzz cases 4071/4161/4475 (the dwell example at 360 samples): the toothless wedge
    drawn through the arc's own points crossed itself (GEOS side location conflict). The
    wedge is the sector between the arc's ends; where the old wedge was valid the sun is
    the same (shipped dwell example, Table 4: same areas)."""
    from plantmech.design import load_design
    from plantmech.workflows import gear_pairs
    from tests.conftest import EXAMPLES

    d = load_design(EXAMPLES / "sugarcane_seeder_dwell.toml")
    d.trajectory.samples = 360
    # at module 6, the module the cases were found at (the default since issue 32, the
    # design's 1 mm, cuts 136 and 129 teeth: 16x the time for the same pitch curves)
    (sun_pair, _), _ = gear_pairs(d, module=6.0)
    assert sun_pair.gear_b.is_valid and sun_pair.gear_b.geom_type == "Polygon"
    # gear 2: 23 teeth on its perimeter, which includes its 19 mm radial step at the lock
    # point; the sun's rolling arc is 406.4 mm = 21.8 pitches (arc length is kept in
    # rolling), so 22 teeth (before the sun was closed over its toothless arc, the
    # spline's swing across it gave 23 by accident)
    assert (sun_pair.teeth_a, sun_pair.teeth_b) == (23, 22)


def test_a_dwell_sun_closes_over_its_toothless_arc_within_gear2s_radii():
    """The dwell example at 360 samples: the rolling start landed 9e-5 deg before gear 2's
    lock point, the first sample took the radius from the step's other side, and the
    periodic spline through the rolling arc alone swung through the centre and out to
    600 mm ("two points share the angle 180.480 deg", exit 2). The sun's pitch curve is
    its rolling arc (radius a1 - r2, 360 - theta_1 deg of it) closed over theta_1 by a
    linear run between the arc's end radii: every radius lies between a1 - max r2 and
    a1 - min r2."""
    from plantmech.design import load_design
    from plantmech.mechanisms.seeder_forward import sun_rolling_start
    from plantmech.verification import train_from_inverse
    from plantmech.workflows import gear_pairs, run_seeder_inverse
    from tests.conftest import EXAMPLES

    d = load_design(EXAMPLES / "sugarcane_seeder_dwell.toml")
    d.trajectory.samples = 360
    tr = train_from_inverse(run_seeder_inverse(d, manufacturability=False).result)
    assert sun_rolling_start(tr) == tr.gear2.theta0  # the lock point, not a hair before
    r2 = tr.gear2(np.linspace(0, 2 * np.pi, 7200))
    # the pitch curves do not depend on the module: cut at 6 mm (23 and 22 teeth, not the
    # default 1 mm's 136 and 129)
    (pair, _), _ = gear_pairs(d, module=6.0)
    rb = np.hypot(*np.asarray(pair.pitch_b.xy).T)
    assert rb.min() >= tr.a1 - r2.max() - 0.05 and rb.max() <= tr.a1 - r2.min() + 0.05
    rolled = np.degrees(abs(pair.phi_b[-1] - pair.phi_b[0]))
    assert rolled == pytest.approx(360 - np.degrees(tr.dwell_theta1), abs=0.05)
