"""``plantmech inverse`` on a general planetary train (``mechanism = "planetary"`` with a
[trajectory]): the first- or second-order inverse design of
``objectives.planetary_inverse``, its round trip
through the forward model, design.toml (a planetary design file with the sun's pitch
curve), summary.json, inverse.csv and a plot. The inverse command hands such a design here
(one line in ``cli._inverse_body``). No physics here."""

from __future__ import annotations

import sys
import time

import numpy as np

from plantmech.outputs.verdict import EXIT_INPUT, verdict, verdict_line


def inverse_planetary(args, design, run) -> int:
    """The inverse design of a planetary [trajectory] file into ``run.path``; the exit
    status (0 feasible, round trip within tolerance and every [limits] check met; 2 a field
    the inverse cannot take; 3 infeasible; 4 a check not met)."""
    import tomli_w

    from plantmech.geometry.trajectory import TrajectoryError
    from plantmech.objectives.planetary_inverse import InverseInputError, run_first_order
    from plantmech.outputs.files import write_csv, write_json

    out = run.path
    t0 = time.perf_counter()
    try:
        job = run_first_order(design)
    except InverseInputError as exc:
        print(f"error: {args.design}: field '{exc}", file=sys.stderr)
        return EXIT_INPUT
    except TrajectoryError as exc:
        print(f"error: {args.design}: field 'trajectory.points': {exc}", file=sys.stderr)
        return EXIT_INPUT
    res = job["result"]
    order = "second-order" if len(design.train.pairs) == 2 else "first-order"
    summary = {"mechanism": "planetary", "name": design.name, "inverse": order,
               "feasible": res.feasible, "reasons": res.reasons,
               "carrier_arm_mm": res.centre_distance, "arm_length_mm": res.arm_length,
               "follower_turns": res.follower_turns, "objectives": job["rows"]}
    written = []
    if res.ratio is not None:
        summary["ratio_range"] = [float(res.ratio.min()), float(res.ratio.max())]
        summary["point_carrier_angle_deg"] = [float(x) for x in res.point_carrier_angle_deg]
    if res.feasible:
        summary.update(centre_distances_mm=[p.centre_distance_mm
                                            for p in job["designed"].train.pairs],
                       carrier_initial_angle_deg=res.carrier0_deg,
                       arm_initial_angle_deg=res.arm0_deg,
                       sun_radius_mm=[float(res.sun_radii.min()), float(res.sun_radii.max())],
                       planet_radius_mm=[float(res.planet_radii.min()),
                                         float(res.planet_radii.max())],
                       point_deviation_mm=[float(x) for x in
                                           job["deviation"]["point_deviation_mm"]])
        if "max_realized_tip_deviation_mm" in job["deviation"]:
            summary["realized_tip_deviation_mm"] = job["deviation"][
                "max_realized_tip_deviation_mm"]
        (out / "design.toml").write_text(
            f"# Written by 'plantmech inverse {args.design}' ({order} inverse design); "
            "'plantmech forward' runs it.\n"
            + tomli_w.dumps(job["designed"].model_dump(mode="json", exclude_none=True)),
            encoding="utf-8")
        written.append(out / "design.toml")
        deg = 180.0 / np.pi
        write_csv(out / "inverse.csv", {
            "carrier_angle_deg": res.psi * deg, "tip_x_mm": res.tip.real,
            "tip_y_mm": res.tip.imag, "carrier_abs_deg": res.carrier * deg,
            "arm_abs_deg": res.arm * deg, "ratio": res.ratio})
        written.append(out / "inverse.csv")
    if "estimate" in job:
        summary["error_estimate"] = job["estimate"]
    summary["wall_time_s"] = round(time.perf_counter() - t0, 4)
    v = summary["verdict"] = verdict(job["rows"], infeasible=not res.feasible)
    from plantmech.outputs.caveats import caveats

    cav = summary["caveats"] = caveats(design, job["rows"])
    write_json(out / "summary.json", summary)
    written.append(out / "summary.json")
    if not args.no_plots:
        from plantmech.outputs.planetary_plots import plot_inverse
        from plantmech.outputs.seeder_plots import save

        written.append(save(plot_inverse(job["trajectory"], res, job["motion"], design.name),
                            out / "trajectory.png", dpi=120))
    print(f"{design.name}: {order} inverse design ("
          + ("seed 000's ratio split, " if order == "second-order"
             else f"{design.train.pairs[0].kind} pair, ") + "fixed sun)")
    if res.centre_distance is not None:
        print(f"  carrier arm {res.centre_distance:.4f} mm, arm {res.arm_length:.4f} mm")
    for reason in res.reasons:
        print(f"  INFEASIBLE: {reason}", file=sys.stderr)
    if job.get("seeder") is not None:  # seed 000's warnings (the dwell's)
        for d in job["seeder"].diagnostics:
            if d.severity == "warning":
                print(f"  WARNING [{d.kind}]: {d.message}")
    if res.feasible:
        print(f"  ratio {summary['ratio_range'][0]:.4f}-{summary['ratio_range'][1]:.4f}, sun "
              f"radius {summary['sun_radius_mm'][0]:.3f}-{summary['sun_radius_mm'][1]:.3f} mm, "
              f"planet turns {res.follower_turns:.6f} per sun turn")
    from plantmech.outputs.files import check_line

    for r in job["rows"]:
        print(check_line(r, 30, digits=4))
    if "estimate" in job:
        from plantmech.objectives.inverse_estimate import estimate_line

        print(estimate_line(job["estimate"]))
    print("wrote: " + ", ".join(str(run.final(p)) for p in written))
    if res.feasible and "max_realized_tip_deviation_mm" in (job["deviation"] or {}):
        summary_note = ("feasible; the written design's forward tip follows the inverse "
                        "design's realized tip (the toothless dwell's) and meets every limit "
                        "of [limits]")
        print(f"  the dwell moves the tip off the planned points: up to "
              f"{job['deviation']['max_point_deviation_mm']:.3f} mm (reported, as the "
              "seeder's realized_vs_planned deviation)")
    else:
        summary_note = ("feasible; the written design's forward tip passes through every "
                        "type-value point and meets every limit of [limits]")
    if not job.get("estimate", {"computed": True})["computed"]:
        summary_note += " (its error estimate was not computed: see above)"
    print(verdict_line(v, summary_note, cav))
    return v["exit_code"]
