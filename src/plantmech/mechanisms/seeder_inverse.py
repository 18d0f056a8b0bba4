"""Trajectory-driven inverse design of the second-order non-circular planetary
seeding mechanism (seed 000, sections 3.2-3.3), for P candidate trajectories at once
(``inverse_population``); one design is P = 1 (``inverse_design`` adds the per-design
report: its diagnostics with the carrier angles and type-value points they cover).

One code path: extreme radii -> L1, L2 (Eq. 1); carrier direction on a dense grid for
the assembly branch that turns the carrier once clockwise (Eq. 2-3); the tip at uniform
carrier angle by the Illinois method; the planned ratio law from the periodic spline;
the toothless dwell (Eq. 5, per design); the stage split, closure normalisation and
pitch radii (Eq. 7-9); the motion the train realizes. The dense carrier direction and
the inversion run in numba kernels (``seeder_inverse_kernel``) on the spline's pieces;
``fused=False`` (and any curve object without spline coefficients, e.g. an analytic test
curve) takes the NumPy form of the same steps, the kernels' reference in the tests.

Infeasible designs are graded as their diagnostics read: the number of errors plus the
carrier angle they cover / 30 deg (``error_score``), so that an optimizer sees a slope
towards feasibility.

Conventions (see docs/conventions.md):
- Fixed frame: origin at the carrier (sun) axis O, x to the right, y up; absolute
  angles counter-clockwise from +x.
- ``carrier_angle`` psi: clockwise rotation of the carrier from its initial
  position, 0..2 pi. The initial position is the farthest trajectory point
  (arm collinear with the carrier, beta_1 = 0), as in the paper's section 3.4.
- ``planet_rel`` psi_4: counter-clockwise rotation of the planet (and arm)
  relative to the carrier; one cycle adds +2 pi.
- ``gear2_angle`` psi_2: clockwise rotation of the intermediate gears 2-3
  relative to the carrier; one cycle adds +2 pi (Eq. 8).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.interpolate import CubicSpline

from plantmech.gears.pitch import radii_from_speed_ratio, toothless_sector_follower_angle
from plantmech.geometry.periodic import (
    cyclic_runs,
    periodic_spline_node_slopes,
    periodic_spline_running_integral,
)
from plantmech.geometry.trajectory import ClosedTrajectory
from plantmech.geometry.trajectory_batch import TrajectoryBatch, row_searchsorted
from plantmech.mechanisms.three_bar import tip_position

TWO_PI = 2.0 * np.pi
ILLINOIS_ITERATIONS = 30


#: largest step of gear 2's pitch radius at the dwell's lock point (mm) that a locking arc
#: (one radius on both sides, seed 000 Eq. 5) is taken to close
DWELL_LOCK_TOLERANCE_MM = 0.01


def dwell_lock_check(info: dict) -> dict:
    """The check that a toothless dwell can lock (``InverseResult.dwell``): gear 2's pitch
    radius where meshing stops and where it resumes (the same point of gear 2, which
    stands still in between) within ``DWELL_LOCK_TOLERANCE_MM``; otherwise the note says
    why the path cannot have a lock there."""
    e = info["edge_pitch_radii"]
    end, start = e["meshing_end"], e["meshing_start"]
    jump = info["lock_radius_jump"]
    ok = bool(jump <= DWELL_LOCK_TOLERANCE_MM)
    note = ("gear 2's pitch radius where the teeth stop meshing and where they resume (the "
            "same point of gear 2: it stands still through the dwell)")
    if not ok:
        note += (f": {end['r2']:.2f} mm against {start['r2']:.2f} mm, the sun's "
                 f"{end['r1']:.2f} against {start['r1']:.2f} mm. The ratio law before the "
                 "dwell and after it differ there, so no locking arc (one radius on both "
                 "sides) fits and Eq. 5 has no edge radius: theta2 and edge_radius are not "
                 "computed. Plan the dwell where the planet turns at the same rate "
                 "relative to the carrier just before it and just after it")
    return {"name": "dwell_lock_radius_jump_mm", "value": round(float(jump), 6), "unit": "mm",
            "limit": f"<= {DWELL_LOCK_TOLERANCE_MM:g} mm", "ok": ok, "note": note}


@dataclass
class Diagnostic:
    """One finding of the inverse design: where and why."""

    kind: str
    message: str
    between_points: list[int] | None = None
    carrier_angle_deg: list[float] | None = None
    severity: str = "error"  # "error" makes the design infeasible; "warning" does not
    #: the first and last flagged samples' carrier angles (deg) where ``carrier_angle_deg``
    #: is refined between samples: the optimizer's grading reads the samples, as the
    #: population path does (``_run_score``)
    sample_angle_deg: list[float] | None = None

    def as_dict(self) -> dict:
        return {
            "kind": self.kind,
            "severity": self.severity,
            "message": self.message,
            "between_points": self.between_points,
            "carrier_angle_deg": self.carrier_angle_deg,
        }


@dataclass
class DwellSpec:
    """Toothless sector of the sun gear: the arm is held in the carrier from point
    ``start`` to point ``end`` (type-value indices). ``anchor``: the point whose
    planned attitude is kept exactly when the planned relative rotation inside the
    dwell is redistributed. ``edge_radius``: R2 of Eq. 5 (None: from the pitch curve)."""

    start: int
    end: int
    anchor: int
    edge_radius: float | None = None


@dataclass
class InverseSettings:
    samples: int = 3600
    a1: float | None = None  # stage-1 centre distance, mm (None: L1/2)
    a2: float | None = None  # stage-2 centre distance, mm (None: L1/2)
    split_exponent: float = 0.5  # stage-1 speed ratio = C * (total ratio)^p
    min_pitch_radius: float = 5.0  # mm
    dwell: DwellSpec | None = None


@dataclass
class InverseResult:
    """Everything the inverse design computed. Arrays are sampled at uniform
    ``carrier_angle`` (n samples, rad). Lengths in mm, angles in rad."""

    feasible: bool
    diagnostics: list[Diagnostic]
    L1: float | None = None
    L2: float | None = None
    a1: float | None = None
    a2: float | None = None
    shaft_offset: float = 0.0  # angle at O between carrier line and gear-2/3 shaft
    u_start: float | None = None
    carrier_angle: np.ndarray | None = None
    u: np.ndarray | None = None
    tip: np.ndarray | None = None  # planned tip (n, 2)
    tip_realized: np.ndarray | None = None  # tip produced by the gear train (dwell applied)
    carrier_abs: np.ndarray | None = None  # absolute carrier direction phi_1
    arm_angle: np.ndarray | None = None  # planned absolute arm angle beta_4
    arm_angle_realized: np.ndarray | None = None
    planet_rel: np.ndarray | None = None  # planned psi_4
    planet_rel_realized: np.ndarray | None = None
    total_ratio: np.ndarray | None = None  # d psi_4 / d psi realized (= 1/i_0)
    stage1_ratio: np.ndarray | None = None  # d psi_2 / d psi (= 1/i_1)
    stage2_ratio: np.ndarray | None = None  # d psi_4 / d psi_2 (= 1/i_2)
    gear2_angle: np.ndarray | None = None
    r1: np.ndarray | None = None
    r2: np.ndarray | None = None
    r3: np.ndarray | None = None
    r4: np.ndarray | None = None
    closure_error: dict = field(default_factory=dict)
    dwell: dict | None = None
    point_carrier_angle: np.ndarray | None = None  # carrier angle at each type-value point

    @property
    def initial_arm_angle(self) -> float:
        return float(self.arm_angle[0])



@dataclass
class InversePopulation:
    """Inverse designs of P trajectories, sampled at n uniform carrier angles ``psi``.
    ``feasible`` (P,); ``error_score`` (P,) 0 where feasible. Arrays of infeasible rows
    hold placeholders. Lengths mm, angles rad (conventions above).

    With ``inverse_population(..., full=True)`` the fields after ``pitch_tangent_angle``
    hold every array of the model (what one design's report shows) and the flags its
    diagnostics are made of; otherwise they are None."""

    feasible: np.ndarray
    error_score: np.ndarray
    psi: np.ndarray  # (n,) clockwise carrier angle from the initial position
    L1: np.ndarray  # (P,)
    L2: np.ndarray
    carrier_abs: np.ndarray  # (P, n) absolute carrier direction phi_1
    arm_angle_realized: np.ndarray  # (P, n) absolute arm angle the gear train gives
    tip_realized: np.ndarray  # (P, n, 2)
    point_carrier_angle: np.ndarray  # (P, N) carrier angle at each type-value point
    pitch_radius_min: np.ndarray  # (P, 4) smallest r1..r4 (mm; outside a dwell)
    closure_error: np.ndarray  # (P, 2) stage 1, stage 2 (rad)
    pitch_tangent_angle: np.ndarray | None = None  # (P, 2) largest mu of each pair (rad)
    # --- full=True ---
    failure: np.ndarray | None = None  # (P,) first error kind ("" where none stopped it)
    a1: np.ndarray | None = None  # (P,) centre distances (mm)
    a2: np.ndarray | None = None
    shaft_offset: np.ndarray | None = None  # (P,) rad
    u_start: np.ndarray | None = None  # (P,) parameter of the initial (farthest) point
    u: np.ndarray | None = None  # (P, n) curve parameter at psi (wrapped)
    tip: np.ndarray | None = None  # (P, n, 2) planned tip
    arm_angle: np.ndarray | None = None  # (P, n) planned beta_4
    planet_rel: np.ndarray | None = None  # (P, n) planned psi_4
    total_ratio: np.ndarray | None = None  # (P, n) d psi_4 / d psi realized (dwell: 0)
    stage1_ratio: np.ndarray | None = None  # (P, n) d psi_2 / d psi
    stage2_ratio: np.ndarray | None = None  # (P, n) d psi_4 / d psi_2
    gear2_angle: np.ndarray | None = None  # (P, n) psi_2
    radii: np.ndarray | None = None  # (P, 4, n) r1..r4 (NaN in a dwell)
    planet_rel_realized: np.ndarray | None = None  # (P, n)
    dwell: list | None = None  # per row: the dwell's numbers (dict) or None
    u_dense: np.ndarray | None = None  # (P, m + 1) dense grid of the carrier direction
    psi_dense: np.ndarray | None = None  # (P, m + 1) carrier angle on it
    carrier_back: np.ndarray | None = None  # (P, m) the carrier turns back (flags)
    ratio_bad: np.ndarray | None = None  # (P, n) ratio law <= 0 outside a dwell
    radius_small: np.ndarray | None = None  # (P, 4, n) below the minimum pitch radius
    dwell_mask: np.ndarray | None = None  # (P, n) samples in the toothless dwell


class _OneCurve:
    """A curve object with the ``ClosedTrajectory`` interface (``__call__(u)``,
    ``period``, ``knots``, ``points``) seen as a population of one: values (1, m, 2) at
    parameters (1, m); derivatives by central differences of step 1e-6 period (for the
    extreme radii's Newton steps; analytic test curves carry no derivatives)."""

    def __init__(self, curve):
        self.curve = curve
        self.points = np.asarray(curve.points, dtype=float)[None]
        self.P, self.N = 1, self.points.shape[1]
        self.period = np.array([float(curve.period)])
        self.knots = np.asarray(curve.knots, dtype=float)[None]
        self.bad = np.zeros(1, bool)

    def __call__(self, u):
        return np.asarray(self.curve(np.asarray(u)[0]), dtype=float)[None]

    def derivatives(self, u):
        h = 1e-6 * self.period[0]
        p, a, b = self(u), self(u + h), self(u - h)
        return p, (a - b) / (2 * h), (a - 2 * p + b) / h**2


def _as_rows(points):
    """The population the model works on: a ``TrajectoryBatch`` (as given, from points
    (P, N, 2) mm, or a ``ClosedTrajectory``'s own one-row batch) or ``_OneCurve``."""
    if isinstance(points, TrajectoryBatch | _OneCurve):
        return points
    if isinstance(points, ClosedTrajectory):
        return points.batch
    if callable(points):
        return _OneCurve(points)
    return TrajectoryBatch(points)


def dense_grid_size(samples: int, points: int) -> int:
    """Intervals of the dense parameter grid of the inverse design (4 per carrier
    sample, at least 64 per type-value span)."""
    return max(4 * samples, 64 * points)


def wrap_angle(a):
    """Angle(s) wrapped to [-pi, pi] (np.angle(exp(1j a)) without the complex numbers)."""
    return a - TWO_PI * np.round(a / TWO_PI)


def _unwrap_rows(phase: np.ndarray) -> np.ndarray:
    """np.unwrap along axis 1, with its rounding (jumps of at least pi are replaced by
    their 2 pi complement), computed only where a jump is."""
    d = np.diff(phase, axis=1)
    jump = np.abs(d) >= np.pi
    out = phase.copy()
    if jump.any():
        dj = d[jump]
        dmod = np.mod(dj + np.pi, TWO_PI) - np.pi
        dmod = np.where((dmod == -np.pi) & (dj > 0), np.pi, dmod)
        corr = np.zeros_like(d)
        corr[jump] = dmod - dj
        out[:, 1:] += np.cumsum(corr, axis=1)
    return out


def extreme_radii(tb, per_span: int = 16, candidates: int = 2, fused: bool = True):
    """((u, rho) of the farthest, (u, rho) of the nearest) point of each trajectory to O,
    each (P,): the ``candidates`` best local extremes of ``per_span`` samples per knot
    span, each refined by safeguarded Newton on d(rho^2)/du = 0 within one sample step (to
    1e-9 mm of parameter; rho itself is flat there, so a search on rho alone cannot
    resolve the place), and the better kept (two near-equal bumps are told apart by
    their refined values, not by their samples). ``fused``: the Newton steps in the numba
    kernel ``seeder_inverse_kernel.refine_extremes`` (a ``TrajectoryBatch`` only; False:
    the NumPy loop, the reference in the tests)."""
    fused = fused and isinstance(tb, TrajectoryBatch)
    m = per_span * tb.N
    h = tb.period / m
    u = h[:, None] * np.arange(m)[None, :]
    xy = tb(u)
    rho2 = xy[..., 0] ** 2 + xy[..., 1] ** 2
    out = []
    for largest in (True, False):
        r = rho2 if largest else -rho2
        local = (r >= np.roll(r, 1, axis=1)) & (r >= np.roll(r, -1, axis=1))
        k = np.argsort(np.where(local, -r, np.inf), axis=1)[:, :candidates]  # (P, c)
        lo = np.take_along_axis(u, k, axis=1) - h[:, None]
        hi, x = lo + 2.0 * h[:, None], lo + h[:, None]

        def slope(at, largest=largest):  # d(rho^2)/du / 2: > 0 before a max (min)
            p, d1, _ = tb.derivatives(at)
            f = (p * d1).sum(axis=-1)
            return f if largest else -f

        # a candidate without a turn inside its bracket keeps its sample (a flat stretch)
        done = ~((slope(lo) > 0) & (slope(hi) < 0))
        if fused:  # each candidate on its own in numba: the same steps, no temporaries
            from plantmech.mechanisms.seeder_inverse_kernel import refine_extremes

            x = refine_extremes(tb.coef, tb.knots, tb.period, lo, hi, x, done, largest)
        for _ in range(0 if fused else 40):
            p, d1, d2 = tb.derivatives(x)
            f = (p * d1).sum(axis=-1)
            fp = (d1 * d1).sum(axis=-1) + (p * d2).sum(axis=-1)
            # keep the bracket: f goes + to - through a maximum, - to + through a minimum
            rising = f > 0 if largest else f < 0
            lo, hi = np.where(rising, x, lo), np.where(rising, hi, x)
            with np.errstate(divide="ignore", invalid="ignore"):
                step = f / fp
            nx = x - step
            nx = np.where(np.isfinite(nx) & (nx >= lo) & (nx <= hi), nx, 0.5 * (lo + hi))
            x = np.where(done, x, nx)
            done |= (np.abs(step) < 1e-9) | (hi - lo < 1e-9)
            if done.all():
                break
        p = tb(x)
        rho = np.hypot(p[..., 0], p[..., 1])
        j = np.argmax(rho if largest else -rho, axis=1)
        rows = np.arange(tb.P)
        out.append((np.mod(x[rows, j], tb.period), rho[rows, j]))
    return out


def _carrier_geometry(tb, u, L1, L2):
    """Tip (P, m, 2), its polar angle beta_3 and the unsigned angle beta_1 at O between
    the carrier and the tip (Eq. 2-3) at parameters u (P, m)."""
    xy = tb(u)
    x, y = xy[..., 0], xy[..., 1]
    rho = np.hypot(x, y)
    L1c, L2c = L1[:, None], L2[:, None]
    with np.errstate(divide="ignore", invalid="ignore"):  # rho = 0: a degenerate row
        cos_b1 = np.clip((L1c**2 + rho**2 - L2c**2) / (2 * L1c * rho), -1.0, 1.0)
    return xy, np.arctan2(y, x), np.arctan2(np.sqrt(np.clip(1.0 - cos_b1**2, 0.0, None)),
                                            cos_b1)


def _branch_sign(tb, u, u_min, u_max, sigma_inner):
    """sigma (P, m): ``sigma_inner`` on the arc from u_min to u_max (traversal order),
    its opposite on the other arc: the assembly branch switches where the curve touches
    rho = L1 + L2 and rho = L2 - L1 (beta_1 = 0 and pi)."""
    per = tb.period[:, None]
    on_inner = np.mod(u - u_min[:, None], per) < np.mod(u_max - u_min, tb.period)[:, None]
    return np.where(on_inner, sigma_inner[:, None], -sigma_inner[:, None])


def _carrier_direction(tb, u, L1, L2, u_min, u_max, sigma_inner):
    """Absolute carrier angle phi_1 = beta_3 + sigma beta_1 (P, m) at parameters u (P, m),
    and the tip there."""
    xy, beta3, beta1 = _carrier_geometry(tb, u, L1, L2)
    return beta3 + _branch_sign(tb, u, u_min, u_max, sigma_inner) * beta1, xy


def invert_carrier(psi, u_dense, phi_dense, psi_dense, alive, carrier_at):
    """Curve parameters u (P, n) where the carrier has turned ``psi`` (n,) clockwise, by
    the Illinois method (modified regula falsi) on each bracket of the dense grids
    (P, m + 1), all rows and samples at once; psi is smooth and monotonic there.
    ``carrier_at(u)``: absolute carrier angle (wrapped) at u (P, n); ``alive`` (P,): the
    rows whose convergence counts. Returns (u, the dense carrier angle at each bracket's
    start, which unwraps it). The NumPy form of ``seeder_inverse_kernel.invert_carrier``."""
    P, n = u_dense.shape[0], len(psi)
    k = row_searchsorted(psi_dense, np.broadcast_to(psi, (P, n)))
    rows = np.arange(P)[:, None]
    lo, hi = u_dense[rows, k], u_dense[rows, k + 1]
    f_lo, f_hi = psi_dense[rows, k] - psi, psi_dense[rows, k + 1] - psi  # <= 0 <= f_hi
    phi_k = phi_dense[rows, k]
    side = np.zeros((P, n))
    u = lo
    for _ in range(ILLINOIS_ITERATIONS):
        den = f_hi - f_lo
        u = np.where(den > 0, lo - f_lo * (hi - lo) / np.where(den > 0, den, 1.0),
                     0.5 * (lo + hi))
        f = phi_dense[:, :1] - (phi_k + wrap_angle(carrier_at(u) - phi_k)) - psi
        right = f > 0
        hi, lo = np.where(right, u, hi), np.where(right, lo, u)
        # Illinois: halve the value kept on the side that stayed, twice in a row
        f_lo = np.where(right, np.where(side > 0, 0.5 * f_lo, f_lo), f)
        f_hi = np.where(right, f, np.where(side < 0, 0.5 * f_hi, f_hi))
        side = np.where(right, 1.0, -1.0)
        # rad of carrier angle (round-off floor ~4e-11)
        if np.abs(np.where(alive[:, None], f, 0.0)).max() < 1e-10:
            break
    return u, phi_k


def _runs(mask: np.ndarray) -> np.ndarray:
    """Number of cyclic True runs per row of ``mask`` (P, m)."""
    starts = (mask & ~np.roll(mask, 1, axis=1)).sum(axis=1)
    return np.where(mask.all(axis=1), 1, starts)


def _run_score(mask, step_deg):
    """Diagnostics' grading for runs of flagged samples: one error per cyclic run plus the
    carrier angle each run spans (first to last flagged sample) / 30 deg."""
    runs = _runs(mask)
    return runs + (mask.sum(axis=1) - runs) * step_deg / 30.0


def _running_integral(values: np.ndarray, step: float) -> np.ndarray:
    """``periodic_spline_running_integral`` of each row of ``values`` (P, n) -> (P, n + 1)."""
    return periodic_spline_running_integral(values.T, step).T


def _node_slopes(values: np.ndarray, step: float) -> np.ndarray:
    """``periodic_spline_node_slopes`` along axis 1 of ``values`` (P, n[, k])."""
    return np.moveaxis(periodic_spline_node_slopes(np.moveaxis(values, 1, 0), step), 0, 1)


def _split_and_close(g, in_dwell, split_exponent, a1, a2, integral):
    """Eq. 7-9 for P ratio laws g = d psi_4 / d psi (P, n), zero on a dwell's samples
    (``in_dwell``, gears idle): stage 1 takes C g^p, normalised so gear 2 closes, stage 2
    the rest, normalised so the planet closes under the same rule that integrates them
    back to angles. ``integral(values (P, n), factor (P,), power)`` -> (P, n + 1): the
    running integral over the cycle of values that sample factor * g^power. Returns
    (stage-1 ratio h, stage-2 ratio q, gear 2's turn psi_2 (P, n + 1), the planet's
    running turn (P, n + 1), pitch radii r1..r4 (P, 4, n) mm, closure errors (P, 2) rad,
    C (P,), the stage-2 normalisation (P,))."""
    p = split_exponent
    ones = np.ones(len(g))
    shape = np.where(in_dwell, 0.0, g**p)
    c = TWO_PI / integral(shape, ones, p)[:, -1]
    h = c[:, None] * shape  # d psi_2 / d psi = 1 / i_1
    q = np.where(in_dwell, 0.0, g ** (1 - p) / c[:, None])  # 1 / i_2 (idle in a dwell)
    norm = TWO_PI / integral(h * q, ones, 1.0)[:, -1]
    q = q * norm[:, None]
    gear2 = integral(h, c, p)
    planet_train = integral(h * q, norm, 1.0)
    r1, r2 = radii_from_speed_ratio(a1[:, None], h)
    r3, r4 = radii_from_speed_ratio(a2[:, None], q)
    closure = np.c_[np.abs(gear2[:, -1] - TWO_PI), np.abs(planet_train[:, -1] - gear2[:, -1])]
    return h, q, gear2, planet_train, np.stack([r1, r2, r3, r4], axis=1), closure, c, norm


def pitch_tangent_angle(radii: np.ndarray, a1: np.ndarray, step: float,
                        nan_ok: bool = False) -> np.ndarray:
    """Largest angle mu (rad) between the pitch tangent and the normal to the radius vector
    of each pair, (P, 2), from the pitch radii r1..r4 (P, 4, n) on the uniform carrier grid:
    gears 2 and 3 share a shaft turning d theta / d psi = h = a1 / r2 - 1 relative to the
    carrier, so tan mu = abs(dr / d psi) / (h r) along gear 2 (sun pair) and gear 3 (planet
    pair); the working pressure angle is the tool's plus mu (``gears.manufacturability``).
    ``nan_ok``: samples with NaN radii (a toothless dwell) are left out of the maximum; the
    slopes are then central differences (local: a spline's would be NaN everywhere)."""
    r2, r3 = radii[:, 1], radii[:, 2]
    h = a1[:, None] / r2 - 1.0
    out = []
    for r in (r2, r3):
        dr = ((np.roll(r, -1, axis=1) - np.roll(r, 1, axis=1)) / (2 * step) if nan_ok
              else _node_slopes(r, step))
        mu = np.arctan(np.abs(dr) / (np.abs(h) * r))
        out.append(np.nanmax(mu, axis=1) if nan_ok else mu.max(axis=1))
    return np.stack(out, axis=1)


class _DwellLaw:
    """One design's ratio law around its dwell: the planned law between samples (the
    periodic spline of psi_4 - psi, scaled as the dwell redistributes it) where the
    meshing arc ends between samples, and the exact running integral on that arc."""

    def __init__(self, psi, planet_rel, info):
        drift = planet_rel - psi
        self.spline = CubicSpline(np.r_[psi, TWO_PI], np.r_[drift, drift[0]],
                                  bc_type="periodic")
        self.scale = info["ratio_scale"]
        self.arc0, self.arc_len = info["carrier_end"], TWO_PI - info["theta1"]
        self.psi = psi

    def __call__(self, x):
        # the law is positive at every sample (checked); between samples a spline can
        # dip, which a fractional power must not see
        return np.maximum(self.scale * (self.spline(np.mod(x, TWO_PI), 1) + 1.0), 1e-12)

    def integral(self, factor: float, power: float) -> np.ndarray:
        return _integrate_on_arc(lambda x: factor * self(x) ** power, self.psi, self.arc0,
                                 self.arc_len)


def inverse_population(points, samples: int = 360, a1: float | None = None,
                       a2: float | None = None, split_exponent: float = 0.5,
                       min_pitch_radius: float = 5.0, dwell: DwellSpec | None = None,
                       full: bool = False, fused: bool = True,
                       tangent_angle: bool = True) -> InversePopulation:
    """Inverse designs of the trajectories through ``points`` (P, N, 2) mm, of a
    ``TrajectoryBatch``, or of one curve (a ``ClosedTrajectory`` or any object with its
    interface): P rows, no Python loop per sample (nor per design, except the toothless
    ``dwell``'s per-design steps). ``a1``, ``a2``: centre distances (mm; None: L1/2);
    ``split_exponent`` p: stage 1 takes C (total ratio)^p; ``min_pitch_radius`` (mm).
    ``samples`` n: uniform carrier angles per cycle. ``dwell``: the sun's toothless sector
    (Eq. 5), the same type-value points for every row, placed on each row's own carrier
    law (the rows' carrier angles differ). ``full``: keep every array and the
    diagnostics' flags (``inverse_design`` reads them).
    ``fused``: the dense carrier direction and the inversion in the numba kernels
    (spline coefficients needed), else their NumPy form. ``tangent_angle``: compute
    ``pitch_tangent_angle`` (else None)."""
    tb = _as_rows(points)
    fused = fused and isinstance(tb, TrajectoryBatch)
    P, N, n = tb.P, tb.N, int(samples)
    score = np.zeros(P)
    failure = np.full(P, "", dtype=object)
    alive = ~tb.bad

    def stop(rows, kind, value):
        """Rows ``rows`` stop here with error ``kind``, graded ``value`` (a number or a
        callable giving (P,) values, evaluated only when a row stops)."""
        nonlocal alive, score
        if not rows.any():
            return
        score = np.where(rows, value() if callable(value) else value, score)
        failure[rows] = kind
        alive = alive & ~rows

    stop(tb.bad, "curve", 10.0)  # no curve at all (as a fitting failure)
    (u_max, rho_max), (u_min, rho_min) = extreme_radii(tb, fused=fused)
    L1, L2 = 0.5 * (rho_max - rho_min), 0.5 * (rho_max + rho_min)
    stop(alive & ((rho_min < 1e-6) | (L1 < 1e-6)), "degenerate", 1.0)
    L1s = np.where(alive, L1, 1.0)
    A1 = np.full(P, float(a1)) if a1 is not None else 0.5 * L1s
    A2 = np.full(P, float(a2)) if a2 is not None else 0.5 * L1s
    stop(alive & ((A1 <= 0) | (A2 <= 0) | (A1 + A2 < L1s - 1e-9) | (np.abs(A1 - A2) > L1s)),
         "centre_distance", 1.0)
    with np.errstate(divide="ignore", invalid="ignore"):
        shaft_offset = np.where(alive, np.arccos(np.clip(
            (A1**2 + L1s**2 - A2**2) / (2 * A1 * L1s), -1.0, 1.0)), 0.0)

    # Dense parameter grid starting at the initial position (farthest point): it picks
    # the assembly branch, finds where the carrier would turn back and brackets the
    # inversion below (whose result does not depend on it).
    m = dense_grid_size(n, N)
    grid = np.linspace(0.0, 1.0, m + 1)
    u_dense = u_max[:, None] + tb.period[:, None] * grid[None, :]
    L2s = np.where(alive, L2, 1.0)
    if fused:  # the numba kernels on the spline's own pieces (seeder_inverse_kernel)
        from plantmech.mechanisms import seeder_inverse_kernel as kernel

        branches = kernel.dense_carrier(tb.coef, tb.knots, tb.period, u_dense, L1s, L2s,
                                        u_min, u_max, alive)
    else:
        _, beta3, beta1 = _carrier_geometry(tb, u_dense, L1s, L2s)
        inner = _branch_sign(tb, u_dense, u_min, u_max, np.ones(P))
        branches = [_unwrap_rows(beta3 + s * inner * beta1) for s in (1.0, -1.0)]
    turns = [np.abs((phi[:, -1] - phi[:, 0]) + TWO_PI) < 1e-3 for phi in branches]
    # the branch sigma = -1 wins when both turn the carrier once clockwise
    use_neg = turns[1]
    sigma = np.where(use_neg, -1.0, 1.0)
    phi_dense = np.where(use_neg[:, None], branches[1], branches[0])
    stop(alive & ~(turns[0] | use_neg), "carrier_turn", 1.0)
    psi_dense = phi_dense[:, :1] - phi_dense  # clockwise carrier rotation
    dpsi = np.diff(psi_dense, axis=1)
    backwards = dpsi <= 0
    back = alive & backwards.any(axis=1)
    stop(back, "carrier_not_monotonic", lambda: _runs(backwards) + np.degrees(
        np.where(backwards, -dpsi, 0.0).sum(axis=1)) / 30.0)
    psi_bracket = np.where(alive[:, None], psi_dense, grid[None, :] * TWO_PI)  # stopped: monotone

    # Tip samples at uniform carrier angle
    psi = np.linspace(0.0, TWO_PI, n, endpoint=False)
    if fused:
        u, phi, tip = kernel.invert_carrier(psi, u_dense, phi_dense, psi_bracket, tb.coef,
                                            tb.knots, tb.period, L1s, L2s, u_min, u_max,
                                            sigma, alive)
    else:
        u, phi_k = invert_carrier(psi, u_dense, phi_dense, psi_bracket, alive,
                                  lambda x: _carrier_direction(tb, x, L1s, L2s, u_min, u_max,
                                                               sigma)[0])
        phi, tip = _carrier_direction(tb, u, L1s, L2s, u_min, u_max, sigma)
        phi = phi_k + wrap_angle(phi - phi_k)
    ex, ey = L1s[:, None] * np.cos(phi), L1s[:, None] * np.sin(phi)
    arm = _unwrap_rows(np.arctan2(tip[..., 1] - ey, tip[..., 0] - ex))
    planet_rel = arm - phi
    planet_rel = planet_rel - planet_rel[:, :1]
    net_arm = arm[:, -1] - arm[:, 0] + wrap_angle(arm[:, 0] - arm[:, -1])
    # carrier angle at each type-value point: exact, unwrapped by the dense grid
    u_pts = tb.knots[:, :-1]
    x_pts = np.mod(u_pts - u_max[:, None], tb.period[:, None])
    j = np.clip(np.floor(x_pts / tb.period[:, None] * m).astype(int), 0, m - 1)
    phi_pts, _ = _carrier_direction(tb, u_pts, L1s, L2s, u_min, u_max, sigma)
    phi_j = phi_dense[np.arange(P)[:, None], j]
    point_psi = phi_dense[:, :1] - (phi_j + wrap_angle(phi_pts - phi_j))
    stop(alive & (np.abs(net_arm) > 1e-3), "planet_turn", 1.0)

    # Planned total ratio g = d psi_4 / d psi from a periodic spline of psi_4 - psi.
    step = TWO_PI / n
    step_deg = 360.0 / n
    g = _node_slopes(planet_rel - psi, step) + 1.0
    g_real, realized_rel = g, planet_rel
    in_dwell = np.zeros((P, n), bool)
    anchor_k = np.zeros(P, int)
    dwell_info: list = [None] * P
    laws: dict[int, _DwellLaw] = {}
    if dwell is not None:  # per design: where the dwell falls depends on its carrier law
        g_real, realized_rel = g.copy(), planet_rel.copy()
        for r in np.flatnonzero(alive):
            rel, g_real[r], in_dwell[r], info = _apply_dwell(dwell, psi, planet_rel[r], g[r],
                                                             point_psi[r])
            if info is None:
                stop(np.arange(P) == r, "dwell", 1.0)
                continue
            realized_rel[r], dwell_info[r] = rel, info
            laws[r] = _DwellLaw(psi, planet_rel[r], info)
            anchor_k[r] = int(np.argmin(np.abs(np.angle(np.exp(1j * (
                psi - point_psi[r, dwell.anchor]))))))
    # Feasibility of the ratio law outside the dwell.
    ratio_bad = (g_real <= 0) & ~in_dwell
    reverses = alive & ratio_bad.any(axis=1)
    stop(reverses, "ratio_not_positive", lambda: _run_score(ratio_bad, step_deg))
    ratio_known = alive | reverses
    laws = {r: law for r, law in laws.items() if alive[r]}  # a stopped row keeps its plan

    def integral(values, factor, power):
        out = _running_integral(values, step)
        for r, law in laws.items():  # the laws jump at the dwell ends (between samples)
            out[r] = law.integral(factor[r], power)
        return out

    h, q, gear2, planet_train, radii, closure, c, norm = _split_and_close(
        np.where(alive[:, None], g_real, 1.0), in_dwell, split_exponent, A1, A2, integral)
    # The motion the train actually produces (integrated ratio law), anchored like the
    # plan: at the initial position, or a dwell's anchor point
    rows = np.arange(P)
    train_rel = planet_train[:, :-1]
    train_rel = (train_rel - train_rel[rows, anchor_k][:, None]
                 + realized_rel[rows, anchor_k][:, None])
    arm_real = phi + train_rel + (arm[:, :1] - phi[:, :1])
    arm_real = arm_real - (TWO_PI * np.round((arm_real[rows, anchor_k] - arm[rows, anchor_k])
                                             / TWO_PI))[:, None]
    tip_real = tip_position(L1s[:, None], L2s[:, None], phi, arm_real)
    radii[np.broadcast_to(in_dwell[:, None], radii.shape)] = np.nan  # no rolling contact
    small = ~in_dwell[:, None] & (radii < min_pitch_radius)
    pitch = alive & small.any(axis=(1, 2))
    if pitch.any():
        score = np.where(pitch, sum(_run_score(small[:, i], step_deg) for i in range(4)),
                         score)
    unclosed = alive[:, None] & (closure >= 1e-9)
    score = score + unclosed.sum(axis=1)
    failure[alive & unclosed.any(axis=1)] = "closure"
    failure[pitch] = "pitch_radius"
    feasible = alive & ~pitch & ~unclosed.any(axis=1)
    for r, law in laws.items():  # exact pitch radii where meshing restarts and stops
        info = dwell_info[r]
        edges = {}
        for key, x in (("meshing_start", law.arc0), ("meshing_end", law.arc0 + law.arc_len)):
            gx = float(law(x))
            e_r1, e_r2 = radii_from_speed_ratio(A1[r], c[r] * gx**split_exponent)
            e_r3, e_r4 = radii_from_speed_ratio(A2[r], gx ** (1 - split_exponent) / c[r]
                                                * norm[r])
            edges[key] = {"r1": float(e_r1), "r2": float(e_r2), "r3": float(e_r3),
                          "r4": float(e_r4)}
        info["edge_pitch_radii"] = edges
        before, after = edges["meshing_end"]["r1"], edges["meshing_start"]["r1"]
        info["sun_radius_at_ends"] = [float(before), float(after)]
        # gear 2 stands still through the dwell: the same point of it faces the sun where
        # meshing stops and where it resumes, so a locking arc needs one radius there
        jump = abs(edges["meshing_end"]["r2"] - edges["meshing_start"]["r2"])
        info["lock_radius_jump"] = float(jump)
        if jump <= DWELL_LOCK_TOLERANCE_MM:
            edge = dwell.edge_radius if dwell.edge_radius is not None else 0.5 * (before
                                                                                 + after)
            info["edge_radius"] = float(edge)
            info["theta2"] = toothless_sector_follower_angle(info["theta1"], edge, A1[r])
        else:  # no radius locks: Eq. 5 has nothing to apply to (dwell_lock_check says why)
            info["edge_radius"] = info["theta2"] = None
        info["max_tip_deviation"] = float(np.hypot(*(tip_real[r] - tip[r]).T).max())

    out = InversePopulation(
        pitch_tangent_angle=(pitch_tangent_angle(radii, A1, step, nan_ok=bool(laws))
                             if tangent_angle else None),
        feasible=feasible, error_score=np.where(feasible, 0.0, np.maximum(score, 1.0)),
        psi=psi, L1=L1, L2=L2, carrier_abs=phi, arm_angle_realized=arm_real,
        tip_realized=tip_real, point_carrier_angle=point_psi,
        pitch_radius_min=np.nanmin(radii, axis=2) if laws else radii.min(axis=2),
        closure_error=closure)
    if full:
        out.failure, out.a1, out.a2, out.shaft_offset, out.u_start = (failure, A1, A2,
                                                                      shaft_offset, u_max)
        out.u, out.tip, out.arm_angle, out.planet_rel = (np.mod(u, tb.period[:, None]), tip,
                                                         arm, planet_rel)
        out.total_ratio = np.where(ratio_known[:, None], g_real, np.nan)
        out.stage1_ratio, out.stage2_ratio, out.gear2_angle = h, q, gear2[:, :-1]
        out.radii, out.planet_rel_realized, out.dwell = radii, train_rel, dwell_info
        out.u_dense, out.psi_dense, out.carrier_back = u_dense, psi_dense, backwards
        out.ratio_bad, out.radius_small, out.dwell_mask = ratio_bad, small, in_dwell
    return out


def _on_run(values: np.ndarray, first: int, last: int) -> np.ndarray:
    """values[first..last] of a cyclic run (one that wraps past the end has last < first)."""
    n = len(values)
    return values[np.arange(first, first + (last - first) % n + 1) % n]


def _bracket_points(traj, u0: float, u1: float) -> list[int]:
    """Type-value points enclosing the parameter span u0..u1 (traversal order)."""
    n = len(traj.points)
    i0 = int(np.floor(traj.point_index_of(u0))) % n
    i1 = int(np.ceil(traj.point_index_of(u1))) % n
    return [i0, i1]


# how far one design's result is filled, by the first error that stopped it
_STAGE = {"degenerate": 0, "centre_distance": 1, "carrier_turn": 2,
          "carrier_not_monotonic": 2, "planet_turn": 3, "dwell": 3,
          "ratio_not_positive": 4}


def inverse_design(traj, settings: InverseSettings, fused: bool = True) -> InverseResult:
    """Run the full inverse design of one trajectory (``ClosedTrajectory``, or any curve
    object with its interface); never raises for an infeasible trajectory. The model is
    ``inverse_population`` with P = 1; here its flags become the diagnostics, each naming
    the type-value points and carrier angles it covers. ``fused``: as there."""
    pop = inverse_population(traj, settings.samples, settings.a1, settings.a2,
                             settings.split_exponent, settings.min_pitch_radius,
                             dwell=settings.dwell, full=True, fused=fused,
                             tangent_angle=False)
    diags: list[Diagnostic] = []
    L1 = float(pop.L1[0])
    res = InverseResult(feasible=False, diagnostics=diags, L1=L1, L2=float(pop.L2[0]),
                        u_start=float(pop.u_start[0]))
    failure = pop.failure[0]
    stage = _STAGE.get(failure, 5)
    if stage == 0:
        diags.append(Diagnostic("degenerate", "trajectory passes through the rotation centre "
                                "or has constant radius; no carrier length follows (Eq. 1)"))
        return res
    a1, a2 = float(pop.a1[0]), float(pop.a2[0])
    res.a1, res.a2 = a1, a2
    if stage == 1:
        diags.append(Diagnostic(
            "centre_distance",
            f"centre distances a1={a1:.3f} mm and a2={a2:.3f} mm cannot place the planet at "
            f"the carrier length L1={L1:.3f} mm (need |a1-a2| <= L1 <= a1+a2)",
        ))
        return res
    res.shaft_offset = float(pop.shaft_offset[0])
    if failure == "carrier_turn":
        diags.append(Diagnostic(
            "carrier_turn",
            "no assembly branch turns the carrier clockwise through exactly one revolution "
            "per cycle; traverse the type-value points in the other order or move the "
            "trajectory so that the rotation centre lies outside it",
        ))
        return res
    if failure == "carrier_not_monotonic":
        u_dense, psi_dense = pop.u_dense[0], pop.psi_dense[0]
        for s, e in cyclic_runs(pop.carrier_back[0]):
            diags.append(Diagnostic(
                "carrier_not_monotonic",
                "the carrier would have to turn back (counter-clockwise) here: the planned "
                "tip cannot be reached by a uniformly turning carrier",
                _bracket_points(traj, u_dense[s], u_dense[e + 1]),
                [float(np.degrees(psi_dense[s])), float(np.degrees(psi_dense[e + 1]))],
            ))
        return res

    psi, u = pop.psi, pop.u[0]
    res.carrier_angle, res.u, res.tip = psi, u, pop.tip[0]
    res.carrier_abs, res.arm_angle, res.planet_rel = (pop.carrier_abs[0], pop.arm_angle[0],
                                                      pop.planet_rel[0])
    res.point_carrier_angle = pop.point_carrier_angle[0]
    if failure == "planet_turn":
        arm = res.arm_angle
        net_arm = float(arm[-1] - arm[0] + wrap_angle(arm[0] - arm[-1]))
        diags.append(Diagnostic(
            "planet_turn",
            f"the arm turns {np.degrees(net_arm):.1f} deg per cycle in the fixed frame; this "
            "train needs a swinging arm (net 0 deg), i.e. one planet turn per carrier turn",
        ))
        return res
    if failure == "dwell":
        diags.append(Diagnostic("dwell", "the dwell anchor point lies inside the dwell",
                                [settings.dwell.start, settings.dwell.end]))
        return res
    res.dwell = pop.dwell[0]
    g_real = pop.total_ratio[0]
    res.total_ratio = g_real
    runs = cyclic_runs(pop.ratio_bad[0])
    if runs:  # located on the law's spline between the samples (geometry.refine)
        from plantmech.geometry.refine import periodic_law, run_of_law

        spline = periodic_law(res.planet_rel - psi)
        scale = res.dwell["ratio_scale"] if res.dwell is not None else 1.0

        def law(x):
            return scale * (spline(x, 1) + 1.0)

    for s, e in runs:
        run = run_of_law(law, psi, s, e)
        diags.append(Diagnostic(
            "ratio_not_positive",
            "the planet would have to stop or turn back relative to the carrier "
            f"(d psi4/d psi reaches {run['minimum']:.4f}): a gear pair cannot give a "
            "zero or negative speed ratio, pitch radius would be <= 0",
            _bracket_points(traj, u[s], u[e]),
            [float(np.degrees(np.mod(run[k], TWO_PI))) for k in ("start", "end")],
            sample_angle_deg=[float(np.degrees(psi[s])), float(np.degrees(psi[e]))],
        ))
    if failure == "ratio_not_positive":
        return res

    res.stage1_ratio, res.stage2_ratio = pop.stage1_ratio[0], pop.stage2_ratio[0]
    res.gear2_angle = pop.gear2_angle[0]
    res.r1, res.r2, res.r3, res.r4 = pop.radii[0]
    res.closure_error = {"stage1": float(pop.closure_error[0, 0]),
                         "stage2": float(pop.closure_error[0, 1])}
    res.planet_rel_realized = pop.planet_rel_realized[0]
    res.arm_angle_realized, res.tip_realized = pop.arm_angle_realized[0], pop.tip_realized[0]
    for name in ("stage1", "stage2"):
        if not res.closure_error[name] < 1e-9:
            diags.append(Diagnostic("closure", f"pair {name} does not close: error "
                                    f"{res.closure_error[name]:.3e} rad"))
    for i, name in enumerate(("r1 (sun)", "r2", "r3", "r4 (planet)")):
        r, a = pop.radii[0, i], (a1, a1, a2, a2)[i]
        for s, e in cyclic_runs(pop.radius_small[0, i]):
            diags.append(Diagnostic(
                "pitch_radius",
                f"pitch radius {name} falls to {_on_run(r, s, e).min():.2f} mm, below the minimum "
                f"{settings.min_pitch_radius:g} mm (centre distance {a:.2f} mm)",
                _bracket_points(traj, u[s], u[e]),
                [float(np.degrees(psi[s])), float(np.degrees(psi[e]))],
            ))
    if res.dwell is not None and res.dwell["max_tip_deviation"] > 0.01:
        dev = np.hypot(*(res.tip_realized - res.tip).T)
        k = int(np.argmax(dev))
        dw = settings.dwell
        rho = np.hypot(*np.asarray(traj.points)[[dw.start, dw.end]].T)
        diags.append(Diagnostic(
            "dwell_not_arc",
            f"the planned section q{dw.start}-q{dw.end} is not an "
            f"arc about the rotation centre (radius {rho[0]:.1f} -> {rho[1]:.1f} mm; the "
            f"arm turns {np.degrees(res.dwell['planned_rel_rotation']):.2f} deg in the "
            "carrier there), so holding the arm in the toothless sector moves the tip "
            f"off the plan by up to {dev.max():.2f} mm (largest at carrier angle "
            f"{np.degrees(psi[k]):.1f} deg)",
            _bracket_points(traj, u[k], u[k]),
            [float(np.degrees(res.dwell["carrier_start"])),
             float(np.degrees(res.dwell["carrier_end"]))],
            severity="warning",
        ))
    if res.dwell is not None and res.dwell["theta2"] is None:
        e = res.dwell["edge_pitch_radii"]
        dw = settings.dwell
        diags.append(Diagnostic(
            "dwell_cannot_lock",
            f"gear 2 cannot lock in the dwell q{dw.start}-q{dw.end}: its pitch radius is "
            f"{e['meshing_end']['r2']:.2f} mm where the teeth stop meshing and "
            f"{e['meshing_start']['r2']:.2f} mm where they resume (a step of "
            f"{res.dwell['lock_radius_jump']:.2f} mm at the same point of gear 2), so no "
            "locking arc fits and Eq. 5 gives no theta2 (check dwell_lock_radius_jump_mm)",
            [dw.start, dw.end],
            [float(np.degrees(res.dwell["carrier_start"])),
             float(np.degrees(res.dwell["carrier_end"]))],
            severity="warning",
        ))
    res.feasible = not any(d.severity == "error" for d in diags)
    return res


def _integrate_on_arc(fn, psi, x0: float, length: float) -> np.ndarray:
    """Running integral over the cycle (n + 1 values from carrier angle 0, the last the
    total) of a law that is smooth on the arc [x0, x0 + length] of carrier angles and
    zero elsewhere; ``fn(x)`` evaluates it anywhere on the arc. A cubic spline through
    the arc ends and the samples inside is integrated exactly, so the jumps at the arc
    ends cost nothing (the trapezoid rule would lose O(step) there)."""
    x = x0 + np.mod(psi - x0, TWO_PI)
    inside = x < x0 + length
    nodes = np.unique(np.r_[x0, x[inside], x0 + length])
    prim = CubicSpline(nodes, fn(nodes)).antiderivative()
    total = float(prim(x0 + length))
    F = np.where(inside, prim(np.minimum(x, x0 + length)), total)
    cum = F - F[0] + total * (x < x[0])
    return np.r_[cum, total]


def _apply_dwell(dw: DwellSpec, psi, planet_rel, g, point_psi):
    """Hold the planet in the carrier from point dw.start to dw.end.

    The planned relative rotation delta inside the dwell is redistributed over the
    rest of the cycle by scaling the ratio law by k = 2 pi / (2 pi - delta), anchored
    so that the attitude at point dw.anchor is kept exactly. Returns
    (realized psi_4, realized ratio, dwell mask, info) or info None if the anchor is
    inside the dwell.
    """
    p0, p1, pa = point_psi[dw.start], point_psi[dw.end], point_psi[dw.anchor]
    span = float(np.mod(p1 - p0, TWO_PI))
    table_x = np.r_[psi, TWO_PI]
    table_y = np.r_[planet_rel, TWO_PI]

    def rext(x):
        x = np.asarray(x, dtype=float)
        return np.interp(np.mod(x, TWO_PI), table_x, table_y) + TWO_PI * np.floor(x / TWO_PI)

    p0_ext = p1 + np.mod(p0 - p1, TWO_PI)  # dwell start, after the non-dwell arc
    if p0_ext < p1:
        p0_ext += TWO_PI
    pa_ext = p1 + np.mod(pa - p1, TWO_PI)
    if pa_ext > p0_ext:
        return planet_rel, g, np.zeros(len(psi), bool), None
    delta = float(rext(p1) - rext(p0_ext) + TWO_PI)
    scale = TWO_PI / (TWO_PI - delta)
    x = p1 + np.mod(psi - p1, TWO_PI)
    in_dwell = x >= p0_ext
    r_anchor = float(rext(pa_ext))
    realized = r_anchor + scale * (rext(np.minimum(x, p0_ext)) - r_anchor)
    realized = np.unwrap(realized)
    g_real = np.where(in_dwell, 0.0, scale * g)
    info = {
        "start_point": dw.start, "end_point": dw.end, "anchor_point": dw.anchor,
        "theta1": span, "carrier_start": float(p0), "carrier_end": float(p1),
        "planned_rel_rotation": delta, "ratio_scale": float(scale),
    }
    return realized, g_real, in_dwell, info
