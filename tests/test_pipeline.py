"""plantmech design: the whole job with one verdict."""

import json

import pytest

from plantmech.design import load_design
from plantmech.interfaces.cli import main
from tests.conftest import EXAMPLES, design_one_generation


def test_design_of_an_uncuttable_seeder_says_so_and_cuts_nothing(tmp_path, capsys):
    rc, out = design_one_generation(tmp_path, "sugarcane_seeder.toml")
    assert rc == 4
    s = json.loads((out / "summary.json").read_text())
    assert s["verdict"]["status"] == "not met" and s["verdict"]["exit_code"] == 4
    # the final design's failing rows are the verdict's, and its gears are not cut
    failed = [c["name"] for c in s["final_checks"] if not c["ok"] and c.get("required", True)]
    assert failed and s["verdict"]["failed"] == failed
    assert any(n.startswith(("cuttable_module", "working_pressure")) for n in failed)
    assert s["gears_skipped"] and not (out / "gears").exists()
    assert [st["stage"] for st in s["stages"]] == ["optimize", "gears"]
    final = load_design(out / "design.toml")
    assert final.train is not None  # a gear train, not just a path
    assert (out / "optimize" / "run.json").exists()
    html = (out / "report.html").read_text()
    assert "NOT MET" in html and (out / "mechanism.gif").stat().st_size > 10_000
    printed = capsys.readouterr().out.strip().splitlines()
    assert printed[-1].startswith("verdict: NOT MET")
    # its caveats: the optimizer moved the planned points and the seeding point
    kinds = {c["kind"]: c for c in s["caveats"]}
    assert kinds["seeding_point_moved"]["from"] == "q4"
    assert kinds["seeding_point_moved"]["to"] == f"q{final.trajectory.sections.e}" != "q4"
    planned = load_design(EXAMPLES / "sugarcane_seeder.toml").trajectory.points
    move = max(((a[0] - b[0]) ** 2 + (a[1] - b[1]) ** 2) ** 0.5
               for a, b in zip(planned, final.trajectory.points, strict=True))
    if move > 1e-6:  # one generation may keep the planned points
        assert kinds["points_moved"]["largest_mm"] == pytest.approx(move, abs=1e-3)
    else:
        assert "points_moved" not in kinds
    assert sum(line.startswith("  caveat: ") for line in printed) == len(s["caveats"])
    assert "caveat: seeding point e moved from q4" in html


def test_design_of_the_manufacturable_transplanter_ends_in_workshop_files(tmp_path, capsys):
    """Every objective and manufacturability check is met at full resolution, so no
    optimization runs; the teeth are cut with the design's stub 25 deg tooth system, the
    gears pass every check (no finding), each STL is one body: exit 0."""
    import trimesh

    out = tmp_path / "o"
    rc = main(["design", str(EXAMPLES / "rice_transplanter_manufacturable.toml"), "--out",
               str(out), "--quiet"])
    s = json.loads((out / "summary.json").read_text())
    assert rc == 0, s["verdict"]
    assert s["verdict"] == {"status": "ok", "ok": True, "exit_code": 0, "failed": []}
    assert [st["stage"] for st in s["stages"]] == ["check", "gears"]
    assert all(c["ok"] for c in s["final_checks"]) and len(s["final_checks"]) == 16
    rec = json.loads((out / "gears" / "verification.json").read_text())
    assert rec["verdict"]["ok"] and rec["findings"] == []
    for name in ("internal", "planet"):
        mesh = trimesh.load(out / "gears" / f"{name}.stl")
        assert mesh.is_watertight and mesh.volume > 0 and len(mesh.split()) == 1
        assert (out / "gears" / f"{name}.dxf").stat().st_size > 1000
    assert "every objective and manufacturability check met" in (out / "report.html").read_text()
    assert not (out / "optimize").exists()
    assert capsys.readouterr().out.strip().splitlines()[-1].startswith("verdict: ok")


def _planetary_file(tmp_path, height_min: float, variables: bool) -> str:
    import tomllib

    import tomli_w

    doc = tomllib.loads((EXAMPLES / "rotary_transplanter_elliptic.toml").read_text())
    doc["limits"]["path_height_mm"] = {"min": height_min}
    if variables:
        doc["optimize"] = {"samples": 360, "variables": {
            "train.pairs.0.driver.eccentricity": [0.1, 0.3], "arm.length_mm": [150.0, 200.0]}}
    path = tmp_path / f"p{int(height_min)}{'v' if variables else ''}.toml"
    path.write_text(tomli_w.dumps(doc))
    return str(path)


def test_design_of_a_general_planetary_train(tmp_path, capsys):
    """`design` on a planetary file: the limit it misses (path height 239 mm < 270 mm) is
    met by moving the fields its [optimize.variables] frees, the teeth are cut and checked,
    the report written, exit 0; without free fields the job says why it did not optimize
    and ends NOT MET (exit 4); a [trajectory] file is sent to `plantmech inverse` (exit 2)."""
    out = tmp_path / "o"
    assert main(["design", _planetary_file(tmp_path, 270.0, True), "--out", str(out),
                 "--quiet", "--generations", "4"]) == 0
    s = json.loads((out / "summary.json").read_text())
    assert [st["stage"] for st in s["stages"]] == ["check", "optimize", "gears"]
    final = {c["name"]: c for c in s["final_checks"]}
    assert final["path_height_mm"]["ok"] and final["path_height_mm"]["value"] > 270.0
    best = load_design(out / "design.toml")
    assert best.arm.length_mm != 160.0 or best.train.pairs[0].driver.eccentricity != 0.18
    assert {"sun.dxf", "idler1.dxf", "planet.dxf"} <= {p.name for p in (out / "gears").iterdir()}
    assert (out / "report.html").stat().st_size > 50_000
    capsys.readouterr()
    out2 = tmp_path / "o2"
    assert main(["design", _planetary_file(tmp_path, 270.0, False), "--out", str(out2),
                 "--quiet"]) == 4
    printed = capsys.readouterr().out
    assert "[optimize.variables]" in printed and "NOT MET" in printed
    inverse_file = EXAMPLES / "planetary" / "first_order_inverse.toml"
    assert main(["design", str(inverse_file), "--out", str(tmp_path / "o3")]) == 2
    assert "plantmech inverse" in capsys.readouterr().err
