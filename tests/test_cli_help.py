"""The command line a newcomer meets: ``--help`` leads with ``design``; ``plantmech docs``
prints the shipped pages; a misspelled command, option, choice, design field or file name
gets the command's own usage and a "did you mean"."""

from __future__ import annotations

import pytest

from plantmech.interfaces.cli import build_parser, main
from plantmech.typos import close_matches, did_you_mean
from tests.conftest import ROOT, write_toml


def _usage_error(argv, capsys) -> str:
    with pytest.raises(SystemExit) as exc:
        main(argv)
    assert exc.value.code == 2
    return capsys.readouterr().err


def test_help_leads_with_design(capsys):
    with pytest.raises(SystemExit):
        main(["--help"])
    out = capsys.readouterr().out
    listed = [line.split()[0] for line in out.split("COMMAND\n", 1)[1].splitlines()
              if line.startswith("    ") and not line.startswith("      ")]
    assert listed[:3] == ["design", "init", "docs"]
    assert "plantmech design my/transplanter.toml --out out" in out
    assert "plantmech inverse" not in out.split("options:")[1]


def test_no_command_says_where_to_start(capsys):
    err = _usage_error([], capsys)
    assert "plantmech design my/transplanter.toml --out out" in err


def test_did_you_mean_rule():
    assert did_you_mean("desing", ["design", "docs"]) == " (did you mean 'design'?)"
    assert did_you_mean("zzz", ["design"]) == ""
    assert close_matches("Name", ["name", "game"])[0] == "name"


def test_misspelled_command_and_choice(capsys):
    err = _usage_error(["desing", "x.toml"], capsys)
    assert "invalid choice: 'desing'" in err and "(did you mean 'design'?)" in err
    err = _usage_error(["optimize", "x.toml", "--out", "o", "--problem", "transplantr"],
                       capsys)
    assert "usage: plantmech optimize" in err and "did you mean 'transplanter'?" in err


def test_misspelled_option_gets_the_commands_usage(capsys):
    err = _usage_error(["gears", "x.toml", "--out", "o", "--modle", "3"], capsys)
    assert err.startswith("usage: plantmech gears")
    assert "unrecognized arguments: --modle 3 (did you mean '--module'?)" in err
    err = _usage_error(["forward", "x.toml", "--out", "o", "--no-plts", "--reprot"], capsys)
    assert err.startswith("usage: plantmech forward")
    assert "'--no-plots'" in err and "'--report'" in err


def test_misspelled_design_field_and_file(tmp_path, capsys):
    doc = {"mechanism": "rice_transplanter", "nmae": "x", "internal_gear": {
        "radii_mm": [40, 45, 50, 45], "lobse": 4}}
    path = write_toml(tmp_path, doc, "design.toml")
    assert main(["forward", path, "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "field 'nmae': unknown field (did you mean 'name'?)" in err
    assert "field 'internal_gear.lobse': unknown field (did you mean 'lobes'?)" in err
    assert main(["forward", str(tmp_path / "design.tml"), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "design.tml: no such design file (did you mean 'design.toml'?)" in err


def test_docs_lists_and_prints_the_shipped_pages(capsys):
    pages = sorted(p.stem for p in (ROOT / "docs").glob("*.md"))
    assert main(["docs"]) == 0
    out = capsys.readouterr().out
    for name in pages:
        assert f"  {name} " in out
    assert main(["docs", "design-file"]) == 0
    assert capsys.readouterr().out == (ROOT / "docs" / "design-file.md").read_text()
    assert main(["docs", "desgin-file"]) == 2
    assert "did you mean 'design-file'?" in capsys.readouterr().err


def test_every_command_is_registered_once():
    sub = next(a for a in build_parser()._actions if hasattr(a, "choices") and a.choices
               and "design" in a.choices)
    assert len(set(sub.choices)) == len(sub.choices) >= 12
