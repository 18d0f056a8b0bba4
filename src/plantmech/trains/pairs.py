"""One gear pair of the general train: the transmission law of non-circular rolling.

The driver's pitch curve r_d(theta_d) is given; the follower's radius at the contact is
fixed by the centre distance a (mm):

============================  =============  ====================  ==================
kind                          r_f            sense (follower vs    contact direction
                                             driver, ``sense``)    from both centres
============================  =============  ====================  ==================
``external``                  a - r_d        opposite (-1)         driver: delta,
                                                                   follower: delta + pi
``internal`` (driver = ring)  r_d - a        same (+1)             delta (both)
``internal_ring_follower``    r_d + a        same (+1)             delta + pi (both)
============================  =============  ====================  ==================

delta: direction of the line of centres driver -> follower in the carrier frame.
Pure rolling: the follower turns d alpha_f = sense * g d alpha_d with the ratio
g = r_d / r_f (seed 000 Eq. 9-10, seed 001 Eq. 5). The law is written through the
running integral F(theta) = integral_0^theta g(t) dt over the driver's body angle:
with the contact at driver body angle theta_d, it lies at follower body angle

    theta_f = sense * F(theta_d)

(this defines the follower's body frame: theta_f = 0 touches theta_d = 0). F is the
periodic cubic spline's exact running integral of g on the grid (``geometry.periodic``),
F(theta + 2 pi) = F(theta) + 2 pi q with q the follower's turns per driver turn; the pair
closes when q is the required number (``follower_turns``); the centre distance that
closes it is solved when not given. Two identical ellipses about their foci at a = 2A:
tan(F / 2) = ((1 - e) / (1 + e)) tan(theta_d / 2) (tests/test_trains.py).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from plantmech.trains.curves import TWO_PI, Curve, hermite_open, hermite_periodic, use_kernels

KINDS = ("external", "internal", "internal_ring_follower")
#: (sense, r_f = kappa * r_d + c * a, contact direction offsets from delta: driver, follower)
_KIND = {"external": (-1, -1.0, 1.0, 0.0, np.pi),
         "internal": (1, 1.0, -1.0, 0.0, 0.0),
         "internal_ring_follower": (1, 1.0, 1.0, np.pi, np.pi)}


class PairError(ValueError):
    """A pair that cannot roll or close (message names the pair and the design)."""


def _ratio(kind: str, r: np.ndarray, a: np.ndarray) -> np.ndarray:
    _, kappa, c, _, _ = _KIND[kind]
    return r / (kappa * r + c * a)


def _turns(follower_turns, P: int) -> np.ndarray:
    """q as a (P,) array (a scalar shared by the designs, or one per design)."""
    return np.broadcast_to(np.asarray(follower_turns, dtype=float), (P,)).astype(float)


def _admissible(kind: str, r: np.ndarray, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(lo, hi) (P,) mm: the centre distances where the follower's radius stays positive
    and the mean ratio can reach q (it brackets the root); PairError when no a can close
    the pair (q on the wrong side of 1 for an internal pair)."""
    rmin, rmax = r.min(axis=1), r.max(axis=1)
    if kind == "external":
        return rmax * (1 + 1e-12), rmax * (1 + 1 / q) * (1 + 1e-9)
    if kind == "internal":
        if np.any(q <= 1):
            raise PairError(f"an internal pair whose driver is the ring turns the follower "
                            f"faster than the ring (q > 1); follower_turns = {q.min():g}")
        return np.zeros_like(rmin), rmin * (1 - 1e-12)
    if np.any(q >= 1):
        raise PairError(f"a ring follower turns slower than its driver (q < 1); "
                        f"follower_turns = {q.max():g}")
    return np.zeros_like(rmin), rmax * (1 - q) / q * (1 + 1e-9)


def _bisected(kind: str, r: np.ndarray, q: np.ndarray, lo: np.ndarray, hi: np.ndarray,
              steps: int = 64) -> np.ndarray:
    """The root of mean(g) = q in [lo, hi] by ``steps`` bisections of the (P, n) table r."""
    rising = kind == "internal"
    for _ in range(steps):
        mid = 0.5 * (lo + hi)
        below = (np.mean(_ratio(kind, r, mid[:, None]), axis=1) < q) == rising
        lo, hi = np.where(below, mid, lo), np.where(below, hi, mid)
    return 0.5 * (lo + hi)


#: samples of the coarse table the centre-distance solve brackets its root on
COARSE_SAMPLES = 256
#: bisections on the coarse table (its root is within 2**-32 of the admissible interval;
#: the coarse table's own root differs from the full one's by far more)
COARSE_STEPS = 32
#: Newton's last relative step (|da| / a) at which the centre distance is taken as solved
CLOSURE_STEP = 1e-14


def solve_centre_distance(kind: str, r: np.ndarray, follower_turns) -> np.ndarray:
    """Centre distance a (P,) mm with mean(g) = q over one driver turn for driver radii r
    (P, N) sampled uniformly (the periodic running integral's end value is exactly the
    mean times 2 pi); q scalar or (P,). Raises PairError when no a can close it.

    The mean ratio m(a) = mean(r / (kappa r + c a)) is monotone in a on the admissible
    interval (``_admissible``), so the root is unique. It is bracketed on a coarse table
    (every N / ``COARSE_SAMPLES``-th radius: ``COARSE_STEPS`` bisections of a (P, 256)
    table), then polished by Newton on the full table with the analytic slope
    dm/da = mean(-c r / (kappa r + c a)^2): each step touches the table once (two
    sums), the error squares per step, and a design's steps end when its relative step
    is below ``CLOSURE_STEP`` (2-3 steps on the bundled examples). A design Newton does
    not settle in 12 steps falls back to the full table's bisection."""
    q = _turns(follower_turns, r.shape[0])
    lo, hi = _admissible(kind, r, q)
    N = r.shape[1]
    stride = max(N // COARSE_SAMPLES, 1)
    a = _bisected(kind, r[:, ::stride], q, lo, hi, COARSE_STEPS) if stride > 1 else \
        _bisected(kind, r, q, lo, hi)
    _, kappa, c, _, _ = _KIND[kind]
    settled = np.zeros(a.shape, dtype=bool)
    for _ in range(12):
        rows = np.flatnonzero(~settled)  # a settled design is left as it is: each design
        rr = r if rows.size == r.shape[0] else r[rows]  # takes its own steps, whatever
        ar = a[rows]  # the population
        rf = kappa * rr + c * ar[:, None]
        g = np.divide(rr, rf, out=rf)  # in place: one (P, N) temporary per step
        f = g.mean(axis=1) - q[rows]
        g /= kappa * rr + c * ar[:, None]
        df = -c * g.mean(axis=1)
        new = np.clip(ar - f / df, lo[rows], hi[rows])
        settled[rows] = np.abs(new - ar) <= CLOSURE_STEP * np.abs(ar)
        a[rows] = new
        if settled.all():
            break
    if not settled.all():  # a pathological table: the full bisection, as before
        left = ~settled
        a[left] = _bisected(kind, r[left], q[left], lo[left], hi[left])
    return a


@dataclass
class PairLaw:
    """The transmission law of P pairs of one kind.

    ``a`` (P,) mm; ``g`` (P, N) ratio r_d / r_f on the driver's grid and ``dg`` its slope
    (1/rad); ``Fp`` (P, N) the periodic part F - q_e theta of the running integral, with
    ``q_e`` (P,) the follower's turns per driver turn as rolled (= ``follower_turns``
    when closed); ``closure_error`` (P,) rad: 2 pi (q_e - follower_turns), the follower's
    extra turn per driver turn. An open driver (``Curve.open``: a break at body angle 0)
    also has the ratio's left limits at 2 pi, ``g_end`` and ``dg_end`` (P,); F is then
    the exact running integral of g's open Hermite table (continuous across the break,
    its slope steps there) and every reading of g and F stops at the break."""

    kind: str
    driver: Curve
    a: np.ndarray
    g: np.ndarray
    dg: np.ndarray
    Fp: np.ndarray
    q_e: np.ndarray
    follower_turns: float | np.ndarray
    name: str = "pair"
    g_end: np.ndarray | None = None
    dg_end: np.ndarray | None = None

    def _periodic_part(self, theta) -> tuple[np.ndarray, np.ndarray]:
        """(F - q_e theta, g - q_e) at driver body angles ``theta`` (rad): the Hermite
        reading of ``Fp`` with its slopes (an open driver's never across its break)."""
        if self.g_end is None:
            return hermite_periodic(self.Fp, self.slope, theta)
        return hermite_open(self.Fp, self.slope, self.Fp[:, 0],
                            self.g_end - self.q_e, theta)

    def _ratio_at(self, theta) -> tuple[np.ndarray, np.ndarray]:
        """(g, dg/dtheta) at driver body angles ``theta`` (rad)."""
        if self.g_end is None:
            return hermite_periodic(self.g, self.dg, theta)
        return hermite_open(self.g, self.dg, self.g_end, self.dg_end, theta)

    @property
    def slope(self) -> np.ndarray:
        """g - q_e (P, N): the slope table of F's periodic part ``Fp`` (computed once)."""
        cached = self.__dict__.get("_slope")
        if cached is None:
            cached = self.__dict__["_slope"] = self.g - self.q_e[:, None]
        return cached

    @property
    def sense(self) -> int:
        return _KIND[self.kind][0]

    @property
    def driver_direction(self) -> float:
        """Offset (rad) of the contact direction from the driver centre to delta."""
        return _KIND[self.kind][3]

    @property
    def follower_direction(self) -> float:
        return _KIND[self.kind][4]

    @property
    def closure_error(self) -> np.ndarray:
        return TWO_PI * (self.q_e - self.follower_turns)

    def F(self, theta) -> tuple[np.ndarray, np.ndarray]:
        """(F, g) at driver body angles ``theta`` (rad), shape (P, ...) or (1, ...)."""
        fp, _ = self._periodic_part(theta)
        g, _ = self._ratio_at(theta)
        q = self.q_e.reshape((-1,) + (1,) * (np.ndim(theta) - 1))
        return fp + q * np.asarray(theta, dtype=float), g

    def follower_radius(self, r_driver) -> np.ndarray:
        _, kappa, c, _, _ = _KIND[self.kind]
        a = self.a.reshape((-1,) + (1,) * (np.ndim(r_driver) - 1))
        return kappa * r_driver + c * a

    def invert(self, F_target: np.ndarray) -> np.ndarray:
        """Driver body angles theta (P, M) with F(theta) = F_target (P, M) (F increases):
        the table's linear inverse, then Newton on the Hermite law (quartic accuracy)."""
        P, N = self.g.shape
        F_target = np.asarray(F_target, dtype=float)
        # fused per angle when the table or the angles are large (NumPy joins the rows'
        # tables for its search: passes over (P, N + 1) however few the angles)
        # (an open law's break is read by its own Hermite reading, below)
        if self.g_end is None and use_kernels(
                P * max(F_target.size // max(F_target.shape[0], 1), N)):
            from plantmech.trains.kernels import invert_rows

            target = np.ascontiguousarray(np.broadcast_to(F_target, (P,) + F_target.shape[1:])
                                          .reshape(P, -1))
            theta = invert_rows(np.ascontiguousarray(self.Fp), self.slope,
                                np.ascontiguousarray(self.q_e, dtype=float), target, 4)
            return theta.reshape((P,) + F_target.shape[1:])
        h = TWO_PI / N
        period = TWO_PI * self.q_e[:, None]
        w = np.floor(F_target / period)
        y = F_target - w * period  # in [0, 2 pi q_e)
        th = np.arange(N + 1) * h
        table = np.concatenate([self.Fp, self.Fp[:, :1]], axis=1) + self.q_e[:, None] * th
        from plantmech.geometry.trajectory_batch import row_searchsorted

        k = row_searchsorted(table, y)
        rows = np.arange(P)[:, None]
        f0, f1 = table[rows, k], table[rows, k + 1]
        theta = th[k] + h * (y - f0) / np.where(f1 > f0, f1 - f0, 1.0)
        q = self.q_e[:, None]
        slope = self.slope
        for _ in range(4):  # Newton on the Hermite interpolant of F (its own slope)
            fp, dfp = (hermite_periodic(self.Fp, slope, theta) if self.g_end is None
                       else self._periodic_part(theta))
            theta = theta - (fp + q * theta - y) / (dfp + q)
        return theta + TWO_PI * w

    def mate(self, name: str = "mate") -> Curve:
        """The follower's pitch curve on its own uniform grid (r, dr/dtheta_f): at
        follower angle phi the contact is at driver angle F^-1(sense * phi)."""
        P, N = self.g.shape
        _, kappa, c, _, _ = _KIND[self.kind]
        if not self.driver.open and use_kernels(P * N):  # one fused pass per design
            from plantmech.trains.fused import mate_tables

            rf, slope = mate_tables(np.ascontiguousarray(self.Fp), np.ascontiguousarray(self.g),
                                    np.ascontiguousarray(self.q_e, dtype=float),
                                    np.ascontiguousarray(self.driver.r, dtype=float),
                                    np.ascontiguousarray(self.driver.dr, dtype=float),
                                    np.ascontiguousarray(self.a, dtype=float), float(kappa),
                                    float(c), float(self.sense))
            return Curve(rf, slope, name)
        phi = TWO_PI * np.arange(N) / N
        theta_d = self.invert(np.broadcast_to(self.sense * phi, (P, N)))
        r_d, dr_d = self.driver(theta_d)
        g = r_d / self.follower_radius(r_d)
        _, kappa, _, _, _ = _KIND[self.kind]
        if self.driver.open:
            return _open_mate(self, r_d, kappa * dr_d / (self.sense * g), name)
        return Curve(self.follower_radius(r_d), kappa * dr_d / (self.sense * g), name)


def _open_mate(law: PairLaw, r_d: np.ndarray, slope: np.ndarray, name: str) -> Curve:
    """The mate of an open driver (``PairLaw.mate``): an open curve whose break, at its
    body angle 0 (theta_f = sense F(0) = 0), meets the driver's. Its right limit there
    rolls on the driver's side that follows it: the driver's left limit at 2 pi when the
    follower turns against the driver (sense -1: theta_d -> 0 from below), its right limit
    at 0 when with it; its left limit at 2 pi on the other side."""
    _, kappa, _, _, _ = _KIND[law.kind]
    d = law.driver

    def side(r, dr):
        rf = law.follower_radius(r)
        return rf, kappa * dr / (law.sense * (r / rf))

    start, end = side(d.r_end, d.dr_end), side(d.r[:, 0], d.dr[:, 0])
    if law.sense > 0:
        start, end = end, start
    r_f, dr_f = law.follower_radius(r_d), slope.copy()
    r_f[:, 0], dr_f[:, 0] = start
    return Curve(r_f, dr_f, name, end[0], end[1])


def pair_law(kind: str, driver: Curve, follower_turns, centre_distance=None,
             tolerance: float = np.radians(0.01), min_radius: float = 0.0,
             name: str = "pair", periodic_mate: bool = True) -> PairLaw:
    """Transmission law of P pairs whose driver is ``driver`` (P designs).

    ``centre_distance`` (mm, scalar or (P,)) None: solved so the follower turns
    ``follower_turns`` times per driver turn; given: the pair must close within
    ``tolerance`` (rad per driver turn) or PairError says the centre distance that
    closes it. The follower's radius must stay above ``min_radius`` (mm), and the driver's
    pitch curve must repeat every 1 / q turn (else the follower's curve would not close).
    ``follower_turns`` q: a scalar or one per design (P,). ``periodic_mate`` False: the
    mate is not a closed gear rolled all round (a toothless sector: ``trains.model``'s
    dwell), so the driver's repetition every 1 / q turn is not asked."""
    if kind not in KINDS:
        raise PairError(f"{name}: unknown kind {kind!r} (expected one of {', '.join(KINDS)})")
    P, N = driver.r.shape
    scalar = np.ndim(follower_turns) == 0
    q = _turns(follower_turns, P)
    if not np.all(q > 0):
        raise PairError(f"{name}: follower_turns must be positive, got {q.min():g}")
    driver.check_positive(min_radius)
    if not driver.open and use_kernels(P * N):  # a population: one fused pass per design
        law = _fused_law(kind, driver, q, centre_distance, min_radius, name,
                         float(q[0]) if scalar else q)
        if law is not None:
            return _checked(law, kind, driver, q, centre_distance, tolerance, name,
                            periodic_mate)
    try:
        _admissible(kind, driver.r, q)  # a pair no centre distance can close: refused
        solved = solve_centre_distance(kind, driver.r, q) if centre_distance is None \
            else None  # a given one: solved only to say where it closes (below)
    except PairError as exc:
        raise PairError(f"{name}: {exc}") from None
    if centre_distance is None:
        a = solved
    else:
        a = np.broadcast_to(np.asarray(centre_distance, dtype=float), (P,)).astype(float)
    _, kappa, c, _, _ = _KIND[kind]
    rf = kappa * driver.r + c * a[:, None]
    bad = rf <= min_radius
    if bad.any():
        d, k = (int(i) for i in np.argwhere(bad)[0])
        raise PairError(f"{name}: the follower's pitch radius is {rf[d, k]:.4g} mm where the "
                        f"driver's is {driver.r[d, k]:.4g} mm (body angle "
                        f"{np.degrees(TWO_PI * k / N):.2f} deg, centre distance {a[d]:.4g} "
                        f"mm), not above {min_radius:g} mm"
                        + (f" (design {d})" if P > 1 else ""))
    g = driver.r / rf
    dg = driver.dr * (c * a[:, None]) / rf**2  # d/dtheta of r / (kappa r + c a)
    if driver.open:
        law, solved = _open_law(kind, driver, a, centre_distance is None, q, min_radius, name)
        law.follower_turns = float(q[0]) if scalar else q
        q_e = law.q_e
    else:
        from plantmech.geometry.periodic import periodic_spline_running_integral

        h = TWO_PI / N
        F = periodic_spline_running_integral(g.T, h).T  # (P, N + 1)
        q_e = F[:, -1] / TWO_PI
        Fp = F[:, :-1] - q_e[:, None] * (h * np.arange(N))
        law = PairLaw(kind, driver, a, g, dg, Fp, q_e, float(q[0]) if scalar else q, name)
    return _checked(law, kind, driver, q, centre_distance, tolerance, name, periodic_mate)


def _fused_law(kind: str, driver: Curve, q: np.ndarray, centre_distance, min_radius: float,
               name: str, turns) -> PairLaw | None:
    """``pair_law``'s closed law of a population by ``trains.fused.pair_laws`` (the same
    solve and spline, 1e-15 relative apart); None when a design is refused (a follower
    radius not above ``min_radius``, no admissible centre distance): the NumPy path then
    says which, with its message."""
    from plantmech.trains.fused import pair_laws

    P, N = driver.r.shape
    try:
        lo, hi = _admissible(kind, driver.r, q)
    except PairError:
        return None
    solve = centre_distance is None
    given = np.zeros(P) if solve else np.broadcast_to(
        np.asarray(centre_distance, dtype=float), (P,)).astype(float)
    _, kappa, c, _, _ = _KIND[kind]
    a, g, dg, Fp, q_e, rf_min = pair_laws(
        np.ascontiguousarray(driver.r, dtype=float), np.ascontiguousarray(driver.dr,
                                                                         dtype=float),
        float(kappa), float(c), np.ascontiguousarray(q, dtype=float), lo, hi, given, solve,
        max(N // COARSE_SAMPLES, 1), COARSE_STEPS if N // COARSE_SAMPLES > 1 else 64,
        CLOSURE_STEP)
    if not np.all(rf_min > min_radius) or not np.all(np.isfinite(q_e)):
        return None
    return PairLaw(kind, driver, a, g, dg, Fp, q_e, turns, name)


def _checked(law: PairLaw, kind: str, driver: Curve, q: np.ndarray, centre_distance,
             tolerance: float, name: str, periodic_mate: bool) -> PairLaw:
    """``law`` once its closure (a given centre distance) and, for a mate rolled all round,
    the driver's repetition every 1 / q turn are checked (PairError naming the design)."""
    P = driver.r.shape[0]
    q_e = law.q_e
    a = law.a
    err = np.abs(law.closure_error)
    if centre_distance is not None and np.any(err > tolerance):
        d = int(np.argmax(err))
        solved = solve_centre_distance(kind, driver.r, q)
        raise PairError(f"{name}: the pair does not close: per driver turn the follower "
                        f"turns {360 * q_e[d]:.4f} deg, {360 * q[d]:.6g} needed, at centre "
                        f"distance {a[d]:.4f} mm; it closes at {solved[d]:.4f} mm (leave "
                        "centre_distance_mm out to solve it)"
                        + (f" (design {d})" if P > 1 else ""))
    if not periodic_mate:
        return law
    if driver.open:
        if np.any(np.abs(q - 1.0) > 1e-12):
            raise PairError(f"{name}: an open driver (a break at body angle 0) needs "
                            f"follower_turns = 1 (got {q.max():g}): the break would meet the "
                            "follower at another body angle every driver turn")
        return law
    gap = _repetition_gap(driver, q)
    if np.any(gap > 1e-6 * driver.r.max(axis=1)):
        d = int(np.argmax(gap))
        raise PairError(f"{name}: the follower turns {q[d]:g} times per driver turn, but the "
                        f"driver's pitch curve does not repeat every {360 / q[d]:g} deg "
                        f"(differs by up to {gap[d]:.4g} mm): the follower's pitch curve "
                        "would not close")
    return law


def _repetition_gap(driver: Curve, q: np.ndarray) -> np.ndarray:
    """Largest |r(theta + 2 pi / q) - r(theta)| (P,) mm over the driver's grid: how far its
    pitch curve is from repeating every 1 / q turn. A shift of whole grid steps (q = 1,
    2, ... when N / q is whole, the same for every design) reads the table itself (a roll,
    0 for q = 1); any other shift evaluates the Hermite interpolant there."""
    P, N = driver.r.shape
    steps = N / q
    whole = np.rint(steps)
    if np.all(steps == steps[0]) and abs(steps[0] - whole[0]) < 1e-9:
        shift = int(whole[0]) % N
        if shift == 0:
            return np.zeros(P)
        return np.abs(np.roll(driver.r, -shift, axis=1) - driver.r).max(axis=1)
    th = TWO_PI * np.arange(N) / N
    return np.abs(driver(th[None, :] + TWO_PI / q[:, None])[0] - driver.r).max(axis=1)


def _open_running_integral(g: np.ndarray, dg: np.ndarray, g_end: np.ndarray,
                           dg_end: np.ndarray) -> np.ndarray:
    """F (P, N + 1) at theta_k = 2 pi k / N, k = 0..N: the exact running integral of the
    open cubic Hermite table of g (values g, slopes dg, left limits g_end, dg_end at 2 pi):
    each interval adds h (g_k + g_k+1) / 2 + h^2 (dg_k - dg_k+1) / 12."""
    P, N = g.shape
    h = TWO_PI / N
    y = np.concatenate([g, g_end.reshape(P, 1)], axis=1)
    d = np.concatenate([dg, dg_end.reshape(P, 1)], axis=1)
    step = 0.5 * h * (y[:, :-1] + y[:, 1:]) + (h * h / 12.0) * (d[:, :-1] - d[:, 1:])
    return np.concatenate([np.zeros((P, 1)), np.cumsum(step, axis=1)], axis=1)


def _open_law(kind: str, driver: Curve, a: np.ndarray, solve: bool, q: np.ndarray,
              min_radius: float, name: str) -> tuple[PairLaw, np.ndarray]:
    """(law, the closing centre distance) of an open driver (``pair_law``): its ratio's
    open Hermite table and running integral (``_open_running_integral``). The closing
    centre distance starts from the periodic solve (``solve_centre_distance`` on the grid)
    and is corrected by Newton on the open integral's mean (it counts the break's two
    limits); ``solve``: the law is at that distance, else at ``a``."""
    _, kappa, c, _, _ = _KIND[kind]
    P, N = driver.r.shape

    def tables(dist):
        col = dist[:, None]
        rf = kappa * driver.r + c * col
        rf_end = kappa * driver.r_end + c * dist
        return (driver.r / rf, driver.dr * (c * col) / rf**2, driver.r_end / rf_end,
                driver.dr_end * (c * dist) / rf_end**2)

    solved = solve_centre_distance(kind, driver.r, q)
    for _ in range(8):
        g, dg, ge, dge = tables(solved)
        mean = _open_running_integral(g, dg, ge, dge)[:, -1] / TWO_PI
        rf = kappa * driver.r + c * solved[:, None]
        rf_end = kappa * driver.r_end + c * solved
        slope = -(c * (np.sum(driver.r / rf**2, axis=1) - 0.5 * driver.r[:, 0] / rf[:, 0]**2
                       + 0.5 * driver.r_end / rf_end**2)) / N
        step = (mean - q) / slope
        trial = solved - step
        rf_min = np.minimum((kappa * driver.r + c * trial[:, None]).min(axis=1),
                            kappa * driver.r_end + c * trial)
        ok = np.isfinite(trial) & (rf_min > 0)  # a step leaving the admissible range: kept
        solved = np.where(ok, trial, solved)
        if np.all(~ok | (np.abs(step) < 1e-13 * np.abs(solved))):
            break
    dist = solved if solve else a
    bad = kappa * driver.r_end + c * dist <= min_radius
    if bad.any():
        d = int(np.argmax(bad))
        raise PairError(f"{name}: the follower's pitch radius falls to "
                        f"{kappa * driver.r_end[d] + c * dist[d]:.4g} mm at the end of the "
                        f"driver's open turn (centre distance {dist[d]:.4g} mm), not above "
                        f"{min_radius:g} mm" + (f" (design {d})" if P > 1 else ""))
    g, dg, ge, dge = tables(dist)
    F = _open_running_integral(g, dg, ge, dge)
    q_e = F[:, -1] / TWO_PI
    Fp = F[:, :-1] - q_e[:, None] * (TWO_PI / N * np.arange(N))
    return PairLaw(kind, driver, dist, g, dg, Fp, q_e, q, name, ge, dge), solved
