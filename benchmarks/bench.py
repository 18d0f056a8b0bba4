"""Benchmarks (``make bench``): wall times on this machine, printed with units."""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from plantmech.design import load_design
from plantmech.workflows import run_seeder_inverse

ROOT = Path(__file__).resolve().parents[1]


def timeit(fn, repeat=5):
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def main() -> None:
    design = load_design(ROOT / "examples" / "sugarcane_seeder.toml")
    for samples in (3600, 36000):
        d = design.model_copy(deep=True)
        d.trajectory.samples = samples
        t = timeit(lambda d=d: run_seeder_inverse(d))
        print(f"inverse design (checks included), {samples} samples: {t * 1e3:.1f} ms")
    from plantmech.mechanisms.seeder_forward import simulate
    from plantmech.verification import train_from_inverse

    job = run_seeder_inverse(design)
    train = train_from_inverse(job.result)
    t = timeit(lambda: simulate(train, samples=3600))
    print(f"forward simulation from pitch curves, 3600 samples: {t * 1e3:.1f} ms")


if __name__ == "__main__":
    main()
