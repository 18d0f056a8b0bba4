"""Closure of external non-circular gear pairs (seed 000 Eq. 8) and its restoration.

A pitch curve r(theta) (mm over its body angle, rad) rolls on a mate at centre
distance a with r_mate = a - r; while the curve turns once the mate turns

    T(a) = integral_0^2pi r / (a - r) dtheta        (rolling: d theta_mate = r / r_mate d theta).

The pair is closed when T equals the required turn (2 pi, or 2 pi - theta_1 for a sun
with a toothless sector of theta_1). When edited radii break this, one of three
documented restorations is applied (docs/conventions.md, "Closure of edited pitch
curves"); none is applied silently:

* ``centre_distance``: solve a (radii kept exactly as given);
* ``radial_offset``:  r -> r + c, a kept (every radius moves by the same c mm);
* ``scale``:          r -> s r, a kept (shape kept, size changes).

Each is a 1-D root of a monotone function, so the solution is unique.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from plantmech.geometry.periodic import RadiusCurve

TWO_PI = 2.0 * np.pi
METHODS = ("check", "centre_distance", "radial_offset", "scale")


class ClosureError(ValueError):
    """A gear pair does not close and cannot (or may not) be made to."""


def _samples(curve: RadiusCurve, dense: int) -> np.ndarray:
    t = curve.theta0 + np.linspace(0.0, TWO_PI, dense, endpoint=False)
    return curve(t)


def mate_turn(curve: RadiusCurve, a: float, dense: int = 8192) -> float:
    """T(a) (rad): turn of the mate while ``curve`` turns once (periodic rule, spectral
    accuracy for a smooth periodic integrand)."""
    r = _samples(curve, dense)
    if np.any(r >= a):
        return float("inf")
    return float(np.mean(r / (a - r)) * TWO_PI)


def solve_centre_distance(curve: RadiusCurve, turn: float = TWO_PI, dense: int = 8192) -> float:
    """Centre distance a (mm) at which the mate turns ``turn`` rad per turn of ``curve``.

    T(a) falls monotonically from +inf (a -> max r) to 0, so the root is unique.
    """
    return float(solve_centre_distances(_samples(curve, dense)[None, :], turn)[0])


def solve_centre_distances(r: np.ndarray, turn) -> np.ndarray:
    """Centre distance (P,) closing each design's pair: mean_k r_pk / (a_p - r_pk) * 2 pi
    = turn, for radii r (P, D) sampled uniformly over one turn. The left side is convex
    and decreasing in a, so Newton from a point left of the root converges monotonically;
    the start is kept inside the bracket (max r, root]."""
    r = np.atleast_2d(r)
    turn = np.broadcast_to(np.asarray(turn, dtype=float), (r.shape[0],))
    rmax = r.max(axis=1)
    # start: a point with f > 0 (left of the root), found by halving the gap to max r
    a = 2.0 * r.mean(axis=1)
    for _ in range(60):
        f = np.mean(r / (a[:, None] - r), axis=1) * TWO_PI - turn
        left = f > 0
        if left.all():
            break
        a = np.where(left, a, rmax + 0.5 * (a - rmax))
    for _ in range(100):
        q = 1.0 / (a[:, None] - r)
        f = np.mean(r * q, axis=1) * TWO_PI - turn
        df = -np.mean(r * q * q, axis=1) * TWO_PI
        step = -f / df
        a = a + step
        if np.all(np.abs(step) <= 1e-12 * a):
            break
    return a


def solve_radial_offset(curve: RadiusCurve, a: float, turn: float = TWO_PI,
                        dense: int = 8192) -> float:
    """Offset c (mm) with  integral (r + c) / (a - r - c) = turn  (monotone increasing in c)."""
    r = _samples(curve, dense)

    def excess(c):
        return float(np.mean((r + c) / (a - r - c)) * TWO_PI - turn)

    lo, hi = -float(r.min()) + 1e-9, a - float(r.max()) - 1e-9
    if hi <= lo:
        raise ClosureError("no radial offset keeps both the curve and its mate positive "
                           f"(radius range {np.ptp(r):.3f} mm >= centre distance {a:.3f} mm)")
    return float(brentq(excess, lo, hi, xtol=1e-13, rtol=1e-15))


def solve_scale(curve: RadiusCurve, a: float, turn: float = TWO_PI, dense: int = 8192) -> float:
    """Factor s with  integral s r / (a - s r) = turn  (monotone increasing in s)."""
    r = _samples(curve, dense)

    def excess(s):
        return float(np.mean(s * r / (a - s * r)) * TWO_PI - turn)

    return float(brentq(excess, 1e-9, a / float(r.max()) * (1 - 1e-12), xtol=1e-15,
                        rtol=1e-15))


@dataclass
class ClosureFix:
    """How one pair was closed (all fields at the boundary units: mm, deg)."""

    pair: str
    method: str
    required_turn_deg: float
    turn_as_given_deg: float
    centre_distance_mm: float  # after the fix
    centre_distance_given_mm: float
    radial_offset_mm: float = 0.0
    scale: float = 1.0
    residual_rad: float = 0.0

    def as_dict(self) -> dict:
        return dict(self.__dict__)


def close_pair(pair: str, theta, radii, a: float, turn: float, method: str,
               kind: str = "hermite", tolerance: float = np.radians(0.01),
               name: str = "gear") -> tuple[RadiusCurve, float, ClosureFix]:
    """Return (curve, centre distance, fix) with the pair closed by ``method``.

    ``check`` refuses an unclosed pair (ClosureError naming the pair, the turn it makes
    and what each restoration would change).
    """
    theta = np.asarray(theta, dtype=float)
    radii = np.asarray(radii, dtype=float)
    curve = RadiusCurve.from_samples(theta, radii, kind=kind, theta0=float(theta[0]), name=name)
    t_given = mate_turn(curve, a)
    fix = ClosureFix(pair, method, float(np.degrees(turn)), float(np.degrees(t_given)), a, a)
    if method not in METHODS:
        raise ClosureError(f"{pair}: unknown closure method {method!r} (expected one of "
                           f"{', '.join(METHODS)})")
    if method == "check":
        if not np.isfinite(t_given):
            raise ClosureError(f"{pair}: the mate's radius a - r is not positive everywhere "
                               f"(max r {_samples(curve, 4096).max():.3f} mm >= a = {a:.3f} mm)")
        if abs(t_given - turn) > tolerance:
            hint = [f"centre distance {solve_centre_distance(curve, turn):.3f} mm"]
            try:
                hint.append(f"radial offset {solve_radial_offset(curve, a, turn):+.3f} mm")
            except ClosureError:
                pass
            hint.append(f"scale {solve_scale(curve, a, turn):.5f}")
            raise ClosureError(
                f"{pair}: the pitch curves do not close: the mate turns "
                f"{np.degrees(t_given):.3f} deg per turn of {name} at a = {a:.3f} mm, "
                f"{np.degrees(turn):.3f} deg needed (Eq. 8). It would close with: "
                + "; ".join(hint) + ". Set train.closure to one of "
                "'centre_distance', 'radial_offset', 'scale' to restore it.")
        fix.residual_rad = float(abs(t_given - turn))
        return curve, a, fix
    if method == "centre_distance":
        a = solve_centre_distance(curve, turn)
        fix.centre_distance_mm = a
    elif method == "radial_offset":
        c = solve_radial_offset(curve, a, turn)
        curve = RadiusCurve.from_samples(theta, radii + c, kind=kind, theta0=float(theta[0]),
                                         name=name)
        fix.radial_offset_mm = c
    else:
        s = solve_scale(curve, a, turn)
        curve = RadiusCurve.from_samples(theta, radii * s, kind=kind, theta0=float(theta[0]),
                                         name=name)
        fix.scale = s
    fix.residual_rad = float(abs(mate_turn(curve, a) - turn))
    return curve, a, fix
