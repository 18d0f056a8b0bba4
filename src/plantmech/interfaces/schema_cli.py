"""``plantmech schema [MECHANISM]``: the JSON Schema of design files, for editors.

Prints the schema (draft 2020-12) to standard output, or writes it to ``--out FILE``
(an existing file is replaced only with ``--force``). Exit status: 0 written, 2 invalid
option (an unknown mechanism, an unusable ``--out``).
"""

from __future__ import annotations

import sys


def _schema(args) -> int:
    import json
    import os
    from pathlib import Path

    from plantmech.design_reference import json_schema

    try:
        schema = json_schema(args.mechanism)
    except ValueError as exc:
        print(f"error: mechanism: {exc}", file=sys.stderr)
        return 2
    text = json.dumps(schema, indent=2) + "\n"
    if args.out is None:
        sys.stdout.write(text)
        return 0
    out = Path(args.out)
    if str(args.out).strip() == "" or out.is_dir():
        print(f"error: --out {args.out!r}: give a file name", file=sys.stderr)
        return 2
    if out.exists() and not args.force:
        print(f"error: --out {out} exists; add --force to replace it", file=sys.stderr)
        return 2
    tmp = out.with_name(f".{out.name}.tmp{os.getpid()}")
    try:
        tmp.write_text(text, encoding="utf-8")
        os.replace(tmp, out)  # replaces a link itself, never writes through it
    except OSError as exc:
        tmp.unlink(missing_ok=True)
        print(f"error: --out {out}: cannot be written ({exc.strerror})", file=sys.stderr)
        return 2
    print(f"wrote {out}")
    return 0


def register(subparsers) -> None:
    """Add the ``schema`` subcommand."""
    p = subparsers.add_parser("schema", help="JSON Schema of design files (for editors); "
                              "reference: plantmech docs design-file")
    p.add_argument("mechanism", nargs="?", default=None,
                   help="one mechanism's schema: sugarcane_seeder, rice_transplanter or "
                   "rice_transplanter_khv (default: any design file)")
    p.add_argument("--out", default=None, help="write to this file instead of stdout")
    p.add_argument("--force", action="store_true", help="replace an existing --out file")
    p.set_defaults(func=_schema)
