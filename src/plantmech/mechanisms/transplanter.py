"""Rice transplanting mechanisms of seed 001, vectorised over designs x arms x samples.

Conventions (docs/conventions.md, "Seed 001"):
- Frame: origin at the carrier axis O, x to the right, y up, absolute angles CCW
  from +x. Positions are complex numbers x + i y (mm) internally.
- ``carrier_angle`` psi = theta_2 of Eq. 2: clockwise carrier turn from the start.
- Arm j (0-based) is mounted on the carrier at phi_H0 - 2 pi j / J (it reaches the
  place of arm 0 after 2 pi j / J more carrier turn).
- Planting arm (Eq. 9-10): tip B at S from the planet axis along phi_2 + beta, break
  point A at H1 along phi_2 + beta + arccos(H1 / S) (right angle at A).

Differential internal train (Eq. 1-8): internal gear and carrier both turn clockwise,
theta_1 = k psi with k = omega_1 / omega_2; relative to the carrier the internal gear
turns gamma_1 = (1 - k) psi counter-clockwise and the mesh point advances over the
lobed internal pitch curve by lobe phase n (1 - k) psi (``gears.internal``); the planet
turns gamma_2 (Eq. 5) counter-clockwise relative to the carrier.

K-H-V train (paper's Fig. 1): fixed sun, and per arm a middle gear and a planet on one
line of the carrier (O -> middle at a, O -> planet at 2 a), external pairs.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from plantmech.gears.internal import LobedInternalPair
from plantmech.geometry.interpolation import interp_rows
from plantmech.geometry.periodic import periodic_spline_running_integral
from plantmech.mechanisms.backlash import backlash_offset

TWO_PI = 2.0 * np.pi


@dataclass
class ArmGeometry:
    """Planting arm (seed 001 Eq. 9-10): S, H1 in mm, beta in rad; scalars, or (P,)
    arrays for a population."""

    S: float | np.ndarray
    H1: float | np.ndarray
    beta: float | np.ndarray

    def __post_init__(self):
        S, H1 = np.broadcast_arrays(np.asarray(self.S, float), np.asarray(self.H1, float))
        bad = ~((H1 > 0) & (H1 <= S))
        if np.any(bad):
            k = int(np.flatnonzero(bad.ravel())[0])
            raise ValueError(f"the break point must lie between the planet axis and the tip: "
                             f"H1 = {H1.ravel()[k]:g} mm, S = {S.ravel()[k]:g} mm "
                             "(need 0 < H1 <= S)")

    @property
    def break_angle(self):
        return np.arccos(np.asarray(self.H1, float) / np.asarray(self.S, float))

    def column(self, name: str):
        """The parameter shaped to broadcast against (P, J, S) arrays."""
        v = np.asarray(getattr(self, name) if name != "break_angle" else self.break_angle,
                       float)
        return v.reshape(-1, 1, 1) if v.ndim else v

    def take(self, k: int) -> ArmGeometry:
        """Design k's arm (scalars)."""
        pick = [np.asarray(getattr(self, f), float) for f in ("S", "H1", "beta")]
        return ArmGeometry(*(float(v.ravel()[k] if v.ndim else v) for v in pick))


@dataclass
class TransplanterMotion:
    """Motion of P designs x J arms at S carrier angles (complex positions, mm)."""

    carrier_angle: np.ndarray  # (S,) rad
    centre: np.ndarray  # (P, J, S) planet axes
    A: np.ndarray  # (P, J, S) break points
    B: np.ndarray  # (P, J, S) tips
    planet_angle: np.ndarray  # (P, J, S) phi_2, absolute, rad
    arm_angle: np.ndarray  # (P, J, S) phi_2 + beta
    tip_rate: np.ndarray  # (P, J, S) dB/dpsi, mm/rad (analytic)
    planet_rate: np.ndarray  # (P, J, S) d gamma_2 / d psi (planet per carrier, rel.)
    closure_error: np.ndarray  # (P,) rad
    centre_distance: np.ndarray  # (P,) mm
    arm_geometry: ArmGeometry
    kind: str

    @property
    def arm_direction(self) -> np.ndarray:
        """Unit vector of the arm line, e^{i (phi_2 + beta)} (P, J, S): (B - centre) / S,
        without another complex exponential."""
        return (self.B - self.centre) / self.arm_geometry.column("S")

    @property
    def needle_angle(self) -> np.ndarray:
        """Direction of the needle A -> B, deg in [0, 360) (the paper's arm angle)."""
        return np.mod(np.degrees(np.angle(self.B - self.A)), 360.0)

    def velocity(self, carrier_speed_deg_s: float) -> np.ndarray:
        """Tip velocity (complex, m/s) for the carrier speed (deg/s, clockwise)."""
        return self.tip_rate * np.radians(carrier_speed_deg_s) / 1000.0


def _arm_points(centre, phi2, dcentre, dphi2, arm: ArmGeometry):
    S, H1 = arm.column("S"), arm.column("H1")
    ang = phi2 + arm.column("beta")
    along = np.empty(ang.shape, complex)  # e^{i ang} for B, A and the rate: cos and sin
    np.cos(ang, out=along.real)  # (numpy's complex exp costs twice as much)
    np.sin(ang, out=along.imag)
    B = centre + S * along
    A = centre + H1 * (along * np.exp(1j * arm.column("break_angle")))
    rate = dcentre + (1j * S) * dphi2 * along
    return A, B, ang, rate


def _column(v):
    v = np.asarray(v, dtype=float)
    return v.reshape(-1, 1, 1) if v.ndim else v


def lobe_advance_per_turn(lobes: float, speed_ratio: float) -> float:
    """Lobes the mesh point passes per carrier turn, m = n (1 - omega_1/omega_2)."""
    return lobes * (1.0 - speed_ratio)


def simulate_differential(pair: LobedInternalPair, speed_ratio: float, carrier0: float,
                          arm: ArmGeometry, phase0: float = 0.0, arms: int = 3,
                          samples: int = 3600, carrier_offset=0.0,
                          backlash=None) -> TransplanterMotion:
    """Differential internal-engagement train (seed 001 Eq. 1-10) for P designs.

    speed_ratio k = omega_1 / omega_2; carrier0 = phi_H0 (rad); phase0 = lobe phase of
    the mesh point of arm 0 at the start (rad); carrier0, phase0 and the arm may be
    scalars or (P,) arrays. The motion repeats every carrier turn
    only when m = n (1 - k) is a whole number (m = 1: the arm swings, net turn 0).

    Tolerances (scalars or (P,)): ``carrier_offset`` (mm): the planet axis bored that
    much farther from O than the centre distance a of the pair; the teeth still set the
    ratio, which depends on r / a only, so the planet turns as in the pair and only the
    axis moves (a (1 + offset / a) is exactly the motion of the pair scaled by that
    factor). ``backlash`` (rad): angular play of the planet (arm) against its drive
    (``mechanisms.backlash.backlash_offset`` on d gamma_2 / d psi).
    """
    n = pair.lobes
    m = lobe_advance_per_turn(n, speed_ratio)
    if abs(m - round(m)) > 1e-9 or round(m) == 0:
        raise ValueError(
            f"omega_1/omega_2 = {speed_ratio:g} with n = {n:g} lobes moves the mesh point "
            f"{m:.6g} lobes per carrier turn; the arms repeat their motion every carrier turn "
            f"only for a whole non-zero number (1 for a swinging arm: omega_1/omega_2 = "
            f"{(n - 1) / n:.6g})")
    from plantmech.mechanisms.transplanter_kernels import differential_motion

    psi = np.linspace(0.0, TWO_PI, samples, endpoint=False)
    P = pair.R.shape[0]
    offset = TWO_PI * np.arange(arms) / arms  # (J,)
    p, h = pair.p, pair.p[1] - pair.p[0]
    rp = pair.planet_radius
    q_rate = pair.R / (n * rp)  # dQ/dp (P, D+1)
    dq_rate = (pair.dR * rp - pair.R * pair.dR) / (n * rp**2)  # d2Q/dp2
    # Q at arm 0's start: cubic Hermite on the dense grid
    phase0 = np.broadcast_to(np.asarray(phase0, dtype=float), (P,))
    f0 = np.mod(phase0, TWO_PI)
    kk = np.clip((f0 / h).astype(int), 0, len(p) - 2)
    s0 = (f0 - p[kk]) / h
    r0 = np.arange(P)
    Q0 = ((2 * s0**3 - 3 * s0**2 + 1) * pair.Q[r0, kk] + (s0**3 - 2 * s0**2 + s0) * h
          * q_rate[r0, kk] + (-2 * s0**3 + 3 * s0**2) * pair.Q[r0, kk + 1]
          + (s0**3 - s0**2) * h * q_rate[r0, kk + 1])
    Q0 = Q0 + TWO_PI * np.floor(phase0 / TWO_PI)

    def per_design(v):
        return np.ascontiguousarray(np.broadcast_to(np.asarray(v, dtype=float), (P,)))

    shape = (P, arms, samples)
    centre, A, B, trate = (np.empty(shape, complex) for _ in range(4))
    phi2, ang, planet_rate = (np.empty(shape) for _ in range(3))
    # mesh point of arm j at lobe phase phase0 + m psi + n 2 pi j / J; Hermite Q and
    # dQ/dp there; the planet axis a e^{i phi_H}; phi_2 = phi_H + Q - Q0 (+ the play's
    # offset); the arm's points: one compiled pass per design, arm and sample
    differential_motion(
        p, pair.Q, q_rate, dq_rate, float(n), float(m), np.ascontiguousarray(phase0), Q0,
        per_design(carrier0), per_design(pair.a + np.asarray(carrier_offset, float)), offset,
        psi, per_design(arm.S), per_design(arm.H1), per_design(arm.beta),
        per_design(arm.break_angle), per_design(0.0 if backlash is None else backlash),
        centre, A, B, phi2, ang, trate, planet_rate)
    return TransplanterMotion(psi, centre, A, B, phi2, ang, trate, planet_rate,
                              pair.closure_error, pair.a.copy(), arm, "differential")


@dataclass
class KHVPair:
    """Sun of a K-H-V train sampled by contact progress sigma (D+1,) over one turn:
    r_sun (P, D+1) at absolute angle carrier0 - sigma, a (P,), M (P, D+1): middle-gear
    turn relative to the carrier, M(2 pi) = 2 pi when closed."""

    sigma: np.ndarray
    r_sun: np.ndarray
    a: np.ndarray
    M: np.ndarray

    @property
    def closure_error(self) -> np.ndarray:
        return np.abs(self.M[:, -1] - TWO_PI)


def khv_pair(angles, radii, carrier0: float, kind: str = "hermite", dense: int = 4096,
             min_radius: float = 1.0) -> KHVPair:
    """Sun pitch curve from control radii (P, N) mm at absolute angles (N,) rad, and the
    centre distance a that makes the middle gear turn once per carrier turn (Eq. 8 of
    seed 000 for this pair). ``carrier0`` (rad): the carrier's start, shared or (P,)."""
    from plantmech.gears.closure import solve_centre_distances
    from plantmech.geometry.periodic import periodic_interpolant_rows, periodic_spline_matrix

    radii = np.atleast_2d(np.asarray(radii, dtype=float))
    sigma = np.linspace(0.0, TWO_PI, dense + 1)
    c0 = np.asarray(carrier0, dtype=float)
    if c0.ndim == 0:  # one shared matrix
        r = radii @ periodic_spline_matrix(np.asarray(angles, float), c0 - sigma, 0, kind).T
    else:  # a carrier start per design (a study's carrier phase): the same interpolant
        at = np.broadcast_to(c0.reshape(-1, 1), (radii.shape[0], 1)) - sigma[None, :]
        r = periodic_interpolant_rows(np.asarray(angles, float), radii, at, kind)[0]
    if np.any(r <= min_radius):
        d, k = np.argwhere(r <= min_radius)[0]
        where = np.degrees(np.ravel(c0)[d if c0.ndim else 0] - sigma[k]) % 360
        raise ValueError(f"sun pitch radius {r[d, k]:.3f} mm at {where:.2f} deg is not above "
                         f"{min_radius:g} mm")
    a = solve_centre_distances(r[:, :-1], TWO_PI)
    # the running integral of the periodic cubic spline through the ratio (the ratio is
    # periodic; SciPy's not-a-knot spline differed by < 1e-9 rad and cost 4x)
    M = periodic_spline_running_integral((r[:, :-1] / (a[:, None] - r[:, :-1])).T,
                                         sigma[1] - sigma[0]).T
    return KHVPair(sigma, r, a, M)


def simulate_khv(pair: KHVPair, carrier0: float, arm: ArmGeometry, arms: int = 2,
                 samples: int = 3600, carrier_offset=0.0, backlash=None) -> TransplanterMotion:
    """Single-DOF K-H-V non-circular planetary train (seed 001 Fig. 1) for P designs.

    Middle gear i: d M = r_s / (a - r_s) d sigma (clockwise rel. carrier); its other
    contact (with the planet) is half a middle turn away, M + pi, at the contact
    progress sigma' = M^-1(M + pi), where the middle radius is a - r_s(sigma'); the
    planet there has radius r_s(sigma') and turns counter-clockwise rel. the carrier:
    d gamma_2 / d psi = [r_s / (a - r_s)](sigma) * [(a - r_s) / r_s](sigma').

    Tolerances (scalars or (P,)): ``carrier_offset`` (mm): the planet axis at 2 a +
    offset from O (the sum of the two centre-distance errors of the carrier's bores; the
    teeth keep each pair's ratio, which depends on r / a only); ``backlash`` (rad): the
    planet's (arm's) angular play against its drive (``mechanisms.backlash``).
    """
    psi = np.linspace(0.0, TWO_PI, samples, endpoint=False)
    offset = TWO_PI * np.arange(arms) / arms
    sg = pair.sigma
    # planet rate as a function of the contact progress sigma on the dense grid (P, D+1):
    # M^-1 by interpolation in each design's monotone table, vectorised over the population
    end = pair.M[:, -1:]
    sig2 = interp_rows(np.mod(pair.M + 0.5 * end, end), pair.M, sg)
    rs2 = interp_rows(sig2, sg, pair.r_sun)
    a = pair.a[:, None]
    rate = (pair.r_sun / (a - pair.r_sun)) * (a - rs2) / rs2
    # planet turn P(sigma): the periodic spline's running integral, as for M
    turn = periodic_spline_running_integral(rate[:, :-1].T, sg[1] - sg[0]).T
    closure = np.abs(turn[:, -1] - TWO_PI)
    # every arm runs through the same chain: arm j at psi is at contact progress psi + 2 pi j/J
    x = psi[None, :] + offset[:, None]  # (J, S)
    wraps = np.floor(x / TWO_PI)
    xf = x - wraps * TWO_PI
    gamma2 = interp_rows(xf, sg, turn, shared_x=True) + TWO_PI * wraps[None]
    out_rate = interp_rows(xf, sg, rate, shared_x=True)
    phiH = _column(carrier0) - (offset[:, None] + psi[None, :])[None]  # (1 or P, J, S)
    centre = (2 * pair.a[:, None, None] + _column(carrier_offset)) * np.exp(1j * phiH)
    phi2 = phiH + gamma2
    if backlash is not None:
        phi2 = phi2 + backlash_offset(out_rate, _column(backlash))
    A, B, ang, trate = _arm_points(centre, phi2, -1j * centre, out_rate - 1.0, arm)
    return TransplanterMotion(psi, centre, A, B, phi2, ang, trate, out_rate,
                              np.maximum(closure, pair.closure_error), pair.a.copy(), arm,
                              "khv")
