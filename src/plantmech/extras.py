"""The optional parts of the install and what a command says when one is missing.

The base install (``pip install plantmech``) is the engine, the gears, the files and
``plantmech design``; three commands need more (pyproject's optional dependencies):

- ``plantmech app``: ``plantmech[app]`` (FastAPI, uvicorn);
- ``plantmech study`` (and ``plantmech report`` on a study's directory):
  ``plantmech[studies]`` (Dask, pyarrow);
- the multibody loads of ``plantmech verify``: ``plantmech[loads]`` (exudyn); without it
  verify still checks the tooth contact and says in its verdict that the loads were not
  computed.

``plantmech[all]`` installs the three. A command that needs a missing extra stops before
writing anything with :class:`MissingExtra`, whose message is the exact ``pip`` line
(exit 2: the install, not the design, is what to change).
"""

from __future__ import annotations

import importlib.util

#: extra -> the modules it brings (the top-level names imported by plantmech)
EXTRAS: dict[str, tuple[str, ...]] = {
    "app": ("fastapi", "uvicorn"),
    "studies": ("dask", "distributed", "pyarrow"),
    "loads": ("exudyn",),
}


class MissingExtra(Exception):
    """A command needs an optional part of the install that is not there."""

    def __init__(self, extra: str, missing: str, what: str):
        self.extra, self.missing, self.what = extra, missing, what
        super().__init__(f"{what} needs the optional dependencies plantmech[{extra}] "
                         f"({missing} is not installed): {install_line(extra)}")


def install_line(extra: str) -> str:
    """The command that installs ``extra``."""
    return f"pip install 'plantmech[{extra}]'"


def missing_module(extra: str) -> str | None:
    """The first module of ``extra`` that cannot be imported, or None (all there)."""
    for name in EXTRAS[extra]:
        try:
            if importlib.util.find_spec(name) is None:
                return name
        except (ImportError, ValueError):  # a broken or half-removed install
            return name
    return None


def available(extra: str) -> bool:
    return missing_module(extra) is None


def require(extra: str, what: str) -> None:
    """Raise :class:`MissingExtra` naming ``what`` (e.g. "'plantmech study'") when a module
    of ``extra`` is missing."""
    name = missing_module(extra)
    if name is not None:
        raise MissingExtra(extra, name, what)


def refused(extra: str, what: str) -> bool:
    """For a command's first line: print the :class:`MissingExtra` error (the pip line) to
    standard error and return True when ``extra`` is missing (the command then returns 2,
    having written nothing); False when it is installed."""
    import sys

    try:
        require(extra, what)
    except MissingExtra as exc:
        print(f"error: {exc}", file=sys.stderr)
        return True
    return False
