"""The layers read one way (docs/architecture.md, "Layers"): no module of src/plantmech imports
a module of a higher layer, at module level or inside a function.

Every module has a rank (LAYERS, lowest first, the order of docs/architecture.md); each
``import`` and ``from ... import`` anywhere in a module's syntax tree (``ast.walk``: module
level, functions, methods, ``if TYPE_CHECKING`` blocks) is resolved to the plantmech module it
loads, and an import of a higher rank is reported as "a.b (layer X) imports c.d (layer Y)".
Modules of one layer may import each other.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src"

# (layer name, module prefixes), lowest first. A module belongs to the layer of its longest
# matching prefix ("plantmech.gears" matches plantmech.gears and plantmech.gears.teeth).
LAYERS: tuple[tuple[str, tuple[str, ...]], ...] = (
    # the package itself: __version__ and the lazy public names, which it imports by string
    # on first use (importlib), never by an import statement
    ("package", ("plantmech",)),
    # plantmech.kinds: the registry of mechanism kinds, naming each kind's hooks by string
    # ("module:function", imported on use), so it imports nothing above the design layer
    ("design", ("plantmech.design", "plantmech.design_planetary", "plantmech.design_reference",
                "plantmech.design_law",
                "plantmech.units", "plantmech.kinds")),
    # the process's signal record (SIGINT/SIGTERM/SIGHUP received, pool workers' initializer):
    # it imports nothing of the package, and the optimizer's pools and every writer read it
    ("process", ("plantmech.outputs.signals",)),
    ("geometry", ("plantmech.geometry",)),
    ("gears", ("plantmech.gears",)),
    ("trains", ("plantmech.trains",)),
    ("mechanisms", ("plantmech.mechanisms",)),
    ("objectives", ("plantmech.objectives",)),
    ("verification", ("plantmech.verification",)),
    ("contact", ("plantmech.contact",)),
    ("optimize", ("plantmech.optimize",)),
    ("studies", ("plantmech.studies",)),
    ("outputs", ("plantmech.outputs",)),
    # job wiring: read a design, call the layers, collect and write the results. The
    # optimization job (optimize/jobs.py: problem, runner, report, best.toml) and the
    # multi-start study (studies/multistart.py: N optimization jobs) are jobs too
    # (plantmech.starters writes a starting design file through outputs.files.OutputFile)
    ("jobs", ("plantmech.jobs", "plantmech.workflows", "plantmech.pipeline", "plantmech.starters",
              "plantmech.optimize.jobs", "plantmech.studies.multistart")),
    # the browser app is an interface beside the CLI; `plantmech app` (interfaces/app_cli.py)
    # starts it, and the app never imports the CLI
    ("app", ("plantmech.app",)),
    ("interfaces", ("plantmech.interfaces",)),
)
RANK = {prefix: rank for rank, (_, prefixes) in enumerate(LAYERS) for prefix in prefixes}
NAME = [name for name, _ in LAYERS]

# (importer, imported module): upward imports kept on purpose, each with its reason. None
# now: the seeder's section location and population evaluation moved from workflows.py to
# objectives/seeder_design.py (issue 16); an entry added here must name its reason.
ALLOWED: dict[tuple[str, str], str] = {}


def module_name(path: Path, src: Path) -> str:
    """Dotted name of the module at `path` under the source root `src`."""
    parts = list(path.relative_to(src).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


def layer_of(module: str) -> int | None:
    """Rank of `module` (index into LAYERS) by its longest matching prefix, or None."""
    parts = module.split(".")
    for end in range(len(parts), 0, -1):
        rank = RANK.get(".".join(parts[:end]))
        if rank is not None:
            return rank
    return None


def _is_module(dotted: str, src: Path) -> bool:
    base = src.joinpath(*dotted.split("."))
    return base.with_suffix(".py").is_file() or (base / "__init__.py").is_file()


def imported_modules(path: Path, src: Path,
                     package: str = "plantmech") -> list[tuple[str, str, int]]:
    """Every `package` module that the file at `path` imports anywhere in its syntax tree, as
    (dotted module, what is imported, line). ``from a.b import c`` is (a.b.c, a.b.c) when c
    is a module, else (a.b, a.b.c); ``import a.b`` is (a.b, a.b). Relative imports are
    resolved against the importing module."""
    name = module_name(path, src)
    here = name.split(".") if path.name == "__init__.py" else name.split(".")[:-1]
    found = []
    for node in ast.walk(ast.parse(path.read_text(), filename=str(path))):
        if isinstance(node, ast.Import):
            found += [(alias.name, alias.name, node.lineno) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = here[: len(here) - (node.level - 1)]
                origin = ".".join(base + ([node.module] if node.module else []))
            else:
                origin = node.module or ""
            for alias in node.names:
                sub = f"{origin}.{alias.name}"
                found.append((sub if _is_module(sub, src) else origin, sub, node.lineno))
    return [item for item in sorted(found, key=lambda item: item[2])
            if item[0] == package or item[0].startswith(package + ".")]


def upward_imports(src: Path = SRC, package: str = "plantmech",
                   allowed: dict[tuple[str, str], str] | None = None) -> list[str]:
    """The imports of a higher layer under `src`/`package`, each as
    "a.b (layer X) imports c.d (layer Y) at line N", minus the `allowed`
    (importer, imported name) pairs."""
    allowed = ALLOWED if allowed is None else allowed
    problems = []
    for path in sorted((src / package).rglob("*.py")):
        importer = module_name(path, src)
        rank = layer_of(importer)
        for module, what, line in imported_modules(path, src, package):
            target = layer_of(module)
            if rank is None or target is None or target <= rank:
                continue
            if (importer, what) in allowed:
                continue
            problems.append(f"{importer} (layer {NAME[rank]}) imports {what} "
                            f"(layer {NAME[target]}) at line {line}")
    return problems


def test_every_module_has_a_layer():
    unranked = [module_name(p, SRC) for p in sorted((SRC / "plantmech").rglob("*.py"))
                if layer_of(module_name(p, SRC)) is None]
    assert not unranked, "modules without a layer in tests/test_layers.py LAYERS: " + \
        ", ".join(unranked)


def test_no_module_imports_a_higher_layer():
    problems = upward_imports()
    assert not problems, f"{len(problems)} upward imports:\n" + "\n".join(problems)


def test_allowed_pairs_are_still_imported():
    """An allow-list entry that no longer matches an import is stale and must go."""
    imports = set()
    for path in (SRC / "plantmech").rglob("*.py"):
        importer = module_name(path, SRC)
        imports |= {(importer, what) for _, what, _ in imported_modules(path, SRC)}
    assert not [pair for pair in ALLOWED if pair not in imports]


@pytest.fixture()
def toy_package(tmp_path):
    """plantmech-shaped tree: geometry/a.py, gears/b.py, outputs/c.py, workflows.py."""
    root = tmp_path / "plantmech"
    for sub in ("geometry", "gears", "outputs"):
        (root / sub).mkdir(parents=True)
        (root / sub / "__init__.py").write_text("")
    (root / "__init__.py").write_text("")
    (root / "geometry" / "a.py").write_text("import numpy as np\n")
    (root / "gears" / "b.py").write_text(
        "from plantmech.geometry.a import np\nfrom ..geometry import a\n")
    (root / "outputs" / "c.py").write_text("from plantmech.gears import b\n")
    (root / "workflows.py").write_text("from plantmech.outputs.c import b\n")
    return tmp_path


def test_parser_accepts_downward_imports(toy_package):
    assert upward_imports(toy_package, allowed={}) == []
    assert imported_modules(toy_package / "plantmech" / "gears" / "b.py", toy_package) == [
        ("plantmech.geometry.a", "plantmech.geometry.a.np", 1),
        ("plantmech.geometry.a", "plantmech.geometry.a", 2)]


def test_parser_finds_module_and_function_level_upward_imports(toy_package):
    geometry = toy_package / "plantmech" / "geometry" / "a.py"
    geometry.write_text("import numpy as np\nfrom plantmech.outputs.c import b\n\n\n"
                        "def f():\n    from plantmech import workflows\n"
                        "    import plantmech.gears.b\n    return workflows\n")
    (toy_package / "plantmech" / "gears" / "b.py").write_text(
        "def g():\n    from ..outputs import c\n    return c\n")
    assert upward_imports(toy_package, allowed={}) == [
        "plantmech.gears.b (layer gears) imports plantmech.outputs.c (layer outputs) at line 2",
        "plantmech.geometry.a (layer geometry) imports plantmech.outputs.c.b (layer outputs) "
        "at line 2",
        "plantmech.geometry.a (layer geometry) imports plantmech.workflows (layer jobs) "
        "at line 6",
        "plantmech.geometry.a (layer geometry) imports plantmech.gears.b (layer gears) "
        "at line 7",
    ]
    allowed = {("plantmech.geometry.a", "plantmech.workflows"): "reason"}
    assert len(upward_imports(toy_package, allowed=allowed)) == 3
