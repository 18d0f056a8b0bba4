"""One registry of mechanism kinds (``plantmech.kinds``, issue 28): every command gets what
it does per kind by a lookup there, never by branching on the kind's name.

- every kind of ``design.MECHANISMS`` has a ``Kind``, and every hook it names resolves to
  a callable (a renamed function fails here, not in a user's command);
- a branch on a mechanism's name (a comparison, ``in``, ``match`` or ``str`` method on a
  design's ``mechanism`` field, or on one of the papers' mechanism names) outside the
  design loader, the registry and the objective sets fails ``test_no_branch_on_a_kind``;
  ``NOT_YET`` (empty since every module moved to the registry) would list a module not
  yet moved with its count, so any new branch fails.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

from plantmech.design import MECHANISMS
from plantmech.kinds import CAPABILITIES, KINDS, kind_of

PKG = Path(__file__).resolve().parents[1] / "src" / "plantmech"

#: names no other identifier of the package has ("planetary" is also a problem's name, so
#: a literal "planetary" counts only when compared with a design's mechanism)
PAPER_NAMES = {"sugarcane_seeder", "rice_transplanter", "rice_transplanter_khv"}

#: where a kind's name is meant to be read: the design loader, the registry, and the
#: objective sets (objectives/: each set belongs to a kind)
ALLOWED = ("design.py", "design_planetary.py", "design_reference.py", "kinds.py",
           "objectives/")

#: modules with branches on a kind's name not yet moved to the registry (issue 28): their
#: count may only fall. On main before the registry: 68 branches in 19 modules; none now
#: (the gear pairs, the strength table's contacts and the report's animation are hooks).
NOT_YET: dict[str, int] = {}


def _is_mechanism(node) -> bool:
    """``x.mechanism`` or a variable named ``mechanism``."""
    return (isinstance(node, ast.Attribute) and node.attr == "mechanism") or (
        isinstance(node, ast.Name) and node.id == "mechanism")


def _paper_literal(node) -> bool:
    if isinstance(node, ast.Constant):
        return node.value in PAPER_NAMES
    if isinstance(node, ast.Tuple | ast.List | ast.Set):
        return any(_paper_literal(e) for e in node.elts)
    return False


def branches(tree: ast.AST) -> list[int]:
    """Line numbers of the branches on a kind's name in a module's syntax tree."""
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Compare):
            parts = [node.left, *node.comparators]
            if any(map(_is_mechanism, parts)) or any(map(_paper_literal, parts)):
                out.append(node.lineno)
        elif isinstance(node, ast.Match) and _is_mechanism(node.subject):
            out.append(node.lineno)
        elif (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
              and node.func.attr in ("startswith", "endswith")
              and _is_mechanism(node.func.value)):
            out.append(node.lineno)
    return sorted(out)


def scan() -> dict[str, list[int]]:
    found = {}
    for path in sorted(PKG.rglob("*.py")):
        rel = path.relative_to(PKG).as_posix()
        lines = branches(ast.parse(path.read_text(encoding="utf-8")))
        if lines:
            found[rel] = lines
    return found


def test_the_scan_sees_a_branch():
    """The scan finds each form of branch (so the test below can fail)."""
    src = '''
if design.mechanism == "planetary": pass
x = 1 if "rice_transplanter" != kind else 2
if mechanism in ("sugarcane_seeder",): pass
match d.mechanism:
    case "planetary": pass
ok = design.mechanism.startswith("rice")
if name == "planetary": pass
'''
    assert branches(ast.parse(src)) == [2, 3, 4, 5, 7]


def test_no_branch_on_a_kind():
    found = scan()
    extra = {m: lines for m, lines in found.items()
             if not m.startswith(ALLOWED) and len(lines) > NOT_YET.get(m, 0)}
    assert not extra, ("branches on a mechanism's name outside the design loader and the "
                       f"objective sets (look the kind up in plantmech.kinds): {extra}")
    # a module moved to the registry leaves NOT_YET (so the list only shrinks)
    stale = {m: n for m, n in NOT_YET.items() if len(found.get(m, [])) < n}
    assert not stale, f"fewer branches than NOT_YET says: lower it: {stale}"


def test_every_kind_is_registered_and_its_hooks_resolve():
    assert set(KINDS) == set(MECHANISMS)
    for name, kind in KINDS.items():
        assert kind.model is MECHANISMS[name]
        assert set(kind.hooks) <= set(CAPABILITIES), name
        for cap in kind.hooks:
            assert callable(kind.hook(cap)), (name, cap)
        for problem in kind.problems:
            from plantmech.optimize.jobs import PROBLEMS

            assert problem in PROBLEMS, (name, problem)
    with pytest.raises(KeyError, match="no 'inverse_cli'"):
        KINDS["rice_transplanter"].hook("inverse_cli")
    with pytest.raises(KeyError, match="unknown mechanism 'steam_engine'"):
        kind_of("steam_engine")
