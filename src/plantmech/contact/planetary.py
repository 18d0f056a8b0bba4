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

A toothless dwell (``trains.model``; seed 000's sector): the cut sun is the partial gear of
``trains.gearing`` in its own frame (contact angle 0 at the follower's lock), turned into the
train's (``_toothless_sun``); the first pair's record leaves the dwell's steps out and the
``dwell`` record (as ``contact/seeder.py``'s) says where the follower is held by the sun's
teeth at the ends of the toothless arc (locked) or jams against them. The loads through a
dwell (``planetary_loads``) get the seeder's treatment (``loads.dwell_impacts``): its ends
are impacts of the rigid model, reported each, the energy balance checked between them.
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

    psi: np.ndarray  # (T,) carrier angle from the start, in the carrier's sense (rad); with
    # the carrier held (a pair on fixed centres: the frame) the driver's turn (the sun's)
    names: list[tuple[str, str]]  # (driver, follower) gear names of every pair
    pairs: list[list[FreePlay]]  # [arm][pair]: follower against its driver at nominal
    planet_lo: np.ndarray  # (J, T) extreme extra CCW turns of each planet (= its arm), rad
    planet_hi: np.ndarray
    tip_nominal: np.ndarray  # (J, T, 2) mm
    tip_lo: np.ndarray
    tip_hi: np.ndarray
    dwell: np.ndarray | None = None  # (J, T): the first pair's toothless dwell (seed 000)
    held: bool = False  # the carrier is held: the frame of a pair on fixed centres

    @property
    def turning(self) -> str:
        """What ``psi`` turns (the word of every printed angle and axis): "driver" with
        the carrier held, where nothing turns at the carrier, else "carrier"."""
        return "driver" if self.held else "carrier"


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
    sun_frame, dwell = _toothless_sun(built, motion)
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
            q_d = motion.driver_angles[k][0, j] + (sun_frame if k == 0 else 0.0)
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
                            np.asarray(hi_all), nominal, tip_lo, tip_hi, dwell,
                            held=bool(built.train.carrier_held))


def _dwell_record(c: PlanetaryContact, j: int, psi_deg, spans) -> dict:
    """Arm j through the first pair's toothless dwell, as the seeder's record
    (``contact/seeder.py``): the steps its follower is held (locked: a free play both ways
    against the sun), the play, and where a sun tooth at an end of the toothless arc jams
    it."""
    fp, held = c.pairs[j][0], c.dwell[j]
    driver, driven = c.names[0]
    free = np.degrees(fp.hi - fp.lo)[held]
    idx = np.flatnonzero(held)
    return {
        "arm": j + 1, "held_gear": driven,
        "carrier_angle_deg": [float(psi_deg[idx[0]]), float(psi_deg[idx[-1]])],
        "steps": int(held.sum()), "locked_steps": int(np.isfinite(free).sum()),
        "free_play_deg": {"max": float(np.nanmax(free)) if np.isfinite(free).any()
                          else None},
        "what_holds_the_arm": f"the {driver}'s toothless arc (turned down to its root) faces "
                              f"{driven}, which is cut with teeth all round: {driven} is held "
                              f"only where a {driver} tooth at an end of the arc touches it "
                              "(locked steps)",
        "jammed_steps": int((fp.jammed & held).sum()),
        "jammed": spans(psi_deg, fp.jammed & held, lambda i: {
            f"{driven}_body_angle_deg": round(float(np.degrees(fp.mesh_driven_angle[i])), 2),
            "tooth": int(fp.mesh_driven_tooth[i])})}


def _toothless_sun(built, motion) -> tuple[float, np.ndarray | None]:
    """(the sun outline's frame turn (rad), the dwell steps (J, T) or None). Without a dwell
    the sun is cut in the train's frame (0). With one (the first pair: a fixed sun, a given
    follower, ``trains.model``) ``plantmech gears`` cuts the follower from its lock point
    and the sun as its partial mate (``trains.gearing``), whose contact angle 0 touches the
    follower's lock: for a clockwise carrier that is where the sun's rolling arc resumes,
    theta_1 past its lock contact theta_L, for a counter-clockwise one the lock itself; so a
    point of the cut sun at angle phi lies at body angle phi + theta_L - theta_1 (resp.
    phi + theta_L) of the train's sun."""
    gap = built.toothless[0] if built.toothless else None
    if gap is None:
        return 0.0, None
    spec = built.train.pairs[0]
    if spec.kind != "external":
        raise ValueError(f"field 'train.pairs.0.dwell': a toothless dwell on an {spec.kind} "
                         "pair is not cut by 'plantmech gears' yet, so not driven either")
    law = built.laws[0]
    theta_lock = float(np.ravel(spec.direction)[0]) + law.driver_direction \
        - float(gap.lock[0, 0, 0])
    width = float(gap.width[0, 0, 0])
    frame = theta_lock - (width if built.train.carrier_sense < 0 else 0.0)
    _, meshes = gap.meshing(motion.driver_angles[0][:1])
    return frame, ~meshes[0]


def planetary_record(c: PlanetaryContact, limits: dict) -> dict:
    """Every pair of every arm (transmission error, backlash band, contact loss, jams),
    every arm through the train (attitude error, tip band) and the checks against
    ``limits`` (keys transmission_error_deg, attitude_error_deg, tip_band_mm), as the
    transplanters' records."""
    from plantmech.contact.seeder import _pair_record, _spans
    from plantmech.contact.transplanter import arm_record, chain_checks
    from plantmech.objectives import Check

    psi_deg = np.degrees(c.psi)
    none = np.zeros(len(psi_deg), dtype=bool)
    arms = len(c.pairs)
    pairs, chained, dwells = [], [], []
    for j in range(arms):
        for k, fp in enumerate(c.pairs[j]):
            driver, driven = c.names[k]
            label = f"{driver} -> {driven}" + (f" (arm {j + 1})" if arms > 1 else "")
            skip = c.dwell[j] if k == 0 and c.dwell is not None else none
            pairs.append(_pair_record(label, fp, psi_deg, skip, driven, driver))
        chained.append(arm_record(j, c, psi_deg))
        if c.dwell is not None and c.dwell[j].any():
            dwells.append(_dwell_record(c, j, psi_deg, _spans))
    rec = {"steps": len(c.psi), "step_deg": float(360.0 / len(c.psi)), "pairs": pairs,
           "arms": chained,
           # what every carrier_angle_deg of the record measures: the carrier's turn, or
           # with the carrier held (the frame of a pair on fixed centres) the driver's
           "angles_of": c.turning}
    if c.held:
        rec["carrier"] = ("held: the frame (fixed centres); the angles are the driver's "
                          "(the sun's) turn")
    te = [p["transmission_error_deg"]["max_abs_mid"] for p in pairs]
    te_max = None if None in te else max(te)
    checks = chain_checks(pairs, chained, limits, te_max, "pairs")
    if dwells:
        # the seeder's record (contact/seeder.py) for arm 1, every arm's counts summed
        rec["dwell"] = dict(dwells[0], arms=dwells,
                            locked_steps=sum(d["locked_steps"] for d in dwells),
                            steps=sum(d["steps"] for d in dwells),
                            jammed_steps=sum(d["jammed_steps"] for d in dwells))
        d = rec["dwell"]
        checks.append(Check("dwell: arm held (locked steps)", float(d["locked_steps"]),
                            f"= {d['steps']}", d["locked_steps"] == d["steps"], "steps"))
    rec["limits"] = limits
    rec["checks"] = [ch.as_dict() for ch in checks]
    rec["ok"] = all(ch.ok for ch in checks)
    return rec


__all__ = ["PlanetaryContact", "analyse_planetary", "gear_file_names", "planetary_record"]


def _combined(parts: list[tuple[float, np.ndarray, float]]) -> tuple[float, np.ndarray, float]:
    """(mass kg, centroid m, inertia about it kg m^2) of rigidly joined plates, each given
    in the common frame."""
    m = sum(p[0] for p in parts)
    c = sum(p[0] * p[1] for p in parts) / m
    j = sum(p[2] + p[0] * (p[1] - c) @ (p[1] - c) for p in parts)
    return float(m), c, float(j)


def _mesh_law_samples(law, spec, u0: float, n: int = 2048, toothless=None):
    """The follower's body angle alpha_f (rad) as a function of its driver's alpha_d = u
    over one driver turn from ``u0`` (``trains.model.mesh``, the pair mapping of
    ``simulate``, with the pair's toothless arc if it has one: alpha_f is then constant
    over it), sampled: u (n,), alpha_f (n,), slope = the follower's turns per driver turn
    with their sense."""
    from plantmech.trains.model import mesh

    u = u0 + TWO_PI * np.arange(n + 1) / n
    alpha_f = np.ravel(mesh(law, spec, u[None, :], toothless=toothless).follower_angle)
    return u[:-1], alpha_f[:-1], float((alpha_f[-1] - alpha_f[0]) / TWO_PI)


def planetary_loads(design, gears: dict[str, GearOutline], spec, samples: int = 3600,
                    steps: int = 1440) -> dict:
    """Input torque(s) (N m), mesh torques and tangential tooth forces (N) of a general
    planetary train over one carrier turn (exudyn through ``contact.loads.solve_loads``,
    the transplanters' and the seeder's engine), and the energy balance. Bodies: the
    carrier (driven at ``spec.carrier_speed_deg_s`` in its sense), a driven sun when the
    file turns it (its speed ratio), and per arm one body per shaft (its follower gear,
    a compound driver fixed to it, the planet with the arm and the payload); masses from
    the gear files' outlines (``gears``, mm) at the face width and density. Each mesh is
    the pitch-curve law of ``trains`` between its driver's and follower's body angles
    relative to the carrier. A toothless dwell (the first pair's): Newmark gamma 0.6, its
    ends are impacts (``dwell_impacts``: every arm's, kinetic-energy jump, drive work and
    peak torque each) and the energy balance is checked between them, as the seeder's
    (``loads.seeder_loads``)."""
    from plantmech.contact.loads import (
        Body,
        MeshLaw,
        PeriodicLaw,
        _rot,
        dwell_impacts,
        polygon_mass_properties,
        solve_loads,
    )
    from plantmech.contact.transplanter_loads import _arm_body, _record
    from plantmech.trains.gearing import built_train, gear_names
    from plantmech.trains.model import simulate

    built = built_train(design)
    motion = simulate(built, samples=samples)
    tr = built.train
    names = gear_names(design)
    s = tr.carrier_rate  # 0: a held carrier (a pair on fixed centres, the sun drives)
    omega = np.radians(spec.carrier_speed_deg_s)
    thick = spec.face_width_mm * 1e-3
    props = {n: polygon_mass_properties(g.rings, thick, spec.density_kg_m3)
             for n, g in gears.items()}
    shafts = built.shafts[0] * 1e-3  # m, carrier frame
    J = motion.tip.shape[1]
    K = len(tr.pairs)
    L = float(np.ravel(tr.arm_length)[0]) * 1e-3
    c0 = float(motion.carrier[0, 0, 0])
    # the carrier body: driven at s omega, or held (s = 0: the frame of a pair on fixed
    # centres, its torque the reaction that holds the centres, no input)
    frame = "frame" if tr.carrier_held else "carrier"
    bodies = [Body(frame, 1.0, 0.1, c0, s * omega, np.zeros(2), np.zeros(2), False)]
    drives, drive_names = [0], [frame]
    sun_speed = s + tr.sun_rate  # the sun's absolute turn per unit psi (k s)
    sun_abs = c0 + float(motion.gear_angles[0][0, 0, 0])  # the sun's absolute angle at 0
    sun_body = None
    if sun_speed != 0.0:  # a driven sun: a body on the ground turning k times the carrier
        m, c, jz = props["sun"]
        sun_body = len(bodies)
        bodies.append(Body("sun", m, jz, sun_abs, sun_speed * omega, c, np.zeros(2), False))
        drives.append(sun_body)
        drive_names.append("sun")
    laws = []
    for j in range(J):
        line = s * TWO_PI * j / J  # arm j's carrier line in the carrier's frame at 0
        shaft_body = {0: sun_body}  # shaft index -> body index (None: the fixed sun)
        angle_offset = {}  # shaft -> body angle minus the shaft's gear frame angle
        for i in range(1, K + 1):
            follower = names[i - 1][1]
            frame0 = float(motion.carrier[0, j, 0] + motion.gear_angles[i][0, j, 0])
            rate = float(motion.gear_rates[i][0, j, 0])
            pivot = _rot(line) @ np.array([shafts[i].real, shafts[i].imag])
            parts = [props[follower]]
            if i < K and tr.pairs[i].driver is not None:  # a compound gear on this shaft
                phase = float(motion.driver_angles[i][0, j, 0]
                              - motion.gear_angles[i][0, j, 0])
                m2, c2, j2 = props[names[i][0]]
                parts.append((m2, _rot(phase) @ c2, j2))
            index = len(bodies)
            shaft_body[i] = index
            label = follower if J == 1 else f"{follower}_{j + 1}"
            if i == K:  # the planet carries the arm: the body's angle is the arm's
                beta0 = float(motion.arm_angle[0, j, 0])
                bodies.append(_arm_body(label + "_arm", _combined(parts), spec, L, beta0,
                                        (s + rate) * omega, pivot, frame0 - beta0))
                angle_offset[i] = beta0 - frame0
            else:
                m, c, jz = _combined(parts)
                bodies.append(Body(label, m, jz, frame0, (s + rate) * omega, c, pivot, True))
                angle_offset[i] = 0.0
        for k, (law, pspec) in enumerate(zip(built.laws, tr.pairs, strict=True)):
            d_alpha0 = float(motion.driver_angles[k][0, j, 0])
            # a toothless dwell's law has a kink at each end of the dwell: sampled on the
            # carrier turn's grid (the sun turns once relative to the carrier), as the
            # seeder's U(psi) (``loads._laws``), so the spline rounds the kinks alike
            u, alpha_f, slope = _mesh_law_samples(
                law, pspec, d_alpha0, n=samples if built.toothless[k] is not None else 2048,
                toothless=built.toothless[k])
            V = PeriodicLaw(u, alpha_f, slope)
            # the driver's alpha from its shaft's body angle: theta_body - offset + phase
            # - theta_carrier (the sun: its absolute angle when fixed)
            phase = d_alpha0 - float(motion.gear_angles[k][0, j, 0])
            # (alpha is relative to arm j's carrier line: the carrier body's angle + line)
            if k == 0 and sun_body is None:
                w, x0 = {0: -1.0}, sun_abs + phase - line
            else:
                w = {shaft_body[k]: 1.0, 0: -1.0}
                x0 = phase - angle_offset.get(k, 0.0) - line
            radius = motion.contact_radii[k][1][0, j] * 1e-3
            label = f"{names[k][0]}_{names[k][1]}" + ("" if J == 1 else f"_{j + 1}")
            laws.append(MeshLaw(label, {shaft_body[k + 1]: 1.0, 0: -1.0},
                                -angle_offset[k + 1] - line, w, x0, V, radius))
    dwell = built.toothless[0] if built.toothless else None
    # a dwell's ends are impacts of the rigid model: gamma 0.6 as the seeder's
    # (``loads.seeder_loads``); without impacts the lighter 0.52
    res = solve_loads(bodies, drives, laws, spec, steps, gamma=0.52 if dwell is None else 0.6)
    driven = ("the frame held (fixed centres), driven sun" if tr.carrier_held else
              f"driven carrier{' and sun' if sun_body is not None else ''}")
    rec = _record(res, drive_names, laws, bodies, spec,
                  f"{len(bodies)} planar rigid bodies ({J} arm(s) x {K} shaft(s), the last "
                  f"with the arm and the payload), {len(bodies)} revolute joints, {driven}, "
                  f"{len(laws)} mesh constraints (pitch-curve laws)", steps,
                  held=("frame",) if tr.carrier_held else ())
    if dwell is not None:
        # the seeder's treatment (``loads.dwell_impacts``): every arm meets the sun's
        # toothless arc, arm j 2 pi j / J of carrier turn before arm 1
        start, sector = (float(np.ravel(v)[0]) for v in tr.pairs[0].dwell)
        cuts = [start + e - TWO_PI * j / J for j in range(J) for e in (0.0, sector)]
        span = max(float(np.ptp(res["energy_change"])), float(np.mean(res["kinetic"])))
        impacts, err = dwell_impacts(res, cuts, span)
        rec["dwell_impacts"] = impacts
        rec["energy_balance"].update(
            max_error_fraction_of_energy_range=err,
            checked="between the dwell's impacts (1 deg either side left out)")
    return rec
