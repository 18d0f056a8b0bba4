"""Internal non-circular gear pairs with a lobed internal gear (seed 001).

Reading of the paper's parameter list (docs/conventions.md, "Seed 001 parameters"):
the control radii r_i (mm) describe the **internal gear**, one lobe of it, at lobe
phases theta_i (deg, 360 per lobe, in the order in which the mesh point meets them);
the internal gear has n identical lobes (n = the paper's mean ratio planet : internal,
relative to the carrier), so its polar angle is the lobe phase / n. The planet rolls
inside it at centre distance a:

    r_planet = R - a        (internal engagement, same sense of rotation),
    d(planet turn) = R / r_planet d(internal turn)   (seed 001 Eq. 5),

and it turns exactly once per lobe, which fixes a (closure):
    (1 / n) integral_0^{2 pi} R(p) / (R(p) - a) dp = 2 pi   (p = lobe phase).

Everything is vectorised over P designs: radii (P, N) at common lobe phases (N,).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from plantmech.geometry.periodic import periodic_spline_matrix, periodic_spline_running_integral

TWO_PI = 2.0 * np.pi


class InternalPairError(ValueError):
    """An internal pair that cannot mesh (message names the lobe phase)."""


def solve_internal_centre_distance(R: np.ndarray, lobes: float) -> np.ndarray:
    """Centre distance a (P,) closing each internal pair: mean(R / (R - a)) = lobes for
    R (P, D) sampled uniformly over one lobe. The left side f(a) rises monotonically and
    convexly from 1 (a = 0) to +inf (a -> min R), so the root is unique: Newton's method
    inside a bracket [lo, hi] that every evaluation narrows, a bisection step wherever
    Newton's step would leave it, until the steps reach round-off (about 6 evaluations
    instead of 60 bisections)."""
    R = np.atleast_2d(R)
    if lobes <= 1:
        raise InternalPairError(f"n = {lobes:g}: the planet must turn faster than the internal "
                                "gear relative to the carrier (n > 1)")
    lo = np.zeros(R.shape[0])
    hi = R.min(axis=1) * (1 - 1e-12)
    a = lo.copy()
    D = R.shape[1]
    for _ in range(100):
        q = 1.0 / (R - a[:, None])
        Rq = R * q
        f = Rq.sum(axis=1) / D - lobes
        df = (Rq * q).sum(axis=1) / D
        lo, hi = np.where(f < 0, a, lo), np.where(f < 0, hi, a)
        new = a - f / df
        done = np.abs(new - a) <= 4 * np.finfo(float).eps * np.maximum(np.abs(a), 1.0)
        a = np.where((new >= lo) & (new <= hi), new, 0.5 * (lo + hi))
        if done.all():
            break
    return a


@dataclass
class LobedInternalPair:
    """P internal pairs sampled on a dense lobe-phase grid p (D+1,), 0..2 pi.

    R, dR: internal pitch radius and dR/dp (P, D+1); a (P,); planet radius R - a;
    Q (P, D+1): planet turn relative to the carrier as the mesh point advances from
    p = 0 to p (rad), Q(2 pi) = 2 pi when closed.
    """

    lobes: float
    p: np.ndarray
    R: np.ndarray
    dR: np.ndarray
    a: np.ndarray
    Q: np.ndarray

    @property
    def planet_radius(self) -> np.ndarray:
        return self.R - self.a[:, None]

    @property
    def closure_error(self) -> np.ndarray:
        return np.abs(self.Q[:, -1] - TWO_PI)

    def internal_polar(self, k: int = 0, lobes_drawn: int | None = None):
        """(angle rad, radius mm) of design k's internal pitch curve over all lobes,
        body angle = -p / n (the mesh point moves clockwise in the gear)."""
        n = int(round(self.lobes)) if lobes_drawn is None else lobes_drawn
        ang = np.concatenate([-(self.p[:-1] + TWO_PI * j) / self.lobes for j in range(n)])
        return ang, np.tile(self.R[k, :-1], n)

    def planet_polar(self, k: int = 0):
        """(angle rad, radius mm) of design k's planet pitch curve: body angle -Q."""
        return -self.Q[k], self.planet_radius[k]


def lobed_internal_pair(phases, radii, lobes: float, kind: str = "hermite",
                        dense: int = 4096, min_planet_radius: float = 0.0,
                        centre_distance=None, tolerance: float = np.radians(0.01),
                        ) -> LobedInternalPair:
    """Build P internal pairs from control radii (P, N) mm at lobe phases (N,) rad.

    ``centre_distance`` None: solved for closure (one planet turn per lobe); given: the
    pair must close within ``tolerance`` (rad) or it is refused.
    Raises InternalPairError naming the lobe phase where the planet radius is not
    above ``min_planet_radius``, or the turn an unclosed pair makes.
    """
    radii = np.atleast_2d(np.asarray(radii, dtype=float))
    phases = np.asarray(phases, dtype=float)
    if np.any(radii <= 0):
        k = np.argwhere(radii <= 0)[0]
        raise InternalPairError(f"internal gear radius r_{k[1]} = {radii[tuple(k)]:g} mm "
                                "is not positive")
    p = np.linspace(0.0, TWO_PI, dense + 1)
    # (P, N) x (D+1, N) by einsum's own loop, not BLAS: a dozen nodes give OpenBLAS's
    # threads nothing to share, and on a busy machine they cost ~50 ms a product waiting
    # for each other (0.1-1 ms this way)
    R = np.einsum("pn,dn->pd", radii, periodic_spline_matrix(phases, p, 0, kind))
    dR = np.einsum("pn,dn->pd", radii, periodic_spline_matrix(phases, p, 1, kind))
    if np.any(R <= 0):
        k = np.argwhere(R <= 0)[0]
        raise InternalPairError(f"the interpolated internal pitch curve reaches "
                                f"{R[tuple(k)]:.3f} mm at lobe phase "
                                f"{np.degrees(p[k[1]]):.2f} deg")
    if centre_distance is None:
        a = solve_internal_centre_distance(R[:, :-1], lobes)
    else:
        a = np.broadcast_to(np.asarray(centre_distance, dtype=float), (R.shape[0],)).copy()
    rp = R - a[:, None]
    bad = rp <= min_planet_radius
    if bad.any():
        d = int(np.argwhere(bad)[0][0])
        k = int(np.argmin(rp[d]))
        span = np.degrees(p[np.flatnonzero(bad[d])])
        raise InternalPairError(
            f"planet pitch radius falls to {rp[d, k]:.3f} mm at lobe phase "
            f"{np.degrees(p[k]):.2f} deg (internal radius {R[d, k]:.3f} mm, centre distance "
            f"{a[d]:.3f} mm), not above {min_planet_radius:g} mm between lobe phases "
            f"{span.min():.1f} and {span.max():.1f} deg: the planet cannot mesh there")
    # planet turn: running integral of the periodic cubic spline through dQ/dp (the
    # integrand is periodic over the lobe; FFT, no per-call spline set-up)
    Q = periodic_spline_running_integral((R[:, :-1] / (lobes * rp[:, :-1])).T, p[1] - p[0]).T
    if centre_distance is not None:
        err = np.abs(Q[:, -1] - TWO_PI)
        if np.any(err > tolerance):
            d = int(np.argmax(err))
            closing = solve_internal_centre_distance(R[d:d + 1, :-1], lobes)[0]
            raise InternalPairError(
                f"the pair does not close: over one lobe ({360 / lobes:g} deg of the internal "
                f"gear) the planet turns {np.degrees(Q[d, -1]):.3f} deg, 360 needed, at centre "
                f"distance {a[d]:.3f} mm; it closes at {closing:.3f} mm (omit "
                "centre_distance_mm to solve it)")
    return LobedInternalPair(float(lobes), p, R, dR, a, Q)


def internal_perimeter(pair: LobedInternalPair) -> np.ndarray:
    """Perimeter (P,) of the whole internal pitch curve (all lobes), mm:
    n * integral sqrt(R^2 + (dR/dTheta)^2) dTheta with Theta = p / n."""
    n = pair.lobes
    integrand = np.sqrt(pair.R**2 + (n * pair.dR) ** 2) / n
    h = pair.p[1] - pair.p[0]
    return n * np.sum(0.5 * (integrand[:, 1:] + integrand[:, :-1]), axis=1) * h


def tooth_fit(pair: LobedInternalPair, module, rules=None) -> dict:
    """Can the pair carry teeth of ``module`` (mm, (P,) or scalar)? Vectorised over designs.

    - ``min_equivalent_teeth``: smallest z_eq = 2 |rho_c| / m over both pitch curves, rho_c
      the radius of curvature (the equivalent spur gear of each span);
    - ``max_working_pressure_angle_deg``: the tool's pressure angle + max atan(|dr/dtheta| / r),
      shared by both curves at the contact (internal: theta = p / n, so dr/dtheta = n dR/dp);
    - ``min_internal_teeth_difference``: z_int_eq - z_planet_eq where the ring curves around
      the planet;
    - ``cuttable_module_mm``: the largest module ``gears.manufacturability`` allows (undercut,
      pointed teeth, shaper for the ring's spans, internal difference) with ``rules``
      (a ``CuttingRules``; default: the standard 20 deg tooth system).
    Internal gear: polar curve (R, p / n); planet: (R - a, Q) with dQ/dp = R / (n (R - a)).
    """
    from plantmech.gears.manufacturability import (
        CuttingRules,
        PairShape,
        assess_pair,
        shape_from_polar,
    )
    from plantmech.geometry.periodic import polar_curvature_radius

    rules = rules or CuttingRules()
    n = pair.lobes
    h = pair.p[1] - pair.p[0]
    ddR = np.gradient(pair.dR, h, axis=1)
    rho_int = polar_curvature_radius(pair.R, pair.dR, ddR, 1.0 / n, 0.0)
    rp = pair.planet_radius
    dQ = pair.R / (n * rp)
    ddQ = np.gradient(dQ, h, axis=1)
    rho_pl = polar_curvature_radius(rp, pair.dR, ddR, dQ, ddQ)
    m = np.broadcast_to(np.asarray(module, dtype=float), (pair.R.shape[0],))
    z_int = (2 * np.abs(rho_int) / m[:, None]).min(axis=1)
    z_pl = (2 * np.abs(rho_pl) / m[:, None]).min(axis=1)
    mu = np.arctan(n * np.abs(pair.dR) / pair.R)
    # internal engagement: where the ring curves around the planet (rho_int > 0) the local
    # pair is an internal spur pair z_int_eq / z_pl_eq; their difference must be large
    # enough against tip and trochoid interference (-inf where the planet curves less)
    k_int, k_pl = 1.0 / rho_int, 1.0 / rho_pl
    with np.errstate(divide="ignore", invalid="ignore"):
        gap = np.where(k_pl > k_int, 2.0 * (1.0 / k_int - 1.0 / k_pl), -np.inf)  # mm
    gap = np.where(k_int > 0, gap, np.inf)
    p = pair.p[:-1]  # one lobe period, uniform, without its repeated end
    one = np.ones_like(pair.R[:, :-1])
    ring = shape_from_polar("internal", p, pair.R[:, :-1], pair.dR[:, :-1], ddR[:, :-1],
                            one / n, 0 * one, internal=True)
    ring.perimeter = n * ring.perimeter  # the lobe period is 1/n of the ring
    planet = shape_from_polar("planet", p, rp[:, :-1], pair.dR[:, :-1], ddR[:, :-1],
                              dQ[:, :-1], ddQ[:, :-1])
    v = assess_pair(PairShape("internal_planet", (ring, planet), mu[:, :-1], gap[:, :-1],
                              module=m), rules)
    return {"min_equivalent_teeth": np.minimum(z_int, z_pl),
            "internal_min_equivalent_teeth": z_int, "planet_min_equivalent_teeth": z_pl,
            "min_internal_teeth_difference": gap.min(axis=1) / m,
            "max_working_pressure_angle_deg": rules.pressure_angle_deg
            + np.degrees(mu.max(axis=1)),
            "cuttable_module_mm": v.module_high, "verdict": v}
