"""plantmech design: the whole job with one verdict."""

import json

from plantmech.design import load_design
from plantmech.interfaces.cli import main
from tests.conftest import EXAMPLES


def test_design_of_an_uncuttable_seeder_says_so_and_cuts_nothing(tmp_path, capsys):
    src = tmp_path / "seeder.toml"
    text = (EXAMPLES / "sugarcane_seeder.toml").read_text()
    src.write_text(text)
    out = tmp_path / "o"
    rc = main(["design", str(src), "--out", str(out), "--generations", "1", "--quiet"])
    assert src.read_text() == text
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
    assert capsys.readouterr().out.strip().splitlines()[-1].startswith("verdict: NOT MET")
