"""The unit-from-the-name rule (``plantmech.units.unit_of``): written once, read by the app's
parameter lists and the planetary optimizer's variables."""

import re
import tomllib
from pathlib import Path

from plantmech.design import load_design
from plantmech.units import unit_of

ROOT = Path(__file__).resolve().parents[1]
ELLIPTIC = ROOT / "examples" / "rotary_transplanter_elliptic.toml"


def test_unit_of_reads_the_suffix_of_a_name_or_dotted_path():
    assert unit_of("train.pairs.0.direction_deg") == "deg"
    assert unit_of("arm.length_mm") == "mm"
    assert unit_of("initial_angle_deg") == "deg"
    assert unit_of("train.pairs.0.driver.eccentricity") == ""
    assert unit_of("arms") == ""
    # only the end counts: a "_deg" or "_mm" inside a name is not a unit
    assert unit_of("deg_mm_count") == ""
    assert unit_of("x_mm.ratio") == ""
    # an item of a list field carries the list's unit
    assert unit_of("train.pairs.0.driver.radii_mm.3") == "mm"
    assert unit_of("train.pairs.0.driver.cos_mm.12") == "mm"
    assert unit_of("pairs.0") == ""


def test_the_rule_is_written_once():
    """No other module of src/plantmech decides a unit by ``endswith("_mm")`` (the app's server
    had it twice and the planetary optimizer once)."""
    pattern = re.compile(r"""endswith\(\s*["']_mm["']""")
    found = [str(p.relative_to(ROOT)) for p in sorted((ROOT / "src").rglob("*.py"))
             if pattern.search(p.read_text())]
    assert found == []


def _with_variables() -> object:
    doc = tomllib.loads(ELLIPTIC.read_text())
    doc["optimize"] = {"variables": {"train.pairs.0.driver.eccentricity": [0.1, 0.35],
                                     "arm.length_mm": [140.0, 200.0],
                                     "carrier.initial_angle_deg": [-30.0, 30.0]}}
    return load_design(doc, name="elliptic.toml")


def test_the_app_and_the_optimizer_name_the_same_units():
    from plantmech.app.server import _planetary_parameters
    from plantmech.optimize.planetary_problem import PlanetaryProblem

    design = _with_variables()
    app = {p["field"]: p["unit"] for p in _planetary_parameters(design)}
    opt = {v.name: v.unit for v in PlanetaryProblem(design, manufacturability=False).variables}
    expected = {"train.pairs.0.driver.eccentricity": "", "arm.length_mm": "mm",
                "carrier.initial_angle_deg": "deg"}
    assert app == expected and opt == expected
    # with no [optimize.variables] the app lists every number of the file, each by its name
    every = _planetary_parameters(load_design(ELLIPTIC))
    assert {p["unit"] for p in every} == {"", "mm", "deg"}
    for p in every:
        assert p["unit"] == unit_of(p["field"])
        if p["unit"] == "deg":  # angles get +-45 deg, the rest +-25 %
            assert (p["min"], p["max"]) == (p["value"] - 45.0, p["value"] + 45.0)


def test_the_khv_panel_lists_every_number_of_its_tables_by_its_unit():
    """The K-H-V example (no optimizer bounds of its own) is edited by its numbers: the
    sun's radii item by item, the carrier's angle, the arm and the seedling box, each in
    its unit and with its current value inside its box; counts (teeth, arms) are not
    edited. The same for the K-H-V train written as a general file."""
    from plantmech.app.server import editable_parameters
    from plantmech.design_planetary import get_path

    for path, sun in (("rice_transplanter_khv.toml", "sun_gear"),
                      ("planetary/rice_transplanter_khv.toml", "train.pairs.0.driver")):
        design = load_design(ROOT / "examples" / path)
        params = editable_parameters(design)
        fields = [p["field"] for p in params]
        assert [f"{sun}.radii_mm.{i}" for i in range(8)] == [
            f for f in fields if ".radii_mm." in f]
        assert "carrier.initial_angle_deg" in fields
        assert not any(f.endswith(("teeth", "arms")) for f in fields)
        for p in params:
            node = design
            for part in p["field"].split("."):
                node = node[int(part)] if part.isdigit() else getattr(node, part)
            assert p["value"] == node and p["min"] < node < p["max"]
            assert p["unit"] == unit_of(p["field"])
        if path.startswith("planetary"):
            assert get_path(design, "train.pairs.0.driver.radii_mm.4") == 19.6
