"""A gear pair file (issue 35) through the commands: `plantmech init pair` writes it,
`forward`, `gears` and `verify` take it by the general train's path; a law that cannot be a
gear pair is refused with exit 2 naming the field and the driver angle."""

from __future__ import annotations

import json
import tomllib

import numpy as np
import pytest
from scipy.special import ellipe

from plantmech.interfaces.cli import main
from tests.conftest import write_toml

E = 0.35


@pytest.fixture(scope="module")
def pair_file(tmp_path_factory):
    d = tmp_path_factory.mktemp("pair")
    assert main(["init", "pair", str(d), "--name", "pair.toml"]) == 0
    return d / "pair.toml"


def test_forward_gears_verify_on_a_pair_file(pair_file, tmp_path, capsys):
    fwd = tmp_path / "fwd"
    assert main(["forward", str(pair_file), "--out", str(fwd), "--no-plots"]) == 0
    s = json.loads((fwd / "summary.json").read_text())
    (p,) = s["pairs"]
    A = 33 * np.pi / (4 * ellipe(E**2))  # module 1, 33 teeth: perimeter 33 pi
    assert p["centre_distance_mm"] == pytest.approx(2 * A, rel=1e-9)
    assert p["ratio_range"][0] == pytest.approx((1 - E) / (1 + E), rel=1e-9)
    assert p["ratio_range"][1] == pytest.approx((1 + E) / (1 - E), rel=1e-9)
    gears = tmp_path / "gears"
    assert main(["gears", str(pair_file), "--out", str(gears), "--backlash", "0.1"]) == 0
    rec = json.loads((gears / "verification.json").read_text())
    assert sorted(g["teeth"] for g in rec["gears"]) == [33, 33]
    (mesh,) = rec["mesh"]
    assert mesh["max_interference_mm"] <= 1e-3
    assert 0.09 < mesh["min_circumferential_backlash_mm"] <= \
        mesh["max_circumferential_backlash_mm"] < 0.2
    ver = tmp_path / "verify"
    code = main(["verify", str(pair_file), "--gears", str(gears), "--out", str(ver),
                 "--no-loads", "--no-plots", "--steps", "180"])
    assert code == 0
    v = json.loads((ver / "verification.json").read_text())
    assert v["verdict"]["status"] == "ok"


def test_refused_law_exits_2_naming_the_angle(pair_file, tmp_path, capsys):
    doc = tomllib.loads(pair_file.read_text())
    law = doc["train"]["pairs"][0]["law"]
    law.pop("constants")
    law["follower_angle"] = "t + 2*sin(t)"  # ratio 1 + 2 cos t: through 0 at 120 deg
    bad = write_toml(tmp_path, doc, "bad.toml")
    for command in (["forward"], ["gears"]):
        capsys.readouterr()
        assert main([*command, str(bad), "--out", str(tmp_path / command[0])]) == 2
        err = capsys.readouterr().err
        assert "train.pairs.0.law" in err and "changes sign at driver angle 120.000 deg" in err
        assert "Traceback" not in err
        assert not (tmp_path / command[0]).exists()


def test_refused_grammar_and_teeth_exit_2(pair_file, tmp_path, capsys):
    doc = tomllib.loads(pair_file.read_text())
    doc["train"]["pairs"][0]["law"]["follower_angle"] = "__import__('os').getcwd()"
    bad = write_toml(tmp_path, doc, "bad.toml")
    assert main(["forward", str(bad), "--out", str(tmp_path / "o")]) == 2
    assert "not one of the functions" in capsys.readouterr().err
    doc = tomllib.loads(pair_file.read_text())
    doc["train"]["pairs"][0]["turns"] = [1, 2]
    bad = write_toml(tmp_path, doc, "bad2.toml")
    assert main(["forward", str(bad), "--out", str(tmp_path / "o")]) == 2
    assert "does not divide by the follower's turns 2" in capsys.readouterr().err


def test_app_evaluates_and_edits_a_pair_file(pair_file):
    """The app's scene of a pair file (the general train's path) and its editable numbers,
    the law's named constants among them."""
    from plantmech.app.server import editable_parameters, evaluate
    from plantmech.design import load_design

    d = load_design(pair_file)
    out = evaluate(d)
    A = 33 * np.pi / (4 * ellipe(E**2))
    assert out["centre_distance_mm"] == [pytest.approx(2 * A, rel=1e-9)]
    assert all(c["ok"] for c in out["checks"])
    fields = {p["field"]: p for p in editable_parameters(d)}
    k = fields["train.pairs.0.law.constants.k"]
    assert k["value"] == pytest.approx((1 + E) / (1 - E)) and k["min"] < k["value"] < k["max"]


def test_verify_names_a_held_carrier_the_frame(pair_file, shared, tmp_path, capsys):
    """A pair on fixed centres (``carrier.held``): nothing turns at the carrier, so neither
    the printed lines, nor verification.json, nor the report call anything there the
    carrier. The angles are the driver's (the sun's) turn; the torque on the held carrier
    is the frame's, holding the centres (no input): the input torque is the sun's alone
    (before, the frame's reaction was added to it as a "carrier" drive)."""
    from plantmech.design import load_design
    from plantmech.outputs.report import planetary_animation
    from plantmech.trains.model import simulate
    from plantmech.trains.spec import build_from_design
    from tests.conftest import EXAMPLES, gears_cut

    gears, code = gears_cut(shared, "init-pair-backlash-0.1", pair_file, "--backlash", "0.1")
    assert code == 0
    ver = tmp_path / "verify"
    assert main(["verify", str(pair_file), "--gears", str(gears), "--out", str(ver),
                 "--steps", "180"]) == 0
    printed = capsys.readouterr().out
    said = [ln for ln in printed.splitlines() if "carrier" in ln]
    assert said == ["  carrier held: the frame (fixed centres); the angles are the driver's "
                    "(the sun's) turn"], said
    assert "(at driver " in printed and "at arm 1, driver " in printed
    assert "loads at 360 deg/s of the driver" in printed
    assert "frame holding the fixed centres" in printed
    rec = json.loads((ver / "verification.json").read_text())
    assert rec["angles_of"] == "driver" and rec["carrier"].startswith("held: the frame")
    loads = rec["loads"]
    tq = loads["input_torque_N_m"]
    assert set(tq) == {"sun", "min", "max"}  # the sun drives; the frame is no input
    assert (tq["min"], tq["max"]) == (tq["sun"]["min"], tq["sun"]["max"])
    assert set(loads["holding_torque_N_m"]) == {"frame"}
    assert "the frame held (fixed centres), driven sun" in loads["model"]
    assert "carrier" not in loads["model"]
    # the report's animation (forward, gears and design --report)
    design = load_design(pair_file)
    a = planetary_animation(design, simulate(build_from_design(design), 360))
    assert a.title.endswith("one driver turn") and a.origin == "driver axis O (fixed)"
    assert a.frame_labels[0].startswith("driver angle")
    assert [lk["label"] for lk in a.links if lk["label"]] == ["frame (fixed centres) and arm 1"]
    # a train whose carrier turns keeps its words
    other = load_design(EXAMPLES / "planetary" / "rice_transplanter.toml")
    b = planetary_animation(other, simulate(build_from_design(other), 360))
    assert b.title.endswith("one carrier turn") and b.origin == "carrier axis O"
    assert b.frame_labels[0].startswith("carrier angle")
