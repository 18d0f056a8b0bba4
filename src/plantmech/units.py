"""The unit a design file's field carries in its name (design layer, the files' naming):
a name ending ``_deg`` is in degrees, ``_mm`` in millimetres, anything else has no unit
named (a ratio, a count, an eccentricity). The one place this rule is written: the app's
parameter lists and the planetary optimizer's variables read it here."""

from __future__ import annotations

#: name suffix -> unit
UNIT_SUFFIXES = (("_deg", "deg"), ("_mm", "mm"))


def unit_of(name: str) -> str:
    """Unit ("deg", "mm" or "") of a field by the end of its name or dotted path
    (``"train.pairs.0.direction_deg"`` -> "deg", ``"arm.length_mm"`` -> "mm",
    ``"train.pairs.0.driver.eccentricity"`` -> ""); an item of a list field carries the
    list's unit (``"train.pairs.0.driver.radii_mm.3"`` -> "mm")."""
    head, _, last = name.rpartition(".")
    if head and last.isdigit():
        name = head
    for suffix, unit in UNIT_SUFFIXES:
        if name.endswith(suffix):
            return unit
    return ""
