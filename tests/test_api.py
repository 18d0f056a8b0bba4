"""The Python API of ``import plantmech`` (issue 17 item 6): lazy exports that
``help(plantmech)`` documents, and examples/api.ipynb executed cell by cell."""

from __future__ import annotations

import json
import pydoc
import subprocess
import sys

import pytest

from tests.conftest import EXAMPLES, ROOT


def test_import_is_lean_and_exports_are_lazy():
    code = ("import sys, plantmech; heavy = [m for m in ('numpy', 'scipy', 'matplotlib', "
            "'pydantic', 'pymoo') if m in sys.modules]; print(heavy); "
            "plantmech.load_design; print('pydantic' in sys.modules)")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert r.stdout.split("\n")[:2] == ["[]", "True"]


def test_help_lists_every_entry_point():
    import plantmech
    import plantmech.optimize.jobs  # noqa: F401 - a subpackage import must not shadow an export

    text = pydoc.render_doc(plantmech, renderer=pydoc.plaintext)
    for name in plantmech._EXPORTS:
        assert name in text
        assert callable(getattr(plantmech, name))
    assert "Liu et al. 2023" in text and "Zhou et al. 2022" in text


def test_unknown_attribute_is_an_attribute_error():
    import pytest

    import plantmech

    with pytest.raises(AttributeError, match="no_such"):
        plantmech.no_such  # noqa: B018


def test_examples_are_package_data_behind_the_repository_symlink():
    import plantmech

    assert (ROOT / "examples").is_symlink()
    shipped = plantmech.list_examples()
    assert shipped == (sorted(p.stem for p in EXAMPLES.glob("*.toml"))
                       + sorted(f"studies/{p.stem}" for p in EXAMPLES.glob("studies/*.toml"))
                       + sorted(f"planetary/{p.stem}" for p in
                                EXAMPLES.glob("planetary/*.toml")))
    assert "studies/seeder_tolerance" in shipped
    with pytest.raises(KeyError, match="did you mean 'studies/seeder_tolerance'"):
        plantmech.example_path("studies/seeder_tolerence")
    for name in shipped:
        assert plantmech.example_path(name).read_bytes() == (EXAMPLES / f"{name}.toml").read_bytes()


def test_notebook_runs(tmp_path, monkeypatch):
    """Every code cell of examples/api.ipynb in order, in one namespace (as a kernel
    would); then its results checked against the jobs run here independently."""
    import matplotlib

    matplotlib.use("Agg")
    monkeypatch.chdir(tmp_path)
    nb = json.loads((EXAMPLES / "api.ipynb").read_text())
    assert nb["nbformat"] == 4
    ns: dict = {}
    for cell in nb["cells"]:
        if cell["cell_type"] == "code":
            exec(compile("".join(cell["source"]), "api.ipynb", "exec"), ns)  # noqa: S102
    import plantmech as pm

    t4 = pm.run_seeder_forward(pm.load_design(EXAMPLES / "sugarcane_table4.toml"))
    assert [c["value"] for c in ns["table4"].summary["objectives"]] == \
        [c["value"] for c in t4.summary["objectives"]]
    assert ns["inverse"].summary["feasible"] is True
    assert set(ns["figures"]) == {"trajectories.png", "speed.png", "attitude.png",
                                  "pitch_curves.png"}
    assert [p.name for p in ns["written"]] == ["report.html", "mechanism.gif"]
    assert all(p.stat().st_size > 1000 for p in ns["written"])


def test_no_export_is_shadowed_by_a_submodule():
    """Importing plantmech.X sets the attribute X on the package: an export of that name
    would turn into the module."""
    import pkgutil

    import plantmech

    submodules = {m.name for m in pkgutil.iter_modules(plantmech.__path__)}
    assert "optimize" in submodules
    assert not submodules & set(plantmech._EXPORTS)
