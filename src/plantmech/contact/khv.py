"""The rice transplanter's K-H-V train driven tooth on tooth (seed 001, Fig. 1): a fixed
non-circular sun, the carrier driven, and per arm a middle gear (on the carrier line at a
from O) and a planet (at 2 a) carrying the planting arm. The sun drives each middle gear,
each middle gear drives its planet; the arms do not interact, so every arm is two pairs
chained like the seeder's stages (``contact/seeder.py``).

Body frames (those ``workflows.gear_pairs`` cuts the gears in): the sun's body frame is
the absolute frame (it never turns). The middle gear's body angle 0 is its contact with
the sun when the sun's contact is at ``th0``, the first sample of the sun's pitch curve
at or above absolute angle 0 (its curve is sampled at carrier0 - sigma on the pair's
dense grid); its contact with the sun then moves to body angle
phi_m = M(sigma) - M(sigma_0) (M: the middle's clockwise turn relative to the carrier,
``KHVPair.M``; sigma_0 = carrier0 - th0), and its contact with the planet is opposite,
at phi_m + pi. The planet's body angle 0 is its contact with the middle when phi_m = 0;
its contact is then at -(G(sigma) - G(sigma_0)) (G: the planet's counter-clockwise turn
relative to the carrier as a function of the contact progress, d G / d sigma =
[r_s / (a - r_s)](sigma) [(a - r_s) / r_s](sigma'), M(sigma') = M(sigma) + pi).

Mesh frames, fixed in the carrier, x along arm j's carrier line (absolute angle
phi_H = carrier0 - psi - 2 pi j / J): sun - middle with the sun at the origin and the
middle at (a, 0); middle - planet with the middle at the origin and the planet at (a, 0).
Poses (rad, CCW, applied to the body-frame outlines): sun -phi_H; middle pi - phi_m in
both frames; planet pi - phi_p. The pitch-curve model gives only these nominal poses, the
reference the toothed result is compared with; where the teeth touch comes from the
outlines alone (``tca.free_play``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.interpolate import CubicSpline

from plantmech.contact.outlines import GearOutline
from plantmech.contact.tca import FreePlay, free_play
from plantmech.contact.transplanter import arm_record, arm_tips, chain_checks, tip_paths

TWO_PI = 2.0 * np.pi
KHV_GEARS = ("sun", "middle", "planet")


@dataclass
class KHVContact:
    """Results over the carrier turn; per arm j (0-based, arm 1 is j = 0)."""

    psi: np.ndarray  # (T,) clockwise carrier angle (rad)
    stage1: list[FreePlay]  # middle j against the sun (extra CCW turn of the middle, rad)
    stage2: list[FreePlay]  # planet j against its middle at the middle's nominal pose
    stage2_lo: list[FreePlay]  # ... with the middle turned to stage 1's lo
    stage2_hi: list[FreePlay]  # ... to stage 1's hi
    planet_lo: np.ndarray  # (J, T) extreme extra CCW turns of each planet (= its arm), rad
    planet_hi: np.ndarray
    tip_nominal: np.ndarray  # (J, T, 2) mm
    tip_lo: np.ndarray
    tip_hi: np.ndarray


def khv_frames(pair, carrier0: float):
    """The contact-progress functions of the gear files' body frames for a KHVPair
    (one design, ``pair.sigma`` its dense grid): sigma_0 (rad), and M, G as callables of
    any real sigma (rad; M(sigma + 2 pi) = M(sigma) + 2 pi, likewise G for a closed
    train)."""
    sg = pair.sigma
    rs = pair.r_sun[0]
    a = float(pair.a[0])
    M = pair.M[0]
    th0_k = int(np.argmin(np.mod(carrier0 - sg[:-1], TWO_PI)))
    sigma0 = float(sg[th0_k])
    # the planet's rate by contact progress (as simulate_khv integrates it)
    target = np.mod(M + 0.5 * M[-1], M[-1])
    rs2 = np.interp(np.interp(target, M, sg), sg, rs)
    rate = (rs / (a - rs)) * (a - rs2) / rs2
    G = CubicSpline(sg, rate).antiderivative()(sg)

    def periodic(table):
        step = float(table[-1])

        def f(s):
            s = np.asarray(s, dtype=float)
            turns = np.floor(s / TWO_PI)
            return np.interp(s - turns * TWO_PI, sg, table) + step * turns
        return f

    return sigma0, periodic(M), periodic(G)


def analyse_khv(design, gears: dict[str, GearOutline], steps: int = 720) -> KHVContact:
    """Drive the K-H-V train of a ``rice_transplanter_khv`` design through one carrier
    turn in ``steps`` steps, every arm's middle gear and planet tooth on tooth
    (``gears``: "sun", "middle", "planet")."""
    from plantmech.mechanisms.transplanter_design import simulate_transplanter

    pair, motion, *_ = simulate_transplanter(design, samples=steps)
    carrier0 = float(np.radians(design.carrier.initial_angle_deg))
    sigma0, M, G = khv_frames(pair, carrier0)
    psi = motion.carrier_angle
    arms = motion.B.shape[1]
    a = float(pair.a[0])
    S = float(design.arm.S_mm)
    beta = float(np.radians(design.arm.beta_deg))
    s1, s2, s2lo, s2hi = [], [], [], []
    lo_all, hi_all, tips = [], [], []
    for j in range(arms):
        sigma = psi + TWO_PI * j / arms
        phi_h = carrier0 - sigma
        phi_m = M(sigma) - M(sigma0)
        phi_p = -(G(sigma) - G(sigma0))
        q_sun = -phi_h
        q_mid = np.pi - phi_m
        q_pl = np.pi - phi_p
        st1 = free_play(gears["middle"], gears["sun"], (a, 0.0), (0.0, 0.0), q_mid, q_sun)
        # the planet's turn per middle turn (both CCW), -r_m / r_p at the planet contact
        h = 1e-4
        ratio = -(G(sigma + h) - G(sigma - h)) / (M(sigma + h) - M(sigma - h))

        def stage2(extra, q_mid=q_mid, q_pl=q_pl, ratio=ratio):
            shift = np.asarray(extra) * ratio
            fp = free_play(gears["planet"], gears["middle"], (a, 0.0), (0.0, 0.0),
                           q_pl + shift, q_mid + extra)
            for key in ("lo", "hi", "reference"):
                setattr(fp, key, getattr(fp, key) + shift)
            return fp

        st2 = stage2(0.0)
        lo1 = np.where(np.isfinite(st1.lo), st1.lo, np.nan_to_num(st1.hi))
        hi1 = np.where(np.isfinite(st1.hi), st1.hi, np.nan_to_num(st1.lo))
        lo2, hi2 = stage2(lo1), stage2(hi1)
        p_lo = np.fmin(lo2.lo, hi2.lo)
        p_hi = np.fmax(lo2.hi, hi2.hi)
        # a middle that jams or loses contact on both flanks leaves the arm unheld
        bad1 = st1.jammed | ~(np.isfinite(st1.lo) | np.isfinite(st1.hi))
        p_lo = np.where(bad1, np.nan, p_lo)
        p_hi = np.where(bad1, np.nan, p_hi)
        s1.append(st1)
        s2.append(st2)
        s2lo.append(lo2)
        s2hi.append(hi2)
        lo_all.append(p_lo)
        hi_all.append(p_hi)
        tips.append(arm_tips(motion, j, S, beta, p_lo, p_hi))
    return KHVContact(psi, s1, s2, s2lo, s2hi, np.asarray(lo_all), np.asarray(hi_all),
                      *tip_paths(tips))


def khv_record(c: KHVContact, limits: dict) -> dict:
    """Every figure of the analysis per arm (both pairs, the chained arm) and the checks
    against ``limits`` (keys transmission_error_deg, attitude_error_deg, tip_band_mm)."""
    from plantmech.contact.seeder import _pair_record

    psi_deg = np.degrees(c.psi)
    none = np.zeros(len(psi_deg), dtype=bool)
    pairs, chained = [], []
    for j in range(len(c.stage1)):
        pairs.append(_pair_record(f"sun -> middle (arm {j + 1})", c.stage1[j], psi_deg, none,
                                  "middle", "sun"))
        pairs.append(_pair_record(f"middle -> planet (arm {j + 1})", c.stage2[j], psi_deg,
                                  none, "planet", "middle"))
        chained.append(arm_record(j, c, psi_deg))
    rec = {"steps": len(c.psi), "step_deg": float(360.0 / len(c.psi)), "pairs": pairs,
           "arms": chained}
    te = [p["transmission_error_deg"]["max_abs_mid"] for p in pairs]
    te_max = None if None in te else max(te)
    rec["checks"] = [ch.as_dict() for ch in chain_checks(pairs, chained, limits, te_max,
                                                         "pairs")]
    rec["limits"] = limits
    rec["ok"] = all(ch["ok"] for ch in rec["checks"])
    return rec
