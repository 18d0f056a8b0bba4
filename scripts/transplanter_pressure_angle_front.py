"""Evidence for docs/manufacturability.md: how low can the working pressure angle of the
rice transplanter's internal pair go while seed 001's twelve objectives (i)-(xii) hold?

NSGA-II over the published parameter set's variables (the `transplanter` problem's: the
twelve internal-gear radii within +-BOUND mm, phi_H0, sigma, S, H1, beta and the seedling
box), two objectives: the summed violation of objectives (i)-(xii) (0 = all met) and the
working pressure angle of the internal pair (deg: the tool's pressure angle plus the
largest pitch tangent angle of the ring; the design file's limit, 45 deg in
examples/rice_transplanter.toml). The evaluation is the optimizer's own (`Transplanter`,
360 samples, interference included). The other tooth-fit values (equivalent teeth (xiii),
teeth difference (xv), cuttable module margin) of the front's designs are written too.

    python scripts/transplanter_pressure_angle_front.py DESIGN.toml OUT_DIR [--bound 15]
        [--generations 80] [--pop 60] [--seed 4]

Writes OUT_DIR/front.csv (the non-dominated designs) and OUT_DIR/front.png.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("design")
    ap.add_argument("out")
    ap.add_argument("--bound", type=float, default=15.0, help="mm, each ring radius")
    ap.add_argument("--generations", type=int, default=80)
    ap.add_argument("--pop", type=int, default=60)
    ap.add_argument("--seed", type=int, default=4)
    ap.add_argument("--objective", choices=("pressure-angle", "manufacturing"),
                    default="pressure-angle",
                    help="second objective: the working pressure angle (deg), or the summed "
                         "relative violation of every tooth-fit check (xiii)-(xv) and the "
                         "cuttable module")
    args = ap.parse_args()

    from pymoo.algorithms.moo.nsga2 import NSGA2
    from pymoo.core.problem import Problem
    from pymoo.optimize import minimize

    from plantmech.design import load_design
    from plantmech.optimize.problems import Transplanter, is_gear_shape_check

    design = load_design(args.design)
    if not design.internal_gear.teeth:
        raise SystemExit("the design needs internal_gear.teeth (the tooth fit is computed "
                         "from the tooth count)")
    problem = Transplanter(design, radius_bound_mm=args.bound, tooth_fit=True)
    kept = {}

    class Front(Problem):
        def __init__(self):
            super().__init__(n_var=problem.n_var, n_obj=2, xl=problem.xl, xu=problem.xu)

        def _evaluate(self, X, out, *a, **k):
            b = problem.evaluate_batch(X)
            gear = np.array([is_gear_shape_check(nm) for nm in b.names])
            agro = np.where(np.isfinite(b.G), b.G, 10.0)[:, ~gear].sum(axis=1)
            k_wpa = b.names.index("working_pressure_angle")
            wpa = np.where(np.isfinite(b.values[:, k_wpa]), b.values[:, k_wpa], 180.0)
            make = np.where(np.isfinite(b.G), b.G, 10.0)[:, gear].sum(axis=1)
            out["F"] = np.c_[agro, wpa if args.objective == "pressure-angle" else make]
            for x, f, v in zip(X, out["F"], b.values, strict=True):
                kept[tuple(np.round(f, 9))] = (v, x)
            kept["names"] = b.names

    rng = np.random.default_rng(args.seed)
    x0 = np.asarray(problem.x0, float) + rng.normal(0.0, 1.0, (args.pop, problem.n_var))
    x0[0] = problem.x0
    t0 = time.perf_counter()
    res = minimize(Front(), NSGA2(pop_size=args.pop, sampling=np.clip(x0, problem.xl,
                                                                      problem.xu)),
                   ("n_gen", args.generations), seed=args.seed)
    wall = time.perf_counter() - t0
    F = res.F[np.argsort(res.F[:, 0])]
    names = kept["names"]
    cols = ["equivalent_teeth", "internal_teeth_difference", "cuttable_module_margin",
            "module"]
    cols = ["working_pressure_angle"] + cols
    extra = np.array([[kept[tuple(np.round(f, 9))][0][names.index(c)] for c in cols]
                      for f in F])
    xs = np.array([kept[tuple(np.round(f, 9))][1] for f in F])
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    second = ("working_pressure_angle_deg" if args.objective == "pressure-angle"
              else "manufacturing_violation")
    np.savetxt(out / "front.csv", np.c_[F, extra, xs], delimiter=",", fmt="%.6f",
               header=f"agronomic_violation,{second}," + ",".join(cols) + ","
               + ",".join(v.name for v in problem.variables), comments="")
    at_bound = [v.name for v, lo, hi, x in zip(problem.variables, problem.xl, problem.xu,
                                                 xs[np.argmin(F[:, 1])], strict=True)
                if min(x - lo, hi - x) < 1e-3 * (hi - lo)]
    met = F[F[:, 0] <= 0.0]
    limit = design.limits.max_working_pressure_angle_deg
    print(f"{args.design}: {args.generations * args.pop} evaluations in {wall:.0f} s; "
          f"smallest {second} {F[:, 1].min():.3f} (agronomic violation "
          f"{F[np.argmin(F[:, 1]), 0]:.3f}); with every objective (i)-(xii) met: "
          + (f"{met[:, 1].min():.3f}" if len(met) else "none found")
          + f"; variables at their bounds there: {at_bound or 'none'}")

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot(F[:, 0], F[:, 1], "o-", ms=3, label="non-dominated designs")
    if args.objective == "pressure-angle":
        ax.axhline(limit, color="tab:red", ls="--", label=f"design file's limit {limit:g} deg")
    ax.set_xlabel("violation of objectives (i)-(xii) (sum, 0 = all met)")
    ax.set_ylabel("working pressure angle of the internal pair (deg)"
                  if args.objective == "pressure-angle" else
                  "tooth-fit violation (xiii)-(xv) + cuttable module (sum, 0 = met)")
    ax.set_title(f"{Path(args.design).name}: ring radii +-{args.bound:g} mm and the "
                 "published parameters", fontsize=9)
    if args.objective == "pressure-angle":
        ax.set_ylim(0, 90)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "front.png", dpi=110)


if __name__ == "__main__":
    main()
