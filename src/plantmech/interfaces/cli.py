"""Command line of plantmech.

``plantmech inverse DESIGN.toml --out DIR [--verify]``: trajectory -> gear train.
``plantmech forward DESIGN.toml --out DIR``: gear train -> motion and objectives.
``plantmech optimize DESIGN.toml --problem NAME --out DIR``: automatic optimization.
``plantmech gears DESIGN.toml --out DIR``: teeth, checks and manufacturing files.

Exit status: 0 done (forward: objectives are reported, met or not; optimize: a design
meeting every objective was found), 2 invalid input (names the field, gear or angle),
3 infeasible design, 4 optimize found no design meeting every objective (the closest
one is written) / gears: a gear is not manufacturable or a file is not what it claims
(the verdict and its findings are printed last and in verification.json).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from plantmech import __version__

EXIT_OK, EXIT_INPUT, EXIT_INFEASIBLE, EXIT_NOT_MET = 0, 2, 3, 4


def _load(args, require_trajectory: bool = False):
    """(design, out dir) or None after printing the input error."""
    from plantmech.design import DesignError, load_design
    from plantmech.outputs.files import OutputError, prepare_out_dir

    try:
        design = load_design(args.design)
        if require_trajectory and design.trajectory is None:
            raise DesignError(f"{args.design}: field 'trajectory' is required for inverse "
                              "design (this file gives a [train]: use 'plantmech forward')")
        return design, prepare_out_dir(args.out, [Path(args.design)])
    except (DesignError, OutputError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return None


def _inverse(args) -> int:
    from plantmech.geometry.trajectory import TrajectoryError
    from plantmech.outputs.files import write_json
    from plantmech.outputs.seeder_report import write_inverse_outputs
    from plantmech.workflows import run_seeder_inverse

    loaded = _load(args, require_trajectory=True)
    if loaded is None:
        return EXIT_INPUT
    design, out = loaded
    t0 = time.perf_counter()
    try:
        job = run_seeder_inverse(design)
    except TrajectoryError as exc:
        print(f"error: {args.design}: field 'trajectory.points': {exc}", file=sys.stderr)
        return EXIT_INPUT
    res = job.result
    if args.verify and res.feasible:
        from plantmech.verification import round_trip

        job.summary.update(round_trip(job))
    job.summary["wall_time_s"] = round(time.perf_counter() - t0, 4)
    written = write_inverse_outputs(out, res, job.summary, job.trajectory,
                                    design.trajectory.samples)
    if not args.no_plots:
        from plantmech.outputs import seeder_plots as sp

        sp.plot_trajectory(out / "trajectory.png", job.trajectory, res, job.sections)
        written.append(out / "trajectory.png")
        if res.arm_angle_realized is not None and res.feasible:
            sp.plot_attitude(out / "attitude.png", res, job.sections)
            sp.plot_ratios(out / "ratios.png", res)
            sp.plot_pitch_curves(out / "pitch_curves.png", res)
            written += [out / "attitude.png", out / "ratios.png", out / "pitch_curves.png"]
    write_json(out / "summary.json", job.summary)
    _print_summary(job.summary)
    print("wrote: " + ", ".join(str(p) for p in written))
    if not res.feasible:
        print("INFEASIBLE: no pitch curves written (see diagnostics above)", file=sys.stderr)
        return EXIT_INFEASIBLE
    return EXIT_OK


def _forward(args) -> int:
    from plantmech.gears.closure import ClosureError
    from plantmech.geometry.periodic import PitchCurveError
    from plantmech.geometry.trajectory import TrajectoryError
    from plantmech.outputs.files import write_json
    from plantmech.outputs.seeder_forward_report import write_forward_outputs
    from plantmech.workflows import InfeasibleDesign, run_seeder_forward

    loaded = _load(args)
    if loaded is None:
        return EXIT_INPUT
    design, out = loaded
    if design.mechanism != "sugarcane_seeder":
        return _forward_transplanter(args, design, out)
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
        write_json(out / "summary.json", exc.job.summary)
        _print_summary(exc.job.summary)
        print("INFEASIBLE: the trajectory's inverse design has no gear train to simulate",
              file=sys.stderr)
        return EXIT_INFEASIBLE
    job.summary["wall_time_s"] = round(time.perf_counter() - t0, 4)
    written = write_forward_outputs(out, job)
    if not args.no_plots:
        from plantmech.outputs import seeder_plots as sp

        for name, fn in (("trajectories.png", sp.plot_forward_trajectories),
                         ("speed.png", sp.plot_forward_speed),
                         ("attitude.png", sp.plot_forward_attitude),
                         ("pitch_curves.png", sp.plot_forward_pitch_curves)):
            fn(out / name, job)
            written.append(out / name)
    _print_forward(job.summary)
    print("wrote: " + ", ".join(str(p) for p in written))
    return EXIT_OK


def _forward_transplanter(args, design, out) -> int:
    from plantmech.gears.internal import InternalPairError
    from plantmech.outputs.transplanter_report import write_transplanter_outputs
    from plantmech.workflows import run_transplanter

    t0 = time.perf_counter()
    try:
        job = run_transplanter(design)
    except (InternalPairError, ValueError) as exc:
        gear = "internal_gear" if design.mechanism == "rice_transplanter" else "sun_gear"
        print(f"error: {args.design}: [{gear}]: {exc}", file=sys.stderr)
        return EXIT_INPUT
    job.summary["wall_time_s"] = round(time.perf_counter() - t0, 4)
    written = write_transplanter_outputs(out, job)
    if not args.no_plots:
        from plantmech.outputs import transplanter_plots as tp

        for name, fn in (("trajectories.png", tp.plot_trajectories),
                         ("attitude_speed.png", tp.plot_attitude_speed),
                         ("ratio.png", tp.plot_ratio), ("gears.png", tp.plot_gears)):
            fn(out / name, job)
            written.append(out / name)
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
    print("wrote: " + ", ".join(str(p) for p in written))
    return EXIT_OK


def _optimize(args) -> int:
    from plantmech.optimize.jobs import optimize, summary_lines

    loaded = _load(args)
    if loaded is None:
        return EXIT_INPUT
    design, out = loaded
    try:
        outcome = optimize(design, args.problem, out, str(args.design), seed=args.seed,
                           generations=args.generations, pop=args.pop,
                           algorithm=args.algorithm, progress=not args.quiet,
                           layer2_points=args.points, tooth_fit=args.tooth_fit,
                           seeding_shifts=args.seeding_shifts,
                           seeding_point=args.seeding_point)
    except ValueError as exc:
        print(f"error: {args.design}: {exc}", file=sys.stderr)
        return EXIT_INPUT
    for line in summary_lines(outcome.record):
        print(line)
    print("wrote: " + ", ".join(str(p) for p in outcome.written))
    return EXIT_OK if outcome.feasible else EXIT_NOT_MET


def _gears(args) -> int:
    from plantmech.gears.findings import VERDICT_OK, describe
    from plantmech.workflows import run_gears

    loaded = _load(args)
    if loaded is None:
        return EXIT_INPUT
    design, out = loaded
    try:
        rec = run_gears(design, out, module=args.module, face_width=args.face_width,
                        backlash=args.backlash,
                        tooth={"pressure_angle_deg": args.pressure_angle,
                               "addendum": args.addendum, "dedendum": args.dedendum},
                        step=args.step)
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
    if "step" in rec:
        print(f"  STEP not written: {rec['step']}")
    print(f"wrote {len(rec['files'])} files and verification.json to {out}")
    for f in rec["findings"]:
        print(f"  NOT OK {describe(f)}")
    ok = rec["verdict"] == VERDICT_OK
    print(f"verdict: {rec['verdict']}" + ("" if ok else
          f" ({len(rec['findings'])} findings on {len(failed)} gears or pairs)"))
    return EXIT_OK if ok else EXIT_NOT_MET


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

    for c in s["trajectory_checks"] + s.get("objectives", []):
        print(check_line(c))
    if "realized_vs_planned_max_deviation_mm" in s:
        print(f"  gear train vs planned trajectory: max deviation "
              f"{s['realized_vs_planned_max_deviation_mm']:.3f} mm")
    if "round_trip_max_deviation_mm" in s:
        print(f"  round trip (forward simulation of the pitch curves): max deviation "
              f"{s['round_trip_max_deviation_mm']:.2e} mm")


def _number(kind, minimum, strict: bool = True):
    """argparse type: a finite number above (or, strict=False, at least) ``minimum``."""
    import math

    def parse(text: str):
        try:
            v = kind(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
        if not math.isfinite(v) or (v <= minimum if strict else v < minimum):
            raise argparse.ArgumentTypeError(
                f"{text} must be {'above' if strict else 'at least'} {minimum:g}")
        return v

    return parse


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="plantmech", description=__doc__.splitlines()[0])
    p.add_argument("--version", action="version", version=f"plantmech {__version__}")
    sub = p.add_subparsers(dest="command", required=True)
    inv = sub.add_parser("inverse", help="trajectory -> gear train (seed 000 §3)")
    inv.add_argument("design", help="design file (TOML)")
    inv.add_argument("--out", required=True, help="output directory")
    inv.add_argument("--verify", action="store_true",
                     help="simulate the generated pitch curves forward (round trip)")
    inv.add_argument("--no-plots", action="store_true", help="skip PNG plots")
    inv.set_defaults(func=_inverse)
    fwd = sub.add_parser("forward", help="gear train -> motion, speed, objectives (seed 000 §4)")
    fwd.add_argument("design", help="design file (TOML) with a [train], or a [trajectory] "
                     "whose inverse design is simulated")
    fwd.add_argument("--out", required=True, help="output directory")
    fwd.add_argument("--no-plots", action="store_true", help="skip PNG plots")
    fwd.set_defaults(func=_forward)
    gears = sub.add_parser("gears", help="teeth by simulated cutting, checks, DXF/SVG/STL")
    gears.add_argument("design", help="design file (TOML)")
    gears.add_argument("--out", required=True, help="output directory")
    gears.add_argument("--module", type=_number(float, 0.0), default=None,
                       help="target module (mm); default: the largest standard module "
                       "leaving 20 teeth (transplanter: from internal_gear.teeth)")
    gears.add_argument("--face-width", type=_number(float, 0.0), default=12.0,
                       help="mm, for STL/STEP")
    gears.add_argument("--backlash", type=_number(float, 0.0, strict=False), default=0.1,
                       help="circumferential backlash per pair, mm")
    gears.add_argument("--pressure-angle", type=_number(float, 0.0), default=20.0,
                       help="tool pressure angle, deg (0-45)")
    gears.add_argument("--addendum", type=_number(float, 0.0), default=1.0,
                       help="addendum, x module")
    gears.add_argument("--dedendum", type=_number(float, 0.0), default=1.25,
                       help="dedendum, x module (above the addendum: root clearance)")
    gears.add_argument("--step", action="store_true",
                       help="also write STEP solids (needs plantmech[step]; minutes per gear)")
    gears.set_defaults(func=_gears)
    from plantmech.optimize.jobs import PROBLEMS

    opt = sub.add_parser("optimize", help="automatic optimization of a design's objectives")
    opt.add_argument("design", help="design file (TOML); never overwritten")
    opt.add_argument("--problem", required=True, choices=PROBLEMS)
    opt.add_argument("--out", required=True, help="output directory")
    opt.add_argument("--seed", type=int, default=0)
    opt.add_argument("--generations", type=_number(int, 1, strict=False), default=None)
    opt.add_argument("--pop", type=_number(int, 4, strict=False), default=None,
                     help="population size (at least 4)")
    opt.add_argument("--algorithm", choices=("nsga2", "de", "cmaes"), default=None,
                     help="default per problem (docs/optimization.md)")
    opt.add_argument("--points", type=_number(int, 4, strict=False), default=16,
                     help="interpolation radii per gear for the seeder's layer 2")
    opt.add_argument("--seeding-shifts", type=_number(int, 0, strict=False), default=0,
                     help="seeder layer 1: also scout moving the seeding point e (and f) on "
                     "by 1..K type-value points (seed 000 Fig. 6 relabels it g)")
    opt.add_argument("--seeding-point", choices=("auto", "keep"), default="auto",
                     help="seeder problems that move type-value points: 'auto' moves the "
                     "seeding point e (and f) on when, at e, a return speed above its "
                     "minimum needs a seeding speed above its limit (the three-bar bound, "
                     "docs/optimization.md); 'keep' never moves it")
    opt.add_argument("--tooth-fit", action="store_true",
                     help="also require the pitch-curve shape checks (transplanter: tooth "
                     "fit (xiii)-(xv); seeder layer 2: convexity and working pressure "
                     "angle); without it they are reported")
    opt.add_argument("--quiet", action="store_true", help="no progress bar")
    opt.set_defaults(func=_optimize)
    return p


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    return args.func(args)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
