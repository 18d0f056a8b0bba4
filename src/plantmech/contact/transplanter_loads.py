"""Loads of the rice transplanter's trains (seed 001) over a carrier turn at constant
input speeds, computed by the multibody engine exudyn and cross-checked against an
energy balance (as ``contact/loads.py`` does for the seeder).

Model (SI inside: m, kg, s, rad): planar rigid bodies, each node at its centre of mass,
revolute joints, the inputs driven by coordinate constraints (their multipliers are the
input torques) and every mesh a scleronomic coordinate constraint between the bodies'
angles (its multiplier is the mesh torque on the driven gear; divided by the driven
gear's pitch radius at the contact, the tangential tooth force). Every mesh constraint
has the form  sum_i a_i theta_i + b - F(sum_i w_i theta_i + x0) = 0  with F a
pitch-curve law (a periodic cubic spline plus whole turns per turn).

- Differential train: the carrier (theta_c = carrier0 - omega t) and the internal gear
  (theta_1 = theta_1(0) - k omega t) both driven about O; per arm j a planet + arm +
  seedling body on the carrier at a from O; its mesh with the internal gear:
  theta_p - theta_c = Gamma_j(gamma_1), gamma_1 = (theta_1 - theta_c) - (theta_1(0) -
  carrier0) the internal gear's turn relative to the carrier (seed 001 Eq. 5).
- K-H-V train: the carrier driven, the sun fixed (ground); per arm j a middle gear on the
  carrier at a and a planet + arm + seedling at 2 a; sun -> middle: u = U_j(psi) (u the
  middle's clockwise turn relative to the carrier, psi = carrier0 - theta_c), middle ->
  planet: theta_p - theta_c = V_j(u).

The laws are the pitch-curve model's (``simulate_transplanter``); the toothed train's
transmission error is reported by the contact analysis, not differentiated twice here.
Masses: gears from their outlines (``loads.polygon_mass_properties``: plate of the face
width and density), centroids placed in the frames the gear files are cut in
(``contact/khv.py``, ``contact/transplanter.py``); the arm a slender rod S long from the
planet axis along the needle's direction phi_2 + beta (the real arm is bent at A), the
seedling a point mass at the tip B. The carrier is balanced (no mass moment); at its
constant speed its inertia does no work. The check: the drives' work equals the change
of kinetic + potential energy at every step (< 1 % of the energy's swing over the turn,
or of the mean kinetic energy if that is larger).
"""

from __future__ import annotations

import numpy as np

from plantmech.contact.loads import (
    Body,
    LoadSpec,
    MeshLaw,
    PeriodicLaw,
    _rot,
    polygon_mass_properties,
    solve_loads,
)

TWO_PI = 2.0 * np.pi


def _arm_body(name, planet_props, spec: LoadSpec, S: float, angle0, omega0, pivot,
              planet_frame_minus_arm: float) -> Body:
    """Planet + arm (rod S long along the body's x) + seedling at the tip; the planet's
    centroid placed by its gear file's frame (``planet_frame_minus_arm``: the planet
    file frame's angle minus the arm's, constant)."""
    mp, cp, jp = planet_props
    cpa = _rot(planet_frame_minus_arm) @ cp
    m = mp + spec.arm_mass_kg + spec.payload_kg
    c = (mp * cpa + np.array([spec.arm_mass_kg * S / 2 + spec.payload_kg * S, 0.0])) / m
    j = (jp + mp * (cpa - c) @ (cpa - c)
         + spec.arm_mass_kg * (S**2 / 12 + (S / 2 - c[0]) ** 2 + c[1] ** 2)
         + spec.payload_kg * ((S - c[0]) ** 2 + c[1] ** 2))
    return Body(name, m, float(j), angle0, omega0, c, pivot, True)


def _record(res: dict, drive_names: list[str], laws: list[MeshLaw], bodies: list[Body],
            spec: LoadSpec, model: str, steps: int, held: tuple[str, ...] = ()) -> dict:
    """The loads record (``verification.json``'s ``loads``) and its series. ``held``: the
    drives held still (a held carrier: the frame of a pair on fixed centres), whose torque
    is the reaction that holds them, no input: recorded as ``holding_torque_N_m``, left
    out of the input torque."""
    change, ke, work = res["energy_change"], res["kinetic"], res["work"]
    every = dict(zip(drive_names, res["input_torques"], strict=True))
    taus = {k: x for k, x in every.items() if k not in held}
    holding = {k: x for k, x in every.items() if k in held}
    total = sum(taus.values())
    rec = {
        "model": f"exudyn {res['version']}: {model}",
        "inputs": spec.model_dump(),
        "masses_kg": {b.name: b.mass for b in bodies[1:]},
        "inertias_kg_m2": {f"{b.name}_about_centroid": b.inertia for b in bodies[1:]},
        "steps": steps,
        "input_torque_N_m": {
            **{name: {"min": float(x.min()), "max": float(x.max()),
                      "rms": float(np.sqrt(np.mean(x**2)))} for name, x in taus.items()},
            "min": float(np.min(total)), "max": float(np.max(total))},
        "mesh_torque_N_m": {law.name: float(np.abs(x).max())
                            for law, x in zip(laws, res["mesh_torques"], strict=True)},
        "tangential_tooth_force_N": {f"{k}_max": float(v.max())
                                     for k, v in res["tooth_forces"].items()},
        "energy_balance": {"max_error_fraction_of_energy_range": res["error"],
                           "checked": "over the whole turn",
                           "energy_range_J": float(np.ptp(change)),
                           "mean_kinetic_energy_J": float(np.mean(ke)),
                           "work_over_cycle_J": float(work[-1]),
                           "energy_change_over_cycle_J": float(change[-1])},
        "series": {"carrier_angle_deg": np.degrees(res["psi"]),
                   **{f"input_torque_{k}_N_m": x for k, x in taus.items()},
                   **{f"holding_torque_{k}_N_m": x for k, x in holding.items()},
                   **{f"tooth_force_{k}_N": x for k, x in res["tooth_forces"].items()},
                   "work_J": work, "energy_change_J": change},
    }
    if holding:
        rec["holding_torque_N_m"] = {name: {"min": float(x.min()), "max": float(x.max()),
                                            "rms": float(np.sqrt(np.mean(x**2)))}
                                     for name, x in holding.items()}
    return rec


def khv_loads(design, gears: dict, spec: LoadSpec, samples: int = 3600,
              steps: int = 1440) -> dict:
    """Input torque (N m), mesh torques and tangential tooth forces (N) of a K-H-V
    train over one carrier turn (``steps`` time steps), and the energy balance; gears
    "middle", "planet" (outlines, mm)."""
    from plantmech.contact.khv import khv_frames
    from plantmech.mechanisms.transplanter_design import simulate_transplanter

    pair, motion, *_ = simulate_transplanter(design, samples=samples)
    c0 = float(np.radians(design.carrier.initial_angle_deg))
    sigma0, M, Gp = khv_frames(pair, c0)
    J = motion.B.shape[1]
    a, S = float(pair.a[0]) * 1e-3, float(design.arm.S_mm) * 1e-3
    beta = float(np.radians(design.arm.beta_deg))
    omega = np.radians(spec.carrier_speed_deg_s)
    psi = motion.carrier_angle
    thick = spec.face_width_mm * 1e-3
    pm = polygon_mass_properties(gears["middle"].rings, thick, spec.density_kg_m3)
    pp = polygon_mass_properties(gears["planet"].rings, thick, spec.density_kg_m3)
    sg, rs = pair.sigma, pair.r_sun[0] * 1e-3
    Mt, Gt = pair.M[0], Gp(sg)
    # the laws on the pair's dense grid (exact samples of the smooth pitch-curve laws;
    # through the carrier-angle samples their second derivatives would carry the
    # interpolation's noise into the torques): the middle's turn M(sigma) and the
    # planet's G(sigma)
    Mlaw = PeriodicLaw(sg[:-1], Mt[:-1], 1.0)
    m0 = float(M(sigma0))
    bodies = [Body("carrier", 1.0, 0.1, c0, -omega, np.zeros(2), np.zeros(2), False)]
    laws = []
    for j in range(J):
        line = -TWO_PI * j / J  # arm j's carrier line, carrier frame
        sigma = psi + TWO_PI * j / J
        s0 = TWO_PI * j / J  # arm j's contact progress at the start
        u0 = Mlaw(s0) - m0  # the middle's contact body angle = its CW turn + const
        theta_p = motion.arm_angle[0, j]
        rel0 = float(theta_p[0] - c0)
        i_m, i_p = len(bodies), len(bodies) + 1
        bodies.append(Body(f"middle_{j + 1}", pm[0], pm[2], c0 + line + np.pi - u0,
                           -omega * (1.0 + Mlaw(s0, 1)), pm[1],
                           a * np.array([np.cos(line), np.sin(line)]), True))
        # the planet file's frame (mesh-frame pose pi - phi_p on the carrier line) minus
        # the arm's angle: pi - G(sigma_0) - beta, constant
        bodies.append(_arm_body(f"planet_arm_{j + 1}", pp, spec, S, float(theta_p[0]),
                                -omega + float(motion.planet_rate[0, j, 0]) * omega,
                                2 * a * np.array([np.cos(line), np.sin(line)]),
                                np.pi - float(Gp(sigma0)) - beta))
        # planet vs middle: rel = G(sigma) + beta - 2 pi j / J at u = M(sigma) - M(sigma_0)
        if not np.all(np.diff(Mt) > 0):
            raise ValueError("the middle gear stands still: no K-H-V mesh law")
        V = PeriodicLaw(Mt[:-1] - m0, Gt[:-1] + beta + line, 1.0)
        # the nominal model's planet angle and this law's agree (1e-6 rad)
        cV = rel0 - V(u0)
        # radii at the contacts: the middle's at the sun (a - r_s(sigma)), the planet's
        # (r_s(sigma'), M(sigma') = M(sigma) + pi)
        s_mod = np.mod(sigma, TWO_PI)
        r_mid = a - np.interp(s_mod, sg, rs)
        target = np.mod(np.interp(s_mod, sg, Mt) + np.pi, Mt[-1])
        r_pl = np.interp(np.interp(target, Mt, sg), sg, rs)
        b1 = np.pi + line
        # C1: u - (M(psi + 2 pi j / J) - M(sigma_0)) = 0, u = theta_c - theta_m + b1
        laws.append(MeshLaw(f"sun_middle_{j + 1}", {0: 1.0, i_m: -1.0}, b1 + m0, {0: -1.0},
                            c0 + s0, Mlaw, r_mid))
        # C2: theta_p - theta_c - V(u) = 0
        laws.append(MeshLaw(f"middle_planet_{j + 1}", {i_p: 1.0, 0: -1.0}, -cV,
                            {0: 1.0, i_m: -1.0}, b1, V, r_pl))
    res = solve_loads(bodies, [0], laws, spec, steps)
    return _record(res, ["carrier"], laws, bodies, spec,
                   f"{len(bodies)} planar rigid bodies ({J} middle gears, {J} planet + arm "
                   f"+ seedling), {len(bodies)} revolute joints, driven carrier, "
                   f"{len(laws)} mesh constraints (pitch-curve laws)", steps)


def differential_loads(design, gears: dict, spec: LoadSpec, samples: int = 3600,
                       steps: int = 1440) -> dict:
    """Input torques of the carrier and of the internal gear (N m), mesh torques and
    tangential tooth forces (N) of the differential train over one carrier turn, and the
    energy balance; gears "internal", "planet" (outlines, mm)."""
    from plantmech.contact.transplanter import planet_turn
    from plantmech.mechanisms.transplanter_design import design_param as _param
    from plantmech.mechanisms.transplanter_design import simulate_transplanter

    pair, motion, *_ = simulate_transplanter(design, samples=samples)
    n = pair.lobes
    k = design.drive.speed_ratio
    k = (n - 1) / n if k is None else k
    m = n * (1.0 - k)
    c0 = float(np.radians(design.carrier.initial_angle_deg))
    phase0 = float(np.radians(_param(design, None, "initial_phase_deg")))
    J = motion.B.shape[1]
    a, S = float(pair.a[0]) * 1e-3, float(design.arm.S_mm) * 1e-3
    omega = np.radians(spec.carrier_speed_deg_s)
    psi = motion.carrier_angle
    thick = spec.face_width_mm * 1e-3
    pi_ = polygon_mass_properties(gears["internal"].rings, thick, spec.density_kg_m3)
    pp = polygon_mass_properties(gears["planet"].rings, thick, spec.density_kg_m3)
    # the internal gear's file frame: its mesh-frame pose p / n on arm 0's carrier line
    th1 = c0 + phase0 / n
    bodies = [Body("carrier", 1.0, 0.1, c0, -omega, np.zeros(2), np.zeros(2), False),
              Body("internal", pi_[0], pi_[2], th1, -k * omega, pi_[1], np.zeros(2), False)]
    # the law on the pair's dense lobe-phase grid: the planet's turn Q(p) (exact samples
    # of the smooth pitch-curve law)
    Qlaw = PeriodicLaw(pair.p[:-1], pair.Q[0, :-1], 1.0)
    laws = []
    for j in range(J):
        line = -TWO_PI * j / J
        ph = phase0 + m * psi + n * TWO_PI * j / J
        theta_p = motion.arm_angle[0, j]
        # the planet file's frame (mesh-frame pose Q(p) on the carrier line) minus the
        # arm's angle, constant
        frame = c0 + line + float(planet_turn(pair, ph[:1])[0]) - float(theta_p[0])
        i_p = len(bodies)
        bodies.append(_arm_body(f"planet_arm_{j + 1}", pp, spec, S, float(theta_p[0]),
                                -omega + float(motion.planet_rate[0, j, 0]) * omega,
                                a * np.array([np.cos(line), np.sin(line)]), frame))
        # theta_p - theta_c = Q(p) + C, p = phase0 + 2 pi n j / J + n gamma_1, gamma_1 =
        # (theta_1 - theta_c) - (theta_1(0) - carrier0) (the internal gear's CCW turn
        # relative to the carrier)
        x0 = phase0 + n * TWO_PI * j / J - n * (th1 - c0)
        cQ = float(theta_p[0] - c0) - Qlaw(float(ph[0]))
        r_pl = np.interp(np.mod(ph, TWO_PI), pair.p, pair.planet_radius[0]) * 1e-3
        laws.append(MeshLaw(f"internal_planet_{j + 1}", {i_p: 1.0, 0: -1.0}, -cQ,
                            {1: n, 0: -n}, x0, Qlaw, r_pl))
    res = solve_loads(bodies, [0, 1], laws, spec, steps)
    return _record(res, ["carrier", "internal"], laws, bodies, spec,
                   f"{len(bodies)} planar rigid bodies (internal gear, {J} planet + arm + "
                   f"seedling), {len(bodies)} revolute joints, driven carrier and internal "
                   f"gear, {J} mesh constraints (pitch-curve laws)", steps)
