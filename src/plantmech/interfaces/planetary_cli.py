"""``plantmech forward`` on a general planetary train (``mechanism = "planetary"``).

The forward command hands such a design here (one line in ``cli._forward_body``): build
the train (pairs, closure, mates), simulate it, evaluate the generic objectives, write
summary.json, motion.csv, pitch_curves.csv and plots, print the verdict. No physics here.
"""

from __future__ import annotations

import sys
import time

from plantmech.outputs.verdict import EXIT_INPUT, verdict, verdict_line


def forward_planetary(args, design, run) -> int:
    """The forward run of a planetary design into ``run.path``; the exit status."""
    from plantmech.objectives.planetary import checks, motion_objectives
    from plantmech.outputs.files import check_line
    from plantmech.outputs.planetary_report import planetary_summary, write_planetary_outputs
    from plantmech.trains.model import simulate
    from plantmech.trains.spec import TrainSpecError, build_from_design

    out = run.path
    t0 = time.perf_counter()
    try:
        built = build_from_design(design)
    except TrainSpecError as exc:
        print(f"error: {args.design}: field '{exc}", file=sys.stderr)
        return EXIT_INPUT
    motion = simulate(built, design.samples)
    values = motion_objectives(motion, design.carrier.speed_deg_s)
    found = checks(values, design.limits)
    summary = planetary_summary(design, motion, values, found)
    summary["wall_time_s"] = round(time.perf_counter() - t0, 4)
    v = summary["verdict"] = verdict(summary["objectives"])
    from plantmech.outputs.caveats import caveats

    cav = summary["caveats"] = caveats(design, summary["objectives"])
    written = write_planetary_outputs(out, design, motion, summary)
    if not args.no_plots:
        from plantmech.outputs import planetary_plots as pp
        from plantmech.outputs.seeder_plots import save

        figures = pp.forward_figures(design, motion)
        written += [save(fig, out / name, dpi=120) for name, fig in figures]
    if getattr(args, "report", False):
        from plantmech.interfaces.report_cli import planetary_report

        written += planetary_report(args, out, design, motion, summary,
                                    [] if args.no_plots else figures, run=run)
    print(f"{design.name}: planetary train, {len(built.laws)} pairs, "
          f"{design.carrier.arms} arm(s)")
    for p in summary["pairs"]:
        print(f"  pair {p['pair'] + 1}: {p['kind']}, centre distance "
              f"{p['centre_distance_mm']:.4f} mm, closure error {p['closure_error_rad']:.1e} "
              f"rad, ratio {p['ratio_range'][0]:.4f}-{p['ratio_range'][1]:.4f}")
    vals, units = summary["values"], summary["units"]
    for name in ("path_width_mm", "path_height_mm", "loops", "attitude_range_deg",
                 "max_tip_speed_m_s", "min_tip_speed_m_s"):
        print(f"  {name:<22} {vals[name]:10.3f} {units[name]}")
    for c in summary["objectives"]:
        print(check_line(c, 22))
    print("wrote: " + ", ".join(str(run.final(p)) for p in written))
    what = ("every limit of [limits] met" if summary["objectives"] else
            "the train closes and runs (no [limits] given: nothing else checked)")
    print(verdict_line(v, what, cav))
    return v["exit_code"]
