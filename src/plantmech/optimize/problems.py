"""Optimization problems on the mechanism engines (pymoo style: bounded variables,
objectives to minimize, constraints as violations >= 0 that must reach 0).

Every problem evaluates a whole population at once: the seeder layer 2 and the
transplanter through the batch APIs (arrays over designs), the seeder layer 1 through
the inverse design of each candidate trajectory (one ~20 ms pipeline per design: the
inverse design is not batched). See docs/optimization.md.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from pymoo.core.problem import Problem

from plantmech.design import SeederDesign
from plantmech.objectives import relative_violation


def _revalidated(d):
    """``d`` validated again; a candidate that breaks one of the design file's semantic
    checks (e.g. two moved type-value points closer than their minimum spacing) is
    evaluated as it is: the optimizer grades it by its objectives and constraints, which a
    design file's refusal would otherwise turn into a crash in the middle of a run."""
    from pydantic import ValidationError

    try:
        return d.__class__.model_validate(d.model_dump())
    except ValidationError:
        return d


class InfeasiblePopulation(RuntimeError):
    """No candidate of a population can be evaluated (the design space is infeasible
    around the start)."""


@dataclass
class Variable:
    name: str
    x0: float
    lower: float
    upper: float
    unit: str
    apply: Callable  # apply(design, value): write the value into a design copy


@dataclass
class Batch:
    """Evaluation of P designs: objectives F (P, m) to minimize, violations G (P, k) >= 0,
    and every check (values/ok (P, K)) for reporting."""

    F: np.ndarray
    G: np.ndarray
    names: list[str]
    units: list[str]
    limits: list[str]
    values: np.ndarray
    ok: np.ndarray
    extra: dict = field(default_factory=dict)
    required: np.ndarray | None = None  # (K,) False: a check reported, not a constraint

    @property
    def violation(self) -> np.ndarray:
        return np.where(np.isfinite(self.G), self.G, 1e6).sum(axis=1)

    @property
    def feasible(self) -> np.ndarray:
        ok = self.ok if self.required is None else self.ok[:, self.required]
        return ok.all(axis=1)


class DesignProblem(Problem):
    """Base class: variables around the design's current values."""

    name = "problem"
    objective_names: list[str] = []

    def __init__(self, design, variables: list[Variable], n_constr: int):
        self.design = design
        self.variables = variables
        self.evaluations = 0
        super().__init__(n_var=len(variables), n_obj=len(self.objective_names),
                         n_ieq_constr=n_constr,
                         xl=np.array([v.lower for v in variables]),
                         xu=np.array([v.upper for v in variables]))

    @property
    def x0(self) -> np.ndarray:
        return np.array([v.x0 for v in self.variables])

    def decode(self, x):
        """The design with the variables ``x`` applied (a new object)."""
        d = self.design.model_copy(deep=True)
        for v, val in zip(self.variables, x, strict=True):
            v.apply(d, float(val))
        if not d.name.endswith(f"(optimized: {self.name})"):
            d.name = f"{d.name} (optimized: {self.name})"
        return _revalidated(d)

    def evaluate_batch(self, X: np.ndarray) -> Batch:  # pragma: no cover - abstract
        raise NotImplementedError

    def _evaluate(self, X, out, *args, **kwargs):
        b = self.evaluate_batch(np.atleast_2d(X))
        self.evaluations += len(X)
        self.remember(np.atleast_2d(X), b)
        out["F"] = np.where(np.isfinite(b.F), b.F, 1e6)
        out["G"] = np.where(np.isfinite(b.G), b.G, 1e6)

    def remember(self, X, b: Batch):
        """Keep the best design ever evaluated (population-based algorithms such as
        CMA-ES do not keep an archive): feasible first, then least violation; and the
        trade-off between the agronomic objectives and manufacturability (``tradeoff``)."""
        self._remember_tradeoff(X, b)
        viol = b.violation
        score = np.where(b.feasible, -1.0 + 1e-3 * np.tanh(
            np.where(np.isfinite(b.F), b.F, 1e6).sum(axis=1) / 100.0), viol)
        k = int(np.argmin(score))
        if getattr(self, "best_score", np.inf) > score[k]:
            self.best_score = float(score[k])
            self.best_x = np.array(X[k], dtype=float)
            self.best_ok = dict(zip(b.names, b.ok[k].tolist(), strict=True))


    def _remember_tradeoff(self, X, b: Batch, keep: int = 400):
        """Archive of the non-dominated (agronomic violation, manufacturability violation)
        pairs over every evaluated design: the summed relative violations of the
        objectives and of the gear-shape checks (``is_gear_shape_check``), whether the
        latter are required or only reported."""
        n = min(b.G.shape[1], len(b.names))
        gear = np.array([is_gear_shape_check(nm) for nm in b.names[:n]])
        if not gear.any():
            return
        # reported-only columns carry no violation in G: their graded one if the problem
        # kept it, else failed = 1
        graded = b.extra.get("graded_violation")
        raw = (np.where(np.isfinite(graded[:, :n]), graded[:, :n], 10.0) if graded is not None
               else np.where(b.ok[:, :n], 0.0, 1.0))
        G = np.where(np.isfinite(b.G[:, :n]), np.maximum(b.G[:, :n], 0.0), 10.0)
        req = b.required[:n] if b.required is not None else np.ones(n, bool)
        G = np.where(gear & ~req, raw, G)
        agro = G[:, ~gear].sum(axis=1) + np.maximum(b.G[:, n:], 0).sum(axis=1)
        manuf = G[:, gear].sum(axis=1)
        old = getattr(self, "tradeoff", None)
        if old is not None:
            X = np.vstack([old["X"], X])
            agro, manuf = np.r_[old["agronomic"], agro], np.r_[old["manufacturing"], manuf]
        front = _non_dominated(agro, manuf)[:keep]
        self.tradeoff = {"X": np.asarray(X)[front], "agronomic": agro[front],
                         "manufacturing": manuf[front],
                         "manufacturing_checks": [nm for nm, g in zip(b.names[:n], gear,
                                                                       strict=True) if g]}


def _non_dominated(f1: np.ndarray, f2: np.ndarray) -> np.ndarray:
    """Indices of the non-dominated points of two minimized values, by f1 ascending."""
    order = np.lexsort((f2, f1))
    best = np.minimum.accumulate(f2[order])
    keep = np.r_[True, f2[order][1:] < best[:-1]]
    return order[keep]


def _reported_only(viol, limits, cols):
    """Turn the checks in columns ``cols`` from constraints into reported values: no
    violation, not required, and their limit text says so. Returns (viol, required,
    limits, extra): ``extra`` keeps the graded violation of every column
    (``{"graded_violation": viol}``) for the trade-off archive, which measures how far a
    design is from manufacturable whether or not the checks are required."""
    graded = viol
    viol = viol.copy()
    viol[:, cols] = 0.0
    required = np.ones(viol.shape[1], bool)
    required[cols] = False
    limits = [f"{lim} (reported, not a constraint here)" if k in cols else lim
              for k, lim in enumerate(limits)]
    return viol, required, limits, {"graded_violation": graded}


def _violations(values, lo, hi, scale):
    """Relative violations of lo < value < hi (None: open), NaN -> large."""
    return relative_violation(values, lo, hi, scale, nan=10.0)


# --- seeder, layer 1: type-value point offsets -> attitude (seed 000 §4.2) ---------------


def default_layer1_points(design: SeederDesign) -> list[int]:
    """Type-value points that steer the layer-1 objectives: those from d up to one past
    e (seeding section: seeding swing, sowing angle, the speeds — the speed bound
    ``speed_lower_bound`` depends on their distance from the axis), the
    point nearest the rotation centre and its neighbours (it sets L2 - L1, hence every
    attitude), and a, the middle of ab and b (picking swing)."""
    s = design.trajectory.sections
    pts = np.asarray(design.trajectory.points, dtype=float)
    n = len(pts)

    def span(i, j):
        out = [i]
        while i != j:
            i = (i + 1) % n
            out.append(i)
        return out

    seeding = span(s.d, (s.e + 1) % n)
    near = int(np.argmin(np.hypot(*pts.T)))
    picking = span(s.a, s.b)
    chosen = seeding + [(near - 1) % n, near, (near + 1) % n] + [
        picking[0], picking[len(picking) // 2], picking[-1]]
    return sorted(set(chosen), key=chosen.index)


def shift_seeding_point(design: SeederDesign, k: int) -> SeederDesign:
    """The design with its seeding point e (and the end of the return section f with it)
    moved on by k type-value points: seed 000's layer 1 relabels the optimized seeding
    point (Fig. 6, "g")."""
    d = design.model_copy(deep=True)
    n = len(d.trajectory.points)
    d.trajectory.sections.e = (d.trajectory.sections.e + k) % n
    d.trajectory.sections.f = (d.trajectory.sections.f + k) % n
    from pydantic import ValidationError

    try:
        return d.__class__.model_validate(d.model_dump())
    except ValidationError:
        raise ValueError(f"moving the seeding point e (and f) on by {k} type-value points "
                         "puts f past the next section point a (--seeding-shifts)") from None


_POOLS: dict = {}


def start_method() -> str:
    """Start method of the worker processes: ``PLANTMECH_START_METHOD`` if set (``fork``,
    ``spawn``, ``forkserver``), else the platform's default (fork on Linux, spawn on
    macOS and Windows). The tasks are module-level functions of picklable arguments, so
    every method works."""
    import multiprocessing as mp
    import os

    return os.environ.get("PLANTMECH_START_METHOD") or mp.get_start_method(allow_none=True) \
        or mp.get_context().get_start_method()


def _pool(workers: int):
    """One process pool per worker count (and start method), started once and reused by
    every generation (starting the interpreter with NumPy, SciPy and shapely loaded for
    each generation cost ~10 % of layer 1's time); closed at exit."""
    key = (workers, start_method())
    ex = _POOLS.get(key)
    if ex is None:
        import atexit
        import multiprocessing as mp
        from concurrent.futures import ProcessPoolExecutor

        from plantmech.outputs.signals import worker_init

        # workers ignore Ctrl-C and SIGHUP (sent to the whole process group): the command
        # decides, deletes its temporary files and stops the pool
        ex = _POOLS[key] = ProcessPoolExecutor(workers, mp_context=mp.get_context(key[1]),
                                               initializer=worker_init)
        atexit.register(ex.shutdown)
    return ex


class _Serial:
    """A pool's ``submit`` run here at once: in a daemonic process (a Dask worker of a
    multi-start study, a pool worker), which may not start processes of its own."""

    @staticmethod
    def submit(fn, *args):
        from concurrent.futures import Future

        f = Future()
        try:
            f.set_result(fn(*args))
        except Exception as exc:  # noqa: BLE001 - raised again by result(), as a pool's
            f.set_exception(exc)
        return f


def _in_pool(workers: int, use):
    """``use(pool)`` with the shared pool of ``workers`` processes; if a worker died (e.g.
    killed), once more with a fresh pool. In a daemonic process: one after another here."""
    import multiprocessing as mp
    from concurrent.futures.process import BrokenProcessPool

    if mp.current_process().daemon:
        return use(_Serial)
    try:
        return use(_pool(workers))
    except BrokenProcessPool:
        _POOLS.pop((workers, start_method()), None)
        return use(_pool(workers))


def _split_map(fn, items):
    """fn over a few large items (one per process): the first here, the others in the
    pool at once, so no process waits for a task while another has two."""
    if len(items) == 1:
        return [fn(items[0])]
    futures = _in_pool(len(items) - 1, lambda ex: [ex.submit(fn, x) for x in items[1:]])
    first = fn(items[0])
    return [first] + [f.result() for f in futures]


# layer 1 evaluates 360 samples per cycle: a pitch-radius dip narrower than a sample can
# pass there and fail at full resolution (seen: 4.73 mm at 3600 samples against a 5 mm limit)
LAYER1_PITCH_MARGIN_MM = 1.5


def _layer1_population(args):
    from plantmech.objectives.layer1 import seeder_inverse_checks_population

    design, points, samples = args
    return seeder_inverse_checks_population(design, points, samples, LAYER1_PITCH_MARGIN_MM)


# the per-candidate arrays of the layer-1 checks (workflows.seeder_inverse_checks[_population])
_LAYER1_ARRAYS = ("values", "ok", "violation", "infeasible", "objectives",
                  "pitch_tangent_angle")


class SeederLayer1(DesignProblem):
    """Offsets (mm) of chosen type-value points -> attitude objectives under Table 1's
    planning limits and the inverse design's feasibility. The speed objectives are
    constraints here too: the path fixes the carrier angle at every tip position (three-
    bar inverse kinematics), so it fixes the speeds; layer 2 can only keep them
    (docs/optimization.md)."""

    name = "seeder-layer1"
    objective_names = ["picking_swing", "seeding_swing", "sowing_angle"]

    def __init__(self, design: SeederDesign, points: list[int] | None = None,
                 bound_mm: float = 40.0, samples: int = 360, workers: int | None = None,
                 speed_constraints: bool = True, gear_shape: bool = False):
        import os

        from plantmech.gears.manufacturability import rules_for

        self.speed_constraints = speed_constraints
        self.gear_shape = gear_shape
        rules = rules_for(design)
        # the path fixes the ratio law, hence mu of both pairs (seed 000 places its type-
        # value points with "the degree of concavity and convexity" of the gears in mind)
        self.max_pitch_tangent_angle_deg = (rules.max_working_pressure_angle_deg
                                            - rules.pressure_angle_deg)
        self.points = default_layer1_points(design) if points is None else list(points)
        self.samples = samples
        self.workers = (os.cpu_count() or 1) if workers is None else workers
        base = np.asarray(design.trajectory.points, dtype=float)
        variables = []
        for i in self.points:
            for axis, label in ((0, "x"), (1, "y")):
                def apply(d, val, i=i, axis=axis):
                    p = list(d.trajectory.points[i])
                    p[axis] = float(base[i, axis] + val)
                    d.trajectory.points[i] = tuple(p)
                variables.append(Variable(f"q{i}_d{label}", 0.0, -bound_mm, bound_mm, "mm",
                                          apply))
        self.check_names = None
        super().__init__(design, variables, n_constr=1 + 7 + 3 + 3 + 2)

    def points_of(self, X) -> np.ndarray:
        """Type-value points (P, N, 2) mm of the candidates X (P, n_var)."""
        pts = np.repeat(np.asarray(self.design.trajectory.points, float)[None], len(X), 0)
        for k, i in enumerate(self.points):
            pts[:, i] += X[:, 2 * k: 2 * k + 2]
        return pts

    def checks(self, X) -> dict:
        """Every layer-1 check of the candidates X (P, n_var): names, units, limits and
        values, ok, violation (P, 13), infeasible (P,) (the inverse design's error
        grading), objectives (P, 3), pitch_tangent_angle (P, 2) deg. The population
        inverse design (a toothless dwell too) split over the worker processes."""
        X = np.atleast_2d(X)
        pts = self.points_of(X)
        parts = np.array_split(np.arange(len(pts)), min(self.workers, len(pts)))
        out = _split_map(_layer1_population, [(self.design, pts[k], self.samples)
                                              for k in parts])
        return dict({k: out[0][k] for k in ("names", "units", "limits")},
                    **{k: np.concatenate([o[k] for o in out]) for k in _LAYER1_ARRAYS})

    def evaluate_batch(self, X):
        c = self.checks(X)
        names, units, limits = c["names"], c["units"], c["limits"]
        values, ok, viol, infeasible, F = (c[k] for k in ("values", "ok", "violation",
                                                          "infeasible", "objectives"))
        # mu of both pairs: the working pressure angle less the tool's, which the path fixes
        mu = np.asarray(c["pitch_tangent_angle"], float)
        lim = self.max_pitch_tangent_angle_deg
        mu_ok = np.isfinite(mu) & (mu < lim)
        names = list(names) + [f"pitch_tangent_angle_{p}" for p in ("sun_gear2",
                                                                    "gear3_planet")]
        units = list(units) + ["deg", "deg"]
        limits = list(limits) + [f"< {lim:g} deg"] * 2
        values, ok = np.c_[values, mu], np.c_[ok, mu_ok]
        viol = np.c_[viol, _violations(mu, None, lim, lim)]
        required = np.ones(len(names), bool)
        cols = [k for k, n in enumerate(names) if is_gear_shape_check(n)] \
            if not self.gear_shape else []
        if not self.speed_constraints:  # the paper's layer 1: attitude and planning only
            cols += [k for k, n in enumerate(names) if "speed" in n]
        graded = viol
        if cols:
            viol, required, limits, _ = _reported_only(viol, limits, cols)
        G = np.c_[infeasible, viol]
        return Batch(F, G, ["feasible_inverse"] + names, [""] + units,
                     ["= 0 errors"] + limits, np.c_[infeasible, values],
                     np.c_[infeasible == 0, ok], required=np.r_[True, required],
                     extra={"graded_violation": np.c_[infeasible, graded]})


# --- seeder, layer 2: interpolation radii of gears 2 and 3 -> speeds (§4.4) ---------------


def is_gear_shape_check(name: str) -> bool:
    """Pitch-curve manufacturability checks (cuttable module, working pressure angle, tooth
    fit): required by the optimizers unless ``--no-manufacturability``, always reported."""
    return (name.startswith(("convex_", "working_pressure_angle", "cuttable_module",
                             "pitch_tangent_angle"))
            or name in Transplanter.TOOTH_FIT)


class SeederLayer2(DesignProblem):
    """Radii of gears 2 and 3 (mm, around the design's [train]) -> seeding peak speed and
    return minimum speed, with every §4.1 objective, convexity of all four pitch curves,
    the working pressure angle and a bound on the deviation from the planned trajectory
    as constraints. Closure: each candidate is closed by the design's restoration
    (``scale`` when it says ``check``: same motion as a solved centre distance, with
    a1 + a2 kept equal to L1)."""

    name = "seeder-layer2"
    objective_names = ["seeding_peak_speed", "neg_return_min_speed_dynamic"]

    def __init__(self, design: SeederDesign, bound_mm: float = 8.0,
                 max_deviation_mm: float = 20.0, samples: int = 720, gear_shape: bool = False):
        if design.train is None:
            raise ValueError("layer 2 needs a [train] (run layer 1 first, or give one)")
        self.samples = samples
        self.gear_shape = gear_shape
        self.max_deviation_mm = max_deviation_mm
        d = design.model_copy(deep=True)
        if d.train.closure == "check":
            d.train.closure = "scale"  # every candidate closes; a1 + a2 keeps L1
        variables = []
        for gear in ("gear2", "gear3"):
            radii = getattr(d.train, gear).radii_mm
            for k, r in enumerate(radii):
                def apply(dd, val, gear=gear, k=k):
                    getattr(dd.train, gear).radii_mm[k] = float(val)
                variables.append(Variable(f"r_{gear[-1]}_{k + 1}", float(r), max(r - bound_mm, 1.0),
                                          r + bound_mm, "mm", apply))
        self.n2 = len(d.train.gear2.radii_mm)
        # 6 objectives + 2 x 2 manufacturability rows, deviation, closure
        super().__init__(d, variables, n_constr=10 + 1 + 1)
        self._reference = None  # where the base train passes the section points

    def evaluate_batch(self, X):
        from plantmech.geometry.deviation import trajectory_deviation_batch
        from plantmech.objectives.seeder_design import evaluate_seeder_population

        if self._reference is None and self.design.train.sections_deg is None:
            from plantmech.objectives.seeder_design import section_reference_psi

            self._reference = section_reference_psi(self.design)
        # one process: split over this machine's two cores a generation took as long
        # (323 vs 305 ms for 40 designs: the two processes slow each other down)
        pop = evaluate_seeder_population(self.design, X[:, :self.n2], X[:, self.n2:],
                                         samples=self.samples, dense=2048,
                                         reference_psi=self._reference)
        ev = pop.evaluation
        names, units, limits = list(ev.names), list(ev.units), list(ev.limits)
        values, ok, viol = ev.values, ev.ok, ev.violation
        closure = pop.motion.closure_error.max(axis=1)
        if self.design.trajectory is not None:
            dev = trajectory_deviation_batch(self.design, pop.motion.tip)
            dv = _violations(dev, None, self.max_deviation_mm, self.max_deviation_mm)
            names.append("deviation_from_plan")
            units.append("mm")
            limits.append(f"< {self.max_deviation_mm:g} mm")
            values = np.c_[values, dev]
            ok = np.c_[ok, dv <= 0]
            viol = np.c_[viol, dv]
        peak = values[:, names.index("seeding_peak_speed")]
        ret = values[:, names.index("return_min_speed_dynamic")]
        required, extra = np.ones(len(names), bool), {}
        if not self.gear_shape:
            viol, required, limits, extra = _reported_only(
                viol, limits, [k for k, n in enumerate(names) if is_gear_shape_check(n)])
        G = np.c_[viol, np.maximum(closure - 1e-6, 0)]
        if G.shape[1] < self.n_ieq_constr:
            G = np.c_[G, np.zeros((len(X), self.n_ieq_constr - G.shape[1]))]
        return Batch(np.c_[peak, -ret], G, names, units, limits, values, ok,
                     required=required, extra=extra)


# --- seeder, joint: both layers' variables in one problem ---------------------------------


class SeederJoint(DesignProblem):
    """Type-value point offsets and radius corrections of gears 2 and 3 in one problem
    (for comparison with the layered method): each candidate trajectory is inverse-
    designed, its gears resampled at ``points`` radii, corrected, and simulated."""

    name = "seeder-joint"
    objective_names = ["picking_swing", "seeding_peak_speed", "neg_return_min_speed_dynamic"]

    def __init__(self, design: SeederDesign, points: int = 16, bound_mm: float = 20.0,
                 radius_bound_mm: float = 6.0, max_deviation_mm: float = 20.0,
                 samples: int = 360, gear_shape: bool = False):
        self.gear_shape = gear_shape
        self.layer1 = SeederLayer1(design, bound_mm=bound_mm, samples=samples)
        self.points = points
        self.samples = samples
        self.max_deviation_mm = max_deviation_mm
        variables = list(self.layer1.variables)
        for gear in ("2", "3"):
            for k in range(points):
                variables.append(Variable(f"dr_{gear}_{k + 1}", 0.0, -radius_bound_mm,
                                          radius_bound_mm, "mm", lambda d, v: None))
        # Table 1 gate, 7 layer-1 rows, 6 objectives + 2 x 2 manufacturability rows, deviation
        super().__init__(design, variables, n_constr=1 + 7 + 10 + 1)

    def decode(self, x):
        """Trajectory from the offsets; [train] resampled from its inverse design with the
        radius corrections added."""
        from plantmech.mechanisms.seeder_trains import with_train

        n1 = self.layer1.n_var
        d = self.layer1.decode(x[:n1]).model_copy(update={"train": None})
        d = with_train(d, self.points)
        dr = x[n1:]
        d.train.gear2.radii_mm = [float(r + c) for r, c in zip(d.train.gear2.radii_mm,
                                                               dr[:self.points], strict=True)]
        d.train.gear3.radii_mm = [float(r + c) for r, c in zip(d.train.gear3.radii_mm,
                                                               dr[self.points:], strict=True)]
        return _revalidated(d)

    def _layer1_rows(self, X) -> list[dict]:
        """Layer-1 checks of each candidate's trajectory (``SeederLayer1.checks``)."""
        c = self.layer1.checks(np.atleast_2d(X)[:, :self.layer1.n_var])
        keys = ("values", "ok", "violation", "infeasible")
        return [dict(names=c["names"], units=c["units"], limits=c["limits"],
                     **{k: c[k][i] for k in keys}) for i in range(len(X))]

    def evaluate_batch(self, X):
        from plantmech.geometry.deviation import trajectory_deviation_batch
        from plantmech.objectives.seeder_design import evaluate_seeder_population

        rows = []
        for x, l1 in zip(X, self._layer1_rows(X), strict=True):
            if l1["infeasible"]:
                rows.append(None)
                continue
            try:
                d = self.decode(x)
                pop = evaluate_seeder_population(d, samples=self.samples, dense=2048)
                dev = trajectory_deviation_batch(d, pop.motion.tip)
            except (ValueError, RuntimeError):
                rows.append(None)
                continue
            rows.append((l1, pop.evaluation, float(dev[0])))
        good = next((r for r in rows if r is not None), None)
        names = (good[0]["names"][:7] + list(good[1].names) + ["deviation_from_plan"]
                 if good else ["feasible_inverse"])
        K = len(names)
        F = np.full((len(X), 3), 1e6)
        G = np.full((len(X), self.n_ieq_constr), 10.0)
        values = np.full((len(X), K), np.nan)
        ok = np.zeros((len(X), K), bool)
        units, limits = [""] * K, [""] * K
        for i, r in enumerate(rows):
            if r is None:
                continue
            l1, ev, dev = r
            dv = _violations(np.array([dev]), None, self.max_deviation_mm,
                             self.max_deviation_mm)[0]
            shape = np.array([is_gear_shape_check(n) and not self.gear_shape
                              for n in ev.names])
            values[i] = np.r_[l1["values"][:7], ev.values[0], dev]
            ok[i] = np.r_[l1["ok"][:7], ev.ok[0], dv <= 0]
            required = np.r_[np.ones(7, bool), ~shape, True]
            G[i] = np.r_[0.0, l1["violation"][:7], np.where(shape, 0.0, ev.violation[0]), dv]
            units = l1["units"][:7] + list(ev.units) + ["mm"]
            limits = l1["limits"][:7] + list(ev.limits) + [f"< {self.max_deviation_mm:g} mm"]
            v = dict(zip(ev.names, ev.values[0], strict=True))
            F[i] = [v["picking_swing"], v["seeding_peak_speed"], -v["return_min_speed_dynamic"]]
        return Batch(F, G, names if good else ["feasible_inverse"] * K, units, limits, values,
                     ok, required=required if good else None)


# --- transplanter: published variables -> twelve objectives --------------------------------


TRANSPLANTER_BOUNDS = {  # half-widths around the design's values
    "initial_angle_deg": 15.0, "initial_phase_deg": 30.0, "S_mm": 15.0, "H1_mm": 10.0,
    "beta_deg": 10.0, "box_x_mm": 15.0, "box_y_mm": 15.0, "box_inclination_deg": 5.0,
}


def not_transplanter(design) -> str:
    """Why the transplanter problem refuses ``design`` (the kinds it takes: ``kinds``)."""
    from plantmech.kinds import KINDS

    takes = " or ".join(k.name for k in KINDS.values() if "transplanter" in k.problems)
    return (f"the transplanter problem optimizes a {takes} design (this file is a "
            f"{design.mechanism})")


class Transplanter(DesignProblem):
    """The published parameter set's variables (internal-gear radii, phi_H0, sigma, S,
    H1, beta, box position) -> the twelve objectives (i)-(xii) as constraints;
    objectives: seedling-block skew, widest hole and the margin of the angle difference
    from the middle of its range."""

    name = "transplanter"
    objective_names = ["seedling_block_skew", "hole_width", "angle_difference_offcentre"]

    TOOTH_FIT = ("equivalent_teeth", "internal_teeth_difference", "working_pressure_angle",
                 "cuttable_module_margin")

    def __init__(self, design, radius_bound_mm: float = 6.0, samples: int = 360,
                 interference: bool = True, tooth_fit: bool = False,
                 ring_scale_bound: float = 0.0):
        from plantmech.kinds import kind_of

        if self.name not in kind_of(design).problems:
            raise ValueError(not_transplanter(design))
        self.samples = samples
        self.interference = interference
        self.tooth_fit = tooth_fit
        # the fixed non-circular gear: the differential's internal gear, the K-H-V's sun
        field = kind_of(design).fixed_gear
        g = getattr(design, field)
        variables = []
        for k, r in enumerate(g.radii_mm):
            def apply(d, val, k=k):
                getattr(d, field).radii_mm[k] = float(val)
            variables.append(Variable(f"r{k}", float(r), max(r - radius_bound_mm, 1.0),
                                      r + radius_bound_mm, "mm", apply))
        from plantmech.mechanisms.transplanter_design import design_param as _param

        setters = {
            "initial_angle_deg": lambda d, v: setattr(d.carrier, "initial_angle_deg", v),
            "initial_phase_deg": lambda d, v: setattr(d.internal_gear, "initial_phase_deg", v),
            "S_mm": lambda d, v: setattr(d.arm, "S_mm", v),
            "H1_mm": lambda d, v: setattr(d.arm, "H1_mm", v),
            "beta_deg": lambda d, v: setattr(d.arm, "beta_deg", v),
            "box_x_mm": lambda d, v: setattr(d.seedling_box, "x_mm", v),
            "box_y_mm": lambda d, v: setattr(d.seedling_box, "y_mm", v),
            "box_inclination_deg": lambda d, v: setattr(d.seedling_box, "inclination_deg", v),
        }
        # a sun has no lobe phase (sigma): the K-H-V train's arm starts with the carrier
        self.param_names = [n for n in TRANSPLANTER_BOUNDS
                            if n != "initial_phase_deg" or hasattr(g, "initial_phase_deg")]
        for name in self.param_names:
            x0 = float(_param(design, None, name))
            b = TRANSPLANTER_BOUNDS[name]
            variables.append(Variable(name, x0, x0 - b, x0 + b,
                                      "deg" if name.endswith("deg") else "mm", setters[name]))
        self.n_r = len(g.radii_mm)
        # the ring's size as one variable (all radii times s, 1 -+ ring_scale_bound): the
        # module (xi) grows with it while the tooth fit in modules (xiii)-(xv) does not move
        self.ring_scale = ring_scale_bound > 0
        if self.ring_scale:
            def scale_radii(d, val):
                getattr(d, field).radii_mm = [float(r) * val for r in getattr(d, field).radii_mm]
            variables.append(Variable("ring_scale", 1.0, 1.0 - ring_scale_bound,
                                      1.0 + ring_scale_bound, "", scale_radii))
        # (i)-(xii), plus (xiii)-(xv) where the train's tooth fit is computed (a lobed
        # internal gear with a tooth count: objectives.transplanter_design.gear_fit)
        n_constr = 12 + len(self.TOOTH_FIT) if g.teeth and hasattr(g, "lobes") else 12
        super().__init__(design, variables, n_constr=n_constr)

    def evaluate_batch(self, X):
        from plantmech.gears.internal import InternalPairError

        try:
            ev = self._evaluate_rows(X)
        except InternalPairError:
            return self._one_by_one(X)
        return self._batch(ev)

    def _batch(self, ev):
        names = ev.names
        v = ev.values
        lo, hi = self.design.limits.angle_difference_deg
        F = np.c_[v[:, names.index("seedling_block_skew")], v[:, names.index("hole_width")],
                  np.abs(v[:, names.index("angle_difference")] - 0.5 * (lo + hi))]
        # an objective a candidate cannot compute (a K-H-V tip that never passes through
        # the seedling mat has no picking angle, hence no skew) is as bad as a candidate
        # that cannot mesh (``_one_by_one``): 1e6, never a NaN the search sorts by
        F = np.where(np.isfinite(F), F, 1e6)
        G, limits = np.where(np.isfinite(ev.violation), ev.violation, 1e6), list(ev.limits)
        required, extra = np.ones(len(names), bool), {}
        if not self.tooth_fit:  # the paper's objectives only; the tooth fit is reported
            G, required, limits, extra = _reported_only(
                G, limits, [names.index(n) for n in self.TOOTH_FIT if n in names])
        return Batch(F, G, names, ev.units, limits, v, ev.ok, required=required, extra=extra)

    def _one_by_one(self, X):
        """Fallback when some candidate's planet cannot mesh: evaluate the others (in
        halves, so a few broken candidates cost a few batch calls, not one call per
        design), give the broken ones a large violation."""
        parts = self._parts(X)
        good = next((p for p in parts if p is not None), None)
        if good is None:
            raise InfeasiblePopulation("no candidate in the population has a meshing planet "
                                       "(every one's planet is cut by the internal gear)")
        K = good.values.shape[1]
        rows = [p if p is not None else Batch(np.full((1, 3), 1e6), np.full((1, K), 1e6),
                                              good.names, good.units, good.limits,
                                              np.full((1, K), np.nan), np.zeros((1, K), bool))
                for p in parts]
        extra = ({"graded_violation": np.vstack([
            r.extra["graded_violation"] if "graded_violation" in r.extra
            else np.full((1, K), 10.0) for r in rows])}
            if "graded_violation" in good.extra else {})
        return Batch(np.vstack([r.F for r in rows]), np.vstack([r.G for r in rows]),
                     good.names, good.units, good.limits, np.vstack([r.values for r in rows]),
                     np.vstack([r.ok for r in rows]), required=good.required, extra=extra)

    def _parts(self, X) -> list:
        """Batches of consecutive rows of X, in order; None for a row whose pair cannot
        mesh (bisection on InternalPairError)."""
        from plantmech.gears.internal import InternalPairError

        try:
            return [self._batch(self._evaluate_rows(X))]
        except InternalPairError:
            if len(X) == 1:
                return [None]
            h = len(X) // 2
            return self._parts(X[:h]) + self._parts(X[h:])

    def _evaluate_rows(self, X):
        """The evaluation of the rows of X (raises InternalPairError if one cannot mesh)."""
        from plantmech.objectives.transplanter_design import evaluate_transplanter_population

        return evaluate_transplanter_population(self.design, self._radii(X), self.samples,
                                                self.interference, self._params(X))[1]

    def _radii(self, X) -> np.ndarray:
        """The ring radii (P, N) of X, mm (times the ring scale, the last variable, if any)."""
        r = X[:, :self.n_r]
        return r * X[:, -1:] if self.ring_scale else r

    def _params(self, X) -> dict:
        """The scalar variables of X (P, n) by name; H1 kept below S."""
        params = {n: X[:, self.n_r + i] for i, n in enumerate(self.param_names)}
        params["H1_mm"] = np.minimum(params["H1_mm"], params["S_mm"])
        return params
