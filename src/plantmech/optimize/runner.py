"""Running a problem with pymoo: seeded, starting from the design's current values,
with a progress bar, a convergence history and a run record (Pyslvs-style: algorithm,
settings, seed, evaluations, wall time, machine)."""

from __future__ import annotations

import os
import platform
import time
from contextlib import contextmanager
from dataclasses import dataclass, field

import numpy as np
from pymoo.core.callback import Callback
from pymoo.core.problem import Problem
from pymoo.optimize import minimize

from plantmech.optimize import ALGORITHMS  # noqa: F401  (re-exported)
from plantmech.optimize.problems import Batch, DesignProblem


class WeightedViolation(Problem):
    """Single-objective form of a problem: minimize the total relative violation of all
    constraints; designs meeting every constraint score below zero, ordered by their
    objectives (-1 + 1e-3 tanh(sum F / 100)), so the first feasible design is seen at once
    and among feasible designs the better ones win."""

    def __init__(self, inner: DesignProblem):
        self.inner = inner
        super().__init__(n_var=inner.n_var, n_obj=1, n_ieq_constr=0, xl=inner.xl, xu=inner.xu)

    def _evaluate(self, X, out, *args, **kwargs):
        b = self.inner.evaluate_batch(np.atleast_2d(X))
        self.inner.evaluations += len(X)
        self.inner.remember(np.atleast_2d(X), b)
        F = np.where(np.isfinite(b.F), b.F, 1e6)
        viol = b.violation
        out["F"] = np.where(viol > 0, viol, -1.0 + 1e-3 * np.tanh(F.sum(axis=1) / 100.0))


@dataclass
class RunResult:
    problem: str
    algorithm: str
    seed: int
    generations: int
    pop_size: int
    evaluations: int
    wall_s: float
    best_x: np.ndarray
    best: Batch  # the best design's evaluation (one row)
    history: list[dict]
    pareto_x: np.ndarray
    pareto_f: np.ndarray
    first_feasible_s: float | None
    first_feasible_evaluations: int | None
    settings: dict = field(default_factory=dict)
    tradeoff: dict | None = None  # DesignProblem.tradeoff: agronomic vs manufacturability

    @property
    def feasible(self) -> bool:
        return bool(self.best.feasible[0])

    def record(self) -> dict:
        """run.json contents (everything needed to rerun it)."""
        names = self.best.names
        return {
            "problem": self.problem,
            "algorithm": self.algorithm,
            "seed": self.seed,
            "generations": self.generations,
            "pop_size": self.pop_size,
            "evaluations": self.evaluations,
            "wall_s": round(self.wall_s, 3),
            "first_feasible_s": (None if self.first_feasible_s is None
                                 else round(self.first_feasible_s, 3)),
            "first_feasible_evaluations": self.first_feasible_evaluations,
            "feasible": self.feasible,
            "objectives": [
                {"name": n, "value": (None if not np.isfinite(v) else float(v)), "unit": u,
                 "limit": lim, "ok": bool(o), "required": bool(q)}
                for n, v, u, lim, o, q in zip(
                    names, self.best.values[0], self.best.units, self.best.limits,
                    self.best.ok[0], (np.ones(len(names), bool) if self.best.required is None
                                      else self.best.required), strict=True)],
            "total_violation": float(self.best.violation[0]),
            "settings": self.settings,
            "machine": {"python": platform.python_version(), "platform": platform.platform(),
                        "cpus": os.cpu_count()},
        }


class _Recorder(Callback):
    def __init__(self, problem: DesignProblem, bar, t0: float, hook=None):
        super().__init__()
        self.problem, self.bar, self.t0, self.hook = problem, bar, t0, hook
        self.stop = False
        self.history: list[dict] = []
        self.first_feasible_s = None
        self.first_feasible_evals = None
        self.out_of_time = False

    def notify(self, algorithm):
        pop = algorithm.pop
        X = pop.get("X")
        if isinstance(algorithm.problem, WeightedViolation):
            viol = np.maximum(pop.get("F")[:, 0], 0.0)
        else:
            G = pop.get("G")
            viol = np.maximum(G, 0).sum(axis=1) if G is not None and G.size else np.zeros(len(X))
        best = float(np.min(viol))
        self.best_so_far = min(getattr(self, "best_so_far", np.inf), best)
        n_feas = int(np.sum(viol <= 1e-12))
        wall = time.perf_counter() - self.t0
        if n_feas and self.first_feasible_s is None:
            self.first_feasible_s = wall
            self.first_feasible_evals = self.problem.evaluations
        self.history.append({"generation": algorithm.n_gen, "evaluations": self.problem.evaluations,
                             "best_violation": best, "feasible_in_population": n_feas,
                             "wall_s": round(wall, 3)})
        if self.bar is not None:
            self.bar.update(1)
            # the least violation so far (the app reads this key from the bar)
            self.bar.set_postfix(best_violation=f"{self.best_so_far:.4g}", feasible=n_feas)
        if self.hook is not None and self.hook(self.problem):
            self.stop = True


_DEADLINE: list[float] = []  # time.perf_counter() deadlines of enclosing time_budget()s


@contextmanager
def time_budget(seconds: float | None):
    """Every ``run`` inside stops at the end of the generation in which ``seconds`` (wall
    time from entering) have passed; None: no limit. The runs' records say they were cut
    (``settings.stopped_by_time_budget``)."""
    if seconds is None:
        yield
        return
    _DEADLINE.append(time.perf_counter() + float(seconds))
    try:
        yield
    finally:
        _DEADLINE.pop()


def _out_of_time() -> bool:
    return bool(_DEADLINE) and time.perf_counter() > min(_DEADLINE)


def run(problem: DesignProblem, algorithm: str = "nsga2", seed: int = 0,
        generations: int = 40, pop_size: int = 40, progress: bool = True,
        stop_when_feasible: bool = False, hook=None, stage: str | None = None) -> RunResult:
    """Optimize ``problem``; the initial population holds the design's current values
    and samples spread over the bounds (seeded). ``hook(problem)`` is called after every
    generation; it stops the run by returning True. ``stage`` (e.g. "stage 2/4") names the
    run in the progress bar when it is one of several."""
    from pymoo.algorithms.moo.nsga2 import NSGA2
    from pymoo.algorithms.soo.nonconvex.de import DE
    from pymoo.termination import get_termination

    if algorithm not in ALGORITHMS:
        raise ValueError(f"unknown algorithm {algorithm!r} (expected one of {ALGORITHMS})")
    rng = np.random.default_rng(seed)
    x0 = np.clip(problem.x0, problem.xl, problem.xu)
    span = problem.xu - problem.xl
    # the current design, small perturbations of it, and samples over the whole box
    near = x0 + rng.normal(0, 0.1, (pop_size // 2, problem.n_var)) * span
    far = problem.xl + rng.random((pop_size - 1 - len(near), problem.n_var)) * span
    X0 = np.clip(np.vstack([x0, near, far]), problem.xl, problem.xu)
    if algorithm == "nsga2":
        algo = NSGA2(pop_size=pop_size, sampling=X0, eliminate_duplicates=True)
        target = problem
    elif algorithm == "de":
        algo = DE(pop_size=pop_size, sampling=X0, variant="DE/rand/1/bin", CR=0.7)
        target = WeightedViolation(problem)
    else:
        from pymoo.algorithms.soo.nonconvex.cmaes import CMAES

        # start at the current design, step a tenth of the box; restarts are not used.
        # The cma package reads seed 0 as "seed from the clock": it gets seed + 1.
        algo = CMAES(x0=x0, sigma=0.1, popsize=pop_size, normalize=True, restarts=0,
                     seed=seed + 1)
        target = WeightedViolation(problem)
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=generations, desc=problem.name + (f" {stage}" if stage else ""),
                   unit="gen", leave=False)
    t0 = time.perf_counter()
    problem.evaluations = 0
    problem.best_score, problem.best_x = np.inf, None
    problem.tradeoff = None
    rec = _Recorder(problem, bar, t0, hook)
    termination = get_termination("n_gen", generations)
    if stop_when_feasible or hook is not None or _DEADLINE:
        from pymoo.core.termination import Termination

        class _Stop(Termination):
            def _update(self, algorithm):
                if _out_of_time():
                    rec.out_of_time = True
                done = (rec.stop or algorithm.n_gen >= generations or rec.out_of_time
                        or (stop_when_feasible and rec.first_feasible_s is not None))
                return 1.0 if done else algorithm.n_gen / generations

        termination = _Stop()
    res = minimize(target, algo, termination, seed=seed + (algorithm == "cmaes"),
                   callback=rec, verbose=False, save_history=False)
    wall = time.perf_counter() - t0
    if bar is not None:
        bar.close()
    X = res.pop.get("X")
    if problem.best_x is not None:  # the best design ever evaluated joins the final pool
        X = np.vstack([X, problem.best_x])
    batch = problem.evaluate_batch(X)
    best_k = _pick_best(batch)
    best = _row(batch, best_k)
    if algorithm == "nsga2" and res.X is not None:
        px = np.atleast_2d(res.X)
        pf = np.atleast_2d(res.F)
    else:
        px, pf = X[best_k:best_k + 1], batch.F[best_k:best_k + 1]
    return RunResult(problem.name, algorithm, seed, generations, pop_size, problem.evaluations,
                     wall, X[best_k], best, rec.history, px, pf, rec.first_feasible_s,
                     rec.first_feasible_evals,
                     {"variables": [{"name": v.name, "x0": v.x0, "lower": v.lower,
                                     "upper": v.upper, "unit": v.unit}
                                    for v in problem.variables],
                      "objectives_minimized": problem.objective_names,
                      "stop_when_feasible": stop_when_feasible,
                      "stopped_by_time_budget": rec.out_of_time},
                     getattr(problem, "tradeoff", None))


def _pick_best(b: Batch) -> int:
    """The feasible design with the best normalised objectives, else the least violating."""
    feas = b.feasible
    if feas.any():
        F = b.F[feas]
        lo, hi = F.min(axis=0), F.max(axis=0)
        score = ((F - lo) / np.where(hi > lo, hi - lo, 1.0)).sum(axis=1)
        return int(np.flatnonzero(feas)[np.argmin(score)])
    return int(np.argmin(b.violation))


def _row(b: Batch, k: int) -> Batch:
    return Batch(b.F[k:k + 1], b.G[k:k + 1], b.names, b.units, b.limits, b.values[k:k + 1],
                 b.ok[k:k + 1], required=b.required)
