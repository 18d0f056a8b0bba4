"""``--report`` of the commands: the option and the glue from a command's results to
:func:`plantmech.outputs.report.write_report` (no physics here: the jobs are run by the
workflows, the report only shows them); and ``plantmech report STUDY_DIR``: the HTML
report of a design study's directory (:mod:`plantmech.outputs.study_report`).

Exit status of ``plantmech report``: 0 the report is written and the study is complete
and meets what it asks (as ``plantmech study``'s own exit status), 2 the directory holds
no study (the message names the file), 4 the report is written but the study stopped
before its end or its requirement is not met."""

from __future__ import annotations

import sys
from pathlib import Path

REPORT_NAME = "report.html"


def add_report_option(parser) -> None:
    parser.add_argument(
        "--report", action="store_true",
        help=f"also write {REPORT_NAME} in --out: one self-contained HTML file (opens "
        "offline) with the verdict, every objective and check, the plots, the gear "
        "drawings and the mechanism animated over one cycle; and mechanism.gif for slides")


def _command(args) -> str:
    return "plantmech " + " ".join(sys.argv[1:]) if sys.argv[1:] else f"plantmech {args.command}"


def _finish(paths: list[Path], run=None) -> list[Path]:
    """Say where the report is: its final place in --out (``run.final``), never the
    temporary directory it is written into."""
    where = run.final if run is not None else Path
    print(f"report: {where(paths[0])}" + (f" (animation for slides: {where(paths[1])})"
                                          if len(paths) > 1 else ""))
    return paths


def inverse_report(args, out: Path, job, figures, run=None) -> list[Path]:
    """Report of ``plantmech inverse``: animation of the feasible gear train."""
    from plantmech.outputs.report import seeder_inverse_animation, write_report

    anim = None
    if job.result.feasible and job.result.tip_realized is not None:
        anim = seeder_inverse_animation(job)
    return _finish(write_report(out / REPORT_NAME, job.summary, figures, anim,
                                command=_command(args)), run=run)


def planetary_report(args, out: Path, design, motion, summary, figures, run=None) -> list[Path]:
    """Report of ``plantmech forward`` on a general planetary train."""
    from plantmech.outputs.report import planetary_animation, write_report

    return _finish(write_report(out / REPORT_NAME, summary, figures,
                                planetary_animation(design, motion), command=_command(args)),
                   run=run)


def forward_report(args, out: Path, job, figures, run=None) -> list[Path]:
    """Report of ``plantmech forward`` (seeder or transplanter job)."""
    from plantmech.outputs.report import job_animation, write_report

    return _finish(write_report(out / REPORT_NAME, job.summary, figures, job_animation(job),
                                command=_command(args)), run=run)


def design_animation(design):
    """The mechanism of a design simulated forward for the animation, or None (with the
    reason printed) when it cannot be simulated."""
    from plantmech.kinds import kind_of

    animate = kind_of(design).hook("animation")  # the kind's own (plantmech.pipeline)
    try:
        return animate(design)
    except Exception as exc:  # noqa: BLE001 - the report says why the animation is missing
        print(f"  report: no animation ({type(exc).__name__}: {exc})", file=sys.stderr)
        return None


def optimize_report(args, out: Path, outcome, run=None) -> list[Path]:
    """Report of ``plantmech optimize``: run record, convergence and Pareto plots, and the
    best design (best.toml) animated."""
    from plantmech.design import DesignError, load_design
    from plantmech.outputs.report import write_report

    figures = [(p.name, p) for p in outcome.written if p.suffix == ".png"]
    anim = None
    best = out / "best.toml"
    if best.exists():
        try:
            anim = design_animation(load_design(best))
        except DesignError as exc:
            print(f"  report: no animation ({exc})", file=sys.stderr)
    rec = one_objective_table(outcome.record)
    rec.setdefault("name", f"optimize --problem {args.problem}")
    return _finish(write_report(out / REPORT_NAME, rec, figures, anim,
                                verdict=(bool(outcome.feasible), _optimize_verdict(outcome)),
                                command=_command(args)), run=run)


def one_objective_table(rec: dict) -> dict:
    """An optimization record for the report with one objective table per run: where the
    best design was re-checked at full resolution (``verified_full_resolution``), its
    re-checked objectives (the ones the verdict reads) replace the optimizer's own rows,
    as "objectives at full resolution"; a layered job's layers alike."""
    out = {}
    for k, v in rec.items():
        out[k] = one_objective_table(v) if isinstance(v, dict) else v
    checked = out.get("verified_full_resolution")
    if isinstance(checked, dict) and "objectives" in checked:
        out.pop("objectives", None)
        out["verified_full_resolution"] = {k: v for k, v in checked.items()
                                           if k != "objectives"}
        out["objectives at full resolution"] = checked["objectives"]
    return out


def _optimize_verdict(outcome) -> str:
    return ("a design meeting every objective was found (best.toml)" if outcome.feasible
            else "NOT MET: no design meets every objective; the closest is best.toml")


def gears_report(args, out: Path, design, rec: dict, run=None) -> list[Path]:
    """Report of ``plantmech gears``: checks per gear, mesh checks, the mesh PNGs and
    every gear's SVG drawing, and the mechanism animated."""
    from plantmech.outputs.report import findings_rows, write_report

    figures = [(f, out / f) for f in rec["files"] if f.endswith(".png")]
    drawings = [(f, out / f) for f in rec["files"] if f.endswith(".svg")]
    # a gear or pair row is ok only without a finding (the mesh check's own "ok" is its
    # interference alone: a pair whose backlash band fails is not ok in the report either)
    failed = {f["gear"] for f in rec["findings"]}
    summary = dict(rec, name=design.name, gear_checks=findings_rows(rec),
                   mesh=[dict(m, ok=bool(m.get("ok")) and m["pair"] not in failed)
                         for m in rec["mesh"]],
                   all_pairs_mesh=bool(rec.get("all_pairs_mesh"))
                   and not failed & {m["pair"] for m in rec["mesh"]})
    v = rec["verdict"]  # the record's (workflows.run_gears): the words it printed
    verdict = (bool(v["ok"]), f"verdict: {v['text']}")
    return _finish(write_report(out / REPORT_NAME, summary, figures, design_animation(design),
                                verdict=verdict,
                                gear_drawings=drawings, command=_command(args)), run=run)


def register(subparsers) -> None:
    p = subparsers.add_parser(
        "report", help="HTML report of a design study's directory (plantmech study --out)")
    p.add_argument("study_dir", help="the --out directory of 'plantmech study' (read only, "
                   "but plots the study skipped with --no-plots are added to it)")
    p.add_argument("--out", default=None, help=f"report file (default STUDY_DIR/{REPORT_NAME})"
                   "; an existing file is replaced only with --force, or if it is a report "
                   "this command wrote")
    p.add_argument("--force", action="store_true", help="replace an existing --out file")
    p.set_defaults(func=_study_report)


def _study_report(args) -> int:
    """Draw the missing plots and the page into temporary files beside the target; the page
    replaces the target in one rename and its JSON record (the study's verdict, what was read
    and written: ``study_report.report_record``) appears beside it (``report.json`` for
    ``report.html``), then the plots join the study directory (never replacing a file
    there)."""
    from plantmech.extras import refused

    if refused("studies", "'plantmech report' (a study's results are Parquet files)"):
        return 2
    import os
    import shutil
    import tempfile

    from plantmech.outputs import signals
    from plantmech.outputs.files import OutputError, OutputFile, is_no_space, write_json
    from plantmech.outputs.study_report import (
        StudyReportError,
        is_previous_record,
        is_previous_report,
        load_study,
        record_path,
        recorded_verdict,
        report_record,
        study_verdict_line,
        write_study_report,
    )

    study = Path(args.study_dir)
    target = Path(args.out) if args.out else study / REPORT_NAME
    record = record_path(target)
    inputs = [study / "study.json", study / "summary.json"]
    try:
        if record == target:
            raise OutputError(f"--out {target}: give the page an .html name (its JSON record "
                              f"is written beside it as {record.name})")
        _, summary = load_study(study)
        output = OutputFile(target, force=args.force or is_previous_report(target),
                            inputs=inputs, hint="it is not a report this command wrote: add "
                            "--force to replace it, or choose another file")
        # the record of this run beside the page, with the study's one verdict
        record_output = OutputFile(record, what="record",
                                   force=args.force or is_previous_record(record),
                                   inputs=inputs, hint="it is not a record of 'plantmech "
                                   "report': add --force to replace it, or choose another "
                                   "--out")
    except (StudyReportError, OutputError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    v = recorded_verdict(summary)
    plots = None
    try:
        with signals.blocked():
            plots = Path(tempfile.mkdtemp(prefix=".plantmech-", dir=target.parent))
        signals.check()
        # page and record appear together (the page first, then its record) or neither
        with record_output as tmp_record, output as tmp:
            write_study_report(study, tmp, command=_command(args), plots_into=plots)
            added = sorted(f.name for f in plots.iterdir() if not (study / f.name).exists())
            write_json(tmp_record, report_record(study, target, _command(args), v, added))
        with signals.blocked():
            for f in plots.iterdir():  # the plots the study skipped join it
                try:
                    os.link(f, study / f.name)
                except OSError:
                    pass
    except (StudyReportError, OutputError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:
        if is_no_space(exc):
            raise
        print(f"error: --out {target}: cannot be written ({exc.strerror or exc})",
              file=sys.stderr)
        return 2
    finally:
        with signals.blocked():
            if plots is not None:
                shutil.rmtree(plots, ignore_errors=True)
    print(f"report: {target}")
    print(f"record: {record}")
    print(study_verdict_line(v))
    return v["exit_code"]
