"""Command line: ``plantmech inverse DESIGN.toml --out DIR [--verify]``.

Exit status: 0 feasible, 2 invalid input, 3 infeasible design.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from plantmech import __version__

EXIT_OK, EXIT_INPUT, EXIT_INFEASIBLE = 0, 2, 3


def _inverse(args) -> int:
    from plantmech.design import DesignError, load_design
    from plantmech.geometry.trajectory import TrajectoryError
    from plantmech.outputs.files import OutputError, prepare_out_dir, write_json
    from plantmech.outputs.seeder_report import write_inverse_outputs
    from plantmech.workflows import run_seeder_inverse

    try:
        design = load_design(args.design)
        out = prepare_out_dir(args.out, [Path(args.design)])
    except (DesignError, OutputError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return EXIT_INPUT
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
    for c in s["trajectory_checks"] + s.get("objectives", []):
        val = "n/a" if c["value"] is None else f"{c['value']:.2f} {c['unit']}"
        print(f"  {'ok  ' if c['ok'] else 'FAIL'} {c['name']:<26} {val:>14}   limit {c['limit']}")
    if "realized_vs_planned_max_deviation_mm" in s:
        print(f"  gear train vs planned trajectory: max deviation "
              f"{s['realized_vs_planned_max_deviation_mm']:.3f} mm")
    if "round_trip_max_deviation_mm" in s:
        print(f"  round trip (forward simulation of the pitch curves): max deviation "
              f"{s['round_trip_max_deviation_mm']:.2e} mm")


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
    return p


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    return args.func(args)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
