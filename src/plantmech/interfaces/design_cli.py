"""``plantmech design DESIGN.toml --out DIR``: the main job, trajectory (or parameter set) to
workshop files with one verdict (``plantmech.pipeline``)."""

from __future__ import annotations

import sys


def register(sub) -> None:
    from plantmech.interfaces.cli import SEED, _number, add_output_options

    p = sub.add_parser(
        "design", help="the whole job: check, optimize every objective and manufacturability, "
        "cut the teeth, write the workshop files, one verdict")
    p.add_argument("design", help="design file (TOML): a seeder trajectory or [train], or a "
                   "transplanter parameter set; never overwritten")
    add_output_options(p)
    p.add_argument("--seed", type=_number(int, **SEED), default=0, help="random seed of the "
                   "optimizer (0 to 2^32 - 1; same seed, same result)")
    p.add_argument("--generations", type=_number(int, 1, strict=False, maximum=10_000),
                   default=None, help="optimizer generations (1-10000; default per problem, "
                   "plantmech docs optimization)")
    p.add_argument("--module", type=_number(float, 0.0, maximum=50.0, least=0.5), default=None,
                   help="tooth module, mm (0.5-50; default: the largest the pitch curves "
                   "allow)")
    p.add_argument("--time-limit", type=_number(float, 0.0, maximum=7 * 86400.0), default=None,
                   help="seconds the optimization may take (it stops at the end of the "
                   "generation that passes it, and says so; up to a week); default: none")
    p.add_argument("--quiet", action="store_true", help="no progress bars")
    p.add_argument("--report", action="store_true",
                   help="accepted for symmetry with the other commands: 'design' always "
                   "writes report.html (and mechanism.gif) into --out")
    p.set_defaults(func=run)


def run(args) -> int:
    from plantmech.interfaces.cli import run_command

    return run_command(args, _body)


def _body(args, design, run) -> int:
    from plantmech.interfaces.cli import _wrote
    from plantmech.outputs.files import check_line
    from plantmech.outputs.verdict import EXIT_INPUT, verdict_line
    from plantmech.pipeline import run_design

    try:
        outcome = run_design(design, run.path, str(args.design), seed=args.seed,
                             progress=not args.quiet, generations=args.generations,
                             module=args.module, time_limit_s=args.time_limit)
    except ValueError as exc:
        print(f"error: {args.design}: {exc}", file=sys.stderr)
        return EXIT_INPUT
    rec = outcome.record
    print(f"{rec['name']}: {rec['wall_s']:.1f} s")
    for c in rec["final_checks"]:
        if not c["ok"] and c.get("required", True):
            print(check_line(c, 36, 2, 12))
    print(_wrote(run, [p for p in outcome.written if p.parent == run.path]))
    report = run.path / "report.html"
    if report in outcome.written:
        print(f"report: {run.final(report)}")
    v = outcome.verdict
    print(verdict_line(v, "every objective and manufacturability check met, the gears mesh, "
                          "the workshop files are written (design.toml, gears/)",
                       rec.get("caveats", ())))
    return v["exit_code"]
