"""The rice transplanter's differential internal train driven tooth on tooth (seed 001):
internal gear and carrier both driven (relative to the carrier the internal gear turns
gamma_1 = (1 - k) psi counter-clockwise, k = omega_1 / omega_2), J planets (one per arm)
meshing with the internal gear at lobe phases n 2 pi j / J apart; each planet carries
its planting arm. The planets do not mesh with each other, so each arm is one pair:
the internal gear (given pose, the driver) and its planet (the driven gear).

Each arm's pair is analysed in its own mesh frame fixed in the carrier: the internal
gear's centre at the origin, the planet's at (a, 0) along the carrier line O -> planet
axis of that arm. The DXF body frames are those of ``workflows.gear_pairs`` (``placed``):
the internal gear's body angle is the polar angle of its lobed pitch curve, where the
contact at lobe phase p lies at body angle -p / n (p = 0 at body angle 0); the planet's
body angle of that contact is -Q(p) (Q: the planet's turn relative to the carrier as the
mesh point advances from p = 0, ``gears.internal``). The contact lies on the line of
centres beyond the planet's axis (+x), so the internal gear's pose is q_1 = p / n and the
planet's q_2 = Q(p).

The pitch-curve model (``transplanter.simulate_differential``) gives only these nominal
poses, the reference the toothed result is compared with; where the teeth touch comes
from the outlines alone (``tca.free_play``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from plantmech.contact.outlines import GearOutline
from plantmech.contact.tca import FreePlay, free_play

TWO_PI = 2.0 * np.pi


@dataclass
class TransplanterContact:
    """Results over the carrier turn; per arm j (0-based, arm 1 is j = 0)."""

    psi: np.ndarray  # (T,) clockwise carrier angle (rad)
    arms: list[FreePlay]  # planet j against the internal gear (extra CCW turn, rad)
    lobe_phase: np.ndarray  # (J, T) lobe phase p of each arm's mesh point (rad)
    planet_lo: np.ndarray  # (J, T) extreme extra CCW turns of each planet (= its arm), rad
    planet_hi: np.ndarray
    tip_nominal: np.ndarray  # (J, T, 2) mm
    tip_lo: np.ndarray
    tip_hi: np.ndarray


def arm_tips(motion, arm: int, S: float, beta: float, lo, hi) -> list[np.ndarray]:
    """The arm's tip (complex, mm) at its nominal pose and turned by the planet's free-play
    ends ``lo`` and ``hi`` (rad): S from the planet axis at the planet angle + beta."""
    centre = motion.centre[0, arm]
    phi2 = motion.planet_angle[0, arm]
    return [centre + S * np.exp(1j * (phi2 + beta + extra)) for extra in (0.0, lo, hi)]


def tip_paths(tips) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(nominal, lo, hi) tip paths (J, T, 2) mm from every arm's ``arm_tips``."""
    z = np.asarray(tips)  # (J, 3, T) complex
    return tuple(np.stack([z[:, k].real, z[:, k].imag], axis=-1) for k in range(3))


def planet_turn(pair, phase: np.ndarray) -> np.ndarray:
    """Q(p) (rad): the planet's turn relative to the carrier as the mesh point advances
    from lobe phase 0 to ``phase`` (any real, rad; Q(p + 2 pi) = Q(p) + 2 pi for a closed
    pair), linear between the pair's dense samples (``LobedInternalPair.Q``, 4096 per
    lobe: within 1e-6 rad of its spline)."""
    phase = np.asarray(phase, dtype=float)
    turns = np.floor(phase / TWO_PI)
    return np.interp(phase - turns * TWO_PI, pair.p, pair.Q[0]) + TWO_PI * turns


def analyse_transplanter(design, gears: dict[str, GearOutline], steps: int = 720
                         ) -> TransplanterContact:
    """Drive the differential train of a ``rice_transplanter`` design through one carrier
    turn in ``steps`` steps, every planet tooth on tooth against the internal gear
    (``gears``: "internal", "planet")."""
    from plantmech.mechanisms.transplanter_design import design_param as _param
    from plantmech.mechanisms.transplanter_design import simulate_transplanter

    pair, motion, *_ = simulate_transplanter(design, samples=steps)
    n = pair.lobes
    k = design.drive.speed_ratio
    k = (n - 1) / n if k is None else k
    m = n * (1.0 - k)  # lobes the mesh point passes per carrier turn
    psi = motion.carrier_angle
    arms = motion.B.shape[1]
    phase0 = float(np.radians(_param(design, None, "initial_phase_deg")))
    a = float(pair.a[0])
    S = float(design.arm.S_mm)
    beta = float(np.radians(design.arm.beta_deg))
    results, phases = [], []
    lo_all, hi_all, tips = [], [], []
    for j in range(arms):
        ph = phase0 + m * psi + n * TWO_PI * j / arms
        fp = free_play(gears["planet"], gears["internal"], (a, 0.0), (0.0, 0.0),
                       planet_turn(pair, ph), ph / n)
        results.append(fp)
        phases.append(ph)
        lo = np.where(np.isfinite(fp.lo), fp.lo, np.nan)
        hi = np.where(np.isfinite(fp.hi), fp.hi, np.nan)
        lo_all.append(lo)
        hi_all.append(hi)
        tips.append(arm_tips(motion, j, S, beta, lo, hi))
    return TransplanterContact(psi, results, np.asarray(phases), np.asarray(lo_all),
                               np.asarray(hi_all), *tip_paths(tips))


def transplanter_record(c: TransplanterContact, limits: dict) -> dict:
    """Every figure of the analysis per arm and the checks against ``limits`` (keys
    transmission_error_deg, attitude_error_deg, tip_band_mm)."""
    from plantmech.contact.seeder import _pair_record

    psi_deg = np.degrees(c.psi)
    none = np.zeros(len(psi_deg), dtype=bool)
    pairs, chained = [], []
    for j, fp in enumerate(c.arms):
        p = _pair_record(f"internal -> planet (arm {j + 1})", fp, psi_deg, none, "planet",
                         "internal")
        pairs.append(p)
        chained.append(arm_record(j, c, psi_deg))
    rec = {"steps": len(c.psi), "step_deg": float(360.0 / len(c.psi)), "pairs": pairs,
           "arms": chained}
    te = [p["transmission_error_deg"]["max_abs_mid"] for p in pairs]
    te_max = max((t for t in te if t is not None), default=None)
    checks = chain_checks(pairs, chained, limits, te_max, "arms")
    rec["limits"] = limits
    rec["checks"] = [ch.as_dict() for ch in checks]
    rec["ok"] = all(ch.ok for ch in checks)
    return rec


def arm_record(j: int, c, psi_deg) -> dict:
    """Arm j's attitude error (its planet's extreme extra turns through the train, deg),
    the steps it is not held, the tip band and the tip's distance from the pitch-curve
    path (mm); ``c``: a contact analysis with planet_lo/hi and tip_lo/hi/nominal per arm
    (the differential and the K-H-V trains)."""
    from plantmech.contact.seeder import _spans

    lo, hi = c.planet_lo[j], c.planet_hi[j]
    held = np.isfinite(lo) & np.isfinite(hi)
    att = np.degrees(np.fmax(np.abs(lo), np.abs(hi)))
    band = np.hypot(*(c.tip_hi[j] - c.tip_lo[j]).T)
    dev = np.fmax(np.hypot(*(c.tip_hi[j] - c.tip_nominal[j]).T),
                  np.hypot(*(c.tip_lo[j] - c.tip_nominal[j]).T))
    return {
        "arm": j + 1,
        "arm_attitude_error_deg": {
            "max_abs": float(np.nanmax(att)) if held.any() else None,
            "lo_min": float(np.nanmin(np.degrees(lo))) if np.isfinite(lo).any() else None,
            "hi_max": float(np.nanmax(np.degrees(hi))) if np.isfinite(hi).any() else None},
        "arm_not_held_steps": int((~held).sum()),
        "arm_not_held": _spans(psi_deg, ~held),
        "tip_band_mm": {"max": float(np.nanmax(band)) if held.any() else None,
                        "median": float(np.nanmedian(band)) if held.any() else None},
        "tip_deviation_from_pitch_curve_path_mm": float(np.nanmax(dev))
        if held.any() else None}


def chain_checks(pairs: list, chained: list, limits: dict, te_max, scope: str) -> list:
    """The verdict's checks over every pair and arm of a transplanter's contact analysis:
    no jam, no contact lost, the transmission error ``te_max`` (deg, the caller's rule
    over its pairs), the arms' attitude error and tip band (every arm held); ``scope``
    names what the step counts run over ("arms", "pairs")."""
    from plantmech.objectives import Check

    lost = sum(p["contact_lost_steps"] for p in pairs)
    jams = sum(p["interference_steps"] for p in pairs)
    not_held = sum(a["arm_not_held_steps"] for a in chained)
    att = [a["arm_attitude_error_deg"]["max_abs"] for a in chained]
    bands = [a["tip_band_mm"]["max"] for a in chained]
    amax = None if None in att else max(att)
    bmax = None if None in bands else max(bands)
    return [
        Check(f"interference (steps jammed, all {scope})", float(jams), "0", jams == 0,
              "steps"),
        Check(f"contact lost (steps, all {scope})", float(lost), "0", lost == 0, "steps"),
        Check("transmission error, max |mid band|", te_max,
              f"<= {limits['transmission_error_deg']:g}",
              te_max is not None and te_max <= limits["transmission_error_deg"], "deg"),
        Check("arm attitude error, max", amax, f"<= {limits['attitude_error_deg']:g}",
              amax is not None and amax <= limits["attitude_error_deg"] and not_held == 0,
              "deg"),
        Check("tip band, max", bmax, f"<= {limits['tip_band_mm']:g}",
              bmax is not None and bmax <= limits["tip_band_mm"] and not_held == 0, "mm"),
    ]
