"""plantmech design: the whole job with one verdict."""

import json

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
    assert capsys.readouterr().out.strip().splitlines()[-1].startswith("verdict: NOT MET")


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
    assert rec["verdict"] == "ok" and rec["findings"] == []
    for name in ("internal", "planet"):
        mesh = trimesh.load(out / "gears" / f"{name}.stl")
        assert mesh.is_watertight and mesh.volume > 0 and len(mesh.split()) == 1
        assert (out / "gears" / f"{name}.dxf").stat().st_size > 1000
    assert "every objective and manufacturability check met" in (out / "report.html").read_text()
    assert not (out / "optimize").exists()
    assert capsys.readouterr().out.strip().splitlines()[-1].startswith("verdict: ok")
