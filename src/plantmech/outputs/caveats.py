"""The caveats of a verdict: what an "ok" rests on that the reader should know.

A verdict is ok or not; its caveats say what it took for granted, so that nothing is met
silently:

- **a limit taken from the file** instead of the default (every field of the limit and
  manufacturing tables whose value differs from the schema's default: a relaxed limit can
  make a design pass);
- **a thin margin**: an objective met with less than ``MARGIN`` of its limit to spare
  (relative to the limit's magnitude, at least 1, as ``objectives.relative_violation``);
- **a change the job made to what the user planned**: type-value points moved (the largest
  move and where), the seeding point moved, a choice the optimizer made for the file
  (interpolation, tooth system), the gears scaled to a standard module.

Each caveat is ``{kind, text, ...}``; ``lines`` prints them, the verdict dict carries their
texts (``with_caveats``), the report shows them under its banner.
"""

from __future__ import annotations

import re

#: an objective met with less than this relative margin is a caveat (1 %)
MARGIN = 0.01
#: the design-file tables whose fields are limits or workshop settings
LIMIT_TABLES = ("limits", "planning_limits", "attitude", "speed", "gear_checks",
                "manufacturing")
#: a type-value point moved less than this (mm) is not a change
MOVE_TOL_MM = 1e-6


def _default_of(section):
    try:
        return type(section)()
    except Exception:  # a table without defaults for every field has no "default" to leave
        return None


def limits_from_file(design) -> list[dict]:
    """Every field of the design's limit and manufacturing tables that differs from the
    schema's default: {kind "limit_from_file", field, value, default, text}."""
    out = []
    for table in LIMIT_TABLES:
        sec = getattr(design, table, None)
        if sec is None or not hasattr(sec, "model_dump"):
            continue
        default = _default_of(sec)
        if default is None:
            continue
        got, ref = sec.model_dump(mode="json"), default.model_dump(mode="json")
        for key, value in got.items():
            if value != ref.get(key):
                out.append({"kind": "limit_from_file", "field": f"{table}.{key}",
                            "value": value, "default": ref.get(key),
                            "text": f"{table}.{key} = {_show(value)} from the file ("
                                    + (f"default {_show(ref.get(key))})"
                                       if ref.get(key) is not None else "no default)")})
    return out


def _show(v) -> str:
    if isinstance(v, dict):
        return "{" + ", ".join(f"{k} {_show(x)}" for k, x in v.items() if x is not None) + "}"
    if isinstance(v, float):
        return f"{v:g}"
    return str(v)


_NUM = r"([-+]?\d+(?:\.\d+)?(?:e[-+]?\d+)?)"


def bounds_of(limit: str) -> tuple[float | None, float | None]:
    """(lower, upper) of a check's limit text ("> 2.5 mm", "< 30 deg", "> 45 and < 65
    deg", ">= 1.4", "<= 0.5"); None where a side is open or the text has no number."""
    lo = re.search(r">=?\s*" + _NUM, limit or "")
    hi = re.search(r"<=?\s*" + _NUM, limit or "")
    return (float(lo.group(1)) if lo else None, float(hi.group(1)) if hi else None)


def thin_margins(checks, margin: float = MARGIN) -> list[dict]:
    """Required checks that are met with less than ``margin`` to spare: {kind
    "thin_margin", name, value, limit, margin, text}."""
    out = []
    for c in checks or []:
        if not c.get("ok") or c.get("required", True) is False or c.get("value") is None:
            continue
        v = float(c["value"])
        lo, hi = bounds_of(str(c.get("limit", "")))
        slack = []
        for b, sign in ((lo, 1.0), (hi, -1.0)):
            if b is not None:
                slack.append(sign * (v - b) / max(abs(b), 1.0))
        if slack and min(slack) < margin:
            s = min(slack)
            unit = c.get("unit") or ""
            out.append({"kind": "thin_margin", "name": c["name"], "value": v,
                        "limit": c.get("limit"), "margin": round(s, 6),
                        "text": f"{c['name']} met with {100 * s:.2g} % to spare "
                                f"({v:.6g} {unit} against {c.get('limit')})".replace(" )",
                                                                                     ")")})
    return out


def changes(planned, final, record: dict | None = None) -> list[dict]:
    """What the job changed of what the user planned: type-value points moved (largest move
    and its point), the seeding point moved, the choices the optimizer made for the file
    (``record['design_choices']``), the standard-module scaling (``record['standard_module']``)."""
    import numpy as np

    out = []
    tp, tf = getattr(planned, "trajectory", None), getattr(final, "trajectory", None)
    if tp is not None and tf is not None and len(tp.points) == len(tf.points):
        p, q = np.asarray(tp.points, dtype=float), np.asarray(tf.points, dtype=float)
        move = np.hypot(*(q - p).T)
        moved = np.flatnonzero(move > MOVE_TOL_MM)
        if len(moved):
            k = int(np.argmax(move))
            out.append({"kind": "points_moved", "count": int(len(moved)),
                        "largest_mm": round(float(move[k]), 3), "point": f"q{k}",
                        "text": f"{len(moved)} of {len(p)} type-value points moved by the "
                                f"optimizer, the most q{k} by {move[k]:.1f} mm"})
        sp, sf = getattr(tp, "sections", None), getattr(tf, "sections", None)
        if sp is not None and sf is not None and sp.e != sf.e:
            out.append({"kind": "seeding_point_moved", "from": f"q{sp.e}", "to": f"q{sf.e}",
                        "text": f"seeding point e moved from q{sp.e} to q{sf.e}"})
    for name, c in ((record or {}).get("design_choices") or {}).items():
        if "file" in str(c.get("set_by", "")) and "does not fix" not in str(c.get("set_by")):
            continue  # the file's own choice
        out.append({"kind": "choice", "name": name, "value": c.get("value"),
                    "text": f"{name.replace('_', ' ')} {c.get('value')} chosen by the job "
                            f"({c.get('set_by')})"})
    std = (record or {}).get("standard_module")
    if std and std.get("scale", 1.0) != 1.0 and std.get("standard"):
        out.append({"kind": "standard_module", "scale": std["scale"],
                    "text": f"gears scaled by {std['scale']:.4f} to the standard module "
                            f"{std['module_mm']:g} mm (from {std['from_module_mm']:.4f})"})
    return out


def caveats(design, checks=(), final=None, record: dict | None = None) -> list[dict]:
    """All caveats of a verdict on ``design`` (the file as the user gave it): its limits
    taken from the file, the thin margins of ``checks``, and when a job made ``final`` from
    it, what it changed."""
    out = limits_from_file(design) + thin_margins(checks)
    if final is not None:
        out += changes(design, final, record)
    return out


def with_caveats(verdict: dict, cavs: list[dict]) -> dict:
    """The verdict dict with its caveats' texts (``caveats``)."""
    verdict["caveats"] = [c["text"] for c in cavs]
    return verdict


def lines(cavs, indent: str = "  ") -> list[str]:
    """The printed caveat lines (before the verdict line)."""
    return [f"{indent}caveat: {c['text'] if isinstance(c, dict) else c}" for c in cavs]
