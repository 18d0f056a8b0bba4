"""``plantmech init KIND DIR``: write a commented starting design (never overwrites)."""

from __future__ import annotations

import sys


def _init(args) -> int:
    from plantmech.outputs.files import OutputError, is_no_space
    from plantmech.starters import write_starter

    try:
        path = write_starter(args.kind, args.dir, args.name)
    except (OutputError, ValueError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:
        if is_no_space(exc):
            raise  # the one full-disk message (cli.ended_by)
        print(f"error: DIR {args.dir}: cannot write there: {exc.strerror or exc}",
              file=sys.stderr)
        return 2
    from plantmech.starters import STARTERS

    if args.kind not in STARTERS:  # a study spec: its header says how to run it
        print(f"wrote {path}: the study spec {args.kind}; how to run it: its first lines")
        return 0
    print(f"wrote {path}: {STARTERS[args.kind].what}")
    print("next:")
    for c in STARTERS[args.kind].commands:
        print("  " + c.format(file=path))
    return 0


def register(subparsers) -> None:
    from plantmech.starters import STARTERS, study_kinds

    kinds = "; ".join(f"{k}: {s.what.split(':')[0]}" for k, s in STARTERS.items())
    studies = study_kinds()
    p = subparsers.add_parser(
        "init", help="write a commented starting design (seeder, seeder-train, transplanter, "
        "planetary, pair)",
        description="Write a commented starting design into DIR, copied from a shipped "
        f"example, with what to edit first and the commands to run. Kinds: {kinds}. "
        f"Study specs for 'plantmech study': {', '.join(studies)}. "
        "An existing file is never overwritten (exit 2).")
    p.add_argument("kind", choices=list(STARTERS) + studies, metavar="KIND",
                   help=f"what to start from: {', '.join(STARTERS)}, or a study spec "
                   "(studies/...)")
    p.add_argument("dir", help="directory to write into (created if missing)")
    p.add_argument("--name", default=None,
                   help="file name in DIR, not a path (default: KIND.toml with '-' as '_')")
    p.set_defaults(func=_init)
