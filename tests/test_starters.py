"""plantmech init / plantmech.starters: commented starting designs that load, never
overwriting a file."""

from __future__ import annotations

import pytest

from plantmech.design import load_design
from plantmech.interfaces.cli import main
from plantmech.starters import STARTERS, example_path, starter_text, write_starter
from tests.conftest import EXAMPLES


@pytest.mark.parametrize("kind", list(STARTERS))
def test_starter_is_the_example_under_a_commented_header(kind, tmp_path):
    path = write_starter(kind, tmp_path / "new" / "dir")
    text = path.read_text()
    example = (EXAMPLES / f"{STARTERS[kind].example}.toml").read_text()
    head = text[: len(text) - len(example)]
    assert text.endswith(example)
    assert all(line.startswith("#") for line in head.splitlines())
    assert f"plantmech forward {path} --out out/forward --report" in head
    # the first command to run is the whole job, and the docs are named as a pip user has them
    then = head.split("# Then run")[1].splitlines()[1]
    assert then == f"#   plantmech design {path} --out out/design"
    assert "plantmech docs design-file" in head and "docs/" not in head
    # the written file is a valid design, the same as the example
    assert load_design(path) == load_design(example_path(STARTERS[kind].example))


def test_init_never_overwrites(tmp_path, capsys):
    assert main(["init", "transplanter", str(tmp_path)]) == 0
    before = (tmp_path / "transplanter.toml").read_text()
    (tmp_path / "transplanter.toml").write_text(before + "# mine\n")
    assert main(["init", "transplanter", str(tmp_path)]) == 2
    assert "never overwrites" in capsys.readouterr().err
    assert (tmp_path / "transplanter.toml").read_text().endswith("# mine\n")
    assert main(["init", "seeder", str(tmp_path), "--name", "mine.toml"]) == 0
    assert (tmp_path / "mine.toml").is_file()


def test_unknown_kind_is_an_input_error(tmp_path, capsys):
    with pytest.raises(SystemExit) as exc:
        main(["init", "tractor", str(tmp_path)])
    assert exc.value.code == 2 and "invalid choice: 'tractor'" in capsys.readouterr().err
    assert starter_text("seeder").startswith("# Starting design written by")


def test_study_specs_are_starters_too(tmp_path, capsys):
    """`plantmech init studies/<name> DIR`: the shipped spec under a header naming the
    starting design it runs on and the command; the written spec loads as the shipped one,
    and the command in its header parses."""
    import shlex

    from plantmech.interfaces.cli import build_parser
    from plantmech.starters import study_kinds
    from plantmech.studies.spec import load_spec

    kinds = study_kinds()
    assert kinds == sorted(f"studies/{p.stem}" for p in (EXAMPLES / "studies").glob("*.toml"))
    for kind in kinds:
        assert main(["init", kind, str(tmp_path)]) == 0
        path = tmp_path / f"{kind.split('/')[1]}.toml"
        text = path.read_text()
        assert text.endswith((EXAMPLES / f"{kind}.toml").read_text())
        assert load_spec(path) == load_spec(EXAMPLES / f"{kind}.toml")
        run = next(ln for ln in text.splitlines() if ln.startswith("#   plantmech study"))
        build_parser().parse_args(shlex.split(run[2:])[1:])
        design_kind = text.split("`plantmech init ")[2].split(" DIR")[0]
        assert design_kind in STARTERS
    assert main(["init", "studies/seeder_tolerance", str(tmp_path)]) == 2
