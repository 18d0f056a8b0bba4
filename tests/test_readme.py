"""The README a newcomer follows: its quick start is exactly `make run` then `make test`, every
`plantmech` command it shows parses, the commands table names every command, and its first
design (the block under "Your first design") runs as written, in an empty directory, to cut
gears, the report and verdict ok."""

from __future__ import annotations

import json
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

from plantmech.interfaces.cli import build_parser
from tests.conftest import ROOT

README = (ROOT / "README.md").read_text(encoding="utf-8")


def _section(title: str) -> str:
    return README.split(f"\n## {title}\n", 1)[1].split("\n## ", 1)[0]


def _blocks(text: str) -> list[list[str]]:
    """The sh code blocks of ``text``, each as its command lines (comments dropped)."""
    out = []
    for block in re.findall(r"```sh\n(.*?)```", text, re.S):
        lines = [ln.split("#", 1)[0].strip() for ln in block.splitlines()]
        out.append([ln for ln in lines if ln])
    return out


def test_quick_start_is_make_run_then_make_test():
    assert _blocks(_section("Quick start (a clone, Python >= 3.11)")) == [["make run",
                                                                          "make test"]]


def test_every_plantmech_command_shown_parses():
    parser = build_parser()
    shown = [ln for block in _blocks(README) for ln in block if ln.startswith("plantmech ")]
    assert len(shown) >= 2
    for line in shown:
        parser.parse_args(shlex.split(line)[1:])  # a usage error exits: the test fails


def test_the_commands_table_names_every_command():
    sub = next(a for a in build_parser()._actions if getattr(a, "choices", None)
               and "design" in a.choices)
    table = _section("Commands")
    for name in sub.choices:
        assert f"`plantmech {name}" in table, name
    for topic in re.findall(r"`plantmech docs ([a-z-]+)`", README):
        assert (ROOT / "docs" / f"{topic}.md").is_file(), topic


def test_first_design_runs_as_written(tmp_path):
    """The README's first design, command by command, with the installed `plantmech`, in
    an empty directory: exit 0, the gears cut, the report and design.toml written."""
    commands = _blocks(_section("Your first design"))[0]
    assert commands == ["plantmech init transplanter my",
                        "plantmech design my/transplanter.toml --out out"]
    exe = Path(sys.executable).with_name("plantmech")
    for line in commands:
        argv = shlex.split(line)
        if argv[0] == "plantmech" and argv[1] == "design":
            argv.append("--quiet")  # no progress bars in the test log
        r = subprocess.run([str(exe)] + argv[1:], cwd=tmp_path, capture_output=True,
                           text=True, timeout=600)
        assert r.returncode == 0, (line, r.stdout[-2000:], r.stderr[-2000:])
    out = tmp_path / "out"
    assert r.stdout.rstrip().splitlines()[-1].startswith("verdict: ok")
    summary = json.loads((out / "summary.json").read_text())
    assert summary["verdict"]["exit_code"] == 0
    for gear in ("internal", "planet"):
        assert (out / "gears" / f"{gear}.dxf").stat().st_size > 1000
    assert (out / "report.html").stat().st_size > 10_000
    design = (out / "design.toml").read_text()
    assert "# Starting design written by `plantmech init transplanter`" in design


@pytest.mark.parametrize("extra", ["app", "studies", "loads"])
def test_each_extra_is_in_the_install_table(extra):
    assert f"`[{extra}]`" in _section("Install")
