"""The sugarcane seeder's train driven tooth on tooth (seed 000): sun fixed, carrier
driven; the sun drives gear 2, gear 3 (on gear 2's shaft) drives the planet, which
carries the arm.

Every pair is analysed in its own mesh frame, fixed in the carrier: the driving
gear A of ``plantmech gears`` (gear 2, gear 3) at the origin, its mate (sun, planet) at
(a, 0). A gear's pose is its rotation q (rad, CCW) applied to its body-frame outline;
the DXF body frames are those of ``workflows.gear_pairs``: gears 2 and 3 share the
train's body frame, the sun's / planet's body angle 0 is its contact at the start of
the pair's rolling (gear 3's contact at the curve's ``theta0``; gear 2's where it is held
through the toothless dwell, ``seeder_forward.sun_rolling_start``, else its ``theta0``).

The nominal poses come from the pitch-curve model (``seeder_forward.simulate``) only as
the reference the toothed result is compared with; where the teeth touch comes from the
outlines alone (``tca.free_play``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from plantmech.contact.outlines import GearOutline
from plantmech.contact.tca import FreePlay, free_play

TWO_PI = 2.0 * np.pi


@dataclass
class SeederContact:
    """Results over the carrier turn (arrays over the steps)."""

    psi: np.ndarray  # clockwise carrier angle (rad)
    in_dwell: np.ndarray
    stage1: FreePlay  # gear 2 against the sun (extra CCW turn of gears 2-3, rad)
    stage2: FreePlay  # planet against gear 3 at its nominal pose (rad)
    stage2_lo: FreePlay  # planet against gear 3 turned to stage 1's lo
    stage2_hi: FreePlay  # ... to stage 1's hi
    planet_lo: np.ndarray  # extreme extra CCW turns of the planet (= the arm), rad
    planet_hi: np.ndarray
    tip_nominal: np.ndarray  # (T, 2) mm
    tip_lo: np.ndarray
    tip_hi: np.ndarray
    carrier_abs: np.ndarray
    arm_nominal: np.ndarray
    stage1_rate: np.ndarray  # d psi_2 / d psi (nominal)
    stage2_rate: np.ndarray  # d psi_4 / d psi_2
    planet_rel: np.ndarray
    gear2_angle: np.ndarray


def _rolling_turn(curve, theta0: float, contact: float, a: float, n: int = 20001) -> float:
    """Mate's turn (rad) while the gear's contact moves from theta0 to ``contact``
    (forward, mod 2 pi): integral of r / (a - r)."""
    span = float(np.mod(contact - theta0, TWO_PI))
    if span < 1e-15:
        return 0.0
    t = np.linspace(0.0, span, n)
    r = curve(theta0 + t)
    f = r / (a - r)
    return float(np.sum(0.5 * (f[1:] + f[:-1]) * np.diff(t)))


def seeder_train(design):
    """The SeederTrain of a design (its [train], or the inverse design of its
    trajectory), as ``workflows.gear_pairs`` builds the gears from it."""
    from plantmech.mechanisms.seeder_trains import (
        inverse_design_of,
        train_from_design,
        train_from_inverse,
    )

    if design.train is not None:
        return train_from_design(design)[0]
    _, res = inverse_design_of(design)
    if not res.feasible:
        raise ValueError("the trajectory's inverse design is infeasible: no gear train")
    return train_from_inverse(res)


def file_frames(train, nominal) -> dict:
    """The gear files' frames on the carrier at the start (rad, in the carrier's frame:
    O -> planet axis along x), as ``analyse_seeder`` poses the outlines: each driving gear
    (2, 3) in its mesh frame turned by minus its contact body angle (the contact faces
    the mate), the planet turned by pi less its rolling from ``theta0``. Returns
    gear 2's, gear 3's and the planet's frame angles, gear 3's minus gear 2's (the two
    share a shaft, turned by this constant) and the planet's minus the arm's (constant:
    the arm is fixed to the planet). ``nominal``: ``seeder_forward.simulate``'s motion."""
    from plantmech.mechanisms.seeder_forward import shaft_offset

    shaft = train.a1 * np.exp(1j * shaft_offset(train))
    to_sun, to_planet = np.angle(-shaft), np.angle(train.L1 - shaft)
    u0 = float(nominal.gear2_angle[0])
    gear2 = to_sun - (train.gear2_contact0 + u0)
    gear3 = to_planet - (train.gear3_contact0 + u0)
    planet0 = -_rolling_turn(train.gear3, train.gear3.theta0, train.gear3_contact0, train.a2)
    planet = to_planet + np.pi - planet0 + float(nominal.planet_rel[0])
    arm = float(nominal.arm_angle[0]) - float(train.carrier0)
    return {"gear2": float(gear2), "gear3": float(gear3), "planet": float(planet),
            "gear3_minus_gear2": float(gear3 - gear2), "planet_minus_arm": float(planet - arm)}


def analyse_seeder(train, gears: dict[str, GearOutline], steps: int = 720) -> SeederContact:
    """Drive the toothed train through one carrier turn in ``steps`` steps."""
    from plantmech.mechanisms.seeder_forward import simulate, sun_rolling_start
    from plantmech.mechanisms.three_bar import tip_position

    nom = simulate(train, samples=steps)
    psi = nom.carrier_angle
    g2 = train.gear2_contact0 + nom.gear2_angle
    # sun: fixed, so it turns +psi relative to the carrier (mesh frames are carrier-fixed)
    sun0 = -_rolling_turn(train.gear2, sun_rolling_start(train), train.gear2_contact0,
                          train.a1)
    q_sun = np.pi - (sun0 - psi)
    q_gear2 = -g2
    s1 = free_play(gears["gear2"], gears["sun"], (0.0, 0.0), (train.a1, 0.0), q_gear2, q_sun)
    planet0 = -_rolling_turn(train.gear3, train.gear3.theta0, train.gear3_contact0, train.a2)
    q_planet = np.pi - (planet0 - nom.planet_rel)
    q_gear3 = -(train.gear3_contact0 + nom.gear2_angle)

    def stage2(extra):
        # the planet's reference follows gear 3's extra turn by the nominal ratio
        # (external pair: the other way)
        shift = -np.asarray(extra) * nom.stage2_rate
        fp = free_play(gears["planet"], gears["gear3"], (train.a2, 0.0), (0.0, 0.0),
                       q_planet + shift, q_gear3 + extra)
        for key in ("lo", "hi", "reference"):
            setattr(fp, key, getattr(fp, key) + shift)
        return fp

    s2 = stage2(0.0)
    lo1 = np.where(np.isfinite(s1.lo), s1.lo, np.nan_to_num(s1.hi))
    hi1 = np.where(np.isfinite(s1.hi), s1.hi, np.nan_to_num(s1.lo))
    s2lo, s2hi = stage2(lo1), stage2(hi1)
    p_lo = np.fmin(s2lo.lo, s2hi.lo)
    p_hi = np.fmax(s2lo.hi, s2hi.hi)
    carrier_abs = train.carrier0 - psi
    arm = nom.arm_angle
    tip_lo = tip_position(train.L1, train.L2, carrier_abs, arm + p_lo)
    tip_hi = tip_position(train.L1, train.L2, carrier_abs, arm + p_hi)
    return SeederContact(psi, nom.in_dwell, s1, s2, s2lo, s2hi, p_lo, p_hi, nom.tip, tip_lo,
                         tip_hi, carrier_abs, arm, nom.stage1_rate, nom.stage2_rate,
                         nom.planet_rel, nom.gear2_angle)


def _spans(psi_deg: np.ndarray, mask: np.ndarray, where=None) -> list[dict]:
    """Runs of ``mask`` over the steps as carrier-angle spans (deg), with ``where(i)`` (a
    dict locating the first step of the run) added."""
    from plantmech.geometry.periodic import cyclic_runs

    out = []
    for a, b in cyclic_runs(np.asarray(mask, dtype=bool)):
        d = {"carrier_angle_deg": [round(float(psi_deg[a]), 3), round(float(psi_deg[b]), 3)],
             "steps": int((b - a) % len(mask) + 1)}
        if where is not None:
            d.update(where(a))
        out.append(d)
    return out


def _pair_record(name: str, fp: FreePlay, psi_deg, skip, driven: str, driver: str) -> dict:
    """Transmission error, backlash band, contact loss, jams and double contact of one
    pair (driven gear's extra turn, deg) outside the ``skip`` steps (the dwell)."""
    lo, hi = np.degrees(fp.lo), np.degrees(fp.hi)
    use = ~skip
    both = use & np.isfinite(lo) & np.isfinite(hi)
    te = np.where(both, 0.5 * (lo + hi), np.nan)
    band = np.where(both, hi - lo, np.nan)
    lost_lo = use & ~fp.jammed & ~np.isfinite(lo)
    lost_hi = use & ~fp.jammed & ~np.isfinite(hi)

    def at(flank):
        # where the contact is lost: the driven gear's body angle facing the driver
        return lambda i: {"flank": flank, f"{driven}_body_angle_deg": round(float(np.degrees(
            fp.mesh_driven_angle[i])), 2), f"{driven}_tooth": int(fp.mesh_driven_tooth[i])}

    def jam_at(i):
        k = (i - 1) % len(psi_deg)
        return {f"{driven}_body_angle_deg": round(float(np.degrees(fp.mesh_driven_angle[i])),
                                                  2),
                f"{driven}_tooth": int(fp.mesh_driven_tooth[i]),
                f"{driver}_tooth_in_contact_before": int(fp.hi_driver_tooth[k])}

    def fmax(x):
        return float(np.nanmax(np.abs(x))) if np.isfinite(x).any() else None

    def worst(x):
        # where the largest |mid-band| error is: carrier angle, the driven gear's body
        # angle facing the driver and its tooth there
        if not np.isfinite(x).any():
            return None
        i = int(np.nanargmax(np.abs(x)))
        return {"carrier_angle_deg": round(float(psi_deg[i]), 3),
                f"{driven}_body_angle_deg": round(float(np.degrees(fp.mesh_driven_angle[i])),
                                                  2),
                f"{driven}_tooth": int(fp.mesh_driven_tooth[i])}

    return {
        "pair": name, "driver": driver, "driven": driven,
        "steps_analysed": int(use.sum()),
        "transmission_error_deg": {
            "max_abs_mid": fmax(te),
            "max_abs_mid_at": worst(te),
            "min_mid": float(np.nanmin(te)) if both.any() else None,
            "max_mid": float(np.nanmax(te)) if both.any() else None,
            "max_abs_lo_flank": fmax(np.where(use, lo, np.nan)),
            "max_abs_hi_flank": fmax(np.where(use, hi, np.nan))},
        "backlash_band_deg": {"min": float(np.nanmin(band)) if both.any() else None,
                              "max": float(np.nanmax(band)) if both.any() else None,
                              "median": float(np.nanmedian(band)) if both.any() else None},
        "contact_lost_steps": int((lost_lo | lost_hi).sum()),
        "contact_lost": _spans(psi_deg, lost_lo, at("lo")) + _spans(psi_deg, lost_hi,
                                                                     at("hi")),
        "interference_steps": int((use & fp.jammed).sum()),
        "interference": _spans(psi_deg, use & fp.jammed, jam_at),
        "reference_overlap_steps": int((use & fp.overlapped).sum()),
        "double_contact_fraction": {
            "lo_flank": float((fp.double_lo & use).sum() / max(use.sum(), 1)),
            "hi_flank": float((fp.double_hi & use).sum() / max(use.sum(), 1))},
    }


def seeder_record(c: SeederContact, train, limits: dict, carrier_speed_deg_s: float = 360.0
                  ) -> dict:
    """Every figure of the analysis and the checks against ``limits`` (keys
    transmission_error_deg, attitude_error_deg, tip_band_mm)."""
    from plantmech.objectives import Check

    psi_deg = np.degrees(c.psi)
    dwell = c.in_dwell
    none = np.zeros_like(dwell)
    p1 = _pair_record("sun -> gear2", c.stage1, psi_deg, dwell, "gear2", "sun")
    p2 = _pair_record("gear3 -> planet", c.stage2, psi_deg, none, "planet", "gear3")
    held = np.isfinite(c.planet_lo) & np.isfinite(c.planet_hi)
    att = np.degrees(np.fmax(np.abs(c.planet_lo), np.abs(c.planet_hi)))
    band = np.hypot(*(c.tip_hi - c.tip_lo).T)
    dev = np.fmax(np.hypot(*(c.tip_hi - c.tip_nominal).T),
                  np.hypot(*(c.tip_lo - c.tip_nominal).T))
    rec = {"steps": len(c.psi), "step_deg": float(360.0 / len(c.psi)),
           "pairs": [p1, p2],
           "chained": {
               "arm_attitude_error_deg": {"max_abs": float(np.nanmax(att)) if held.any()
                                          else None,
                                          "lo_min": float(np.nanmin(np.degrees(c.planet_lo))),
                                          "hi_max": float(np.nanmax(np.degrees(c.planet_hi)))},
               "arm_not_held_steps": int((~held).sum()),
               "arm_not_held": _spans(psi_deg, ~held),
               "tip_band_mm": {"max": float(np.nanmax(band)) if held.any() else None,
                               "median": float(np.nanmedian(band)) if held.any() else None},
               "tip_deviation_from_pitch_curve_path_mm": float(np.nanmax(dev))
               if held.any() else None}}
    omega = np.radians(carrier_speed_deg_s)
    if train.dwell_start is not None and dwell.any():
        fp = c.stage1
        free = np.degrees(fp.hi - fp.lo)[dwell]
        idx = np.flatnonzero(dwell)
        first, last = int(idx[0]), int(idx[-1])
        before, after = (first - 1) % len(dwell), (last + 1) % len(dwell)
        rec["dwell"] = {
            "carrier_angle_deg": [float(psi_deg[first]), float(psi_deg[last])],
            "locked_steps": int(np.isfinite(free).sum()), "steps": int(dwell.sum()),
            "gear2_free_play_deg": {"max": float(np.nanmax(free)) if np.isfinite(free).any()
                                    else None},
            "what_holds_the_arm": "the sun's toothless arc (turned down to its root) faces "
                                  "gear 2, which is cut with teeth all round (no concave "
                                  "locking arc): gear 2 is held only where a sun tooth at "
                                  "an end of the arc touches it (locked steps); the free "
                                  "play above is the arm's play (through gear 3 and the "
                                  "planet)",
            # held gear 2 against the sun's teeth at the arc's ends: interference
            "jammed_steps": int((fp.jammed & dwell).sum()),
            "jammed": _spans(psi_deg, fp.jammed & dwell, lambda i: {
                "gear2_body_angle_deg": round(float(np.degrees(fp.mesh_driven_angle[i])), 2),
                "gear2_tooth": int(fp.mesh_driven_tooth[i])}),
            # gears 2-3 stop and restart: their speed relative to the carrier jumps
            "gear2_speed_jump_rad_s": {
                "at_start": float(c.stage1_rate[before] * omega),
                "at_end": float(c.stage1_rate[after] * omega)},
            "arm_speed_jump_rad_s": {
                "at_start": float(c.stage1_rate[before] * c.stage2_rate[before] * omega),
                "at_end": float(c.stage1_rate[after] * c.stage2_rate[after] * omega)},
        }
    te_max = max((p["transmission_error_deg"]["max_abs_mid"] or 0.0) for p in (p1, p2))
    lost = p1["contact_lost_steps"] + p2["contact_lost_steps"]
    jams = p1["interference_steps"] + p2["interference_steps"]
    amax = rec["chained"]["arm_attitude_error_deg"]["max_abs"]
    bmax = rec["chained"]["tip_band_mm"]["max"]
    checks = [
        Check("interference (steps jammed)", float(jams), "0", jams == 0, "steps"),
        Check("contact lost (steps, outside the dwell)", float(lost), "0", lost == 0, "steps"),
        Check("transmission error, max |mid band|", te_max,
              f"<= {limits['transmission_error_deg']:g}",
              te_max <= limits["transmission_error_deg"], "deg"),
        Check("arm attitude error, max", amax, f"<= {limits['attitude_error_deg']:g}",
              amax is not None and amax <= limits["attitude_error_deg"]
              and rec["chained"]["arm_not_held_steps"] == 0, "deg"),
        Check("tip band, max", bmax, f"<= {limits['tip_band_mm']:g}",
              bmax is not None and bmax <= limits["tip_band_mm"]
              and rec["chained"]["arm_not_held_steps"] == 0, "mm"),
    ]
    if "dwell" in rec:
        d = rec["dwell"]
        checks.append(Check("dwell: arm held (locked steps)", float(d["locked_steps"]),
                            f"= {d['steps']}", d["locked_steps"] == d["steps"], "steps"))
    rec["limits"] = limits
    rec["checks"] = [ch.as_dict() for ch in checks]
    rec["ok"] = all(ch.ok for ch in checks)
    return rec
