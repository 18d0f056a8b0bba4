"""Population forward kinematics of the second-order seeder train: P designs that
share the interpolation angles of their pitch curves are simulated at once with
array operations only (no Python loop per design or per sample).

Same model and conventions as ``seeder_forward``: pitch-curve radii of gears 2 and 3
at common node angles, r1 = a1 - r2, r4 = a2 - r3, rolling in the carrier frame, an
optional toothless dwell. Both interpolants (periodic cubic spline, periodic Hermite
with centred-difference tangents) are piecewise cubic Hermite with node slopes linear in
the node radii (one small matrix product for the population); everything else runs in
one fused pass per design (``seeder_kernel``, numba): the radii along the dense body
angles, the centre distances that close each pair (Newton, as
``gears.closure.solve_centre_distances``), the rolling integrals, the inversion of the
carrier law, the tip and its rate (``three_bar``'s formulae) and the angular play
(``backlash.backlash_offset``'s rule).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from plantmech.geometry.periodic import (  # noqa: F401 (re-export)
    periodic_interpolant_rows,
    periodic_spline_matrix,
)

TWO_PI = 2.0 * np.pi


@dataclass
class PopulationMotion:
    carrier_angle: np.ndarray  # (S,)
    tip: np.ndarray  # (P, S, 2) mm
    arm_angle: np.ndarray  # (P, S) rad
    total_ratio: np.ndarray  # (P, S)
    tip_rate: np.ndarray  # (P, S, 2) mm/rad
    closure_error: np.ndarray  # (P, 2) rad: stage 1, stage 2
    a1: np.ndarray | None = None  # (P,) mm, as given or solved
    a2: np.ndarray | None = None
    gear2_angle: np.ndarray | None = None  # (P, S) rad
    in_dwell: np.ndarray | None = None  # (S,)


@functools.lru_cache(maxsize=8)
def _spline_factors(dense: int):
    from plantmech.mechanisms.seeder_kernel import spline_factors

    return spline_factors(dense)


def simulate_population(nodes, radii2, radii3, L1, L2, a1, a2, carrier0, arm0,
                        contact2_0=np.pi, contact3_0=0.0, samples: int = 3600,
                        dense: int = 4096, kind: str = "spline",
                        dwell_start: float | None = None, dwell_sector: float = 0.0,
                        backlash=None) -> PopulationMotion:
    """Simulate P trains. radii2, radii3: (P, N) mm at ``nodes`` (N,) rad; L1, L2,
    carrier0, arm0 scalars or (P,); a1, a2 likewise, or None to solve the centre
    distance that closes each pair (Eq. 8; a1 for a sun turn of 2 pi - dwell_sector).
    contact2_0, contact3_0: body angles (rad) of gears 2 and 3 at their contacts at
    psi = 0, shared or (P,) (a per-design phase). ``dwell_start``/``dwell_sector`` (rad,
    shared): the toothless dwell. ``backlash``: None or the angular play (rad, scalar or
    (P,)) of the arm against the carrier (``backlash_offset``)."""
    r2n = np.atleast_2d(np.asarray(radii2, dtype=float))
    r3n = np.atleast_2d(np.asarray(radii3, dtype=float))
    nodes = np.asarray(nodes, dtype=float)
    # both interpolants are piecewise cubic Hermite with node slopes linear in the radii
    slopes = periodic_spline_matrix(nodes, nodes, 1, kind)
    knots = np.r_[nodes, nodes[0] + TWO_PI]
    closed = lambda R: np.c_[R, R[:, :1]]  # noqa: E731  (periodic: the end value is the start's)
    s2, s3 = r2n @ slopes.T, r3n @ slopes.T
    psi = np.linspace(0.0, TWO_PI, samples, endpoint=False)
    return simulate_curves((knots, closed(r2n), closed(s2)), (knots, closed(r3n), closed(s3)),
                           L1, L2, a1, a2, carrier0, arm0, contact2_0, contact3_0, psi,
                           dense, dwell_start, dwell_sector, backlash)


def meshing_angle(psi, dwell_start: float | None, dwell_sector: float):
    """(meshing carrier angle, in-dwell mask) at carrier angles psi (rad): the carrier
    angle the gears have rolled through, held at the dwell start while the toothless
    sector (``dwell_sector`` rad from ``dwell_start``) passes and ``dwell_sector`` behind
    the carrier after it (seed 000's theta_1)."""
    psi = np.asarray(psi, dtype=float)
    theta1 = float(dwell_sector) if dwell_start is not None else 0.0
    if theta1 > 0:
        start = float(dwell_start)
        in_dwell = (psi >= start) & (psi < start + theta1)
        return (np.where(psi >= start + theta1, psi - theta1, np.where(in_dwell, start, psi)),
                in_dwell)
    return psi, np.zeros(psi.shape, dtype=bool)


def simulate_curves(gear2, gear3, L1, L2, a1, a2, carrier0, arm0, contact2_0, contact3_0,
                    psi, dense: int = 4096, dwell_start: float | None = None,
                    dwell_sector: float = 0.0, backlash=None, target=None,
                    in_dwell=None, rescale: bool = True) -> PopulationMotion:
    """The one forward simulation of P seeder trains (``seeder_kernel.simulate_rows``).

    gear2, gear3: (knots (N + 1,) rad from theta0 to theta0 + 2 pi, radii (P, N + 1) mm,
    slopes (P, N + 1) mm/rad): each gear's pitch curve as a piecewise cubic Hermite over
    one turn of its body angle, the last column the left limit at the end knot (the first
    column again for a periodic curve; another value at a break). psi (S,): carrier
    angles (rad, increasing in their meshing angle ``target``, by default
    ``meshing_angle``). ``rescale``: the sun's rolling integral scaled to the meshing span
    (stage 1 closed exactly, the population's convention); False: as integrated, an
    unclosed pair rolling on periodically (the single design's forward model, which
    shows a closure error as it is). Other arguments as ``simulate_population``."""
    from plantmech.mechanisms.seeder_kernel import simulate_rows

    psi = np.asarray(psi, dtype=float)
    samples = psi.shape[0]
    if int(dense) < 4 or samples < 1:
        raise ValueError(f"dense ({dense}) must be at least 4 and samples ({samples}) at "
                         "least 1")
    x2, R2, S2 = (np.ascontiguousarray(np.asarray(v, dtype=float)) for v in gear2)
    x3, R3, S3 = (np.ascontiguousarray(np.asarray(v, dtype=float)) for v in gear3)
    P = R2.shape[0]
    # writeable copies: numba types a read-only array apart (a broadcast (1,) row would
    # be one), and each type is a compilation and a cache entry of its own
    row = lambda v: np.array(np.broadcast_to(np.asarray(v, dtype=float), (P,)))  # noqa: E731
    theta1 = float(dwell_sector) if dwell_start is not None else 0.0
    if target is None:
        target, in_dwell = meshing_angle(psi, dwell_start, dwell_sector)
    tip, rate = np.empty((P, samples, 2)), np.empty((P, samples, 2))
    arm, ratio, gear2_angle = (np.empty((P, samples)) for _ in range(3))
    closure, a1_out, a2_out = np.empty((P, 2)), np.empty(P), np.empty(P)
    cp, piv = _spline_factors(int(dense))
    simulate_rows(
        x2, R2, S2, x3, R3, S3, row(contact2_0), row(contact3_0),
        row(0.0 if a1 is None else a1), row(0.0 if a2 is None else a2), a1 is None,
        a2 is None, TWO_PI - theta1, int(dense), psi, np.cos(psi), np.sin(psi),
        np.ascontiguousarray(target, dtype=float), np.ascontiguousarray(in_dwell), theta1,
        row(L1), row(L2), row(carrier0), row(arm0),
        row(0.0 if backlash is None else backlash), backlash is not None, bool(rescale),
        cp, piv,
        tip, arm, ratio, rate, gear2_angle, closure, a1_out, a2_out)
    return PopulationMotion(psi, tip, arm, ratio, rate, closure, a1_out, a2_out, gear2_angle,
                            in_dwell)
