"""Teeth and files for the general planetary train (trains/gearing.py through
``workflows.run_gears`` and ``plantmech gears``), checked against independent expectations:
the elliptic example's three identical ellipses give three identical gears, the closed-form
perimeter and working pressure angle of an ellipse, and a circular internal pair."""

from __future__ import annotations

import copy
import json
import tomllib

import numpy as np
import pytest
from scipy.special import ellipe

from plantmech.design import DesignError, load_design
from plantmech.interfaces.cli import main
from tests.conftest import EXAMPLES, hausdorff_distance
from tests.conftest import write_toml as _write

EXAMPLE = EXAMPLES / "rotary_transplanter_elliptic.toml"
A, E = 25.0, 0.18  # the example's ellipses (mm, -)


def _doc() -> dict:
    return tomllib.loads(EXAMPLE.read_text())




@pytest.fixture(scope="module")
def elliptic(tmp_path_factory):
    """``run_gears`` on the elliptic example at module 2 (25 teeth: an odd count puts a tooth
    at the far end and a space at the near end, so the three gears are one gear turned;
    the default module, 2.5 mm, gives 20: tests/test_modules.py): (record, outlines, out
    dir)."""
    from plantmech.workflows import run_gears

    out = tmp_path_factory.mktemp("elliptic")
    outlines = {}
    rec = run_gears(load_design(EXAMPLE), out, module=2.0, outlines=outlines)
    return rec, outlines, out


def ellipse_perimeter(a: float, e: float) -> float:
    """4 a E(e^2) (mm): the complete elliptic integral of the second kind."""
    return 4 * a * ellipe(e**2)


def test_elliptic_example_gears_are_cut_and_ok(elliptic):
    rec, _, out = elliptic
    assert rec["verdict"]["ok"] and rec["findings"] == []
    assert [g["name"] for g in rec["gears"]] == ["sun", "idler1", "planet"]
    assert [m["pair"] for m in rec["mesh"]] == ["sun_idler1", "idler1_planet"]
    P = ellipse_perimeter(A, E)
    for g in rec["gears"]:
        # closure: the pitch curve carries whole teeth, z pi m = its perimeter (closed form)
        assert g["teeth"] == 25  # --module 2: 155.80 / (2 pi) = 24.8 -> 25 teeth
        assert g["teeth"] * np.pi * g["module_mm"] == pytest.approx(P, abs=2e-3)
        assert g["perimeter_mm"] == pytest.approx(P, abs=2e-3)
        assert g["stl_watertight"] and g["cutter"] == "rack"
        # working pressure angle of an ellipse about a focus: alpha + atan(e / sqrt(1 - e^2))
        assert g["max_pressure_angle_deg"] == pytest.approx(
            20 + np.degrees(np.arctan(E / np.sqrt(1 - E**2))), abs=0.05)
    for m in rec["mesh"]:
        assert m["ok"] and m["max_interference_mm"] <= 1e-3
        assert 0.09 <= m["min_circumferential_backlash_mm"] <= 0.11  # asked 0.1
    on_disk = json.loads((out / "verification.json").read_text())
    assert on_disk["verdict"] == rec["verdict"] and len(on_disk["mesh"]) == 2
    assert sorted(on_disk["files"]) == sorted(
        [f"{g}.{x}" for g in ("sun", "idler1", "planet") for x in ("dxf", "svg", "stl")]
        + ["sun_idler1_mesh.png", "idler1_planet_mesh.png"])


def test_idler_and_planet_are_the_sun_turned(elliptic):
    """Two ellipses about their foci at a = 2A are the same ellipse, the mate's near end
    at the contact (turned by 180 deg); the planet, the idler's mate, is the sun again. The
    sun's 25 teeth put a tooth at its far end and a space at its near end, as the idler
    needs at the contact: so the cut gears themselves agree, not only their pitch curves."""
    from shapely import affinity

    _, outlines, _ = elliptic
    sun = outlines["sun"][0]
    for name, turn in (("idler1", 180.0), ("planet", 0.0)):
        g = affinity.rotate(outlines[name][0], turn, origin=(0, 0))
        d = hausdorff_distance(sun.exterior, g.exterior, densify=0.05)
        assert d < 0.01, (name, d)  # mm (found 0.002)
        assert sun.symmetric_difference(g).area < 1e-4 * sun.area


def test_stl_files_are_single_watertight_bodies(elliptic):
    import trimesh

    _, outlines, out = elliptic
    for name, (poly, _) in outlines.items():
        mesh = trimesh.load(out / f"{name}.stl", force="mesh")
        assert mesh.is_watertight and len(mesh.split(only_watertight=False)) == 1, name
        assert mesh.volume == pytest.approx(poly.area * 12.0, rel=1e-6), name


def test_teeth_from_the_design_file_set_the_module():
    from plantmech.trains.gearing import built_train, pair_modules

    doc = _doc()
    doc["train"]["pairs"][0]["teeth"] = 30
    d = load_design(doc, name="t.toml")
    mods = pair_modules(d, built_train(d))
    P = ellipse_perimeter(A, E)
    assert [m["teeth_a"] for m in mods] == [30, 30]  # the idler's pair takes the module
    for m in mods:
        assert m["module_mm"] == pytest.approx(P / (30 * np.pi), rel=1e-4)
        assert m["source"] == "train.pairs.0.teeth"


@pytest.mark.parametrize("edit, message", [
    (lambda d: d["train"]["pairs"][1].update(teeth=30), r"pairs\.1\.teeth: .*idler"),
    (lambda d: d["train"]["pairs"][0].update(teeth=3), r"pairs\.0\.teeth"),
])
def test_bad_tooth_counts_name_the_field(edit, message):
    doc = _doc()
    edit(doc)
    with pytest.raises(DesignError, match=message):
        load_design(doc, name="t.toml")


def test_module_leaving_too_few_teeth_exits_2_naming_the_option(tmp_path, capsys):
    out = tmp_path / "o"
    assert main(["gears", str(EXAMPLE), "--out", str(out), "--module", "20"]) == 2
    err = capsys.readouterr().err
    assert "--module" in err and "sun" in err and not out.exists()


def test_an_uncuttable_curve_exits_4_naming_the_gear_and_place(tmp_path, capsys):
    """e = 0.6: the working pressure angle 20 + atan(e / sqrt(1 - e^2)) = 56.9 deg is above
    the 45 deg limit, on every gear of the chain (three equal ellipses)."""
    doc = _doc()
    doc["train"]["pairs"][0]["driver"]["eccentricity"] = 0.6
    out = tmp_path / "o"
    assert main(["gears", _write(tmp_path, doc), "--out", str(out)]) == 4
    text = capsys.readouterr().out
    assert "verdict: NOT MET" in text
    assert "NOT OK sun: working_pressure_angle 56.87 deg (limit 45 deg) at body angle" in text
    rec = json.loads((out / "verification.json").read_text())
    assert rec["verdict"]["label"] == "not manufacturable"
    bad = {(f["gear"], f["check"]) for f in rec["findings"]}
    assert {("sun", "working_pressure_angle"), ("idler1", "working_pressure_angle"),
            ("planet", "working_pressure_angle")} <= bad
    assert all("body_angle_deg" in f["where"] for f in rec["findings"]
               if f["check"] == "working_pressure_angle")


def test_circular_internal_pair_shapes_have_the_spur_values():
    """A circular ring of radius R driving a planet that turns twice per ring turn: the
    planet is a circle of R / 2 at a = R / 2; the internal pair's equivalent difference
    2 (rho_ring - rho_planet) = R everywhere; no working pressure angle beyond the tool's."""
    from plantmech.gears.manufacturability import rules_for
    from plantmech.trains.gearing import assess, built_train, gear_names, pair_shapes

    R = 60.0
    doc = _doc()
    doc["train"]["pairs"] = [{"kind": "internal", "follower_turns": 2.0, "driver": {
        "family": "ellipse", "semi_major_mm": R, "eccentricity": 0.0}}]
    d = load_design(doc, name="t.toml")
    built = built_train(d)
    assert built.laws[0].a[0] == pytest.approx(R / 2, rel=1e-9)
    (shape,) = pair_shapes(built, gear_names(d))
    ring, planet = shape.gears
    assert ring.internal and not planet.internal
    assert np.allclose(ring.curvature_radius, -R, rtol=1e-6)  # the ring wraps the planet
    assert np.allclose(planet.curvature_radius, R / 2, rtol=1e-6)
    assert planet.perimeter[0] == pytest.approx(np.pi * R, rel=1e-6)  # its own turn
    assert np.allclose(shape.internal_difference, R, rtol=1e-6)
    (v,), rules = assess(d, built)
    assert v.working_pressure_angle_deg[0] == pytest.approx(rules.pressure_angle_deg)
    # the internal difference binds the module at R / min_internal_difference
    assert v.bounds["internal difference sun_planet"][0] == pytest.approx(
        R / rules_for(d).min_internal_difference, rel=1e-6)


def test_what_is_still_refused_says_what_works(tmp_path, capsys):
    """Every command takes a planetary file now; what is refused is a seeder or
    transplanter problem, and --report where none is written for it, each by name."""
    import argparse

    from plantmech.design import DesignError, load_design
    from plantmech.interfaces.cli import refuse_planetary

    out = tmp_path / "o"
    assert main(["optimize", str(EXAMPLE), "--problem", "transplanter", "--out", str(out)]) == 2
    assert "--problem planetary" in capsys.readouterr().err and not out.exists()
    inverse = EXAMPLES / "planetary" / "sugarcane_seeder_inverse.toml"
    assert main(["inverse", str(inverse), "--out", str(out), "--report"]) == 2
    assert "--report" in capsys.readouterr().err and not out.exists()
    # a command outside the list (none of the CLI's today) is told which ones work
    args = argparse.Namespace(command="other", design=str(EXAMPLE))
    with pytest.raises(DesignError) as err:
        refuse_planetary(args, load_design(EXAMPLE))
    for works in ("'plantmech forward'", "'plantmech gears'",
                  "'plantmech optimize --problem planetary'", "'plantmech inverse'",
                  "'plantmech study'", "'plantmech design'", "'plantmech verify'",
                  "'plantmech app'"):
        assert works in str(err.value)


def test_a_ring_follower_beside_an_idler_is_refused_by_field(tmp_path, capsys):
    doc = copy.deepcopy(_doc())
    doc["train"]["pairs"][1]["kind"] = "internal"
    doc["train"]["pairs"][1]["follower_turns"] = 2.0
    out = tmp_path / "o"
    code = main(["gears", _write(tmp_path, doc), "--out", str(out)])
    err = capsys.readouterr().err
    # the idler would be a ring on one side: refused (or the pair does not roll at all)
    assert code == 2 and "train.pairs.1" in err and not out.exists()


def test_a_ring_follower_is_cut_first_with_twice_the_teeth(tmp_path):
    """An elliptic sun (e = 0.1) driving a ring that turns half a turn per sun turn: the
    ring's pitch perimeter is twice the sun's (they roll without slip, the ring turning
    half as often), so at one module it carries twice the teeth; the default module leaves
    20 teeth on the smaller gear (the sun: 25 at 2 mm). The ring is gear A (internal)."""
    from plantmech.workflows import run_gears

    doc = _doc()
    doc["carrier"]["arms"] = 1
    doc["train"]["pairs"] = [{"kind": "internal_ring_follower", "follower_turns": 0.5,
                              "driver": {"family": "ellipse", "semi_major_mm": 25.0,
                                         "eccentricity": 0.1}}]
    doc.pop("limits")
    rec = run_gears(load_design(doc, name="t.toml"), tmp_path)
    assert rec["verdict"]["ok"], rec["findings"]
    ring, sun = rec["gears"]
    assert (ring["name"], ring["internal"], sun["name"]) == ("planet", True, "sun")
    # the default: the largest standard module the curves allow (the sun's near vertex,
    # 2 B^2 / A / 17.1 = 2.9 mm): 2.5 mm; 4 A E(e^2) / (2.5 pi) = 19.95 -> 20 teeth
    z = round(ellipse_perimeter(25.0, 0.1) / (2.5 * np.pi))
    assert (ring["teeth"], sun["teeth"]) == (2 * z, z) == (40, 20)
    assert sun["perimeter_mm"] == pytest.approx(ellipse_perimeter(25.0, 0.1), abs=2e-3)
    assert ring["perimeter_mm"] == pytest.approx(2 * sun["perimeter_mm"], rel=1e-4)
    assert rec["mesh"][0]["max_interference_mm"] <= 1e-3
