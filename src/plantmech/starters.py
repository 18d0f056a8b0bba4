"""The example designs shipped inside the package, and starting designs for ``plantmech init``.

The examples are package data (``plantmech/examples/*.toml``, the repository's ``examples/``
is a symlink to that directory), so a ``pip install`` user has them too:

>>> from plantmech.starters import example_path, list_examples
>>> sorted(list_examples())[:2]
['rice_transplanter', 'rice_transplanter_khv']
>>> example_path("sugarcane_seeder").name
'sugarcane_seeder.toml'

A starting design is one of the examples with a header of comments saying what it is, what to
change first and which commands to run on it (:func:`starter_text`, :func:`write_starter`).
"""

from __future__ import annotations

from pathlib import Path
from typing import NamedTuple


class Starter(NamedTuple):
    """One kind of starting design: the example it copies and what to tell the designer.
    (A NamedTuple, not a dataclass: ``plantmech --help`` reads it, and dataclasses costs
    ~40 ms of start-up.)"""

    example: str
    what: str
    edit_first: tuple[str, ...]
    commands: tuple[str, ...]


STARTERS: dict[str, Starter] = {
    "seeder": Starter(
        "sugarcane_seeder",
        "a sugarcane seeder designed from its tip trajectory (Liu et al. 2023, Table 2): "
        "the type-value points and the section boundaries a-f give the path, the inverse "
        "design gives the gear train",
        ("[trajectory] points: the tip path, mm, in the order the tip runs through them",
         "[trajectory.sections]: which point starts picking (a), transport (b, c, d), "
         "seeding (e) and the return (f)",
         "[attitude] and [speed]: the limits of the section-4.1 objectives"),
        ("plantmech design {file} --out out/design",
         "plantmech inverse {file} --out out/inverse --verify --report",
         "plantmech forward {file} --out out/forward --report",
         "plantmech optimize {file} --problem seeder-layered --out out/optimize --report",
         "plantmech gears {file} --out out/gears --report"),
    ),
    "seeder-train": Starter(
        "sugarcane_table4",
        "a sugarcane seeder given by its gear train (Liu et al. 2023, Table 4): two "
        "non-circular pairs from their interpolation radii, simulated forward",
        ("[train.gear2] and [train.gear3] radii_mm: the pitch radii of gears 2 and 3 at "
         "angles_deg (mm)",
         "[train] L1_mm, L2_mm, a1_mm, a2_mm: carrier, arm and centre distances (mm)",
         "[train.dwell]: the sun's toothless sector (delete the table for none)"),
        ("plantmech design {file} --out out/design",
         "plantmech forward {file} --out out/forward --report",
         "plantmech optimize {file} --problem seeder-layer2 --out out/optimize --report",
         "plantmech gears {file} --out out/gears --report"),
    ),
    "transplanter": Starter(
        "rice_transplanter",
        "a rice transplanter with a differential internal-engagement non-circular gear "
        "train (Zhou et al. 2022, the published parameter set)",
        ("[internal_gear] radii_mm and phases_deg: the lobed internal pitch curve (mm, deg)",
         "[arm], [carrier]: the planting arm and the arms' start",
         "[seedling_box] and [field]: where the seedlings are picked and planted"),
        ("plantmech design {file} --out out/design",
         "plantmech forward {file} --out out/forward --report",
         "plantmech optimize {file} --problem transplanter --out out/optimize --report",
         "plantmech gears {file} --out out/gears --report"),
    ),
    "planetary": Starter(
        "rotary_transplanter_elliptic",
        "a general non-circular planetary train (any chain of gear pairs): the classic rotary "
        "transplanter with three identical elliptic gears (fixed sun, idler, planet; two "
        "arms at 180 deg)",
        ("[[train.pairs]]: the chain, each pair's kind and its driver's pitch curve (an "
         "ellipse, an eccentric circle, a Fourier series or control radii)",
         "[arm], [carrier]: the arm's length and start, the arms and the carrier's sense",
         "[limits]: what the tip path must do; [optimize.variables]: the fields the "
         "optimizer may move (dotted paths with bounds)"),
        ("plantmech design {file} --out out/design",
         "plantmech forward {file} --out out/forward --report",
         "plantmech gears {file} --out out/gears",
         "plantmech verify {file} --gears out/gears --out out/verify"),
    ),
    "pair": Starter(
        "planetary/elliptic_pair",
        "a non-circular gear pair on fixed centres (the carrier held) given by its "
        "transmission law: two identical elliptic gears about their foci, module 1, 33 teeth",
        ("[train.pairs.law]: the law, follower_angle phi(t) (rad, of the driver's turn t, "
         "rad) or ratio g(t), an expression or a table (driver_deg with follower_deg or "
         "ratio_table); segment_deg = [t0, t1] for a law wanted over part of the turn",
         "[[train.pairs]] turns = [n1, n2] (the driver's and the follower's turns: lobed "
         "gears) and teeth; the size: law.module_mm with teeth, or centre_distance_mm",
         "or give the driver's pitch curve instead of the law ([train.pairs.driver], "
         "as in `plantmech init planetary`)"),
        ("plantmech design {file} --out out/design",
         "plantmech forward {file} --out out/forward --report",
         "plantmech gears {file} --out out/gears --backlash 0.1",
         "plantmech verify {file} --gears out/gears --out out/verify"),
    ),
}


def _examples_dir():
    from importlib import resources

    return resources.files("plantmech") / "examples"


#: the subdirectories of shipped examples: study specs and general planetary trains
EXAMPLE_GROUPS = ("studies", "planetary")


def list_examples() -> list[str]:
    """Names (without ``.toml``) of the example files shipped in the package: the designs,
    then ``studies/<name>`` (the study specs of ``plantmech study --spec``) and
    ``planetary/<name>``."""
    root = _examples_dir()
    names = sorted(p.name[:-5] for p in root.iterdir() if p.name.endswith(".toml"))
    for group in EXAMPLE_GROUPS:
        names += sorted(f"{group}/{p.name[:-5]}" for p in (root / group).iterdir()
                        if p.name.endswith(".toml"))
    return names


def example_path(name: str) -> Path:
    """Path of a shipped example file, by name with or without ``.toml``
    (``"sugarcane_seeder"``, ``"studies/seeder_tolerance"``)."""
    from plantmech.typos import did_you_mean

    stem = name[:-5] if name.endswith(".toml") else name
    names = list_examples()
    if stem not in names:
        raise KeyError(f"no example {name!r}{did_you_mean(stem, names)}; shipped: "
                       + ", ".join(names))
    return Path(str(_examples_dir() / f"{stem}.toml"))


def starter_text(kind: str, file_name: str = "design.toml") -> str:
    """The starting design of ``kind`` (a key of :data:`STARTERS`) as commented TOML:
    a header (what it is, what to edit first, the commands to run) and then the example,
    with its own comments."""
    s = STARTERS[kind]
    body = example_path(s.example).read_text(encoding="utf-8")
    head = [f"Starting design written by `plantmech init {kind}`: {s.what}.",
            f"Copied from the shipped example '{s.example}.toml'; edit it freely.",
            "", "Edit first:"]
    head += [f"  - {line}" for line in s.edit_first]
    head += ["", "Then run (every command checks the file and names a bad field):"]
    head += [f"  {c.format(file=file_name)}" for c in s.commands]
    head += ["", "Units: mm and degrees; m/s for speeds. Every field: plantmech docs "
             "design-file.", ""]
    import textwrap

    lines = []
    for h in head:  # prose wrapped at 92 columns (commands stay whole, for copy and paste)
        indent = "    " if h.startswith("  - ") else ""
        short = len(h) <= 92 or h.startswith("  plantmech ")
        lines += [h] if short else textwrap.wrap(h, 92, subsequent_indent=indent,
                                                 break_on_hyphens=False)
    return "\n".join(f"# {h}".rstrip() for h in lines) + "\n" + body


#: the starting design a shipped study spec runs on, by the spec's name prefix
STUDY_DESIGNS = {"seeder": "seeder-train", "transplanter": "transplanter",
                 "planetary": "planetary"}


def study_kinds() -> list[str]:
    """``plantmech init`` kinds of the shipped study specs: ``studies/<name>``."""
    return [n for n in list_examples() if n.startswith("studies/")]


def study_text(kind: str, file_name: str = "study.toml") -> str:
    """A shipped study spec (``kind`` = ``studies/<name>``) under a header of comments: the
    starting design it runs on and the command."""
    design = STUDY_DESIGNS[kind.split("/", 1)[1].split("_", 1)[0]]
    design_file = f"{design.replace('-', '_')}.toml"
    head = [f"Study spec written by `plantmech init {kind}`, copied from the shipped example",
            f"'{kind}.toml'; it runs on a {design} design (`plantmech init {design} DIR`):",
            f"  plantmech study DIR/{design_file} --spec {file_name} --out out/study --report",
            "Needs plantmech[studies] (Dask, pyarrow). Every field: plantmech docs studies.", ""]
    body = example_path(kind).read_text(encoding="utf-8")
    return "\n".join(f"# {h}".rstrip() for h in head) + "\n" + body


def write_starter(kind: str, directory: str | Path, file_name: str | None = None) -> Path:
    """Write the starting design of ``kind`` into ``directory`` (created if needed) as
    ``file_name`` (default ``<kind>.toml``; a plain file name, never empty nor a path out of
    ``directory``; ``directory`` never a symbolic link); a study spec for ``studies/<name>``
    (:func:`study_kinds`). Never overwrites nor writes through a link: raises
    :class:`~plantmech.outputs.files.OutputError` (ValueError for a ``file_name`` that is a
    path). The file appears whole or not at all (``OutputFile``); a directory created for it
    is removed again if it is not written."""
    from plantmech.outputs.files import OutputFile, refuse_link

    directory = Path(directory)
    default = f"{kind.split('/')[-1].replace('-', '_')}.toml"
    if file_name is not None and file_name.strip() == "":
        raise ValueError(f"--name {file_name!r}: empty; give a file name (or leave --name out "
                         f"for {default})")
    name = default if file_name is None else file_name
    if name in (".", "..") or Path(name).name != name or "/" in name or "\\" in name:
        raise ValueError(f"--name {file_name!r}: give a file name, not a path (it is written "
                         f"into {directory})")
    refuse_link(directory, "DIR")
    target = directory / name
    missing = [d for d in [directory, *directory.parents] if not d.exists()]
    directory.mkdir(parents=True, exist_ok=True)
    text = (study_text(kind, str(target)) if kind.startswith("studies/")
            else starter_text(kind, str(target)))
    try:
        with OutputFile(target, what="init", hint="plantmech init never overwrites a "
                        "file") as tmp:
            tmp.write_text(text, encoding="utf-8")
    except BaseException:
        for d in missing:  # the directories made for it, innermost first
            try:
                d.rmdir()
            except OSError:
                break
        raise
    return target
