"""The design-file reference, generated from the pydantic models of ``design.py``.

``json_schema(mechanism)`` is the JSON Schema of one mechanism's design file (or of any
of them); ``markdown_reference()`` is ``docs/design-file.md``: every table and field with
its meaning, unit, type, default, limits and the paper's symbol (from the fields'
descriptions and constraints). Regenerate the document with
``python -m plantmech.design_reference > docs/design-file.md``; a test checks that the
committed file is up to date.
"""

from __future__ import annotations

import json
from typing import Annotated, Any, Union

from plantmech import design as D

HEADER = """# Design-file reference

Generated from the pydantic models in `src/plantmech/design.py` by
`python -m plantmech.design_reference > docs/design-file.md` (do not edit by hand; a
test checks it is up to date). For editors: `plantmech schema` prints the JSON Schema.

A design file is TOML. Units: mm, degrees (deg), deg/s, m/s as each field says.
Types are strict: a number takes an integer or a float (never `true` or `"254"`), an
integer (index, count) takes an integer only (never `3.0`), a switch takes `true` or
`false`. Unknown fields are refused (check the spelling). Limits that keep a run bounded:
at most {max_points} type-value points or radii per curve, at most {max_samples} samples
per carrier turn, coordinates and lengths within +-{max_size:g} mm, files of at most
{max_bytes} bytes nested at most {max_nesting} levels deep. Errors name the file and the
field (with the point index).

Papers: seed 000 = Liu et al., sugarcane seeder with a second-order non-circular
planetary gear train (Int J Agric & Biol Eng 16(6), 2023); seed 001 = Zhou et al., rice
transplanting mechanisms with non-circular planetary gear trains (J Agric Eng LIII:1412,
2022).
"""


def json_schema(mechanism: str | None = None) -> dict:
    """JSON Schema (draft 2020-12) of one mechanism's design file, or of any design file
    (``mechanism`` None: one of the mechanisms, told apart by the ``mechanism`` field)."""
    from pydantic import Field, TypeAdapter

    if mechanism is not None:
        if mechanism not in D.MECHANISMS:
            raise ValueError(f"unknown mechanism {mechanism!r} (expected one of "
                             f"{', '.join(D.MECHANISMS)})")
        schema = D.MECHANISMS[mechanism].model_json_schema()
    else:
        union = Annotated[Union[tuple(D.MECHANISMS.values())],  # noqa: UP007
                          Field(discriminator="mechanism")]
        schema = TypeAdapter(union).json_schema()
        schema["title"] = "plantmech design file"
    schema["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    return schema


def _resolve(node: dict, defs: dict) -> dict:
    if "$ref" in node:
        return defs[node["$ref"].split("/")[-1]]
    return node


def _non_null(node: dict, defs: dict) -> tuple[dict, bool]:
    """The schema of a field without its ``null`` alternative, and whether it may be
    left out as null."""
    options = node.get("anyOf")
    if options:
        rest = [o for o in options if o.get("type") != "null"]
        if len(rest) == 1:
            return _resolve(rest[0], defs) | {k: v for k, v in rest[0].items()
                                               if k != "$ref"}, True
    return node, False


def _type_text(node: dict, defs: dict) -> str:
    node = _resolve(node, defs) if "$ref" in node and "properties" not in node else node
    if "enum" in node:
        return " \\| ".join(f'`"{v}"`' for v in node["enum"])
    if "const" in node:
        return f'`"{node["const"]}"`'
    if "properties" in node:
        return "table"
    if "oneOf" in node:  # a table told apart by its discriminator (a pitch-curve family)
        key = node.get("discriminator", {}).get("propertyName", "kind")
        return f"table, one of {len(node['oneOf'])} (by `{key}`)"
    t = node.get("type")
    if t == "array":
        if "prefixItems" in node:
            return "[" + ", ".join(_type_text(i, defs) for i in node["prefixItems"]) + "]"
        return f"array of {_type_text(node.get('items', {}), defs)}"
    if t == "object":
        return "table of " + _type_text(node.get("additionalProperties", {}), defs)
    if "anyOf" in node:
        return " or ".join(_type_text(o, defs) for o in node["anyOf"])
    return {"number": "number", "integer": "integer", "boolean": "true/false",
            "string": "string"}.get(t, str(t))


def _limits_text(node: dict, defs: dict) -> str:
    parts = []
    for key, sym in (("minimum", ">="), ("exclusiveMinimum", ">"), ("maximum", "<="),
                     ("exclusiveMaximum", "<")):
        if key in node:
            parts.append(f"{sym} {node[key]:g}")
    if "minItems" in node or "maxItems" in node:
        lo, hi = node.get("minItems"), node.get("maxItems")
        if node.get("prefixItems") is None:
            parts.append(f"{lo or 0}-{hi} items" if hi is not None else f">= {lo} items")
    if "maxLength" in node:
        parts.append(f"at most {node['maxLength']} characters")
    items = node.get("items") or (node.get("prefixItems") or [None])[0]
    if isinstance(items, dict):
        inner = _limits_text(_resolve(items, defs), defs)
        if inner:
            parts.append(inner if inner.startswith("each ") else f"each {inner}")
    return ", ".join(parts)


def _default_text(prop: dict, required: bool) -> str:
    if required:
        return "**required**"
    if "default" not in prop:
        return ""
    v = prop["default"]
    if v is None:
        return "none"
    if isinstance(v, dict):
        return "see the table"
    return f"`{json.dumps(v)}`"


def _table(name: str, model: dict, defs: dict, lines: list[str], seen: set[str]) -> None:
    props = model.get("properties", {})
    required = set(model.get("required", []))
    lines += ["", f"### `{name}`" if name else "### top level", ""]
    if model.get("description"):
        lines += [" ".join(model["description"].split()), ""]
    lines += ["| field | type | default | limits | meaning |",
              "|---|---|---|---|---|"]
    nested = []
    for key, prop in props.items():
        node, optional_table = _non_null(prop, defs)
        node = _resolve(node, defs) | {k: v for k, v in node.items() if k != "$ref"}
        desc = " ".join((prop.get("description") or node.get("description") or "").split())
        lines.append(f"| `{key}` | {_type_text(node, defs)} | "
                     f"{_default_text(prop, key in required)} | {_limits_text(node, defs)} "
                     f"| {desc.replace('|', '/')} |")
        path = f"{name}.{key}" if name else key
        if "properties" in node:
            nested.append((path, node))
        elif "oneOf" in node:
            nested += _variants(path, node, defs)
        elif node.get("type") == "array" and isinstance(node.get("items"), dict):
            item = _resolve(node["items"], defs)
            if "properties" in item:  # an array of tables ([[name]] in TOML)
                nested.append((f"{path}[]", item))
    for sub, node in nested:
        _table(sub, node, defs, lines, seen)


def _variants(path: str, node: dict, defs: dict) -> list[tuple[str, dict]]:
    """Each table of a discriminated union, named by its discriminator's value."""
    key = node.get("discriminator", {}).get("propertyName", "kind")
    out = []
    for option in node["oneOf"]:
        model = _resolve(option, defs)
        value = model.get("properties", {}).get(key, {}).get("const", model.get("title"))
        out.append((f'{path} ({key} = "{value}")', model))
    return out


def markdown_reference() -> str:
    """``docs/design-file.md``: every mechanism's tables and fields."""
    lines = [HEADER.format(max_points=D.MAX_POINTS, max_samples=D.MAX_SAMPLES,
                           max_size=D.MAX_SIZE_MM, max_bytes=D.MAX_FILE_BYTES,
                           max_nesting=D.MAX_NESTING).rstrip()]
    for mech, model in D.MECHANISMS.items():
        schema = model.model_json_schema()
        defs = schema.get("$defs", {})
        lines += ["", f"## `mechanism = \"{mech}\"`"]
        _table("", schema, defs, lines, set())
    return "\n".join(lines) + "\n"


def undocumented_fields() -> list[str]:
    """Dotted names of model fields without a description (should be none)."""
    from pydantic import BaseModel

    missing: list[str] = []

    def walk(model: type[BaseModel], prefix: str, seen: set) -> None:
        if model in seen:
            return
        seen.add(model)
        for name, info in model.model_fields.items():
            if not info.description:
                missing.append(f"{prefix}{name}")
            for sub in _models_in(info.annotation):
                walk(sub, f"{prefix}{name}.", seen)

    for mech, model in D.MECHANISMS.items():
        walk(model, f"{mech}:", set())
    return missing


def _models_in(annotation: Any) -> list:
    from typing import get_args

    from pydantic import BaseModel

    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return [annotation]
    out = []
    for a in get_args(annotation):
        out += _models_in(a)
    return out


if __name__ == "__main__":  # pragma: no cover
    print(markdown_reference(), end="")
