"""How far an inverse design could be from the train its trajectory means (issue 34).

The inverse design interpolates the type-value points (``geometry.trajectory``) and reads the
carrier and arm angles off that curve; where the chain is nearly straight or folded (the
farthest and nearest points of the path) the carrier angle is very sensitive to the curve's
shape, so a few points can leave the pitch curves millimetres from those of the mechanism
that drew the path, while the round trip (which re-simulates the design's own interpolation)
still passes to a micrometre. The round trip cannot see this; a second reading of the same
points can.

The estimate: the same inverse design run on every other type-value point (the even and the
odd ones, two "halves"), each compared with the full design at equal absolute carrier angle
(the mechanism in the same position): the contact pitch radius of each gear and the tip
position. The largest difference over both halves and the turn is the estimate (mm). A
half has half the points, so its interpolation error is several times the full design's
(a cubic through points h apart errs as h^4 where the path is smooth, 16 times for 2 h): the
estimate is meant as a bound on the full design's own error, not as that error. Where it
exceeds the limit (``trajectory.error_estimate_limit_mm``), the span of carrier angle and the
type-value points around it are named: that is where to add points.

Not computed (said so, never counted as met or failed) when a half is infeasible (too few
points to draw the path at all) or the design has a toothless dwell (its point indices do
not survive the halving).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

TWO_PI = 2.0 * np.pi
#: default limit on the estimate (mm), ``trajectory.error_estimate_limit_mm``
DEFAULT_LIMIT_MM = 1.0


@dataclass
class InverseSolution:
    """What the estimate compares of one inverse design, at its n uniform carrier angles:
    the absolute carrier angle (rad, unwrapped, C0 + s psi), the tip (complex, mm), the
    contact pitch radius of each gear (mm, by name) and the carrier angle psi (deg, from
    the design's start) at each type-value point."""

    carrier: np.ndarray
    tip: np.ndarray
    radii: dict
    point_psi_deg: np.ndarray
    carrier_sense: int


def first_order_solution(res, carrier_sense: int) -> InverseSolution:
    """``objectives.planetary_inverse.FirstOrderResult`` (feasible) as a solution: the sun's
    and the planet's contact radii at each carrier sample (the sun's body angle s psi)."""
    n = len(res.psi)
    j = (carrier_sense * np.arange(n)) % n  # sun_radii[j] is the contact at psi_k
    inv = np.empty(n, dtype=int)
    inv[j] = np.arange(n)
    return InverseSolution(np.asarray(res.carrier, float), np.asarray(res.tip),
                           {"sun": res.sun_radii[inv], "planet": res.planet_radii[inv]},
                           np.asarray(res.point_carrier_angle_deg, float), carrier_sense)


def seeder_solution(res) -> InverseSolution:
    """``mechanisms.seeder_inverse.InverseResult`` (feasible, no dwell) as a solution: the
    radii of the sun, gears 2 and 3 and the planet at each carrier sample; the seeder's
    carrier turns clockwise."""
    return InverseSolution(np.asarray(res.carrier_abs, float),
                           res.tip[:, 0] + 1j * res.tip[:, 1],
                           {"sun": res.r1, "gear 2": res.r2, "gear 3": res.r3,
                            "planet": res.r4},
                           np.degrees(np.asarray(res.point_carrier_angle, float)), -1)


def _periodic_at(values: np.ndarray, psi: np.ndarray) -> np.ndarray:
    """The periodic cubic spline through ``values`` at uniform carrier angles 2 pi k / n,
    evaluated at ``psi`` (rad)."""
    from scipy.interpolate import CubicSpline

    n = len(values)
    x = TWO_PI * np.arange(n + 1) / n
    return CubicSpline(x, np.r_[values, values[:1]], bc_type="periodic")(np.mod(psi, TWO_PI))


def compare(full: InverseSolution, other: InverseSolution) -> dict:
    """Distances of ``other`` from ``full`` at each of full's carrier samples, at equal
    absolute carrier angle: {"tip": (n,), gear name: (n,)} in mm."""
    s = full.carrier_sense
    # other's psi where its carrier line lies as full's does at psi_k
    psi_other = s * (full.carrier - other.carrier[0])
    out = {"tip": np.abs(full.tip - (_periodic_at(other.tip.real, psi_other)
                                     + 1j * _periodic_at(other.tip.imag, psi_other)))}
    for name, r in full.radii.items():
        out[name] = np.abs(r - _periodic_at(other.radii[name], psi_other))
    return out


def _bracketing_points(point_psi_deg: np.ndarray, lo: float, hi: float) -> tuple[int, int]:
    """The type-value points just before carrier angle ``lo`` and just after ``hi`` (deg,
    both in [0, 360), the span lo -> hi in the carrier's sense)."""
    p = np.mod(point_psi_deg, 360.0)
    before = np.where(p <= lo + 1e-9, lo - p, lo - p + 360.0)
    after = np.where(p >= hi - 1e-9, p - hi, p - hi + 360.0)
    return int(np.argmin(before)), int(np.argmin(after))


def _spans(excess: np.ndarray, every: np.ndarray, psi_deg: np.ndarray,
           point_psi_deg: np.ndarray) -> list[dict]:
    """The runs of ``excess`` as spans of carrier angle and the type-value points around
    them, the largest distance first."""
    from plantmech.geometry.periodic import cyclic_runs

    out = []
    for a, b in cyclic_runs(excess):
        idx = np.arange(a, a + (b - a) % len(every) + 1) % len(every)
        lo, hi = float(psi_deg[a]), float(psi_deg[b])
        i, j = _bracketing_points(point_psi_deg, lo, hi)
        out.append({"points": [i, j], "carrier_angle_deg": [round(lo, 2), round(hi, 2)],
                    "largest_mm": float(every[idx].max())})
    return sorted(out, key=lambda s: -s["largest_mm"])


def error_estimate(points, full: InverseSolution,
                   solve: Callable[[np.ndarray], InverseSolution | str],
                   limit_mm: float = DEFAULT_LIMIT_MM) -> dict:
    """The every-other-point estimate of an inverse design ``full`` made from ``points``
    (N x 2): ``solve(points)`` runs the same inverse design on other points and gives its
    solution or a string (why it is infeasible). Returns {computed, reason (when not),
    limit_mm, pitch_radius_mm {gear: mm}, tip_mm, largest (gear), worst_carrier_angle_deg,
    spans (where any distance exceeds the limit, else where the largest is: points and
    carrier angles), halves (per half: its points and its largest distance)}."""
    pts = np.asarray(points, dtype=float)
    out: dict = {"computed": False, "limit_mm": float(limit_mm),
                 "method": "the same inverse design on the even and on the odd type-value "
                 "points, compared at equal carrier angle"}
    worst: dict | None = None
    halves = []
    for h, label in ((0, "even"), (1, "odd")):
        sub = pts[h::2]
        got = solve(sub) if len(sub) >= 4 else f"{len(sub)} points are too few for a curve"
        if isinstance(got, str):
            out["reason"] = (f"the design through the {label} type-value points alone "
                             f"({len(sub)} of {len(pts)}, numbered within that half) is "
                             f"infeasible: {got}")
            return out
        d = compare(full, got)
        halves.append({"points": label, "largest_mm": float(max(v.max() for v in d.values()))})
        worst = d if worst is None else {k: np.maximum(worst[k], v) for k, v in d.items()}
    n = len(full.carrier)
    psi_deg = 360.0 * np.arange(n) / n
    radii = {k: float(v.max()) for k, v in worst.items() if k != "tip"}
    largest = max(worst, key=lambda k: worst[k].max())
    every = np.max(np.stack(list(worst.values())), axis=0)
    excess = every > limit_mm
    if not excess.any():
        excess = every >= every.max()
    at = float(psi_deg[int(np.argmax(every))])
    out.update(computed=True, pitch_radius_mm=radii, tip_mm=float(worst["tip"].max()),
               largest=largest, worst_carrier_angle_deg=round(at, 2),
               worst_points=list(_bracketing_points(full.point_psi_deg, at, at)),
               spans=_spans(excess, every, psi_deg, full.point_psi_deg), halves=halves)
    return out


def estimate_rows(est: dict) -> list[dict]:
    """The checks of a computed estimate (none when it was not computed): the largest pitch
    radius distance and the tip distance, each against the limit, the note naming the gear
    and the spans where to add points."""
    if not est.get("computed"):
        return []
    lim = est["limit_mm"]
    spans = est["spans"]
    where = "; ".join(f"q{s['points'][0]}-q{s['points'][1]} (carrier angle "
                      f"{s['carrier_angle_deg'][0]:.1f}-{s['carrier_angle_deg'][1]:.1f} deg, "
                      f"up to {s['largest_mm']:.3g} mm)" for s in spans[:3])
    if len(spans) > 3:
        where += f" and {len(spans) - 3} more spans"
    gear = max(est["pitch_radius_mm"], key=est["pitch_radius_mm"].get)
    rows = []
    for name, value, what in (
            ("error_estimate_pitch_radius_mm", est["pitch_radius_mm"][gear],
             f"the {gear}'s pitch radius"),
            ("error_estimate_tip_mm", est["tip_mm"], "the tip at equal carrier angle")):
        ok = bool(value <= lim)
        note = (f"{what} moves by up to {value:.4g} mm when the design is made from every "
                "other type-value point (a bound on how far the design may be from the "
                "mechanism that drew the path)")
        if not ok:
            note += f"; add type-value points at {where}"
        rows.append({"name": name, "value": round(float(value), 6), "unit": "mm",
                     "limit": f"<= {lim:g} mm", "ok": ok, "note": note})
    return rows


def estimate_line(est: dict) -> str:
    """One line for the terminal."""
    if not est.get("computed"):
        return f"  error estimate not computed: {est.get('reason', '')}"
    r = est["pitch_radius_mm"]
    gear = max(r, key=r.get)
    i, j = est["worst_points"]
    return (f"  error estimate (every other point): pitch radius {r[gear]:.4g} mm ({gear}), "
            f"tip {est['tip_mm']:.4g} mm (limit {est['limit_mm']:g} mm); largest at carrier "
            f"angle {est['worst_carrier_angle_deg']:.1f} deg, between q{i} and q{j}")


__all__ = ["DEFAULT_LIMIT_MM", "InverseSolution", "compare", "error_estimate",
           "estimate_line", "estimate_rows", "first_order_solution", "seeder_solution"]


def first_order_estimate(points, res, arm: str, kind: str, carrier_sense: int, samples: int,
                         limit_mm: float = DEFAULT_LIMIT_MM) -> dict:
    """The estimate of a feasible first-order inverse design ``res``
    (``objectives.planetary_inverse.first_order_inverse`` of ``points`` with the other
    arguments)."""
    from plantmech.geometry.trajectory import ClosedTrajectory, TrajectoryError
    from plantmech.objectives.planetary_inverse import first_order_inverse

    def solve(sub):
        try:
            r = first_order_inverse(ClosedTrajectory.through(sub), arm, kind, carrier_sense,
                                    samples)
        except TrajectoryError as exc:
            return str(exc)
        if r.feasible and abs(r.follower_turns - res.follower_turns) > 1e-6:
            return f"its planet turns {r.follower_turns:.6f} times per sun turn"
        return first_order_solution(r, carrier_sense) if r.feasible else "; ".join(r.reasons)

    return error_estimate(points, first_order_solution(res, carrier_sense), solve, limit_mm)


def seeder_estimate(points, settings, res, limit_mm: float = DEFAULT_LIMIT_MM) -> dict:
    """The estimate of a feasible seeder (second-order) inverse design ``res``
    (``mechanisms.seeder_inverse.inverse_design`` of ``points`` with ``settings``). Not
    computed with a toothless dwell: its start, end and anchor are type-value points that
    a half does not all keep."""
    from dataclasses import replace

    from plantmech.geometry.trajectory import ClosedTrajectory, TrajectoryError
    from plantmech.mechanisms.seeder_inverse import inverse_design

    if settings.dwell is not None:
        return {"computed": False, "limit_mm": float(limit_mm),
                "reason": "the toothless dwell is given by type-value points, which the "
                "every-other-point designs do not all keep"}

    def solve(sub):
        try:
            r = inverse_design(ClosedTrajectory.through(sub), replace(settings))
        except TrajectoryError as exc:
            return str(exc)
        if not r.feasible:
            return "; ".join(f"[{d.kind}] {d.message}" for d in r.diagnostics
                             if d.severity == "error")
        return seeder_solution(r)

    return error_estimate(points, seeder_solution(res), solve, limit_mm)


__all__ += ["first_order_estimate", "seeder_estimate"]
