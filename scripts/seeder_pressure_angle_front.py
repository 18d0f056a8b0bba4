"""Evidence for docs/manufacturability.md: how far can re-planning the seeder's trajectory
lower the pitch tangent angle mu of its gears while keeping seed 000's layer-1 objectives?

NSGA-II over offsets (+-BOUND mm) of *every* type-value point (not only layer 1's default
points), two objectives: the summed relative violation of layer 1's agronomic checks
(feasible inverse design, Table 1, the three attitude and three speed objectives; 0 = all
met) and the larger pitch tangent angle mu of the two pairs (deg; the working pressure angle
is the tool's 20 deg plus mu, limit 45 deg, so mu < 25 deg is needed). The evaluation is
``SeederLayer1`` (the optimizer's own layer 1, 360 samples).

    python scripts/seeder_pressure_angle_front.py DESIGN.toml OUT_DIR [--bound 40]
        [--generations 300] [--pop 80] [--seed 2]

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
    ap.add_argument("--bound", type=float, default=40.0, help="mm, each coordinate")
    ap.add_argument("--generations", type=int, default=300)
    ap.add_argument("--pop", type=int, default=80)
    ap.add_argument("--seed", type=int, default=2)
    args = ap.parse_args()

    from pymoo.algorithms.moo.nsga2 import NSGA2
    from pymoo.core.problem import Problem
    from pymoo.optimize import minimize

    from plantmech.design import load_design
    from plantmech.optimize.problems import SeederLayer1, is_gear_shape_check

    design = load_design(args.design).model_copy(update={"train": None})
    n = len(design.trajectory.points)
    layer1 = SeederLayer1(design, points=list(range(n)), bound_mm=args.bound, workers=1)

    class Front(Problem):
        def __init__(self):
            super().__init__(n_var=layer1.n_var, n_obj=2, xl=layer1.xl, xu=layer1.xu)

        def _evaluate(self, X, out, *a, **k):
            b = layer1.evaluate_batch(X)
            gear = np.array([is_gear_shape_check(nm) for nm in b.names])
            agro = np.where(np.isfinite(b.G), b.G, 10.0)[:, ~gear].sum(axis=1)
            mu = np.nanmax(np.where(np.isfinite(b.values[:, gear]), b.values[:, gear], 90.0),
                           axis=1)
            out["F"] = np.c_[agro, mu]

    rng = np.random.default_rng(args.seed)
    x0 = rng.normal(0.0, 3.0, (args.pop, layer1.n_var))
    x0[0] = 0.0
    t0 = time.perf_counter()
    res = minimize(Front(), NSGA2(pop_size=args.pop, sampling=np.clip(x0, layer1.xl, layer1.xu)),
                   ("n_gen", args.generations), seed=args.seed)
    wall = time.perf_counter() - t0
    F = res.F[np.argsort(res.F[:, 0])]
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    np.savetxt(out / "front.csv", F, delimiter=",", fmt="%.6f",
               header="agronomic_violation,max_pitch_tangent_angle_deg", comments="")
    met = F[F[:, 0] <= 0.0]
    print(f"{args.design}: {args.generations * args.pop} evaluations in {wall:.0f} s; "
          f"smallest mu {F[:, 1].min():.1f} deg (agronomic violation "
          f"{F[np.argmin(F[:, 1]), 0]:.3f}); with every layer-1 objective met: "
          + (f"{met[:, 1].min():.1f} deg" if len(met) else "none found"))

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot(F[:, 0], F[:, 1], "o-", ms=3, label="non-dominated designs")
    ax.axhline(layer1.max_pitch_tangent_angle_deg, color="tab:red", ls="--",
               label=f"limit mu < {layer1.max_pitch_tangent_angle_deg:g} deg (45 deg working)")
    ax.set_xlabel("layer-1 agronomic violation (sum of relative violations, 0 = met)")
    ax.set_ylabel("largest pitch tangent angle mu (deg)")
    ax.set_title(f"{Path(args.design).name}: every point +-{args.bound:g} mm", fontsize=9)
    ax.set_ylim(0, 90)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "front.png", dpi=110)


if __name__ == "__main__":
    main()
