"""plantmech: design planting mechanisms driven by non-circular planetary gear trains.

From a planned tip path (or a published parameter set) to gears a workshop can cut, with
one verdict: ``plantmech design`` checks the design, optimizes every objective and the
manufacturability checks, cuts the teeth and writes DXF/SVG/STL files and a report.
Sugarcane seeders (Liu et al. 2023), rice transplanters (Zhou et al. 2022) and general
non-circular planetary trains.

``plantmech design DESIGN.toml --out DIR``: the whole job, to cut gears (start here).
``plantmech init KIND DIR``: write a commented starting design.
``plantmech docs [TOPIC]``: the documentation, shipped with the package.
``plantmech inverse | forward | optimize | gears | verify``: the steps one at a time.

Exit status (every command): 0 everything asked of the design is met (objectives, checks,
manufacturability), 2 invalid input (names the field, gear or angle), 3 infeasible design,
4 it ran but something is not met (printed last as the verdict, and in the JSON record),
5 no space left on the device, 130 / 143 / 129 stopped by Ctrl-C / SIGTERM / SIGHUP (in both
cases nothing is written and an existing --out is left as it was).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from plantmech import __version__, typos
from plantmech.outputs.caveats import caveats
from plantmech.outputs.verdict import (
    EXIT_INFEASIBLE,
    EXIT_INPUT,
    EXIT_NO_SPACE,
    verdict,
    verdict_line,
)


def add_output_options(parser: argparse.ArgumentParser) -> None:
    """``--out DIR`` and ``--force`` for a command that writes files (use with
    :func:`run_command`)."""
    parser.add_argument("--out", required=True,
                        help="output directory (created; the results appear there all "
                        "together when the command ends with a result, exit 0/3/4)")
    parser.add_argument("--force", action="store_true",
                        help="replace the existing contents of --out (otherwise a --out "
                        "that holds anything is refused)")


def run_command(args, body, require_trajectory: bool = False, inputs: tuple = (),
                resume=None) -> int:
    """Load ``args.design``, run ``body(args, design, run)`` and return its exit status.

    The one way a command reads its design and writes its files (other commands adopt it
    by registering ``add_output_options(sub)`` and returning ``run_command(args, body)``):

    - the design is read with ``load_design`` (a regular file, bounded in size and
      nesting, strictly validated); an invalid one prints the error naming the file and
      field and returns 2 before anything is created; ``inputs``: the command's other
      inputs (files or directories: --out may not hold them nor be them); ``resume``: see
      :class:`~plantmech.outputs.files.OutputRun`;
    - ``body`` writes every file into ``run.path``, a fresh temporary directory beside
      ``--out`` (``run.final(p)`` gives a file's final place, for messages), and returns
      the exit status: 0 done, 3 infeasible, 4 a check or objective not met (files are
      then moved into ``--out`` at once), or 2 invalid input (nothing is kept);
    - ``--out`` is checked first (not empty, not below a file, writable, not an input nor
      holding one or a link to one, by file identity); existing contents are replaced only
      with ``--force``, else 2 saying what is there;
    - an exception or a signal deletes the temporary directory and leaves ``--out`` as it
      was (SIGINT returns 130, SIGTERM 143, SIGHUP 129; a full disk 5: :func:`ended_by`);
      a value that is not finite about to be written is reported as not computable (exit
      3, nothing written).
    """
    from plantmech.design import DesignError, load_design
    from plantmech.kinds import kind_of
    from plantmech.outputs.files import NonFiniteOutput, OutputError, OutputRun

    try:
        design = load_design(Path(args.design))
        refuse_planetary(args, design)
        kind = kind_of(design)
        if require_trajectory:
            if not kind.has("inverse_cli"):
                raise DesignError(f"{args.design}: field 'mechanism': inverse design is for "
                                  "the sugarcane seeder and the general planetary train; a "
                                  f"{design.mechanism} design runs with 'plantmech forward'")
            if kind.inverse_needs_trajectory and design.trajectory is None:
                raise DesignError(f"{args.design}: field 'trajectory' is required for inverse "
                                  "design (this file gives a [train]: use 'plantmech forward')")
        run = OutputRun(args.out, [Path(args.design), *map(Path, inputs)],
                        force=getattr(args, "force", False), resume=resume)
        with run:
            try:
                run.exit_code = body(args, design, run)
            except NonFiniteOutput as exc:
                print(f"error: {args.design}: a result is not computable: {exc}; nothing "
                      "written", file=sys.stderr)
                run.exit_code = None
                return EXIT_INFEASIBLE
        return run.exit_code
    except (DesignError, OutputError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return EXIT_INPUT
    except (KeyboardInterrupt, OSError) as exc:
        code = ended_by(exc)
        if code is None:
            raise
        return code


def ended_by(exc: BaseException) -> int | None:
    """The exit status of a run ended by a signal (128 + its number: Ctrl-C 130, SIGTERM
    143, SIGHUP 129) or by a full disk (5), after saying so; None for any other exception.
    The one place these endings are told: ``run_command`` and ``main`` both ask it. The
    output classes (``OutputRun``, ``OutputFile``) have already deleted their temporary
    files and left ``--out`` as it was."""
    from plantmech.outputs.files import is_no_space
    from plantmech.outputs.signals import stopped

    if isinstance(exc, KeyboardInterrupt):
        return stopped(exc)
    if is_no_space(exc):
        where = f" ({exc.filename})" if getattr(exc, "filename", None) else ""
        print(f"error: no space left on the device{where}: nothing was written, --out left "
              "as it was", file=sys.stderr)
        return EXIT_NO_SPACE
    return None


def refuse_planetary(args, design) -> None:
    """A general planetary train (``mechanism = "planetary"``) runs with ``plantmech
    forward``, ``plantmech gears``, ``plantmech optimize --problem planetary``,
    ``plantmech inverse`` (from a [trajectory]), ``plantmech verify`` and the app so far;
    any other command or problem refuses it by name (DesignError, exit 2). ``--report``
    of forward, gears, optimize, study and design takes it; of inverse not yet."""
    from plantmech.design import DesignError
    from plantmech.kinds import kind_of

    command = getattr(args, "command", None)
    kind = kind_of(design)
    if kind.commands is None:  # every command takes it
        return
    if command not in kind.commands:
        raise DesignError(f"{args.design}: field 'mechanism': a \"planetary\" train runs with "
                          "'plantmech forward', 'plantmech gears', 'plantmech optimize "
                          "--problem planetary', 'plantmech inverse' (from a [trajectory]), "
                          "'plantmech study', 'plantmech design', 'plantmech verify' and "
                          f"'plantmech app' so far; '{command}' is for the seeder and the rice "
                          "transplanters only")
    problem = getattr(args, "problem", None)
    if command == "optimize" and problem not in kind.problems:
        raise DesignError(f"{args.design}: option --problem: a \"planetary\" train is "
                          f"optimized with --problem planetary ('{problem}' is for the seeder "
                          "and the rice transplanters)")
    if command not in kind.report_commands and getattr(args, "report", False):
        raise DesignError(f"{args.design}: option --report: the HTML report is not available "
                          f"for mechanism \"planetary\" yet ('{command}' writes its files and "
                          "verification.json without it)")


def _wrote(run, paths) -> str:
    return "wrote: " + ", ".join(str(run.final(p)) for p in paths)


def _inverse(args) -> int:
    return run_command(args, _inverse_body, require_trajectory=True)


def _inverse_body(args, design, run) -> int:
    from plantmech.kinds import kind_of

    return kind_of(design).hook("inverse_cli")(args, design, run)


def _inverse_seeder(args, design, run) -> int:
    """The seeder's inverse design (three-bar split of its [trajectory]) into ``run.path``."""
    from plantmech.geometry.trajectory import TrajectoryError
    from plantmech.outputs.files import write_json
    from plantmech.outputs.seeder_report import write_inverse_outputs
    from plantmech.workflows import run_seeder_inverse

    out = run.path
    t0 = time.perf_counter()
    try:
        job = run_seeder_inverse(design, speeds=True, estimate=True)
    except TrajectoryError as exc:
        print(f"error: {args.design}: field 'trajectory.points': {exc}", file=sys.stderr)
        return EXIT_INPUT
    res = job.result
    if args.verify and res.feasible:
        from plantmech.verification import round_trip

        try:
            job.summary.update(round_trip(job))
        except ValueError as exc:  # e.g. a dwell the forward simulator cannot place
            job.summary["round_trip_not_computable"] = str(exc)
    job.summary["wall_time_s"] = round(time.perf_counter() - t0, 4)
    written = write_inverse_outputs(out, res, job.summary, job.trajectory,
                                    design.trajectory.samples)
    if not args.no_plots:
        from plantmech.outputs import seeder_plots as sp

        figures = [("trajectory.png", sp.plot_trajectory(job.trajectory, res, job.sections))]
        if res.arm_angle_realized is not None and res.feasible:
            figures += [("attitude.png", sp.plot_attitude(res, job.sections)),
                        ("ratios.png", sp.plot_ratios(res)),
                        ("pitch_curves.png", sp.plot_pitch_curves(res))]
        written += [sp.save(fig, out / name) for name, fig in figures]
    s = job.summary
    problems = []
    if "round_trip_not_computable" in s:
        problems.append(f"round trip (--verify) not computable: {s['round_trip_not_computable']}")
    v = s["verdict"] = verdict(s["trajectory_checks"], s.get("objectives", []),
                               s.get("manufacturing_checks", []),
                               s.get("dwell_checks", []), s.get("error_estimate_checks", []),
                               infeasible=not res.feasible,
                               problems=problems)
    cav = s["caveats"] = caveats(design, s["trajectory_checks"] + s.get("objectives", [])
                                 + s.get("manufacturing_checks", []))
    write_json(out / "summary.json", s)
    _print_summary(s)
    if args.report:
        from plantmech.interfaces.report_cli import inverse_report

        written += inverse_report(args, out, job, [] if args.no_plots else figures,
                                  run=run)
    print(_wrote(run, written))
    if not res.feasible:
        print("INFEASIBLE: no pitch curves written (see diagnostics above)", file=sys.stderr)
    print(verdict_line(v, "feasible, every planning check, attitude and speed objective "
                          "met, pitch curves cuttable" + (
                              "" if s.get("error_estimate", {}).get("computed", True) else
                              " (its error estimate was not computed: see above)"), cav))
    return v["exit_code"]


def _forward(args) -> int:
    return run_command(args, _forward_body)


def _forward_body(args, design, run) -> int:
    from plantmech.kinds import kind_of

    return kind_of(design).hook("forward_cli")(args, design, run)


def _forward_seeder(args, design, run) -> int:
    """The seeder's forward simulation (its [train], or its trajectory's inverse design)."""
    from plantmech.gears.closure import ClosureError
    from plantmech.geometry.periodic import PitchCurveError
    from plantmech.geometry.trajectory import TrajectoryError
    from plantmech.outputs.files import write_json
    from plantmech.outputs.seeder_forward_report import write_forward_outputs
    from plantmech.workflows import InfeasibleDesign, run_seeder_forward

    out = run.path
    t0 = time.perf_counter()
    try:
        job = run_seeder_forward(design)
    except TrajectoryError as exc:
        print(f"error: {args.design}: field 'trajectory.points': {exc}", file=sys.stderr)
        return EXIT_INPUT
    except (ClosureError, PitchCurveError, ValueError) as exc:
        print(f"error: {args.design}: [train]: {exc}", file=sys.stderr)
        return EXIT_INPUT
    except InfeasibleDesign as exc:
        v = exc.job.summary["verdict"] = verdict(infeasible=True)
        write_json(out / "summary.json", exc.job.summary)
        _print_summary(exc.job.summary)
        print("INFEASIBLE: the trajectory's inverse design has no gear train to simulate",
              file=sys.stderr)
        print(verdict_line(v, ""))
        return EXIT_INFEASIBLE
    job.summary["wall_time_s"] = round(time.perf_counter() - t0, 4)
    v = job.summary["verdict"] = verdict(job.summary["objectives"])
    cav = job.summary["caveats"] = caveats(design, job.summary["objectives"])
    written = write_forward_outputs(out, job)
    figures = []
    if not args.no_plots:
        from plantmech.outputs import seeder_plots as sp

        figures = [(name, fn(job)) for name, fn in (
            ("trajectories.png", sp.plot_forward_trajectories),
            ("speed.png", sp.plot_forward_speed), ("attitude.png", sp.plot_forward_attitude),
            ("pitch_curves.png", sp.plot_forward_pitch_curves))]
        written += [sp.save(fig, out / name, dpi=130) for name, fig in figures]
    _print_forward(job.summary)
    if args.report:
        from plantmech.interfaces.report_cli import forward_report

        written += forward_report(args, out, job, figures, run=run)
    print(_wrote(run, written))
    print(verdict_line(v, "every section-4.1 objective met, pitch curves cuttable", cav))
    return v["exit_code"]


def _forward_transplanter(args, design, run) -> int:
    from plantmech.gears.internal import InternalPairError
    from plantmech.outputs.transplanter_report import write_transplanter_outputs
    from plantmech.workflows import run_transplanter

    out = run.path
    t0 = time.perf_counter()
    try:
        job = run_transplanter(design)
    except (InternalPairError, ValueError) as exc:
        from plantmech.kinds import kind_of

        print(f"error: {args.design}: [{kind_of(design).fixed_gear}]: {exc}", file=sys.stderr)
        return EXIT_INPUT
    job.summary["wall_time_s"] = round(time.perf_counter() - t0, 4)
    v = job.summary["verdict"] = verdict(job.summary["objectives"])
    cav = job.summary["caveats"] = caveats(design, job.summary["objectives"])
    written = write_transplanter_outputs(out, job)
    figures = []
    if not args.no_plots:
        from plantmech.outputs import transplanter_plots as tp
        from plantmech.outputs.seeder_plots import save

        figures = [(name, fn(job)) for name, fn in (
            ("trajectories.png", tp.plot_trajectories),
            ("attitude_speed.png", tp.plot_attitude_speed),
            ("ratio.png", tp.plot_ratio), ("gears.png", tp.plot_gears))]
        written += [save(fig, out / name, dpi=120) for name, fig in figures]
    s = job.summary
    print(f"{s['name']}: {s['mechanism']}, centre distance {s['centre_distance_mm']:.3f} mm, "
          f"closure error {s['closure_error_rad']:.1e} rad")
    from plantmech.outputs.files import check_line

    for c in s["objectives"]:
        print(check_line(c, 24))
    for arm, st in s["stages_deg"].items():
        parts = ", ".join(f"{k} {v[0]:.1f}-{v[1]:.1f}" for k, v in st.items() if v)
        print(f"  {arm}: {parts} deg")
    dev = s["arm_phase_deviation_mm"]
    print("  arms repeat each other after the carrier phase shift to "
          f"{max(dev):.1e} mm" if max(dev) < 1e-6 else
          f"  arms differ after the carrier phase shift by up to {max(dev):.2f} mm")
    if args.report:
        from plantmech.interfaces.report_cli import forward_report

        written += forward_report(args, out, job, figures, run=run)
    print(_wrote(run, written))
    print(verdict_line(v, "every objective met, pitch curves cuttable", cav))
    return v["exit_code"]


def _optimize(args) -> int:
    return run_command(args, _optimize_body)


def _optimize_body(args, design, run) -> int:
    from plantmech.optimize.jobs import optimize, summary_lines
    from plantmech.optimize.problems import InfeasiblePopulation
    from plantmech.outputs.files import write_json

    out = run.path
    try:
        outcome = optimize(design, args.problem, out, str(args.design), seed=args.seed,
                           generations=args.generations, pop=args.pop,
                           algorithm=args.algorithm, progress=not args.quiet,
                           layer2_points=args.points,
                           manufacturability=not args.no_manufacturability,
                           seeding_shifts=args.seeding_shifts,
                           seeding_point=args.seeding_point)
    except ValueError as exc:
        print(f"error: {args.design}: {exc}", file=sys.stderr)
        return EXIT_INPUT
    except InfeasiblePopulation as exc:
        write_json(out / "run.json", {"problem": args.problem, "feasible": False,
                                      "infeasible": str(exc)})
        print(f"INFEASIBLE: {exc}", file=sys.stderr)
        print(_wrote(run, [out / "run.json"]))
        return EXIT_INFEASIBLE
    for line in summary_lines(outcome.record):
        print(line)
    written = list(outcome.written)
    cav = _optimize_caveats(design, out, outcome.record)
    if args.report:
        from plantmech.interfaces.report_cli import optimize_report

        written += optimize_report(args, out, outcome, run=run)
    print(_wrote(run, written))
    v = outcome.record["verdict"]
    print(verdict_line(v, "best.toml meets every objective"
                       + (" and manufacturability check" if outcome.record.get(
                           "manufacturability_required") else "")
                       + ", re-checked at full resolution", cav))
    return v["exit_code"]


def _optimize_caveats(design, out, record: dict) -> list:
    """The optimize verdict's caveats (``outputs.caveats``: the file's limits, the thin
    margins of the re-checked best design, what the optimizer changed of the file), added
    to run.json."""
    from plantmech.design import DesignError, load_design
    from plantmech.outputs.files import write_json

    best = None
    if (out / "best.toml").is_file():
        try:
            best = load_design(out / "best.toml")
        except DesignError:
            best = None
    rows = (record.get("verified_full_resolution") or {}).get("objectives") \
        or record.get("objectives") or []
    cav = record["caveats"] = caveats(design, rows, best, record)
    if (out / "run.json").is_file():
        write_json(out / "run.json", record)
    return cav


def _gears(args) -> int:
    if args.dedendum is not None and args.addendum is not None \
            and args.dedendum <= args.addendum:
        print(f"error: --dedendum {args.dedendum:g} must be above --addendum "
              f"{args.addendum:g} (root clearance)", file=sys.stderr)
        return EXIT_INPUT
    return run_command(args, _gears_body)


def _gears_body(args, design, run) -> int:
    from plantmech.gears.findings import describe
    from plantmech.gears.manufacturability import rules_for
    from plantmech.gears.modules import module_choice_line
    from plantmech.outputs.caveats import lines as caveat_lines
    from plantmech.workflows import run_gears

    out = run.path
    try:
        rules = rules_for(design, {"pressure_angle_deg": args.pressure_angle,
                                   "addendum": args.addendum, "dedendum": args.dedendum})
        rec = run_gears(design, out, module=args.module, face_width=args.face_width,
                        backlash=args.backlash,
                        tooth={"pressure_angle_deg": rules.pressure_angle_deg,
                               "addendum": rules.addendum, "dedendum": rules.dedendum},
                        step=args.step, method=args.teeth)
    except ValueError as exc:
        print(f"error: {args.design}: {exc}", file=sys.stderr)
        return EXIT_INPUT
    failed = {f["gear"] for f in rec["findings"]}
    for g in rec["gears"]:
        rc = g["cutter_pitch_radius_mm"]
        cutter = (g["cutter"] if rc is None else f"shaper r {rc:.2f} mm")
        stl = g["stl"]
        print(f"  {'FAIL' if g['name'] in failed else 'ok  '} {g['name']:<9} z = "
              f"{g['teeth']:>3}, m = {g['module_mm']:.4f} mm, {cutter}, max working pressure "
              f"angle {g['max_pressure_angle_deg']:.1f} deg, STL "
              + ("one watertight body" if stl["written"] else f"refused ({stl['bodies']} bodies)"))
    for mm in rec["mesh"]:
        play = ("none (the outlines overlap everywhere)"
                if mm["min_circumferential_backlash_mm"] is None else
                f"{mm['min_circumferential_backlash_mm']:.3f}..."
                f"{mm['max_circumferential_backlash_mm']:.3f} mm (asked "
                f"{rec['backlash_mm']:g}), normal gap {mm['min_normal_gap_mm']:.3f}..."
                f"{mm['max_normal_gap_mm']:.3f} mm")
        print(f"  {'FAIL' if mm['pair'] in failed else 'ok  '} mesh {mm['pair']}: interference "
              f"{mm['max_interference_mm']:.4f} mm, circumferential backlash {play}")
    for c in rec.get("module_choice", []):
        print("  " + module_choice_line(c))
    for note in rec.get("notes", []):
        print(f"  note: {note}")
    if "step" in rec:
        print(f"  STEP not written: {rec['step']}")
    print(f"wrote {len(rec['files'])} files and verification.json to {run.final(out)}")
    if args.report:
        from plantmech.interfaces.report_cli import gears_report

        gears_report(args, out, design, rec, run=run)
    for f in rec["findings"]:
        print(f"  NOT OK {describe(f)}")
    for line in caveat_lines(rec.get("caveats", [])):
        print(line)
    v = rec["verdict"]  # the record's (workflows.run_gears), printed as it holds it
    print(f"verdict: {v['text']}")
    return v["exit_code"]


def _print_forward(s: dict) -> None:
    t = s["train"]
    print(f"{s['name']}: forward simulation ({s['source']})")
    print(f"  L1 = {t['L1_mm']:.2f} mm, L2 = {t['L2_mm']:.2f} mm, a1 = {t['a1_mm']:.3f} mm, "
          f"a2 = {t['a2_mm']:.3f} mm")
    for f in s["closure_restoration"]:
        if f["method"] != "check" and abs(f["turn_as_given_deg"] - f["required_turn_deg"]) > 1e-6:
            change = {"centre_distance": f"centre distance {f['centre_distance_given_mm']:.3f}"
                                         f" -> {f['centre_distance_mm']:.3f} mm",
                      "radial_offset": f"every radius {f['radial_offset_mm']:+.3f} mm",
                      "scale": f"radii x {f['scale']:.5f}"}[f["method"]]
            print(f"  closure of {f['pair']}: the mate turned {f['turn_as_given_deg']:.3f} deg,"
                  f" {f['required_turn_deg']:.3f} needed; restored by {change}")
    ce = s["closure_error_rad"]
    print(f"  closure error: stage 1 {ce['stage1']:.2e} rad, stage 2 {ce['stage2']:.2e} rad")
    print(f"  zero-speed seeding travel v_c = {s['zero_speed_travel_m_s']:.3f} m/s "
          f"(used: {s['travel_speed_used_m_s']:.3f} m/s)")
    from plantmech.outputs.files import check_line

    for c in s["objectives"]:
        print(check_line(c, 34, 3))
    if "deviation_from_trajectory_mm" in s:
        dv = s["deviation_from_trajectory_mm"]
        print(f"  deviation from the planned trajectory: max {dv['max_tip_to_plan']:.2f} mm "
              f"(tip -> plan), {dv['max_plan_to_tip']:.2f} mm (plan -> tip)")


def _print_summary(s: dict) -> None:
    print(f"{s['name']}: {'feasible' if s['feasible'] else 'INFEASIBLE'}")
    print(f"  L1 = {s['L1_mm']:.2f} mm, L2 = {s['L2_mm']:.2f} mm", end="")
    if s.get("a1_mm"):
        print(f", a1 = {s['a1_mm']:.2f} mm, a2 = {s['a2_mm']:.2f} mm")
    else:
        print()
    for d in s["diagnostics"]:
        where = ""
        if d["between_points"]:
            where += f" between q{d['between_points'][0]} and q{d['between_points'][1]}"
        if d["carrier_angle_deg"]:
            a, b = d["carrier_angle_deg"]
            where += f" (carrier angle {a:.1f}-{b:.1f} deg)"
        print(f"  {d['severity'].upper()} [{d['kind']}]{where}: {d['message']}")
    from plantmech.outputs.files import check_line
    from plantmech.workflows import seeder_checks

    for c in seeder_checks(s):
        print(check_line(c))
    if "error_estimate" in s:
        from plantmech.objectives.inverse_estimate import estimate_line

        print(estimate_line(s["error_estimate"]))
    if "realized_vs_planned_max_deviation_mm" in s:
        print(f"  gear train vs planned trajectory: max deviation "
              f"{s['realized_vs_planned_max_deviation_mm']:.3f} mm")
    if "round_trip_max_deviation_mm" in s:
        print(f"  round trip (forward simulation of the pitch curves): max deviation "
              f"{s['round_trip_max_deviation_mm']:.2e} mm")


def _number(kind, minimum, strict: bool = True, maximum=None, least=None):
    """argparse type of every numeric option (the one place their ranges are checked): a
    finite ``kind`` (int or float) above (or, strict=False, at least) ``minimum``, and,
    if given, at least ``least`` and at most ``maximum``; never wrapped or rounded."""
    import math

    def parse(text: str):
        try:
            v = kind(text)
        except ValueError:
            what = "a whole number" if kind is int else "a number"
            raise argparse.ArgumentTypeError(f"{text!r} is not {what}") from None
        bad = (not math.isfinite(v) or (v <= minimum if strict else v < minimum)
               or (least is not None and v < least) or (maximum is not None and v > maximum))
        if bad:
            raise argparse.ArgumentTypeError(
                f"{text} must be {'above' if strict else 'at least'} {minimum:g}"
                + (f", at least {least:g}" if least is not None else "")
                + (f" and at most {maximum:g}" if maximum is not None else ""))
        return v

    return parse


#: the range of every random seed option (NumPy's and pymoo's seeds are 32 bits)
SEED = {"minimum": 0, "strict": False, "maximum": 2**32 - 1}
class _Parser(argparse.ArgumentParser):
    """argparse with "did you mean" on a misspelled command, choice or option, and an
    unknown option reported by the command's own usage (not the top level's)."""

    def parse_args(self, args=None, namespace=None):
        args, unknown = self.parse_known_args(args, namespace)
        if unknown:
            sub = self._command_parser(getattr(args, "command", None)) or self
            options = [o[2:] for o in sub._option_string_actions if o.startswith("--")]
            hints = "".join(typos.did_you_mean(u.split("=")[0].lstrip("-"), options)
                            .replace(" '", " '--") for u in unknown if u.startswith("-"))
            sub.error(f"unrecognized arguments: {' '.join(unknown)}{hints}")
        return args

    def _command_parser(self, command):
        for action in self._actions:
            if isinstance(action, argparse._SubParsersAction):
                return action.choices.get(command)
        return None

    def error(self, message):
        import re

        m = re.search(r"invalid choice: '(.*)' \(choose from (.*)\)$", message)
        if m:
            choices = re.findall(r"'([^']*)'", m.group(2))
            message += typos.did_you_mean(m.group(1), choices)
        if message.endswith("required: COMMAND"):
            message += ("; start with 'plantmech init transplanter my' then 'plantmech design "
                        "my/transplanter.toml --out out' ('plantmech --help': every command)")
        super().error(message)


def build_parser() -> argparse.ArgumentParser:
    from plantmech.interfaces.report_cli import add_report_option

    p = _Parser(
        prog="plantmech", description="\n".join(__doc__.split("\n\n")[:2]),
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog="Start with: plantmech init transplanter my; then plantmech design "
        "my/transplanter.toml --out out (cut gears, design.toml and a verdict). "
        "'plantmech COMMAND --help' for each; 'plantmech docs' for the documentation.")
    p.add_argument("--version", action="version", version=f"plantmech {__version__}")
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")
    from plantmech.interfaces import (
        app_cli,
        design_cli,
        docs_cli,
        init_cli,
        report_cli,
        schema_cli,
        study_cli,
        verify_cli,
    )

    design_cli.register(sub)  # the main job first, then how to start, then the steps
    init_cli.register(sub)
    docs_cli.register(sub)
    inv = sub.add_parser("inverse", help="seeder or planetary [trajectory]: planned tip "
                         "trajectory -> gear train (inverse design of Liu et al. 2023, "
                         "section 3)",
                         description="Inverse design of the sugarcane seeder of Liu et al. "
                         "(2023): closed trajectory through the type-value points, planning "
                         "checks (Table 1), ratio law, pitch curves of the four gears, "
                         "feasibility verdict. A mechanism = \"planetary\" file with a "
                         "[trajectory]: a first-order train (fixed sun, one pair) or seed "
                         "000's second-order train (two pairs), written as design.toml and "
                         "checked by running it forward.")
    inv.add_argument("design", help="design file (TOML)")
    add_output_options(inv)
    inv.add_argument("--verify", action="store_true",
                     help="simulate the generated pitch curves forward (round trip)")
    inv.add_argument("--no-plots", action="store_true", help="skip PNG plots")
    add_report_option(inv)
    inv.set_defaults(func=_inverse)
    fwd = sub.add_parser(
        "forward", help="gear train -> motion and objectives: seeders (Liu et al. 2023, "
        "section 4) and rice transplanters (Zhou et al. 2022)",
        description="Forward simulation of a gear train and every objective with value, "
        "limit and pass/fail. Sugarcane seeder (mechanism = \"sugarcane_seeder\"): a [train] "
        "given by its pitch curves (Liu et al. 2023, Table 4), or the inverse design of a "
        "[trajectory]. Rice transplanters (mechanism = \"rice_transplanter\" or "
        "\"rice_transplanter_khv\"): the trains of Zhou et al. (2022) and their twelve "
        "objectives (i)-(xii).")
    fwd.add_argument("design", help="design file (TOML) with a [train], or a [trajectory] "
                     "whose inverse design is simulated")
    add_output_options(fwd)
    fwd.add_argument("--no-plots", action="store_true", help="skip PNG plots")
    add_report_option(fwd)
    fwd.set_defaults(func=_forward)
    gears = sub.add_parser("gears",
                           help="teeth (envelope or simulated cutting), checks, DXF/SVG/STL")
    gears.add_argument("design", help="design file (TOML)")
    add_output_options(gears)
    gears.add_argument("--module", type=_number(float, 0.0, maximum=50.0, least=0.5),
                       default=None, help="target module (mm, 0.5-50); default: the design's "
                       "tooth count (internal_gear.teeth, sun_gear.teeth, train.pairs[].teeth), "
                       "else the largest standard module (ISO 54, or [manufacturing] "
                       "modules_mm) the pitch curves allow, with the whole tooth count nearest "
                       "perimeter / (pi m) in multiples of the lobes and turns (said in the "
                       "output and verification.json's module_choice)")
    gears.add_argument("--face-width", type=_number(float, 0.0, maximum=1000.0),
                       default=12.0, help="mm (up to 1000), for STL/STEP")
    gears.add_argument("--backlash", type=_number(float, 0.0, strict=False, maximum=5.0),
                       default=0.1, help="circumferential backlash per pair, mm (0-5)")
    gears.add_argument("--pressure-angle", type=_number(float, 0.0, maximum=35.0, least=5.0),
                       default=None, help="tool pressure angle, deg (5-35); default: the "
                       "design's (manufacturing.pressure_angle_deg, else 20)")
    gears.add_argument("--addendum", type=_number(float, 0.0, maximum=2.0),
                       default=None, help="addendum, x module (up to 2); default: the "
                       "design's manufacturing.addendum (1.0)")
    gears.add_argument("--dedendum", type=_number(float, 0.0, maximum=3.0),
                       default=None, help="dedendum, x module (above the addendum: root "
                       "clearance; up to 3); default: the design's manufacturing.dedendum "
                       "(1.25)")
    gears.add_argument("--teeth", choices=("envelope", "simulated"), default="envelope",
                       help="how teeth are generated: from the envelope condition of the "
                       "meshing equation (default: rack- and shaper-cut gears and the mates "
                       "cut by their driver's teeth, a planet cut by its ring within the "
                       "simulated cut's reach; any "
                       "envelope that fails its self-check falls back to simulation, said in "
                       "verification.json) or by simulated cutting of every gear (the "
                       "reference)")
    gears.add_argument("--step", action="store_true",
                       help="also write STEP solids (needs plantmech[step]; seconds per gear)")
    add_report_option(gears)
    gears.set_defaults(func=_gears)
    from plantmech.optimize import ALGORITHMS, PROBLEMS

    opt = sub.add_parser("optimize", help="automatic optimization of a design's objectives")
    opt.add_argument("design", help="design file (TOML); never overwritten")
    opt.add_argument("--problem", required=True, choices=PROBLEMS)
    add_output_options(opt)
    opt.add_argument("--seed", type=_number(int, **SEED),
                     default=0, help="random seed (0 to 2^32 - 1): the same seed gives the "
                     "same run")
    opt.add_argument("--generations", type=_number(int, 1, strict=False, maximum=10_000),
                     default=None, help="generations (1-10000); default per problem")
    opt.add_argument("--pop", type=_number(int, 4, strict=False, maximum=2000),
                     default=None, help="population size (4-2000)")
    opt.add_argument("--algorithm", choices=ALGORITHMS, default=None,
                     help="default per problem (plantmech docs optimization)")
    opt.add_argument("--points", type=_number(int, 4, strict=False, maximum=128),
                     default=16, help="interpolation radii per gear for the seeder's layer 2 "
                     "(4-128)")
    opt.add_argument("--seeding-shifts", type=_number(int, 0, strict=False, maximum=20),
                     default=0, help="seeder layer 1 (0-20): also scout moving the seeding "
                     "point e (and f) on by 1..K type-value points (Liu et al. 2023, Fig. 6, "
                     "relabels it g)")
    opt.add_argument("--seeding-point", choices=("auto", "keep"), default="auto",
                     help="seeder problems that move type-value points: 'auto' moves the "
                     "seeding point e (and f) on when, at e, a return speed above its "
                     "minimum needs a seeding speed above its limit (the three-bar bound, "
                     "plantmech docs optimization); 'keep' never moves it")
    opt.add_argument("--no-manufacturability", action="store_true",
                     help="only report the pitch-curve manufacturability checks (cuttable "
                     "module, working pressure angle, tooth fit) instead of requiring them; "
                     "recorded in run.json. By default every problem requires them")
    opt.add_argument("--quiet", action="store_true", help="no progress bar")
    add_report_option(opt)
    opt.set_defaults(func=_optimize)
    verify_cli.register(sub)
    schema_cli.register(sub)
    study_cli.register(sub)
    report_cli.register(sub)
    app_cli.register(sub)
    return p


class _ReaderMayLeave:
    """Standard output that outlives its reader: when the pipe closes (``plantmech ... |
    head``), what is still to print goes to /dev/null and the job runs to its end, files
    and exit status included, instead of dying on BrokenPipeError half-way."""

    def __init__(self, stream):
        self._stream = stream

    def _leave(self):
        import os

        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, self._stream.fileno())  # also for the interpreter's final flush
        os.close(devnull)

    def write(self, text):
        try:
            return self._stream.write(text)
        except BrokenPipeError:
            self._leave()
            return len(text)

    def flush(self):
        try:
            self._stream.flush()
        except BrokenPipeError:
            self._leave()

    def __getattr__(self, name):
        return getattr(self._stream, name)


def main(argv: list[str] | None = None) -> int:
    if not isinstance(sys.stdout, _ReaderMayLeave) and hasattr(sys.stdout, "fileno"):
        try:
            sys.stdout.fileno()
            sys.stdout = _ReaderMayLeave(sys.stdout)
        except (OSError, ValueError):  # no file behind it (captured by a test): nothing to do
            pass
    from plantmech.outputs import signals

    # as a program (argv None) the signals are ignored after the command: a signal after the
    # results are in place is never a kill that contradicts the exit status. Installed before
    # the parser is built (it imports the design model: a second and more), so that a signal
    # then is an exit status too, not a KeyboardInterrupt traceback
    with signals.handled(restore=argv is not None):
        try:
            parser = build_parser()
            for a in sys.argv[1:] if argv is None else argv:
                # argparse takes "--option=--" as the option left out (its default), silently
                if a.startswith("--") and a.endswith("=--"):
                    parser.error(f"argument {a[:-3]}: '--' is not a value")
            args = parser.parse_args(argv)
            if args.command != "init":
                import matplotlib

                matplotlib.use("Agg")  # files only: the CLI never opens a window
            code = args.func(args)
        except (KeyboardInterrupt, OSError) as exc:
            code = ended_by(exc)
            if code is None:
                raise
        got = signals.received()
        if got is not None and not signals.finished() and code != 128 + got:
            code = ended_by(signals.Interrupted(got))  # swallowed on the way: not a result
        return code


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
