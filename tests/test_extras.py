"""plantmech.extras: a command whose optional dependencies are missing stops before writing
anything, names the extra and gives the exact pip line (exit 2); the extras pyproject
declares are the ones the commands ask for."""

import tomllib

import pytest

from plantmech import extras
from plantmech.interfaces.cli import main
from tests.conftest import EXAMPLES, ROOT


@pytest.fixture
def missing(monkeypatch):
    """Make an extra look uninstalled (its first module replaced by one that is nowhere)."""

    def hide(extra):
        monkeypatch.setitem(extras.EXTRAS, extra, ("plantmech_no_such_module",))

    return hide


def test_pyproject_declares_each_extra_and_all():
    meta = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    opt = meta["optional-dependencies"]
    assert set(extras.EXTRAS) <= set(opt)
    assert opt["all"] == ["plantmech[app,studies,loads]"]
    assert "plantmech[all]" in opt["dev"]
    base = " ".join(meta["dependencies"])
    for extra, modules in extras.EXTRAS.items():  # none of an extra's modules in the base
        for m in modules:
            assert m not in base, (extra, m)
        assert any(m in " ".join(opt[extra]) for m in modules)


def test_installed_extras_are_found():
    for extra in extras.EXTRAS:  # the development install has them all (.[dev])
        assert extras.available(extra), extra
        extras.require(extra, "x")


def test_missing_extra_message():
    with pytest.raises(extras.MissingExtra) as e:
        extras.EXTRAS["_t"] = ("plantmech_no_such_module",)
        try:
            extras.require("_t", "'plantmech x'")
        finally:
            del extras.EXTRAS["_t"]
    assert str(e.value) == ("'plantmech x' needs the optional dependencies plantmech[_t] "
                            "(plantmech_no_such_module is not installed): "
                            "pip install 'plantmech[_t]'")


def test_study_without_extra_exit_2_nothing_written(missing, tmp_path, capsys):
    missing("studies")
    out = tmp_path / "o"
    rc = main(["study", str(EXAMPLES / "sugarcane_seeder.toml"), "--spec",
               str(EXAMPLES / "studies" / "seeder_tolerance.toml"), "--out", str(out)])
    err = capsys.readouterr().err
    assert rc == 2 and "pip install 'plantmech[studies]'" in err
    assert "'plantmech study' needs" in err and not out.exists()


def test_report_of_a_study_without_extra(missing, tmp_path, capsys):
    missing("studies")
    assert main(["report", str(tmp_path)]) == 2
    assert "pip install 'plantmech[studies]'" in capsys.readouterr().err


def test_app_without_extra(missing, capsys):
    missing("app")
    assert main(["app", "--no-browser"]) == 2
    assert "pip install 'plantmech[app]'" in capsys.readouterr().err
