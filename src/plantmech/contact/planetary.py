"""A general planetary train (``mechanism = "planetary"``, ``trains/``) driven tooth on
tooth through one carrier turn: the written gear files (DXF outlines from ``plantmech
gears``) posed as the pitch-curve model poses their frames, every pair's free play from
the outlines alone (``tca.free_play``), chained along each arm's gears to the arm.

Frames. ``trains.gearing`` cuts every pair from its first gear's pitch curve in the
train's own body frames (the driver's frame; the follower's: its contact angle 0 touches
the driver's 0, theta_f = sense F(theta_d)). So in the carrier frame, gear k's outline
sits at its shaft (``BuiltTrain.shafts``) turned by its body angle alpha
(``TrainMotion.gear_angles`` for a follower, ``driver_angles`` for a pair's driver: a
compound gear carries its phase). The carrier frame turns as a whole, and free play is a
rotation about a gear's own centre, so the analysis runs in it.

Chaining (as the seeder's and the K-H-V trains', ``contact/seeder.py``, ``contact/khv.py``):
the sun is the reference (extra turn 0). A pair's follower gets the free play of its own
mesh with the driver at its nominal pose (the pair's record); through the train, the
driver is turned to both ends of its own play (the ends it got from the pairs before),
the follower carried along by the pair's instantaneous ratio sense r_d / r_f, and the
follower's ends are the extremes of the two. An idler or a compound shaft hands its ends
on to the next pair. The last follower's ends are the arm's attitude error and, with the
arm length, its tip band.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from plantmech.contact.outlines import GearOutline
from plantmech.contact.tca import FreePlay, free_play

TWO_PI = 2.0 * np.pi


@dataclass
class PlanetaryContact:
    """Results over the carrier turn (T steps); per arm j (0-based) and pair k."""

    psi: np.ndarray  # (T,) carrier angle from the start, in the carrier's sense (rad)
    names: list[tuple[str, str]]  # (driver, follower) gear names of every pair
    pairs: list[list[FreePlay]]  # [arm][pair]: follower against its driver at nominal
    planet_lo: np.ndarray  # (J, T) extreme extra CCW turns of each planet (= its arm), rad
    planet_hi: np.ndarray
    tip_nominal: np.ndarray  # (J, T, 2) mm
    tip_lo: np.ndarray
    tip_hi: np.ndarray


def gear_file_names(design) -> list[str]:
    """Every gear of a planetary design once, in train order (the DXF names that
    ``plantmech gears`` writes)."""
    from plantmech.trains.gearing import gear_names

    out: list[str] = []
    for pair in gear_names(design):
        out += [n for n in pair if n not in out]
    return out


def _ends(fp: FreePlay, shift=0.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(lo, hi, held): a flank that lost its contact takes the other's value (the gear
    rests on the flank it has), ``held`` False where the gear has no contact or jams."""
    lo, hi = fp.lo, fp.hi
    held = ~fp.jammed & (np.isfinite(lo) | np.isfinite(hi))
    lo_ = np.where(np.isfinite(lo), lo, np.nan_to_num(hi))
    hi_ = np.where(np.isfinite(hi), hi, np.nan_to_num(lo))
    return lo_ + shift, hi_ + shift, held


def analyse_planetary(design, gears: dict[str, GearOutline], steps: int = 720
                      ) -> PlanetaryContact:
    """Drive a planetary design's train through one carrier turn in ``steps`` steps, every
    pair of every arm tooth on tooth (``gears``: the outlines by gear name,
    ``gear_file_names``). ValueError (from ``trains``) when the train cannot be built."""
    from plantmech.trains.gearing import built_train, gear_names
    from plantmech.trains.model import simulate

    built = built_train(design)
    motion = simulate(built, samples=steps)
    names = gear_names(design)
    shafts = built.shafts[0]
    centres = [(float(z.real), float(z.imag)) for z in shafts]
    L = float(np.ravel(built.train.arm_length)[0])
    arms = motion.tip.shape[1]
    records, lo_all, hi_all, tips = [], [], [], []
    for j in range(arms):
        e_lo = e_hi = np.zeros(steps)  # the driver's play ends through the train (rad)
        held = np.ones(steps, dtype=bool)
        per_pair = []
        for k, law in enumerate(built.laws):
            driver, driven = gears[names[k][0]], gears[names[k][1]]
            q_d = motion.driver_angles[k][0, j]
            q_f = motion.gear_angles[k + 1][0, j]
            r_d, r_f = (r[0, j] for r in motion.contact_radii[k])
            ratio = law.sense * r_d / r_f  # d alpha_f / d alpha_d at the contact

            def play(extra, q_d=q_d, q_f=q_f, ratio=ratio, driver=driver, driven=driven,
                     k=k):
                shift = extra * ratio
                return free_play(driven, driver, centres[k + 1], centres[k], q_f + shift,
                                 q_d + extra), shift

            nominal, _ = play(0.0)
            per_pair.append(nominal)
            if k == 0:
                e_lo, e_hi, ok = _ends(nominal)
            else:
                (at_lo, s_lo), (at_hi, s_hi) = play(e_lo), play(e_hi)
                lo1, hi1, ok1 = _ends(at_lo, s_lo)
                lo2, hi2, ok2 = _ends(at_hi, s_hi)
                e_lo, e_hi, ok = np.fmin(lo1, lo2), np.fmax(hi1, hi2), ok1 & ok2
            held &= ok
        lo = np.where(held, e_lo, np.nan)
        hi = np.where(held, e_hi, np.nan)
        centre, beta = motion.centre[0, j], motion.arm_angle[0, j]
        tips.append([centre + L * np.exp(1j * (beta + extra)) for extra in (0.0, lo, hi)])
        records.append(per_pair)
        lo_all.append(lo)
        hi_all.append(hi)
    z = np.asarray(tips)  # (J, 3, T)
    nominal, tip_lo, tip_hi = (np.stack([z[:, i].real, z[:, i].imag], axis=-1)
                               for i in range(3))
    return PlanetaryContact(motion.carrier_angle, names, records, np.asarray(lo_all),
                            np.asarray(hi_all), nominal, tip_lo, tip_hi)


def planetary_record(c: PlanetaryContact, limits: dict) -> dict:
    """Every pair of every arm (transmission error, backlash band, contact loss, jams),
    every arm through the train (attitude error, tip band) and the checks against
    ``limits`` (keys transmission_error_deg, attitude_error_deg, tip_band_mm), as the
    transplanters' records."""
    from plantmech.contact.seeder import _pair_record
    from plantmech.contact.transplanter import arm_record, chain_checks

    psi_deg = np.degrees(c.psi)
    none = np.zeros(len(psi_deg), dtype=bool)
    arms = len(c.pairs)
    pairs, chained = [], []
    for j in range(arms):
        for k, fp in enumerate(c.pairs[j]):
            driver, driven = c.names[k]
            label = f"{driver} -> {driven}" + (f" (arm {j + 1})" if arms > 1 else "")
            pairs.append(_pair_record(label, fp, psi_deg, none, driven, driver))
        chained.append(arm_record(j, c, psi_deg))
    rec = {"steps": len(c.psi), "step_deg": float(360.0 / len(c.psi)), "pairs": pairs,
           "arms": chained}
    te = [p["transmission_error_deg"]["max_abs_mid"] for p in pairs]
    te_max = None if None in te else max(te)
    checks = chain_checks(pairs, chained, limits, te_max, "pairs")
    rec["limits"] = limits
    rec["checks"] = [ch.as_dict() for ch in checks]
    rec["ok"] = all(ch.ok for ch in checks)
    return rec


__all__ = ["PlanetaryContact", "analyse_planetary", "gear_file_names", "planetary_record"]
