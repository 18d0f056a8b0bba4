"""``plantmech schema [MECHANISM]``: the JSON Schema of design files, for editors.

Prints the schema (draft 2020-12) to standard output, or writes it to ``--out FILE``
(written whole or not at all; an existing file is replaced only with ``--force``; never a
link, a directory, a device or a FIFO). Exit status: 0 written, 2 invalid option (an unknown
mechanism, an unusable ``--out``).
"""

from __future__ import annotations

import sys


def _schema(args) -> int:
    import json
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
    from plantmech.outputs.files import OutputError, OutputFile, is_no_space

    out = Path(args.out)
    try:
        with OutputFile(out, force=args.force) as tmp:
            tmp.write_text(text, encoding="utf-8")
    except OutputError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:
        if is_no_space(exc):
            raise  # the one full-disk message (cli.ended_by)
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
