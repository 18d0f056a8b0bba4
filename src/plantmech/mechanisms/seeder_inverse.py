"""Trajectory-driven inverse design of the second-order non-circular planetary
seeding mechanism (seed 000, sections 3.2-3.3).

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
from scipy.optimize import minimize_scalar

from plantmech.gears.pitch import (
    cumulative_trapezoid_periodic,
    radii_from_speed_ratio,
    toothless_sector_follower_angle,
)
from plantmech.geometry.periodic import cyclic_runs, periodic_spline_node_slopes
from plantmech.geometry.trajectory import ClosedTrajectory
from plantmech.geometry.trajectory_batch import row_searchsorted
from plantmech.mechanisms.three_bar import tip_position

TWO_PI = 2.0 * np.pi
ILLINOIS_ITERATIONS = 30


@dataclass
class Diagnostic:
    """One finding of the inverse design: where and why."""

    kind: str
    message: str
    between_points: list[int] | None = None
    carrier_angle_deg: list[float] | None = None
    severity: str = "error"  # "error" makes the design infeasible; "warning" does not

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


def _extreme_radii(traj: ClosedTrajectory) -> tuple[tuple[float, float], tuple[float, float]]:
    """((u, rho) of the farthest, (u, rho) of the nearest) trajectory point to O.

    A fitted trajectory goes through the population code's ``extreme_radii`` (samples,
    then Newton on d(rho^2)/du = 0: one implementation for both, exact to 1e-9 mm of
    parameter). Any other curve object (e.g. an analytic test curve without derivatives)
    is searched on rho alone, which resolves the place only to ~1e-6 (rho is flat there).
    """
    if isinstance(traj, ClosedTrajectory):
        from plantmech.mechanisms.seeder_inverse_batch import extreme_radii

        return tuple((float(u[0]), float(rho[0])) for u, rho in extreme_radii(traj.batch))
    u = np.linspace(0.0, traj.period, 256 * len(traj.points), endpoint=False)
    rho = np.hypot(*traj(u).T)
    h = u[1] - u[0]
    out = []
    for sign in (-1.0, 1.0):  # farthest, then nearest
        k = int(np.argmin(sign * rho))
        res = minimize_scalar(lambda t, s=sign: s * float(np.hypot(*traj(t))),
                              bounds=(u[k] - h, u[k] + h), method="bounded",
                              options={"xatol": 1e-10})
        out.append((float(np.mod(res.x, traj.period)), float(np.hypot(*traj(res.x)))))
    return tuple(out)


def _carrier_geometry(traj, u, L1, L2, u_min, u_max):
    """The parts of the carrier direction both assembly branches share at parameters u:
    (tip xy, its polar angle beta_3, the unsigned angle beta_1 at O between the carrier
    and the tip (Eq. 2-3), whether u lies on the arc from u_min to u_max)."""
    xy = traj(u)
    rho = np.hypot(xy[:, 0], xy[:, 1])
    beta3 = np.arctan2(xy[:, 1], xy[:, 0])
    cos_b1 = np.clip((L1**2 + rho**2 - L2**2) / (2 * L1 * rho), -1.0, 1.0)
    period = traj.period
    on_inner = np.mod(u - u_min, period) < np.mod(u_max - u_min, period)
    return xy, beta3, np.arctan2(np.sqrt(np.clip(1.0 - cos_b1**2, 0.0, None)), cos_b1), \
        on_inner


def _carrier_direction(traj, u, L1, L2, u_min, u_max, sigma_inner, geometry=None):
    """Absolute carrier angle phi_1 = beta_3 + sigma*beta_1 (Eq. 2-3), and the tip xy.

    sigma switches sign where the curve touches rho = L1+L2 and rho = L2-L1
    (beta_1 = 0 and pi): it is ``sigma_inner`` on the arc from u_min to u_max
    (in traversal order) and its opposite on the other arc. ``geometry``: the
    ``_carrier_geometry`` at u when already known (atan2 is odd in its first argument,
    so the sign may multiply beta_1).
    """
    xy, beta3, beta1, on_inner = geometry or _carrier_geometry(traj, u, L1, L2, u_min, u_max)
    return beta3 + np.where(on_inner, sigma_inner, -sigma_inner) * beta1, xy


def dense_grid_size(samples: int, points: int) -> int:
    """Intervals of the dense parameter grid of the inverse design (4 per carrier
    sample, at least 64 per type-value span)."""
    return max(4 * samples, 64 * points)


def _on_run(values: np.ndarray, first: int, last: int) -> np.ndarray:
    """values[first..last] of a cyclic run (one that wraps past the end has last < first)."""
    n = len(values)
    return values[np.arange(first, first + (last - first) % n + 1) % n]


def invert_carrier(psi, u_dense, phi_dense, psi_dense, alive, carrier_at):
    """Curve parameters u (P, n) where the carrier has turned ``psi`` (n,) clockwise, by
    the Illinois method (modified regula falsi) on each bracket of the dense grids
    (P, m + 1), all rows and samples at once; psi is smooth and monotonic there.
    ``carrier_at(u)``: absolute carrier angle (wrapped) at u (P, n); ``alive`` (P,): the
    rows whose convergence counts. Returns (u, the dense carrier angle at each bracket's
    start, which unwraps it). Shared by the single-design (P = 1) and population codes."""
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


def wrap_angle(a):
    """Angle(s) wrapped to [-pi, pi] (np.angle(exp(1j a)) without the complex numbers)."""
    return a - TWO_PI * np.round(a / TWO_PI)


def _bracket_points(traj: ClosedTrajectory, u0: float, u1: float) -> list[int]:
    """Type-value points enclosing the parameter span u0..u1 (traversal order)."""
    n = len(traj.points)
    i0 = int(np.floor(traj.point_index_of(u0))) % n
    i1 = int(np.ceil(traj.point_index_of(u1))) % n
    return [i0, i1]


def inverse_design(traj: ClosedTrajectory, settings: InverseSettings,
                   fused: bool = True) -> InverseResult:
    """Run the full inverse design; never raises for an infeasible trajectory.

    ``fused``: the carrier direction on the dense grid and the Illinois inversion run in
    the numba kernels of ``seeder_inverse_kernel`` (a ``ClosedTrajectory`` only; any
    other curve object, or ``fused=False``, takes the NumPy path, the same model, kept
    as the kernels' reference in the tests)."""
    diags: list[Diagnostic] = []
    n = int(settings.samples)
    (u_max, rho_max), (u_min, rho_min) = _extreme_radii(traj)
    L1 = 0.5 * (rho_max - rho_min)
    L2 = 0.5 * (rho_max + rho_min)
    res = InverseResult(feasible=False, diagnostics=diags, L1=L1, L2=L2, u_start=u_max)
    if rho_min < 1e-6 or L1 < 1e-6:
        diags.append(Diagnostic("degenerate", "trajectory passes through the rotation centre "
                                "or has constant radius; no carrier length follows (Eq. 1)"))
        return res

    a1 = settings.a1 if settings.a1 is not None else 0.5 * L1
    a2 = settings.a2 if settings.a2 is not None else 0.5 * L1
    res.a1, res.a2 = a1, a2
    if a1 <= 0 or a2 <= 0 or a1 + a2 < L1 - 1e-9 or abs(a1 - a2) > L1:
        diags.append(Diagnostic(
            "centre_distance",
            f"centre distances a1={a1:.3f} mm and a2={a2:.3f} mm cannot place the planet at "
            f"the carrier length L1={L1:.3f} mm (need |a1-a2| <= L1 <= a1+a2)",
        ))
        return res
    cos_off = np.clip((a1**2 + L1**2 - a2**2) / (2 * a1 * L1), -1.0, 1.0)
    res.shaft_offset = float(np.arccos(cos_off))

    # Dense parameter grid starting at the initial position (farthest point): it picks
    # the assembly branch, finds where the carrier would turn back and brackets the
    # inversion below (whose result does not depend on it).
    m = dense_grid_size(n, len(traj.points))
    u_dense = u_max + np.linspace(0.0, traj.period, m + 1)
    best = None
    fused = fused and isinstance(traj, ClosedTrajectory)
    if fused:  # the numba kernels on the spline's own pieces (seeder_inverse_kernel)
        from plantmech.mechanisms import seeder_inverse_kernel as kernel

        spline = (np.ascontiguousarray(traj.spline.c), np.ascontiguousarray(traj.knots),
                  traj.period)
        branches = kernel.dense_carrier(*spline, u_dense, L1, L2, u_min, u_max)
    else:
        shared = _carrier_geometry(traj, u_dense, L1, L2, u_min, u_max)
    for row, sigma_inner in enumerate((1.0, -1.0)):
        if fused:
            phi = branches[row]
        else:
            phi, _ = _carrier_direction(traj, u_dense, L1, L2, u_min, u_max, sigma_inner,
                                        shared)
            phi = np.unwrap(phi)
        if abs((phi[-1] - phi[0]) + TWO_PI) < 1e-3:  # clockwise, one revolution
            best = (sigma_inner, phi)
    if best is None:
        diags.append(Diagnostic(
            "carrier_turn",
            "no assembly branch turns the carrier clockwise through exactly one revolution "
            "per cycle; traverse the type-value points in the other order or move the "
            "trajectory so that the rotation centre lies outside it",
        ))
        return res
    sigma_inner, phi_dense = best
    psi_dense = phi_dense[0] - phi_dense  # clockwise carrier rotation
    backwards = np.diff(psi_dense) <= 0
    if backwards.any():
        for s, e in cyclic_runs(backwards):
            diags.append(Diagnostic(
                "carrier_not_monotonic",
                "the carrier would have to turn back (counter-clockwise) here: the planned "
                "tip cannot be reached by a uniformly turning carrier",
                _bracket_points(traj, u_dense[s], u_dense[e + 1]),
                [float(np.degrees(psi_dense[s])), float(np.degrees(psi_dense[e + 1]))],
            ))
        return res

    # Tip samples at uniform carrier angle
    psi = np.linspace(0.0, TWO_PI, n, endpoint=False)
    if fused:
        u, phi, tip = kernel.invert_carrier(psi, u_dense, phi_dense, psi_dense, *spline, L1,
                                            L2, u_min, u_max, sigma_inner)
    else:
        u, phi_k = invert_carrier(
            psi, u_dense[None], phi_dense[None], psi_dense[None], np.ones(1, bool),
            lambda x: _carrier_direction(traj, x[0], L1, L2, u_min, u_max,
                                         sigma_inner)[0][None])
        u, phi_k = u[0], phi_k[0]
        phi, tip = _carrier_direction(traj, u, L1, L2, u_min, u_max, sigma_inner)
        phi = phi_k + wrap_angle(phi - phi_k)
    elbow = L1 * np.c_[np.cos(phi), np.sin(phi)]
    arm = np.unwrap(np.arctan2(tip[:, 1] - elbow[:, 1], tip[:, 0] - elbow[:, 0]))
    planet_rel = arm - phi
    planet_rel = planet_rel - planet_rel[0]
    net_arm = float(arm[-1] - arm[0] + wrap_angle(arm[0] - arm[-1]))
    res.carrier_angle, res.u, res.tip = psi, np.mod(u, traj.period), tip
    res.carrier_abs, res.arm_angle, res.planet_rel = phi, arm, planet_rel
    # carrier angle at each type-value point: exact, unwrapped by the dense grid
    u_pts = traj.knots[:-1]
    j = np.clip(np.floor(np.mod(u_pts - u_max, traj.period) / traj.period * m).astype(int),
                0, m - 1)
    phi_pts, _ = _carrier_direction(traj, u_pts, L1, L2, u_min, u_max, sigma_inner)
    res.point_carrier_angle = phi_dense[0] - (phi_dense[j] + wrap_angle(phi_pts - phi_dense[j]))
    if abs(net_arm) > 1e-3:
        diags.append(Diagnostic(
            "planet_turn",
            f"the arm turns {np.degrees(net_arm):.1f} deg per cycle in the fixed frame; this "
            "train needs a swinging arm (net 0 deg), i.e. one planet turn per carrier turn",
        ))
        return res

    # Planned total ratio g = d psi_4 / d psi from a periodic spline of psi_4 - psi.
    step = TWO_PI / n
    drift = planet_rel - psi
    g = periodic_spline_node_slopes(drift, step) + 1.0
    # the same spline between samples is needed only around a dwell (its edges)
    spl = (CubicSpline(np.r_[psi, TWO_PI], np.r_[drift, drift[0]], bc_type="periodic")
           if settings.dwell is not None else None)

    in_dwell = np.zeros(n, dtype=bool)
    realized_rel = planet_rel.copy()
    g_real = g.copy()
    if settings.dwell is not None:
        realized_rel, g_real, in_dwell, res.dwell = _apply_dwell(
            settings.dwell, psi, planet_rel, g, res.point_carrier_angle)
        if res.dwell is None:
            diags.append(Diagnostic("dwell", "the dwell anchor point lies inside the dwell",
                                    [settings.dwell.start, settings.dwell.end]))
            return res
    # Feasibility of the ratio law outside the dwell.
    bad = (g_real <= 0) & ~in_dwell
    for s, e in cyclic_runs(bad):
        i0 = int(np.floor(traj.point_index_of(u[s]))) % len(traj.points)
        i1 = int(np.ceil(traj.point_index_of(u[e]))) % len(traj.points)
        diags.append(Diagnostic(
            "ratio_not_positive",
            "the planet would have to stop or turn back relative to the carrier "
            f"(d psi4/d psi reaches {_on_run(g_real, s, e).min():.3f}): a gear pair cannot give a "
            "zero or negative speed ratio, pitch radius would be <= 0",
            [i0, i1],
            [float(np.degrees(psi[s])), float(np.degrees(psi[e]))],
        ))
    res.total_ratio = g_real
    if bad.any():
        return res

    # Ratio split (Eq. 7-8): stage 1 takes (total)^p, normalised so gear 2 closes.
    p = settings.split_exponent
    shape = np.where(in_dwell, 0.0, g_real ** p)
    scale = 1.0
    if res.dwell is None:
        def integral(values, fn):
            return cumulative_trapezoid_periodic(values, step, smooth=True)
    else:
        # The laws jump at the dwell ends, which fall between samples: integrate the
        # smooth law on the meshing arc only, with the arc ends as nodes.
        arc0 = res.dwell["carrier_end"]
        arc_len = TWO_PI - res.dwell["theta1"]
        scale = res.dwell["ratio_scale"]

        def integral(values, fn):
            return _integrate_on_arc(fn, psi, arc0, arc_len)

    def g_at(x):
        # the law is positive at every sample (checked above); between samples a spline
        # can dip, which a fractional power must not see
        return np.maximum(scale * (spl(np.mod(x, TWO_PI), 1) + 1.0), 1e-12)

    c = TWO_PI / integral(shape, lambda x: g_at(x) ** p)[-1]
    h = c * shape  # d psi_2 / d psi = 1 / i_1
    q = np.where(in_dwell, 0.0, g_real ** (1 - p) / c)  # 1 / i_2 (gears 3-4 idle in dwell)
    # Discrete closure: the tabulated laws are normalised so that both pairs close
    # under the same rule that integrates them back to angles.
    norm = TWO_PI / integral(h * q, g_at)[-1]
    q = q * norm
    gear2 = integral(h, lambda x: c * g_at(x) ** p)
    planet_train = integral(h * q, lambda x: norm * g_at(x))
    if res.dwell is not None:
        # exact pitch radii where meshing restarts (dwell end) and stops (dwell start)
        edges = {}
        for key, x in (("meshing_start", arc0), ("meshing_end", arc0 + arc_len)):
            gx = float(g_at(x))
            e_r1, e_r2 = radii_from_speed_ratio(a1, c * gx**p)
            e_r3, e_r4 = radii_from_speed_ratio(a2, gx ** (1 - p) / c * norm)
            edges[key] = {"r1": float(e_r1), "r2": float(e_r2), "r3": float(e_r3),
                          "r4": float(e_r4)}
        res.dwell["edge_pitch_radii"] = edges
    r1, r2 = radii_from_speed_ratio(a1, h)
    r3, r4 = radii_from_speed_ratio(a2, q)
    res.stage1_ratio, res.stage2_ratio, res.gear2_angle = h, q, gear2[:-1]
    for r in (r1, r2, r3, r4):
        r[in_dwell] = np.nan  # no rolling contact while the sun's toothless sector passes
    res.r1, res.r2, res.r3, res.r4 = r1, r2, r3, r4
    res.closure_error = {
        "stage1": float(abs(gear2[-1] - TWO_PI)),
        "stage2": float(abs(planet_train[-1] - gear2[-1])),
    }
    # The motion the train actually produces (integrated ratio law), anchored like the plan.
    train_rel = planet_train[:-1]
    anchor_k = 0
    if res.dwell is not None:
        anchor_k = int(np.argmin(np.abs(np.angle(np.exp(1j * (
            psi - res.point_carrier_angle[settings.dwell.anchor]))))))
    train_rel = train_rel - train_rel[anchor_k] + realized_rel[anchor_k]
    res.planet_rel_realized = train_rel
    arm_real = phi + train_rel + (arm[0] - phi[0])
    shift = TWO_PI * np.round((arm_real[anchor_k] - arm[anchor_k]) / TWO_PI)
    arm_real, train_rel = arm_real - shift, train_rel - shift
    res.arm_angle_realized = arm_real
    res.tip_realized = tip_position(L1, L2, phi, arm_real)
    for name, ok in (("stage1", res.closure_error["stage1"] < 1e-9),
                     ("stage2", res.closure_error["stage2"] < 1e-9)):
        if not ok:
            diags.append(Diagnostic("closure", f"pair {name} does not close: error "
                                    f"{res.closure_error[name]:.3e} rad"))
    # Pitch radius limits.
    for name, r, a, mask in (("r1 (sun)", r1, a1, ~in_dwell), ("r2", r2, a1, ~in_dwell),
                             ("r3", r3, a2, np.ones(n, bool)), ("r4 (planet)", r4, a2,
                                                                np.ones(n, bool))):
        small = mask & ~in_dwell & (r < settings.min_pitch_radius)
        for s, e in cyclic_runs(small):
            diags.append(Diagnostic(
                "pitch_radius",
                f"pitch radius {name} falls to {_on_run(r, s, e).min():.2f} mm, below the minimum "
                f"{settings.min_pitch_radius:g} mm (centre distance {a:.2f} mm)",
                _bracket_points(traj, u[s], u[e]),
                [float(np.degrees(psi[s])), float(np.degrees(psi[e]))],
            ))
    if res.dwell is not None:
        dw = settings.dwell
        edge = dw.edge_radius
        before = res.dwell["edge_pitch_radii"]["meshing_end"]["r1"]
        after = res.dwell["edge_pitch_radii"]["meshing_start"]["r1"]
        if edge is None:
            edge = 0.5 * (before + after)
        res.dwell["edge_radius"] = float(edge)
        res.dwell["sun_radius_at_ends"] = [float(before), float(after)]
        res.dwell["theta2"] = toothless_sector_follower_angle(res.dwell["theta1"], edge, a1)
    if res.dwell is not None:
        dev = np.hypot(*(res.tip_realized - res.tip).T)
        res.dwell["max_tip_deviation"] = float(dev.max())
        if dev.max() > 0.01:
            k = int(np.argmax(dev))
            rho = np.hypot(*traj.points[[settings.dwell.start, settings.dwell.end]].T)
            diags.append(Diagnostic(
                "dwell_not_arc",
                f"the planned section q{settings.dwell.start}-q{settings.dwell.end} is not an "
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
