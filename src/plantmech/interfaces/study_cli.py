"""``plantmech study DESIGN.toml --spec STUDY.toml --out DIR [--scheduler ADDRESS]
[--workers N]``: tolerance Monte Carlo, parameter sweeps and multi-start optimization on
Dask (docs/studies.md). No physics here: the engine is ``plantmech.studies``.

Exit status: 0 the study ran to the end (every chunk written; with ``required_probability``
in a tolerance spec: and the probability that every objective holds reaches it;
multi-start: at least one start met every objective), 2 invalid input (names the file and
field or option), 3 the design itself is infeasible, 4 the study stopped before the end
(a chunk failed, or --max-chunks: rerun the same command to resume) or its requirement
was not met.
"""

from __future__ import annotations

import sys
from pathlib import Path

EXIT_OK, EXIT_INPUT, EXIT_INFEASIBLE, EXIT_NOT_MET = 0, 2, 3, 4


def register(subparsers) -> None:
    from plantmech.interfaces.cli import _number
    from plantmech.studies.spec import MAX_CHUNKS

    p = subparsers.add_parser("study", help="tolerance Monte Carlo, sweeps, multi-start "
                              "optimization on Dask (needs plantmech[studies])")
    p.add_argument("design", help="design file (TOML); never overwritten")
    p.add_argument("--spec", required=True, help="study file (TOML): kind = 'tolerance', "
                   "'sweep' or 'multi-start'; shipped ones: plantmech.example_path("
                   "'studies/seeder_tolerance') and the other studies/ names of "
                   "plantmech.list_examples()")
    p.add_argument("--out", required=True, help="output directory; rerun with the same "
                   "inputs and --out to resume a study stopped by --max-chunks or a failed "
                   "chunk (a --out holding this same study needs no --force)")
    p.add_argument("--force", action="store_true",
                   help="replace the existing contents of --out (otherwise a --out that "
                   "holds anything but this same study is refused)")
    p.add_argument("--scheduler", default=None, metavar="ADDRESS",
                   help="address of a running Dask scheduler (e.g. tcp://10.0.0.5:8786); "
                   "default: a local cluster on this machine")
    p.add_argument("--workers", type=_number(int, 1, strict=False, maximum=64), default=2,
                   help="worker processes of the local cluster (1-64, default 2)")
    p.add_argument("--max-chunks", type=_number(int, 1, strict=False, maximum=MAX_CHUNKS),
                   default=None,
                   help="stop after this many new chunks (resume later)")
    p.add_argument("--no-plots", action="store_true", help="skip PNG plots")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.add_argument("--report", action="store_true",
                   help="also write report.html in --out: the verdict, P(ok) per objective, "
                   "the tolerances, the tip-path band, the sensitivity ranking and the "
                   "histograms (self-contained; 'plantmech report DIR' rebuilds it)")
    p.set_defaults(func=run)


def run(args) -> int:
    from plantmech.extras import refused

    if refused("studies", "'plantmech study'"):
        return EXIT_INPUT
    from plantmech.interfaces.cli import run_command
    from plantmech.studies.spec import StudySpecError, load_spec

    try:
        spec = load_spec(args.spec)
    except StudySpecError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return EXIT_INPUT
    return run_command(args, lambda a, design, run: _body(a, design, run, spec),
                       inputs=(Path(args.spec),), resume=lambda out: _same_study(args, spec, out))


def _fingerprint(design, spec) -> str:
    from plantmech.studies.spec import fingerprint

    return fingerprint(design.model_dump_json(), spec.model_dump_json())


def _same_study(args, spec, out: Path) -> bool:
    """``out`` holds this very study (study.json with the inputs' fingerprint): it is
    resumed without --force (its finished chunks are kept). Another study there is
    refused by name (OutputError)."""
    from plantmech.design import DesignError, load_design
    from plantmech.outputs.files import OutputError

    try:
        from plantmech.studies.summary import read_state

        state = read_state(out)  # bounded: a FIFO or a device there is no study
        same = state.get("fingerprint") == _fingerprint(load_design(args.design), spec)
    except (OSError, ValueError, AttributeError, DesignError):
        return False
    if not same:
        raise OutputError(f"--out {out} holds a study of another design or study file "
                          "(study.json): its chunks would not belong to this one; add --force "
                          "to replace it, or choose another directory")
    return True


def _body(args, design, run, spec) -> int:
    from plantmech.outputs import signals
    from plantmech.studies.engine import StudyStateError
    from plantmech.studies.parameters import StudyInputError
    from plantmech.studies.spec import StudySpecError
    from plantmech.workflows import InfeasibleDesign

    try:  # the spec against the design, before any work: a refusal keeps nothing
        if spec.kind == "multi-start":
            from plantmech.studies.multistart import check_problem

            check_problem(design, spec, args.spec)
        else:
            from plantmech.studies.parameters import check_parameters

            try:
                check_parameters(design, list(spec.parameters))
            except StudyInputError as exc:
                raise StudySpecError(f"{args.spec}: field 'parameters': {exc}") from None
    except StudySpecError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return EXIT_INPUT
    out = run.path
    if args.scheduler and args.workers != 2:
        print("note: --workers is ignored with --scheduler (the cluster has its own)",
              file=sys.stderr)
    fp = _fingerprint(design, spec)
    try:
        if spec.kind == "multi-start":
            from plantmech.studies.multistart import run_multistart

            outcome = run_multistart(design, spec, out, fp, str(args.design), args.scheduler,
                                     args.workers, not args.quiet, args.max_chunks)
        else:
            from plantmech.studies.runner import run_study

            outcome = run_study(design, spec, out, fp, args.scheduler, args.workers,
                                not args.quiet, args.max_chunks)
    except StudyInputError as exc:
        print(f"error: {args.spec}: field 'parameters': {exc}", file=sys.stderr)
        return EXIT_INPUT
    except (StudyStateError, StudySpecError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return EXIT_INPUT
    except InfeasibleDesign:
        print(f"INFEASIBLE: {args.design}: the trajectory's inverse design has no gear train",
              file=sys.stderr)
        return EXIT_INFEASIBLE
    except ValueError as exc:  # a design the population model cannot take
        print(f"error: {args.design}: {exc}", file=sys.stderr)
        return EXIT_INPUT
    got = signals.received()
    if got is not None and not signals.finished() and outcome.stats.stopped_early:
        # a signal while chunks were computed is the documented stop (docs/studies.md): the
        # chunks finished so far are kept and summarised (complete = false, exit 4) to
        # resume from; a signal anywhere else (or a second one now) leaves --out as it was
        signals.consume()
        for tmp in (out / "chunks").glob("*.tmp*"):  # a chunk cut while being written
            tmp.unlink()
        print(f"stopped by {signals.NAMES.get(got, got)}: the finished chunks are kept; rerun "
              "the same command to resume", file=sys.stderr)
    signals.check()
    return _report(args, spec, design, run, outcome)


def _report(args, spec, design, run, outcome) -> int:
    import json

    from plantmech.outputs.files import write_json
    from plantmech.outputs.study_report import study_verdict_line, study_verdict_record

    out = run.path
    st = outcome.stats
    summary_run = outcome.summary["run"]
    print(f"chunks: {st.computed_chunks} computed, {st.skipped_chunks} already done "
          f"(resumed), {len(st.failed)} failed, of {st.total_chunks}; {st.evaluations} "
          f"{'starts' if spec.kind == 'multi-start' else 'designs'} in {st.wall_s:.1f} s on "
          f"{st.workers} workers (cluster start {st.cluster_start_s:.1f} s)"
          + (f", {summary_run['designs_per_s']:.1f} designs/s" if spec.kind != "multi-start"
             and summary_run["designs_per_s"] else ""))
    s = outcome.summary
    # study.json says whether the directory holds the whole study
    state = json.loads((out / "study.json").read_text(encoding="utf-8"))
    write_json(out / "study.json", {**state, "complete": st.complete})
    if not st.complete:
        for c, msg in st.failed:
            print(f"chunk {c} failed: {msg}", file=sys.stderr)
        print(f"INCOMPLETE: {st.total_chunks - st.skipped_chunks - st.computed_chunks} "
              f"chunk(s) not done; rerun the same command to resume "
              f"({run.final(out / 'chunks')})", file=sys.stderr)
        if "complete" not in s:  # nothing finished yet: nothing to summarise
            v = s["verdict"] = study_verdict_record(s)
            write_json(out / "summary.json", s)
            print(study_verdict_line(v))
            return v["exit_code"]
        print("the summary and plots below cover the finished chunks only "
              "(summary.json: complete = false)", file=sys.stderr)
    written = [out / "summary.json"]
    if spec.kind == "tolerance":
        written += _tolerance_files(args, design, out, s)
        req = spec.required_probability
        if req is not None:
            s["required_probability"] = req
            s["requirement_met"] = bool(s["probability_all_ok"] >= req)
    elif spec.kind == "sweep":
        if not args.no_plots:
            from plantmech.outputs.study_plots import plot_sweep
            from plantmech.studies.engine import read_results

            plot_sweep(out / "sweep.png", read_results(out), s)
            written.append(out / "sweep.png")
        print(f"sweep: {s['samples']} designs, every objective met by "
              f"{100 * s['fraction_all_ok']:.1f} %"
              + (f"; {s['variants_not_moved']} could not be built or moved (a field outside "
                 "what the design file accepts: red x in sweep.png)"
                 if s.get("variants_not_moved") else ""))
    else:
        if not args.no_plots:
            from plantmech.outputs.study_plots import plot_multistart
            from plantmech.studies.engine import read_results

            plot_multistart(out / "multistart.png", read_results(out))
            written.append(out / "multistart.png")
        print(f"multi-start {s['problem']}: {s['successes']} of {s['starts']} starts met "
              f"every objective (seeds {s['seeds_succeeded']})")
        for b in s["best"]:
            print(f"  #{b['rank']} seed {b['seed']}: total violation {b['total_violation']:.4g}"
                  f" -> {run.final(out / b['file'])}")
        written += [out / b["file"] for b in s["best"]]
    # the verdict: built once, recorded, read by the report and printed last
    v = s["verdict"] = study_verdict_record(s)
    write_json(out / "summary.json", s)
    if getattr(args, "report", False):
        from plantmech.outputs.study_report import write_study_report

        written.append(write_study_report(out, command="plantmech " + " ".join(sys.argv[1:])))
        print(f"report: {run.final(written[-1])}")
    print("wrote: " + ", ".join(str(run.final(p)) for p in written)
          + f", {run.final(out / 'chunks')}/ (Parquet)")
    print(study_verdict_line(v))
    return v["exit_code"]


def _tolerance_files(args, design, out: Path, s: dict) -> list[Path]:
    import numpy as np

    from plantmech.outputs.files import write_csv

    band = s.pop("band")
    write_csv(out / "band.csv", {
        "carrier_angle_deg": band["carrier_angle_deg"],
        "nominal_x_mm": band["nominal_tip_mm"][:, 0], "nominal_y_mm": band["nominal_tip_mm"][:, 1],
        "normal_x": band["normal"][:, 0], "normal_y": band["normal"][:, 1],
        "mc_mean_mm": band["mc_mean_mm"], "mc_std_mm": band["mc_std_mm"],
        "mc_min_mm": band["mc_min_mm"], "mc_max_mm": band["mc_max_mm"],
        "first_order_mean_mm": band["first_order_mean_mm"],
        "first_order_std_mm": band["first_order_std_mm"]})
    s["band_summary"] = {
        "largest_mc_std_mm": float(np.max(band["mc_std_mm"])),
        "largest_first_order_std_mm": float(np.max(band["first_order_std_mm"])),
        "largest_envelope_width_mm": float(np.max(band["mc_max_mm"] - band["mc_min_mm"])),
        "largest_std_difference_mm": float(np.max(np.abs(band["mc_std_mm"]
                                                         - band["first_order_std_mm"]))),
        "file": "band.csv"}
    written = [out / "band.csv"]
    plan = None
    if getattr(design, "trajectory", None) is not None:  # the planned trajectory (seeder)
        from plantmech.geometry.trajectory import ClosedTrajectory

        traj = ClosedTrajectory.through(np.asarray(design.trajectory.points, float))
        _, u = traj.arc_length_samples(2000)
        plan = traj(u)
        write_csv(out / "plan.csv", {"x_mm": plan[:, 0], "y_mm": plan[:, 1]})
        written.append(out / "plan.csv")
    if not args.no_plots:
        from plantmech.outputs import study_plots as sp
        from plantmech.studies.engine import read_results

        data = read_results(out)
        sp.plot_histograms(out / "histograms.png", data, s)
        sp.plot_sensitivity(out / "sensitivity.png", s)
        sp.plot_band(out / "band.png", {**s, "band": band}, plan)
        written += [out / "histograms.png", out / "sensitivity.png", out / "band.png"]
    print(f"tolerance study: {s['samples']} samples; P(every objective met) = "
          f"{s['probability_all_ok']:.4f}; P(the {len(s['nominal_met'])} objectives the "
          f"nominal design meets all still met) = {s['probability_nominal_met_kept']:.4f}")
    if s.get("variants_not_moved"):
        print(f"  {s['variants_not_moved']} of {s['samples']} variants could not be built or "
              "moved (a field outside what the design file accepts): counted as not met, "
              "left out of the tip-path band")
    for o in s["objectives"]:
        top = o["sensitivity"]["ranking"][0]
        nom = "not computable" if o["nominal"] is None else f"{o['nominal']:>10.4f}"
        fo = "n/a" if o["first_order_std"] is None else f"{o['first_order_std']:.4g}"
        std = f"{o['std']:.4g}" if "std" in o else "n/a"  # not computed in any variant
        print(f"  {o['name']:<36} nominal {nom:>10} {o['unit']:<4} "
              f"P(ok {o['limit']}) = {o['probability_ok']:.4f}   std {std}"
              f" (first order {fo}); most: {top['parameter']}")
    bs = s["band_summary"]
    print(f"  tip-path band: largest std {bs['largest_mc_std_mm']:.4f} mm (first order "
          f"{bs['largest_first_order_std_mm']:.4f} mm), envelope up to "
          f"{bs['largest_envelope_width_mm']:.3f} mm wide")
    return written
