"""Drawing data for the app: the engine's results as JSON-ready arrays.

No physics is computed here: the angles, positions and radii come from the forward or
inverse results of ``plantmech.workflows``; this module only places each gear's pitch
curve (body frame, mm) rigidly at its centre and absolute rotation (rad) per animation
frame, and downsamples the curves the browser plots. Units: mm, deg, m/s as named.
"""

from __future__ import annotations

import numpy as np

DEG = 180.0 / np.pi


def _r(a, nd: int = 3):
    """Round an array for JSON (mm to the micrometre is more than a screen shows): a
    contiguous float array (serialized by orjson), or a float for a scalar."""
    a = np.round(np.asarray(a, dtype=float), nd)
    return float(a) if a.ndim == 0 else np.ascontiguousarray(a)


def _xy(z) -> list:
    """Complex positions (mm), any shape -> nested lists ending in [x, y] (a complex
    array's memory is its (x, y) pairs: viewed as floats, not copied into a new stack)."""
    z = np.ascontiguousarray(z, dtype=complex)
    return _r(z.view(float).reshape(z.shape + (2,)))


def _cis(angle) -> np.ndarray:
    """e^(i angle) for real angles (rad): cos and sin through NumPy's vectorized kernels
    (its complex exp takes several times longer per element)."""
    angle = np.asarray(angle, dtype=float)
    out = np.empty(angle.shape, dtype=complex)
    np.cos(angle, out=out.real)
    np.sin(angle, out=out.imag)
    return out


def frame_index(n: int, frames: int) -> np.ndarray:
    """Indices of ``frames`` samples spread uniformly over ``n`` (all if n <= frames)."""
    if n <= frames:
        return np.arange(n)
    return np.linspace(0, n, frames, endpoint=False).astype(int)


def _gear(name: str, body: np.ndarray, centre, rot, role: str, detail: int = 720) -> dict:
    """A gear: closed pitch curve in its body frame (complex, mm), centre per frame
    (complex, mm; one value for a fixed gear) and absolute rotation per frame (rad)."""
    centre = np.broadcast_to(np.asarray(centre, dtype=complex), np.shape(rot))
    body = np.asarray(body)
    body = body[:: max(1, len(body) // detail)]
    return {"name": name, "role": role, "body": _xy(body), "centre": _xy(centre),
            "rot": _r(rot, 5)}


def checks_list(checks) -> list[dict]:
    """Checks (dicts or Check objects) as {name, value, unit, limit, ok}."""
    out = []
    for c in checks:
        d = c if isinstance(c, dict) else c.as_dict()
        v = d.get("value")
        if v is not None:
            v = float(v)
            v = None if not np.isfinite(v) else v
        out.append({"name": d["name"], "value": v, "unit": d.get("unit", ""),
                    "limit": d.get("limit", ""), "ok": bool(d.get("ok"))})
    return out


# --- seeder ------------------------------------------------------------------------------


def trajectory_part(design, traj, detail: int = 720, spans: bool = True) -> dict:
    """Planned closed curve through the type-value points (sampled uniformly in its
    parameter: for drawing), the points, and (``spans``) the curve between each point and
    the next (24 samples each: the spans drawn red when a diagnostic names them)."""
    if traj is None:
        return {}
    period = traj.period
    plan = traj(np.linspace(0.0, period, detail, endpoint=False))
    out = {"plan": _r(plan), "points": _r(design.trajectory.points),
           "sections_points": design.trajectory.sections.model_dump()}
    if spans:
        n = len(design.trajectory.points)
        u0 = np.array([traj.point_parameter(i) for i in range(n)])
        u1 = np.roll(u0, -1)
        u1 = np.where(u1 <= u0, u1 + period, u1)
        uu = u0[:, None] + (u1 - u0)[:, None] * np.linspace(0.0, 1.0, 24)[None, :]
        out["spans"] = _r(traj(np.mod(uu.ravel(), period)).reshape(n, 24, 2))
    return out


def diagnostics_list(diags) -> list[dict]:
    return [d.as_dict() if hasattr(d, "as_dict") else dict(d) for d in diags]


def seeder_forward_scene(job, frames: int = 360, detail: int = 720) -> dict:
    """Everything the page draws for a simulated seeder train (``SeederForwardJob``)."""
    from plantmech.mechanisms.seeder_forward import shaft_offset

    tr, res, d = job.train, job.result, job.design
    n = len(res.carrier_angle)
    k = frame_index(n, frames)
    psi = res.carrier_angle
    car = tr.carrier0 - psi  # absolute carrier direction phi_1 (rad)
    P = tr.L1 * np.exp(1j * car)  # planet axis
    S = tr.a1 * np.exp(1j * (car + shaft_offset(tr)))  # gear 2-3 shaft
    c2 = tr.gear2_contact0 + res.gear2_angle  # gear-2 body angle at the sun contact
    c3 = tr.gear3_contact0 + res.gear3_angle if hasattr(res, "gear3_angle") else (
        tr.gear3_contact0 + res.gear2_angle)
    theta = np.linspace(0.0, 2 * np.pi, 361)[:-1]
    r1 = tr.a1 - tr.gear2(c2)  # sun radius at the contact (O -> S line)
    r4 = tr.a2 - tr.gear3(c3)
    arm = res.arm_angle
    sun_body = r1 * np.exp(1j * np.angle(S))
    planet_body = r4 * np.exp(1j * (np.angle(S - P) - arm))
    gears = [
        _gear("sun (gear 1, fixed)", sun_body, 0.0, np.zeros(len(k)), "sun", detail),
        _gear("gear 2", tr.gear2(theta) * np.exp(1j * theta), S[k],
              np.angle(-S[k]) - c2[k], "gear2", detail),
        _gear("gear 3", tr.gear3(theta) * np.exp(1j * theta), S[k],
              np.angle(P[k] - S[k]) - c3[k], "gear3", detail),
        _gear("planet (gear 4)", planet_body, P[k], arm[k], "planet", detail),
    ]
    carrier_speed = d.operation.carrier_speed_deg_s
    vel = res.velocity(carrier_speed)
    ks = frame_index(n, detail)
    sec = {key: float(v * DEG) for key, v in job.section_psi.items()}
    tip_at = {key: _r(np.interp(v, psi, res.tip[:, 0], period=2 * np.pi), 2)
              for key, v in job.section_psi.items()}
    tip_at = {key: [tip_at[key], float(np.round(np.interp(job.section_psi[key], psi,
                                                          res.tip[:, 1], period=2 * np.pi), 2))]
              for key in tip_at}
    out = {
        "mechanism": "sugarcane_seeder",
        "frames": {"carrier_angle_deg": _r(psi[k] * DEG, 3),
                   "links": [{"name": "carrier", "points": _xy(np.c_[np.zeros(len(k)), S[k],
                                                                      P[k]])},
                             {"name": "arm (cane)", "points": _xy(np.c_[P[k], res.tip[k, 0]
                                                                         + 1j * res.tip[k, 1]])}],
                   "tip": _r(res.tip[k])},
        "gears": gears,
        "tip_path": _r(res.tip[ks]),
        "sections_deg": sec,
        "section_tip": tip_at,
        "train": {"L1_mm": tr.L1, "L2_mm": tr.L2, "a1_mm": tr.a1, "a2_mm": tr.a2},
        "plots": {
            "carrier_angle_deg": _r(psi[ks] * DEG, 3),
            "attitude_deg": _r((arm[ks] - arm[0]) * DEG, 3),
            "speed_static_m_s": _r(np.hypot(vel[ks, 0], vel[ks, 1]), 4),
            "speed_dynamic_m_s": _r(res.speed(carrier_speed, job.travel_m_s)[ks], 4),
            "total_ratio": _r(res.total_ratio[ks], 5),
            "stage1_ratio": None if res.stage1_rate is None else _r(res.stage1_rate[ks], 5),
            "stage2_ratio": None if res.stage2_rate is None else _r(res.stage2_rate[ks], 5),
            "travel_m_s": job.travel_m_s,
        },
        "samples": int(n),
    }
    if d.train is not None:
        out["train_points"] = {
            name: {"angles_deg": list(g.angles()), "radii_mm": list(g.radii_mm),
                   "a_mm": a, "curve": _r(g_curve(theta) * 1.0), "theta_deg": _r(theta * DEG)}
            for name, g, g_curve, a in (("gear2", d.train.gear2, tr.gear2, tr.a1),
                                        ("gear3", d.train.gear3, tr.gear3, tr.a2))}
    return out


def speed_plots(psi, speeds: dict, detail: int = 720) -> dict:
    """Speed plot data of an inverse design (``workflows.inverse_speed_objectives``):
    static and dynamic (Eq. 17) tip speed (m/s) over the carrier angle (deg)."""
    ks = frame_index(len(psi), detail)
    return {"speed_carrier_angle_deg": _r(psi[ks] * DEG, 3),
            "speed_static_m_s": _r(speeds["static_m_s"][ks], 4),
            "speed_dynamic_m_s": _r(speeds["dynamic_m_s"][ks], 4),
            "travel_m_s": float(speeds["travel_m_s"])}


def seeder_inverse_scene(job, frames: int = 360, detail: int = 720) -> dict:
    """Drawing data of a seeder inverse design (``SeederInverseJob``): the realized
    train of the inverse result (carrier, gears 1-4 on their pitch curves, arm, tip),
    the planned trajectory, Table 1 and attitude. Without a feasible train only the
    planned curve and the diagnostics are drawn. The spans between the points are sent
    only when an error names some of them (the page draws them red; the planned curve is
    the rest)."""
    from plantmech.mechanisms.seeder_trains import gear_body_angles

    res, d = job.result, job.design
    diagnostics = diagnostics_list(res.diagnostics)
    named = any(g.get("severity") == "error" and g.get("between_points") for g in diagnostics)
    out = {"mechanism": "sugarcane_seeder",
           **trajectory_part(d, job.trajectory, detail, spans=named),
           "feasible": bool(res.feasible), "samples": int(d.trajectory.samples),
           "diagnostics": diagnostics}
    if res.arm_angle_realized is None or res.r2 is None or not res.feasible:
        if res.total_ratio is not None and res.carrier_angle is not None:
            # no train: the ratio the trajectory asks for is drawn, its bad span marked
            # (the diagnostics' carrier angles), with the planned attitude
            ks = frame_index(len(res.carrier_angle), detail)
            out["plots"] = {"carrier_angle_deg": _r(res.carrier_angle[ks] * DEG, 3),
                            "total_ratio": _r(res.total_ratio[ks], 5)}
            if res.arm_angle is not None:
                arm = res.arm_angle
                out["plots"]["attitude_deg"] = _r((arm[ks] - arm[0]) * DEG, 3)
        return out
    psi = res.carrier_angle
    n = len(psi)
    k = frame_index(n, frames)
    car = res.carrier_abs
    off = res.shaft_offset
    car_k = car[k]  # the drawn frames only: the rest of the turn is never placed
    S = res.a1 * _cis(car_k + off)
    P = res.L1 * _cis(car_k)
    ang = gear_body_angles(res)
    rot2 = car_k - res.gear2_angle[k]
    rot4 = car_k + res.planet_rel_realized[k]
    tip = res.tip_realized
    gears = []
    for name, role, r, key, centre, rot in (
            ("sun (gear 1, fixed)", "sun", res.r1, "sun", 0.0, np.zeros(len(k))),
            ("gear 2", "gear2", res.r2, "gear2", S, rot2),
            ("gear 3", "gear3", res.r3, "gear3", S, rot2),
            ("planet (gear 4)", "planet", res.r4, "planet", P, rot4)):
        ok = np.isfinite(r)
        a = ang[key][ok]
        if role == "sun":  # fixed: its body frame is the machine frame at the start
            a = a + car[0]
        gears.append(_gear(name, r[ok] * _cis(a), centre, rot, role, detail))
    arm = res.arm_angle_realized
    ks = frame_index(n, detail)
    sec = {key: float(res.point_carrier_angle[i] * DEG) for key, i in job.sections.items()}
    out.update({
        "frames": {"carrier_angle_deg": _r(psi[k] * DEG, 3),
                   "links": [{"name": "carrier",
                              "points": _xy(np.stack([np.zeros(len(k)), S, P], axis=-1))},
                             {"name": "arm (cane)",
                              "points": _xy(np.stack([P, tip[k, 0] + 1j * tip[k, 1]],
                                                     axis=-1))}],
                   "tip": _r(tip[k])},
        "gears": gears,
        "tip_path": _r(tip[ks]),
        "sections_deg": sec,
        "section_tip": {key: _r(d.trajectory.points[i], 2) for key, i in job.sections.items()},
        "train": {"L1_mm": res.L1, "L2_mm": res.L2, "a1_mm": res.a1, "a2_mm": res.a2},
        "plots": {
            "carrier_angle_deg": _r(psi[ks] * DEG, 3),
            "attitude_deg": _r((arm[ks] - arm[0]) * DEG, 3),
            "total_ratio": _r(res.total_ratio[ks], 5),
            "stage1_ratio": _r(res.stage1_ratio[ks], 5),
            "stage2_ratio": _r(res.stage2_ratio[ks], 5),
        },
        "samples": int(n),
    })
    return out


def khv_middles_and_planets(pair, m, carrier0: float, k, detail: int = 720) -> list[dict]:
    """The middle gear and the planet of every arm of a K-H-V train (seed 001 Fig. 1;
    docs/conventions.md), placed from the engine's results: ``pair`` (KHVPair: sun radius
    r_s(sigma) mm, centre distance a mm, middle turn M(sigma) rad relative to the carrier
    over the contact progress sigma) and ``m`` (TransplanterMotion: planet axes and
    absolute planet angles phi_2 per arm), frames ``k``, carrier start ``carrier0`` (rad).

    Arm j's carrier direction is phi_H = carrier0 - 2 pi j / J - psi, its middle gear
    sits at a e^(i phi_H) and turns by -M(sigma) relative to the carrier (sigma = psi +
    2 pi j / J), so its absolute rotation is phi_H - M. Its pitch curve in its body frame:
    radius a - r_s(sigma) at body angle pi + M(sigma) (the sun contact, towards O). The
    planet (at 2a, absolute angle phi_2) meets the middle at sigma' with M(sigma') =
    M(sigma) + pi: radius r_s(sigma') at body angle phi_H + pi - phi_2, towards the
    middle. Arm 0's samples give the planet's body curve (all arms share it)."""
    two_pi = 2 * np.pi
    sg, r_sun, a, M = pair.sigma, pair.r_sun[0], float(pair.a[0]), pair.M[0]
    psi = m.carrier_angle
    J = m.centre.shape[1]
    middle_body = (a - r_sun[:-1]) * np.exp(1j * (np.pi + M[:-1]))
    # the planet's body curve from arm 0 (sigma = psi)
    target = np.mod(np.interp(psi, sg, M) + 0.5 * M[-1], M[-1])
    r_planet = np.interp(np.interp(target, M, sg), sg, r_sun)
    phi_h0 = carrier0 - psi
    planet_body = r_planet * np.exp(1j * (phi_h0 + np.pi - m.planet_angle[0, 0]))
    out = []
    for j in range(J):
        offset = two_pi * j / J
        phi_h = carrier0 - offset - psi[k]
        x = psi[k] + offset
        wraps = np.floor(x / two_pi)
        turn = np.interp(x - wraps * two_pi, sg, M) + M[-1] * wraps
        out.append(_gear(f"middle {j + 1}", middle_body, a * np.exp(1j * phi_h),
                         phi_h - turn, "middle", detail))
        out.append(_gear(f"planet {j + 1}", planet_body, m.centre[0, j, k],
                         m.planet_angle[0, j, k], "planet", detail))
    return out


def transplanter_scene(job, frames: int = 360, detail: int = 720) -> dict:
    """Drawing data of a transplanting mechanism (``TransplanterJob``): internal gear
    (or fixed sun) and planets on their pitch curves, the arms (planet axis -> break
    point A -> tip B), the tip paths, the seedling box and the ground."""
    d, m, pair = job.design, job.motion, job.pair
    psi = m.carrier_angle
    n = len(psi)
    k = frame_index(n, frames)
    ks = frame_index(n, detail)
    J = m.B.shape[1]
    c0 = np.radians(d.carrier.initial_angle_deg)
    gears, links = [], []
    g = getattr(d, "internal_gear", None)  # the differential's lobed internal gear
    if g is not None:
        ang, R = pair.internal_polar(0)
        phase0 = np.radians(g.initial_phase_deg)
        ratio = d.drive.speed_ratio or (g.lobes - 1) / g.lobes
        # the internal gear turns clockwise theta_1 = k psi (seed 001 Eq. 1)
        rot = c0 + phase0 / pair.lobes - ratio * psi[k]
        gears.append(_gear("internal gear", R * np.exp(1j * ang), 0.0, rot, "internal", detail))
        pa, pr = pair.planet_polar(0)
        q0 = np.interp(phase0 % (2 * np.pi), pair.p, pair.Q[0])
        for j in range(J):
            gears.append(_gear(f"planet {j + 1}", pr * np.exp(1j * (pa + q0)),
                               m.centre[0, j, k], m.planet_angle[0, j, k], "planet", detail))
    else:
        z = pair.r_sun[0] * np.exp(1j * (c0 - pair.sigma))
        gears.append(_gear("sun (fixed)", z, 0.0, np.zeros(len(k)), "sun", detail))
        gears += khv_middles_and_planets(pair, m, c0, k, detail)
    for j in range(J):
        links.append({"name": f"carrier {j + 1}",
                      "points": _xy(np.c_[np.zeros(len(k)), m.centre[0, j, k]])})
        links.append({"name": f"arm {j + 1}",
                      "points": _xy(np.c_[m.centre[0, j, k], m.A[0, j, k], m.B[0, j, k]])})
    b = d.seedling_box
    u = np.exp(1j * np.radians(b.inclination_deg))
    o = complex(b.x_mm, b.y_mm)
    floor = np.array([o, o + b.length_mm * u])
    top = floor + 1j * u * b.mat_thickness_mm
    speed = np.abs(m.velocity(d.drive.carrier_speed_deg_s)[0])
    stages = job.summary["stages_deg"]
    return {
        "mechanism": d.mechanism, "feasible": True, "diagnostics": [],
        "frames": {"carrier_angle_deg": _r(psi[k] * DEG, 3), "links": links,
                   "tip": _xy(m.B[0, 0, k])},
        "gears": gears,
        "tip_paths": [_xy(m.B[0, j, ks]) for j in range(J)],
        "box": {"floor": _xy(floor), "mat": _xy(np.r_[floor, top[::-1]])},
        "ground_y_mm": float(job.summary["ground_y_mm"]),
        "gearbox_radius_mm": float(job.gearbox_radius_mm),
        "stages_deg": stages,
        "plots": {
            "carrier_angle_deg": _r(psi[ks] * DEG, 3),
            "needle_angle_deg": [_r(m.needle_angle[0, j, ks], 3) for j in range(J)],
            "tip_speed_m_s": [_r(speed[j, ks], 4) for j in range(J)],
            "planet_ratio": _r(m.planet_rate[0, 0, ks], 5),
        },
        "samples": int(n),
    }


def planetary_scene(design, motion, frames: int = 360, detail: int = 720) -> dict:
    """Drawing data of a general planetary train (``mechanism = "planetary"``) from its
    forward motion (``trains.model.TrainMotion``, P = 1): every gear's pitch curve in its
    body frame (the built train's curves; ``trains.gearing.gear_names`` as roles, so the
    cut teeth of ``plantmech gears`` land on them) at its centre with its absolute
    rotation per frame (``trains.placement.place_gears``); the
    carrier's line of shafts and the arm per arm; the tip paths. The sun is drawn once
    (every arm sees the same sun); an idler is the follower of the pair before."""
    from plantmech.trains.curves import TWO_PI
    from plantmech.trains.placement import place_gears

    built = motion.built
    psi = motion.carrier_angle
    n = len(psi)
    k = frame_index(n, frames)
    ks = frame_index(n, detail)
    J = motion.tip.shape[1]
    th = TWO_PI * np.arange(detail) / detail

    def body(curve):
        return curve(th[None, :])[0][0] * _cis(th)

    def style(name: str, ring: bool) -> str:
        if ring:
            return "internal"
        return "sun" if name == "sun" else ("planet" if name == "planet" else "middle")

    gears = []
    for p in place_gears(motion, k):  # every gear once (trains.placement)
        g = _gear(p.label, body(p.curve), p.centre[0], p.angle[0], p.name, detail)
        g["style"] = style(p.name, p.ring)
        gears.append(g)
    shafts = built.shafts[0]
    links = []
    for j in range(J):
        turn = _cis(motion.carrier[0, j, k])
        chain = shafts[None, :] * turn[:, None]  # (frames, K + 1): O and every shaft
        links.append({"name": f"carrier {j + 1}", "points": _xy(chain)})
        links.append({"name": f"arm {j + 1}",
                      "points": _xy(np.c_[motion.centre[0, j, k], motion.tip[0, j, k]])})
    speed = np.abs(motion.velocity(design.carrier.speed_deg_s)[0])
    return {
        "mechanism": "planetary", "feasible": True, "diagnostics": [],
        "frames": {"carrier_angle_deg": _r(psi[k] * DEG, 3), "links": links,
                   "tip": _xy(motion.tip[0, 0, k])},
        "gears": gears,
        "tip_paths": [_xy(motion.tip[0, j, ks]) for j in range(J)],
        "plots": {
            "carrier_angle_deg": _r(psi[ks] * DEG, 3),
            "arm_angle_deg": [_r(motion.arm_angle[0, j, ks] * DEG, 3) for j in range(J)],
            "tip_speed_m_s": [_r(speed[j, ks], 4) for j in range(J)],
            "planet_ratio": _r(motion.gear_rates[-1][0, 0, ks], 5),
        },
        "samples": int(n),
    }


# --- teeth --------------------------------------------------------------------------------


def _polar_on_grid(xy: np.ndarray, n: int) -> np.ndarray:
    """Radius (mm) of a closed curve around the origin at n uniform polar angles."""
    xy = np.asarray(xy, dtype=float)
    th = np.mod(np.arctan2(xy[:, 1], xy[:, 0]), 2 * np.pi)
    r = np.hypot(xy[:, 0], xy[:, 1])
    order = np.argsort(th, kind="stable")
    th, r = th[order], r[order]
    grid = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    return np.interp(grid, th, r, period=2 * np.pi)


def _circular_corr(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """c[k] = sum_i a[i] b[i - k] (circular), for every k."""
    return np.fft.irfft(np.fft.rfft(a) * np.conj(np.fft.rfft(b)), len(a))


def align_pitch_curve(drawn_xy, cut_xy, n: int = 1440, keep: float = 0.8
                      ) -> tuple[float, float]:
    """Rotation delta (rad) that carries a cut gear's pitch curve ``cut_xy`` (its body
    frame, mm) onto the drawn pitch curve ``drawn_xy`` (the scene's body frame, mm) of the
    same gear, both about the gear's centre, and the RMS radial residual (mm) left over the
    best-fitting ``keep`` of the turn: weighted least squares of the polar radii over every
    rotation (circular correlations), refitted without the worst-fitting angles (three times) (a
    sun's toothless dwell sector is drawn as the arc the gear 2 rests on, cut as the
    mate's own curve), refined between grid steps by a parabola."""
    rd, rc = _polar_on_grid(drawn_xy, n), _polar_on_grid(cut_xy, n)
    grid = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    w = np.ones(n)
    for _ in range(4):
        # ssd[k] = sum_i w[i] (rd[i] - rc[i - k])^2: the cut curve turned by k grid steps
        ssd = (w * rd**2).sum() + _circular_corr(w, rc**2) - 2.0 * _circular_corr(w * rd, rc)
        k = int(np.argmin(ssd))
        y0, y1, y2 = ssd[(k - 1) % n], ssd[k], ssd[(k + 1) % n]
        den = y0 - 2.0 * y1 + y2
        frac = 0.5 * (y0 - y2) / den if den > 0 else 0.0
        delta = (k + float(np.clip(frac, -0.5, 0.5))) * 2 * np.pi / n
        err = np.abs(np.interp(grid - delta, grid, rc, period=2 * np.pi) - rd)
        w = (err <= np.quantile(err, keep)).astype(float)
    return float(np.mod(delta, 2 * np.pi)), float(np.sqrt((w * err**2).sum() / w.sum()))


def teeth_for_scene(gears: list[dict], outlines: dict, tolerance: float = 0.005) -> dict:
    """The cut outlines of ``outlines`` ({gear name: (polygon, pitch polyline)}, from
    ``workflows.run_gears``) turned into the body frames of the drawn ``gears`` (scene
    gears whose role is the cut gear's name: sun, gear2, gear3, planet, internal,
    middle), so the page draws the teeth where the pitch curve was. A gear is drawn with
    teeth only if its cut pitch curve fits the drawn one to ``tolerance`` x its mean
    radius (RMS over the best-fitting 80 % of the turn, ``align_pitch_curve``); otherwise
    the reason is given. Returns {role: {...}}."""
    by_role = {g["role"]: g for g in gears}
    out = {}
    for name, (poly, pitch_xy) in outlines.items():
        g = by_role.get(name)
        if g is None:
            out[name] = {"drawn": False, "reason": "no drawn gear of that name"}
            continue
        body = np.asarray(g["body"], dtype=float)
        delta, residual = align_pitch_curve(body, pitch_xy)
        mean_r = float(np.hypot(body[:, 0], body[:, 1]).mean())
        entry = {"delta_deg": round(float(np.degrees(delta)), 4),
                 "residual_mm": round(residual, 4), "drawn": residual <= tolerance * mean_r}
        if not entry["drawn"]:
            entry["reason"] = (f"its cut pitch curve differs from the drawn one by "
                               f"{residual:.3g} mm RMS over the best-fitting 80 % of the "
                               f"turn (limit {tolerance * mean_r:.3g} mm)")
        else:
            c, s = np.cos(delta), np.sin(delta)
            rot = np.array([[c, -s], [s, c]])
            rings = [poly.exterior, *poly.interiors] if hasattr(poly, "exterior") else [
                ring for p in poly.geoms for ring in (p.exterior, *p.interiors)]
            entry["rings"] = [_r(np.asarray(ring.coords)[:-1, :2] @ rot.T).tolist()
                              for ring in rings]
        out[name] = entry
    return out
