"""The design-file reference and the JSON Schema (design_reference.py, schema_cli.py)."""

import json

from plantmech.design import MECHANISMS
from plantmech.design_reference import json_schema, markdown_reference, undocumented_fields
from plantmech.interfaces.cli import main
from tests.conftest import ROOT


def test_every_field_is_described():
    assert undocumented_fields() == []


def test_committed_reference_is_up_to_date():
    committed = (ROOT / "docs" / "design-file.md").read_text(encoding="utf-8")
    assert committed == markdown_reference(), (
        "docs/design-file.md is stale: run `make docs` (python -m plantmech.design_reference "
        "> docs/design-file.md)")


def test_reference_names_every_field_with_limits_and_defaults():
    md = markdown_reference()
    assert "| `points` | array of [number, number] | **required** |" in md
    assert "| `samples` | integer | `3600` | >= 90, <= 20000 |" in md
    assert "L1: carrier length" in md and "sigma: lobe phase" in md
    for mech in MECHANISMS:
        assert f'## `mechanism = "{mech}"`' in md


def test_schema_command_and_discriminated_union(tmp_path, capsys):
    assert main(["schema"]) == 0
    schema = json.loads(capsys.readouterr().out)
    assert set(schema["discriminator"]["mapping"]) == set(MECHANISMS)
    one = json_schema("rice_transplanter")
    assert one["properties"]["mechanism"]["const"] == "rice_transplanter"
    assert one["$defs"]["Arm"]["properties"]["S_mm"]["exclusiveMinimum"] == 0
    out = tmp_path / "s.json"
    assert main(["schema", "sugarcane_seeder", "--out", str(out)]) == 0
    assert json.loads(out.read_text())["title"] == "SeederDesign"
    assert main(["schema", "sugarcane_seeder", "--out", str(out)]) == 2
    assert "--force" in capsys.readouterr().err
    assert main(["schema", "windmill"]) == 2
