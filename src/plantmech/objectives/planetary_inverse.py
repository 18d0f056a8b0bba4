"""Inverse design of a first-order non-circular planetary train from a tip trajectory.

The train (docs/architecture.md, "Train model"): a fixed sun on O, one pair (sun ->
planet) whose planet axis the carrier holds at the centre distance a from O (the carrier
arm, seed 000's L1), and an arm of length L (the tip link, seed 000's L2) fixed on the
planet. It is the open two-link chain of ``mechanisms.three_bar`` (seed 000 Eq. 2-3, 12-16):

    tip Z = a e^{i C} + L e^{i beta}

with C the carrier line's absolute angle and beta the arm's. A closed trajectory through
type-value points (``geometry.trajectory.ClosedTrajectory``, the seeder's [trajectory]
points) fixes, at each curve parameter u, the carrier angle by the law of cosines

    C(u) = arg Z(u) + sigma arccos((a^2 + rho^2 - L^2) / (2 a rho)),  rho = |Z(u)|

(``branch`` sigma = +1 or -1: the elbow on the left or the right of O -> tip), and the arm
angle beta(u) = arg(Z - a e^{i C}). The carrier turns uniformly: C = C0 + s psi (s = -1
clockwise), so the trajectory must make the carrier turn once, monotonically (the rotation
centre inside the curve, traversed in the carrier's sense); the samples at uniform psi come
from inverting C(u) (dense table, then Newton with the analytic dC/du).

The planet's rate relative to the carrier is d alpha_p / d psi = d beta / d psi - s and the
fixed sun's is d alpha_s / d psi = (k - 1) s = -s; a pair turns its follower sense g times
its driver (``trains.pairs``: sense -1 external, +1 internal), so the ratio law is

    g(psi) = (d beta / d psi - s) / (-s sense)  > 0,

and the pitch radii follow from g = r_d / r_f with the pair's kind (seed 000 Eq. 9-10,
``gears.pitch.radii_from_speed_ratio`` for an external pair): r_d = a g / (1 + g)
(external), a g / (g - 1) (internal: the sun a ring), a g / (1 - g) (ring follower). With
the sun's phase set to C0 + its contact direction, the sun's contact body angle is
theta_d = s psi, so the sun's radii at the uniform carrier samples are its radii at uniform
body angles. The planet turns q = (net beta - 2 pi s) / (-2 pi s sense) times per sun turn
relative to the carrier; for a general trajectory only q = 1 closes the planet's own curve
(``trains.pairs.pair_law`` checks it when the written file is built).

Everything is in mm and radians inside; ``FirstOrderResult`` holds degrees where it says so.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from plantmech.geometry.trajectory import ClosedTrajectory

TWO_PI = 2.0 * np.pi
#: sense of a pair's follower relative to its driver (``trains.pairs``)
_SENSE = {"external": -1, "internal": 1, "internal_ring_follower": 1}


@dataclass
class FirstOrderResult:
    """The inverse design of a first-order train. ``feasible`` False: ``reasons`` say why
    (each naming the type-value points and carrier angles concerned) and the laws may be
    missing. Arrays at the uniform carrier angles ``psi`` (n,) rad."""

    feasible: bool
    reasons: list[str] = field(default_factory=list)
    psi: np.ndarray | None = None
    u: np.ndarray | None = None  # curve parameter at each psi (mm of chord)
    tip: np.ndarray | None = None  # (n,) complex, mm
    carrier: np.ndarray | None = None  # C (rad, absolute, unwrapped)
    arm: np.ndarray | None = None  # beta (rad, absolute, unwrapped)
    ratio: np.ndarray | None = None  # g = r_sun / r_planet
    sun_radii: np.ndarray | None = None  # r_d at sun body angle theta_k = 2 pi k / n (mm)
    planet_radii: np.ndarray | None = None  # r_f at the same contacts (mm)
    follower_turns: float | None = None  # q the trajectory asks for
    centre_distance: float | None = None  # a: carrier arm = the pair's centre distance (mm)
    arm_length: float | None = None  # L (mm)
    carrier0_deg: float | None = None
    arm0_deg: float | None = None
    sun_phase_deg: float | None = None
    point_carrier_angle_deg: np.ndarray | None = None  # psi at each type-value point


def _points_near(traj: ClosedTrajectory, u) -> str:
    """'between q_i and q_j' for curve parameter(s) u."""
    n = len(traj.points)
    idx = traj.point_index_of(np.atleast_1d(u))
    i0, i1 = int(np.floor(idx.min())) % n, int(np.ceil(idx.max())) % n
    return f"q{i0}" if i0 == i1 else f"between q{i0} and q{i1}"


def extreme_radii(traj: ClosedTrajectory) -> tuple[tuple[float, float], tuple[float, float]]:
    """((u, rho) of the farthest, (u, rho) of the nearest) trajectory point to O (mm):
    dense samples, then Newton on d(rho^2)/du = 0 with the spline's own derivatives."""
    u = np.linspace(0.0, traj.period, 256 * len(traj.points), endpoint=False)
    xy = traj(u)
    rho2 = (xy**2).sum(axis=1)
    out = []
    for k in (int(np.argmax(rho2)), int(np.argmin(rho2))):
        x = u[k]
        for _ in range(20):
            p, d1, d2 = traj(x), traj(x, 1), traj(x, 2)
            f, df = 2 * p @ d1, 2 * (d1 @ d1 + p @ d2)
            if df == 0:
                break
            x_new = float(np.clip(x - f / df, u[k] - 2 * (u[1] - u[0]), u[k] + 2 * (u[1] - u[0])))
            if abs(x_new - x) < 1e-13 * traj.period:
                x = x_new
                break
            x = x_new
        out.append((float(np.mod(x, traj.period)), float(np.hypot(*traj(x)))))
    return tuple(out)


def _carrier_angle(traj, u, a, L, u_min, u_max, sigma_inner):
    """(tip Z, absolute carrier angle C) at parameters u (wrapped C): C = arg Z + sigma
    arccos((a^2 + rho^2 - L^2) / (2 a rho)); sigma is ``sigma_inner`` on the arc from the
    nearest point to the farthest (traversal order) and its opposite on the other arc: the
    chain straightens (rho = L + a) and folds (rho = |L - a|) there, where the elbow
    changes side (seed 000 Eq. 2-3)."""
    xy = traj(u)
    Z = xy[..., 0] + 1j * xy[..., 1]
    rho = np.abs(Z)
    c = np.clip((a * a + rho * rho - L * L) / (2 * a * rho), -1.0, 1.0)
    period = traj.period
    inner = np.mod(u - u_min, period) < np.mod(u_max - u_min, period)
    return Z, np.angle(Z) + np.where(inner, sigma_inner, -sigma_inner) * np.arccos(c)


def first_order_inverse(traj: ClosedTrajectory, arm: str = "long", kind: str = "external",
                        carrier_sense: int = -1, samples: int = 3600) -> FirstOrderResult:
    """The ratio law and the sun's pitch radii of a first-order train (fixed sun, one pair
    of ``kind``, an arm on the planet) whose arm tip follows ``traj``, at ``samples``
    uniform carrier angles from the farthest point of the trajectory.

    The planet turns whole turns relative to the carrier, so the chain straightens and
    folds once each per cycle: the tip touches rho = L + a and rho = |L - a|, and the
    trajectory's farthest and nearest radii fix the lengths (seed 000 Eq. 1): ``arm``
    "long": L = (rho_max + rho_min) / 2, a = (rho_max - rho_min) / 2 (seed 000's carrier
    and arm); "short": the two exchanged. Never raises for an infeasible trajectory: the
    result says why (``reasons``)."""
    from plantmech.geometry.periodic import periodic_spline_node_slopes

    s, n = int(carrier_sense), int(samples)
    res = FirstOrderResult(False)
    sense_word = "clockwise" if s < 0 else "counter-clockwise"
    (u_max, rho_max), (u_min, rho_min) = extreme_radii(traj)
    half_sum, half_diff = 0.5 * (rho_max + rho_min), 0.5 * (rho_max - rho_min)
    L, a = (half_sum, half_diff) if arm == "long" else (half_diff, half_sum)
    res.centre_distance, res.arm_length = a, L
    if half_diff < 1e-6 * rho_max:
        res.reasons.append("the trajectory keeps one distance from the carrier axis: no "
                           "carrier arm follows from its extreme radii (seed 000 Eq. 1)")
        return res
    m = max(8 * n, 64 * len(traj.points))
    u_dense = u_max + np.linspace(0.0, traj.period, m + 1)
    best = None
    for sigma in (1.0, -1.0):
        _, C = _carrier_angle(traj, u_dense, a, L, u_min, u_max, sigma)
        C = np.unwrap(C)
        if abs(s * (C[-1] - C[0]) - TWO_PI) < 1e-3:
            best = (sigma, C)
    if best is None:
        res.reasons.append(
            f"on neither assembly branch does the carrier turn once {sense_word} per cycle "
            f"(carrier arm {a:.3f} mm, arm {L:.3f} mm): traverse the type-value points the "
            "other way round, or move the trajectory")
        return res
    sigma, C = best
    psi_dense = s * (C - C[0])
    back = np.diff(psi_dense) <= 0
    if back.any():
        k = int(np.argmax(back))
        res.reasons.append(
            f"the carrier would have to stop or turn back {_points_near(traj, u_dense[k])} "
            f"(carrier angle {np.degrees(psi_dense[k]):.1f} deg): a uniformly turning "
            "carrier cannot follow this trajectory")
        return res
    # u at uniform psi: the Illinois method on the dense table's brackets
    psi = TWO_PI * np.arange(n) / n
    k = np.clip(np.searchsorted(psi_dense, psi, side="right") - 1, 0, m - 1)
    lo, hi = u_dense[k], u_dense[k + 1]
    f_lo, f_hi = psi_dense[k] - psi, psi_dense[k + 1] - psi
    C_k = C[k]

    def psi_at(u):
        _, c = _carrier_angle(traj, u, a, L, u_min, u_max, sigma)
        return s * (C_k + np.angle(np.exp(1j * (c - C_k))) - C[0])

    side = np.zeros(n)
    u = lo
    for _ in range(60):
        den = f_hi - f_lo
        u = np.where(den > 0, lo - f_lo * (hi - lo) / np.where(den > 0, den, 1.0),
                     0.5 * (lo + hi))
        f = psi_at(u) - psi
        right = f > 0
        hi, lo = np.where(right, u, hi), np.where(right, lo, u)
        f_lo = np.where(right, np.where(side > 0, 0.5 * f_lo, f_lo), f)
        f_hi = np.where(right, f, np.where(side < 0, 0.5 * f_hi, f_hi))
        side = np.where(right, 1.0, -1.0)
        if np.abs(f).max() < 1e-12:
            break
    Z, c_u = _carrier_angle(traj, u, a, L, u_min, u_max, sigma)
    carrier = C[0] + s * psi + np.angle(np.exp(1j * (c_u - C[0] - s * psi)))
    arm_angle = np.unwrap(np.angle(Z - a * np.exp(1j * carrier)))
    relative = arm_angle - carrier  # the planet's body angle relative to the carrier
    net = relative[-1] - relative[0] + np.angle(np.exp(1j * (relative[0] - relative[-1])))
    sense = _SENSE[kind]
    q = net / (-TWO_PI * s * sense)  # planet turns per sun turn, both relative to the carrier
    drift = relative - (net / TWO_PI) * psi  # periodic part of the planet's relative angle
    rate = periodic_spline_node_slopes(drift, TWO_PI / n) + net / TWO_PI  # d alpha_p / d psi
    g = rate / (-s * sense)
    res.psi, res.u, res.tip, res.carrier, res.arm = (psi, np.mod(u, traj.period), Z, carrier,
                                                     arm_angle)
    res.ratio, res.follower_turns = g, float(q)
    res.carrier0_deg = float(np.degrees(carrier[0]))
    res.arm0_deg = float(np.degrees(arm_angle[0]))
    j_pts = np.searchsorted(u_dense, u_max + np.mod(traj.knots[:-1] - u_max, traj.period))
    res.point_carrier_angle_deg = np.degrees(psi_dense[np.clip(j_pts, 0, m)])
    if not g.min() > 0:
        from plantmech.geometry.refine import minimum_between, periodic_law

        k = int(np.argmin(g))
        spline = periodic_law(drift)
        step = TWO_PI / n
        x_min, g_min = minimum_between(
            lambda x: (spline(x, 1) + net / TWO_PI) / (-s * sense), psi[k] - step,
            psi[k] + step)  # between the samples (geometry.refine)
        res.reasons.append(
            f"the planet would have to stop or turn the other way relative to the carrier "
            f"{_points_near(traj, u[k])} (carrier angle "
            f"{np.degrees(np.mod(x_min, TWO_PI)):.2f} deg; the "
            f"{kind} pair's ratio law reaches {g_min:.4f}, the planet turning {q:.3f} times "
            "per sun turn): no one pair rolls this law (an external pair turns the planet "
            "against the sun, an internal one with it); a swinging arm needs a second-order "
            "train (seed 000)")
        return res
    if kind == "internal" and not g.min() > 1:
        k = int(np.argmin(g))
        res.reasons.append(f"an internal pair (the sun a ring) needs a ratio above 1 (the "
                           f"planet faster than the ring); the law falls to {g[k]:.4f} at "
                           f"carrier angle {np.degrees(psi[k]):.1f} deg")
        return res
    if kind == "internal_ring_follower" and not g.max() < 1:
        k = int(np.argmax(g))
        res.reasons.append(f"a ring planet turns slower than the sun: the ratio must stay "
                           f"below 1; the law reaches {g[k]:.4f} at carrier angle "
                           f"{np.degrees(psi[k]):.1f} deg")
        return res
    kappa, c = {"external": (-1.0, 1.0), "internal": (1.0, -1.0),
                "internal_ring_follower": (1.0, 1.0)}[kind]
    r_d = c * a * g / (1.0 - kappa * g)  # g = r_d / (kappa r_d + c a)
    r_f = kappa * r_d + c * a
    # sun's contact body angle theta_d = s psi: radii at theta_k = 2 pi k / n
    j = (s * np.arange(n)) % n
    res.sun_radii, res.planet_radii = r_d[j], r_f[j]
    eps_d = np.pi if kind == "internal_ring_follower" else 0.0
    res.sun_phase_deg = float(np.degrees(carrier[0] + eps_d))
    res.feasible = True
    return res


def forward_deviation(traj: ClosedTrajectory, motion) -> dict:
    """How far the forward motion's tip (arm 1 of design 0, ``trains.model.TrainMotion``)
    passes from each type-value point (mm) and from the trajectory at the same carrier
    samples: {point_deviation_mm (per point), max_point_deviation_mm}."""
    tip = motion.tip[0, 0]
    pts = traj.points[:, 0] + 1j * traj.points[:, 1]
    # nearest distance from each point to the densely sampled closed tip polyline
    a, b = tip, np.roll(tip, -1)
    d = b - a
    t = np.clip(((pts[:, None] - a[None]) * d.conjugate()[None]).real
                / np.maximum(np.abs(d) ** 2, 1e-300)[None], 0.0, 1.0)
    dist = np.abs(pts[:, None] - (a[None] + t * d[None])).min(axis=1)
    return {"point_deviation_mm": dist, "max_point_deviation_mm": float(dist.max())}


__all__ = ["FirstOrderResult", "extreme_radii", "first_order_inverse", "forward_deviation"]


def control_radii_count(samples: int, most: int = 900) -> int:
    """Control radii written for the sun's curve: the largest divisor of ``samples`` not
    above ``most`` (every (samples / count)-th sample of the law)."""
    return max(k for k in range(4, min(most, samples) + 1) if samples % k == 0)


def first_order_design(design, result: FirstOrderResult):
    """The planetary design file (a validated ``PlanetaryDesign``) of a feasible first-order
    inverse design: ``design`` with the sun's pitch curve (``family = "radii"``, periodic
    spline through ``control_radii_count`` radii at uniform body angles), the pair's
    centre distance and follower turns, the arm's length, the carrier's and the arm's start
    angles filled in; its [trajectory]
    kept as the record of the plan."""
    n = len(result.sun_radii)
    K = control_radii_count(n)
    data = design.model_dump(exclude_none=True)
    pair = data["train"]["pairs"][0]
    pair.pop("follower", None)
    pair["driver"] = {"family": "radii",
                      "radii_mm": [float(r) for r in result.sun_radii[:: n // K]],
                      "interpolation": "spline",
                      "phase_deg": float(np.round(result.sun_phase_deg, 12))}
    pair["follower_turns"] = float(np.round(result.follower_turns, 9))
    pair["direction_deg"] = 0.0
    pair["centre_distance_mm"] = float(result.centre_distance)
    data["arm"]["length_mm"] = float(result.arm_length)
    data["carrier"]["initial_angle_deg"] = result.carrier0_deg
    data["arm"]["initial_angle_deg"] = result.arm0_deg
    data["train"]["sun_speed_ratio"] = 0.0
    if not data["name"].endswith("(inverse design)"):
        data["name"] = f"{data['name']} (inverse design)"
    return type(design).model_validate(data)


__all__ += ["control_radii_count", "first_order_design"]


#: largest distance (mm) the forward motion of the written design may pass from a
#: type-value point (the round trip of ``run_first_order``).
ROUND_TRIP_TOLERANCE_MM = 0.01


class InverseInputError(ValueError):
    """A planetary [trajectory] file the first-order inverse design cannot take (the
    message starts with the field)."""


def check_first_order_input(design) -> None:
    """InverseInputError naming the field when ``design`` is not a first-order train
    (fixed sun, one pair) the trajectory can determine."""
    t = design.train
    if design.trajectory is None:
        raise InverseInputError("trajectory: inverse design needs the planned tip trajectory "
                                "([trajectory] points)")
    if len(t.pairs) not in (1, 2):
        raise InverseInputError(f"train.pairs: the inverse design of a planetary train takes a "
                                f"first-order train (one pair, sun -> planet) or seed 000's "
                                f"second-order train (two pairs); this file has "
                                f"{len(t.pairs)} pairs")
    for k, p in enumerate(t.pairs):
        if p.driver is not None or p.follower is not None or p.law is not None:
            raise InverseInputError(f"train.pairs.{k}: the inverse design computes the pitch "
                                    "curves; leave out the driver, follower and law tables")
        if len(t.pairs) == 2 and (p.kind != "external" or p.follower_turns != 1):
            raise InverseInputError(f"train.pairs.{k}.kind: seed 000's second-order train has "
                                    "two external pairs closing once per turn (kind = "
                                    "\"external\", follower_turns = 1)")
    if t.sun_speed_ratio != 0:
        raise InverseInputError(f"train.sun_speed_ratio: the inverse design takes a fixed sun "
                                f"(0), got {t.sun_speed_ratio:g}")
    if design.trajectory.dwell is not None and len(t.pairs) != 2:
        raise InverseInputError("trajectory.dwell: a toothless dwell is designed into seed "
                                "000's second-order train (two pairs, the sun's toothless "
                                f"sector); this file has {len(t.pairs)} pair")


def run_first_order(design) -> dict:
    """The first-order inverse design of a planetary [trajectory] file, checked by its
    round trip: {result, trajectory, designed (the planetary design or None), motion (its
    forward run or None), deviation, rows (the checks: inverse feasibility, the file's
    given lengths and turns, the round trip, its [limits]), feasible}. Raises
    InverseInputError (naming the field) or geometry.trajectory.TrajectoryError."""
    check_first_order_input(design)
    if len(design.train.pairs) == 2:
        return _run_second_order(design)
    tr = design.trajectory
    traj = ClosedTrajectory.through(tr.points)
    pair = design.train.pairs[0]
    s = -1 if design.carrier.direction == "clockwise" else 1
    res = first_order_inverse(traj, tr.arm, pair.kind, s, tr.samples)
    job = {"result": res, "trajectory": traj, "designed": None, "motion": None,
           "deviation": None, "rows": []}
    for name, given, found in (("train.pairs.0.centre_distance_mm", pair.centre_distance_mm,
                                 res.centre_distance),
                                ("arm.length_mm", design.arm.length_mm, res.arm_length)):
        if given is not None and found is not None and abs(given - found) > 1e-6 * found:
            raise InverseInputError(
                f"{name}: {given:g} mm, but the trajectory fixes it at {found:.6f} mm "
                f"(its farthest and nearest radii, trajectory.arm = \"{tr.arm}\"); leave it "
                "out")
    if res.feasible and abs(res.follower_turns - pair.follower_turns) > 1e-6:
        res.feasible = False
        res.reasons.append(f"train.pairs.0.follower_turns = {pair.follower_turns:g}, but this "
                           f"trajectory turns the planet {res.follower_turns:.6f} times per "
                           "sun turn")
    job["feasible"] = res.feasible
    if not res.feasible:
        return job
    designed = first_order_design(design, res)
    from plantmech.objectives.inverse_estimate import first_order_estimate

    return _with_estimate(_round_trip(job, designed, traj), lambda: first_order_estimate(
        tr.points, res, tr.arm, pair.kind, s, tr.samples, tr.error_estimate_limit_mm))


def _with_estimate(job: dict, estimate) -> dict:
    """``job`` with its error estimate (``objectives.inverse_estimate``; ``estimate()``
    computes it) under "estimate" and its checks among the rows, if the design is
    feasible."""
    from plantmech.objectives.inverse_estimate import estimate_rows

    if job["feasible"]:
        job["estimate"] = estimate()
        job["rows"] += estimate_rows(job["estimate"])
    return job


def _round_trip(job: dict, designed, traj) -> dict:
    """Build and run ``designed`` forward; the round-trip row and the [limits] rows."""
    from plantmech.objectives.planetary import design_evaluation
    from plantmech.trains.model import simulate
    from plantmech.trains.spec import TrainSpecError, build_from_design

    res = job["result"]
    try:
        built = build_from_design(designed)
    except TrainSpecError as exc:  # e.g. the planet's curve does not close (q != 1)
        res.feasible = job["feasible"] = False
        res.reasons.append(f"the written train cannot be built: {exc}")
        return job
    motion = simulate(built, designed.samples)
    dev = forward_deviation(traj, motion)
    job.update(designed=designed, motion=motion, deviation=dev)
    tol = ROUND_TRIP_TOLERANCE_MM
    seeder = job.get("seeder")
    if seeder is not None and seeder.dwell is not None:
        # the dwell holds the arm in the carrier over its sector and redistributes the
        # planned turn (seed 000 Eq. 5): the train is meant to give the inverse design's
        # realized tip, not the planned points (they are reported, not checked)
        realized = seeder.tip_realized[:, 0] + 1j * seeder.tip_realized[:, 1]
        psi = TWO_PI * np.arange(designed.samples) / designed.samples
        gap = np.abs(motion.tip[0, 0] - realized) if (
            realized.shape == psi.shape and np.allclose(seeder.carrier_angle, psi,
                                                        atol=1e-12)) else np.array([np.inf])
        dev["max_realized_tip_deviation_mm"] = float(gap.max())
        job["rows"] = [{"name": "round_trip_realized_tip_deviation_mm",
                        "value": round(float(gap.max()), 9), "unit": "mm",
                        "limit": f"<= {tol:g} mm", "ok": bool(gap.max() <= tol),
                        "note": "largest distance of the written design's forward tip from the "
                        "inverse design's realized tip (dwell applied) at the same carrier "
                        "angle, over the turn"}]
    else:
        job["rows"] = [{"name": "round_trip_point_deviation_mm",
                        "value": round(dev["max_point_deviation_mm"], 9), "unit": "mm",
                        "limit": f"<= {tol:g} mm", "ok": dev["max_point_deviation_mm"] <= tol,
                        "note": "largest distance of the written design's forward tip path "
                        "from a type-value point"}]
    job["rows"] += [{k: v for k, v in r.items() if k != "violation"}
                    for r in design_evaluation(designed)
                    if not r["name"].startswith(("cuttable_module", "working_pressure"))]
    return job


__all__ += ["ROUND_TRIP_TOLERANCE_MM", "InverseInputError", "check_first_order_input",
            "run_first_order"]


def _run_second_order(design) -> dict:
    """Seed 000's second-order train from a planetary [trajectory] file with two pairs: the
    seeder's inverse design (``mechanisms.seeder_inverse.inverse_design``: carrier and arm
    from the extreme radii, the ratio split between the pairs by
    ``trajectory.split_exponent``, centre distances from the file or L1 / 2) written as a
    planetary design (``second_order_design``) and checked by the same round trip."""
    from plantmech.mechanisms.seeder_inverse import DwellSpec, InverseSettings, inverse_design

    tr = design.trajectory
    t = design.train
    traj = ClosedTrajectory.through(tr.points)
    if design.carrier.direction != "clockwise":
        raise InverseInputError("carrier.direction: seed 000's inverse design turns the "
                                "carrier clockwise")
    dwell = None
    if tr.dwell is not None:
        dwell = DwellSpec(start=tr.dwell.start, end=tr.dwell.end, anchor=tr.dwell.anchor,
                          edge_radius=tr.dwell.edge_radius_mm)
    settings = InverseSettings(samples=tr.samples, a1=t.pairs[0].centre_distance_mm,
                               a2=t.pairs[1].centre_distance_mm,
                               split_exponent=tr.split_exponent,
                               min_pitch_radius=t.min_pitch_radius_mm, dwell=dwell)
    seeder = inverse_design(traj, settings)
    res = FirstOrderResult(seeder.feasible, [d.message for d in seeder.diagnostics
                                             if d.severity == "error"])
    res.centre_distance, res.arm_length = seeder.L1, seeder.L2
    job = {"result": res, "trajectory": traj, "designed": None, "motion": None,
           "deviation": None, "rows": [], "feasible": res.feasible, "seeder": seeder}
    if arm_given := design.arm.length_mm:
        if abs(arm_given - seeder.L2) > 1e-6 * seeder.L2:
            raise InverseInputError(f"arm.length_mm: {arm_given:g} mm, but the trajectory fixes "
                                    f"it at {seeder.L2:.6f} mm (seed 000 Eq. 1); leave it out")
    if seeder.carrier_angle is not None:
        res.psi, res.u = seeder.carrier_angle, seeder.u
        res.tip = seeder.tip[:, 0] + 1j * seeder.tip[:, 1]
        res.carrier, res.arm = seeder.carrier_abs, seeder.arm_angle
        res.ratio = seeder.total_ratio
        res.point_carrier_angle_deg = np.degrees(seeder.point_carrier_angle)
    if not res.feasible:
        return job
    res.follower_turns = 1.0
    res.carrier0_deg = float(np.degrees(seeder.carrier_abs[0]))
    res.arm0_deg = float(np.degrees(seeder.arm_angle_realized[0]))
    from plantmech.objectives.inverse_estimate import seeder_estimate

    def estimate():
        return seeder_estimate(tr.points, settings, seeder, tr.error_estimate_limit_mm)

    if seeder.dwell is not None:  # the contacts' radii while the teeth mesh
        res.sun_radii = seeder.r1[np.isfinite(seeder.r1)]
        res.planet_radii = seeder.r4[np.isfinite(seeder.r4)]
        from plantmech.mechanisms.seeder_inverse import dwell_lock_check

        job = _round_trip(job, second_order_dwell_design(design, seeder), traj)
        if job["feasible"]:
            job["rows"].append(dwell_lock_check(seeder.dwell))
        return _with_estimate(job, estimate)
    res.sun_radii = seeder.r1[(-np.arange(len(seeder.r1))) % len(seeder.r1)]
    res.planet_radii = seeder.r4
    return _with_estimate(_round_trip(job, second_order_design(design, seeder), traj),
                          estimate)


def second_order_design(design, seeder):
    """Seed 000's train from its inverse design (``mechanisms.seeder_inverse.InverseResult``)
    as a planetary design: pair 0 the fixed sun -> gear 2 (centre distance a1, line of
    centres at the shaft offset from the carrier line), pair 1 gear 3 (fixed on gear 2's
    shaft) -> the planet (a2, towards the planet axis at L1 on the carrier line), the arm L2.

    Frames (``trains.model``): with the sun's orientation C0 + delta_1 its contact body angle
    is theta_1 = -psi, so the sun's radii at uniform body angles are r1 at psi = -theta;
    gear 2's frame touches the sun's 0 at its 0 and turns psi_2(psi) (``gear2_angle``,
    clockwise) with the carrier angle; gear 3's phase delta_2 - delta_1 - pi on the shaft
    puts its contact body angle at theta_3 = psi_2(psi), where its radius is r3(psi). Both
    curves are written as ``control_radii_count`` control radii at uniform body angles
    (periodic spline); the side of the shaft (delta_1 = +offset) does not change the
    planet's motion."""
    from scipy.interpolate import CubicSpline

    n = len(seeder.r1)
    K = control_radii_count(n)
    a1, a2, L1 = seeder.a1, seeder.a2, seeder.L1
    d1 = seeder.shaft_offset
    shaft1 = a1 * np.exp(1j * d1)
    d2 = float(np.angle(L1 - shaft1))
    sun = seeder.r1[(-np.arange(n)) % n][:: n // K]
    theta3 = np.r_[seeder.gear2_angle, TWO_PI]
    r3 = CubicSpline(theta3, np.r_[seeder.r3, seeder.r3[0]], bc_type="periodic")(
        TWO_PI * np.arange(K) / K)
    C0 = float(seeder.carrier_abs[0])
    data = design.model_dump(exclude_none=True)
    p0, p1 = data["train"]["pairs"]
    p0.update(kind="external", follower_turns=1.0, centre_distance_mm=float(a1),
              direction_deg=float(np.degrees(d1)),
              driver={"family": "radii", "radii_mm": [float(r) for r in sun],
                      "interpolation": "spline",
                      "phase_deg": float(np.degrees(C0 + d1))})
    p1.update(kind="external", follower_turns=1.0, centre_distance_mm=float(a2),
              direction_deg=float(np.degrees(d2)),
              driver={"family": "radii", "radii_mm": [float(r) for r in r3],
                      "interpolation": "spline",
                      "phase_deg": float(np.degrees(d2 - d1 - np.pi))})
    data["carrier"]["initial_angle_deg"] = float(np.degrees(C0))
    data["arm"]["length_mm"] = float(seeder.L2)
    data["arm"]["initial_angle_deg"] = float(np.degrees(seeder.arm_angle_realized[0]))
    data["train"]["sun_speed_ratio"] = 0.0
    if not data["name"].endswith("(inverse design)"):
        data["name"] = f"{data['name']} (inverse design)"
    return type(design).model_validate(data)


__all__ += ["second_order_design"]


def second_order_dwell_design(design, seeder):
    """Seed 000's train with the sun's toothless dwell from its inverse design
    (``mechanisms.seeder_inverse.InverseResult`` with ``dwell``) as a planetary design,
    the dedicated model's train (``mechanisms.seeder_trains.train_from_inverse``) written
    through the mapping of examples/planetary/sugarcane_table4.toml: pair 0 the fixed sun
    -> gear 2 with gear 2 GIVEN (the sun derived, rolling 360 - theta_1 deg per gear-2
    turn) and the dwell (psi_s, theta_1) as [train.pairs.dwell]; pair 1 gear 3 (on gear
    2's shaft) -> the planet. Gears 2 and 3 step at the lock point (their ratio jumps when
    meshing stops and restarts), so each is an OPEN curve (``open = true``, not-a-knot
    spline) on the inverse design's own knots, measured from its break: body angle 0 is
    the lock (the right limit: the radius where meshing resumes, 360 deg the left: where
    it stops); their phases put the lock at the contact when the dwell starts."""
    from plantmech.mechanisms.seeder_forward import shaft_offset
    from plantmech.mechanisms.seeder_trains import train_from_inverse

    tr = train_from_inverse(seeder)
    d1 = shaft_offset(tr)
    d2 = float(np.angle(tr.L1 - tr.a1 * np.exp(1j * d1)))

    def open_curve(curve):
        x = np.asarray(curve.spline.x, dtype=float) - curve.theta0
        r = np.asarray(curve.spline(curve.spline.x), dtype=float)
        angles = [float(v) for v in np.degrees(x)]
        angles[0], angles[-1] = 0.0, 360.0
        return {"family": "radii", "radii_mm": [float(v) for v in r], "angles_deg": angles,
                "interpolation": "spline", "open": True}

    c2 = float(np.mod(tr.gear2_contact0 - tr.gear2.theta0, TWO_PI))
    c3 = float(np.mod(tr.gear3_contact0 - tr.gear3.theta0, TWO_PI))
    data = design.model_dump(exclude_none=True)
    p0, p1 = data["train"]["pairs"]
    gear2 = open_curve(tr.gear2)
    gear2["phase_deg"] = float(np.degrees(c2))
    gear3 = open_curve(tr.gear3)
    gear3["phase_deg"] = float(np.degrees(np.mod(d2 - d1 - np.pi + c2 - c3, TWO_PI)))
    p0.update(kind="external", follower_turns=1.0, centre_distance_mm=float(tr.a1),
              direction_deg=float(np.degrees(d1)), follower=gear2,
              dwell={"start_deg": float(np.degrees(tr.dwell_start)),
                     "sector_deg": float(np.degrees(tr.dwell_theta1))})
    p1.update(kind="external", follower_turns=1.0, centre_distance_mm=float(tr.a2),
              direction_deg=float(np.degrees(d2)), driver=gear3)
    data["train"]["grid"] = max(data["train"].get("grid", 8192), 16384)  # the seeder's
    data["carrier"]["initial_angle_deg"] = float(np.degrees(tr.carrier0))
    data["arm"]["length_mm"] = float(tr.L2)
    data["arm"]["initial_angle_deg"] = float(np.degrees(tr.arm0))
    data["train"]["sun_speed_ratio"] = 0.0
    if not data["name"].endswith("(inverse design)"):
        data["name"] = f"{data['name']} (inverse design)"
    return type(design).model_validate(data)


__all__ += ["second_order_dwell_design"]
