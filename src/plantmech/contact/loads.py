"""Loads of the seeder's train over a carrier turn at constant carrier speed, computed by
the multibody engine exudyn and cross-checked against an energy balance.

Model (SI units inside: m, kg, s, rad): three planar rigid bodies, each node at its centre
of mass: the carrier (turns about O; balanced, so at constant speed it needs no torque),
gears 2-3 (one body, revolute joint on the carrier at a1 from O, off the carrier line
when a1 + a2 > L1), planet + arm + payload (one
body, revolute joint on the carrier at L1). The sun is fixed (ground). The carrier is
driven by a coordinate constraint theta_c = carrier0 - omega t; its multiplier is the
input torque. The two meshes are scleronomic coordinate constraints, with
u = theta_c - theta_23 (gear 2's clockwise turn relative to the carrier, seed 000's
Delta phi_2) and psi = carrier0 - theta_c (the clockwise carrier angle):
  C1 (sun -> gear 2):      u - U(psi) = 0
  C2 (gear 3 -> planet):   theta_4 - theta_c - V(u) - (arm0 - carrier0) = 0
Their multipliers are the mesh torques on gears 2-3 and on the planet; divided by the
pitch radius at the contact they give the tangential tooth forces. U and V are the
pitch-curve model's laws (``seeder_forward.simulate``): the toothed train's
transmission error (micro-radians to tenths of a degree) is reported by the contact
analysis and not differentiated twice here.

Masses: gears from their outlines (plate of the face width and density: area, centroid,
polar moment), the arm as a slender rod L2 long, the payload (cane / seedling) a point
mass at the tip. The check: the drive's work W(t) = integral of torque x carrier speed
equals the change of kinetic + potential energy at every step (< 1 % of the energy's
range over the turn, or of the mean kinetic energy if that is larger).
"""

from __future__ import annotations

from bisect import bisect_right

import numpy as np
from pydantic import BaseModel, ConfigDict, Field
from scipy.interpolate import CubicSpline

TWO_PI = 2.0 * np.pi
G = 9.81  # m/s^2, along -y of the mechanism frame


class LoadSpec(BaseModel):
    """Optional load inputs (options of ``plantmech verify``)."""

    model_config = ConfigDict(extra="forbid")
    density_kg_m3: float = Field(7850.0, gt=0, description="gear material (steel)")
    face_width_mm: float = Field(12.0, gt=0, description="gear face width")
    arm_mass_kg: float = Field(1.0, ge=0, description="arm: slender rod, planet axis -> tip")
    payload_kg: float = Field(0.5, ge=0, description="cane / seedling held at the tip")
    carrier_speed_deg_s: float = Field(360.0, gt=0, description="constant carrier speed")
    gravity: bool = True


def polygon_mass_properties(rings: list, thickness_m: float, density: float):
    """(mass kg, centroid (2,) m, polar moment about the centroid kg m^2) of a plate
    bounded by closed rings in mm (the largest ring outside, the others holes)."""
    parts = []
    for r in rings:
        p = np.asarray(r, dtype=float) * 1e-3
        x, y = p[:, 0], p[:, 1]
        x1, y1 = np.roll(x, -1), np.roll(y, -1)
        cr = x * y1 - x1 * y
        parts.append((0.5 * cr.sum(), cr, x, y, x1, y1))
    k = int(np.argmax([abs(a) for a, *_ in parts]))
    area = mx = my = jz = 0.0
    for i, (a, cr, x, y, x1, y1) in enumerate(parts):
        sign = (1.0 if i == k else -1.0) * np.sign(a)  # outer adds, holes subtract
        area += sign * a
        mx += sign * ((x + x1) * cr).sum() / 6.0
        my += sign * ((y + y1) * cr).sum() / 6.0
        jz += sign * ((x * x + x * x1 + x1 * x1 + y * y + y * y1 + y1 * y1) * cr).sum() / 12.0
    m = density * thickness_m * area
    c = np.array([mx, my]) / area
    return float(m), c, float(density * thickness_m * jz - m * c @ c)


class PeriodicLaw:
    """F(x) = slope x + s(x), s a periodic cubic spline of period ``period`` through
    samples (x (N,) increasing over less than one period, y (N,)); a scalar evaluation
    without array overhead (the multibody solver calls it at every Newton iteration)."""

    def __init__(self, x, y, slope: float, period: float = TWO_PI):
        x = np.asarray(x, dtype=float)
        y = np.asarray(y, dtype=float) - slope * x
        xs = np.r_[x, x[0] + period]
        sp = CubicSpline(xs, np.r_[y, y[0]], bc_type="periodic")
        self.slope, self.period, self.x0 = float(slope), float(period), float(xs[0])
        self.breaks = sp.x.tolist()
        self.coef = sp.c.T.tolist()  # (N, 4): highest power first
        self.n = len(self.coef)

    def __call__(self, x: float, nu: int = 0) -> float:
        x = float(x)
        xm = self.x0 + (x - self.x0) % self.period
        i = min(max(bisect_right(self.breaks, xm) - 1, 0), self.n - 1)
        d = xm - self.breaks[i]
        c3, c2, c1, c0 = self.coef[i]
        if nu == 0:
            return self.slope * x + ((c3 * d + c2) * d + c1) * d + c0
        if nu == 1:
            return self.slope + (3.0 * c3 * d + 2.0 * c2) * d + c1
        return 6.0 * c3 * d + 2.0 * c2


def _laws(nominal):
    """U(psi) (gear 2's turn vs the carrier's) and V(u) (planet's vs gear 2's), C2
    periodic splines plus one turn per turn, with their first two derivatives (scalar
    callables F(x, nu))."""
    psi = nominal.carrier_angle
    u = np.r_[nominal.gear2_angle, nominal.gear2_angle[0] + TWO_PI]
    v = np.r_[nominal.planet_rel, nominal.planet_rel[0] + TWO_PI]
    keep = np.r_[True, np.diff(u) > 1e-9]  # gear 2 stands still in the dwell
    keep[-1] = False  # the turn's end: the period closes it
    return PeriodicLaw(psi, u[:-1], 1.0), PeriodicLaw(u[keep], v[keep], 1.0)


def seeder_loads(train, nominal, gears: dict, spec: LoadSpec, steps: int = 1440) -> dict:
    """Input torque (N m), mesh torques and tangential tooth forces (N) over one carrier
    turn (``steps`` time steps), and the energy balance."""
    import exudyn as exu
    from exudyn.itemInterface import (
        Force,
        MarkerBodyPosition,
        MarkerNodeCoordinate,
        MarkerNodeCoordinates,
        MarkerObjectODE2Coordinates,
        NodePointGround,
        NodeRigidBody2D,
        ObjectConnectorCoordinate,
        ObjectConnectorCoordinateVector,
        ObjectGenericODE2,
        ObjectGround,
        ObjectJointRevolute2D,
        ObjectRigidBody2D,
        SensorNode,
        SensorObject,
    )

    from plantmech.mechanisms.seeder_forward import shaft_offset

    # the gear 2-3 shaft on the carrier: off the carrier line by this angle at O (CCW side,
    # as outputs/seeder_report places it), on it when a1 + a2 = L1
    off = shaft_offset(train)
    omega = np.radians(spec.carrier_speed_deg_s)
    period = TWO_PI / omega
    L1, L2, a1 = train.L1 * 1e-3, train.L2 * 1e-3, train.a1 * 1e-3
    c0, arm0 = float(train.carrier0), float(train.arm0)
    U, V = _laws(nominal)
    thick = spec.face_width_mm * 1e-3
    props = {n: polygon_mass_properties(gears[n].rings, thick, spec.density_kg_m3)
             for n in ("gear2", "gear3", "planet")}
    (ma, ca, ja), (mb, cb, jb) = props["gear2"], props["gear3"]
    m23 = ma + mb
    c23 = (ma * ca + mb * cb) / m23  # in the common body frame of gears 2-3
    j23 = ja + ma * (ca - c23) @ (ca - c23) + jb + mb * (cb - c23) @ (cb - c23)
    # planet + arm + payload about the planet axis; the planet's own small centroid
    # offset is taken at its distance, on the arm line (its direction in the planet's
    # frame is not in the gear files)
    mp, cp, jp = props["planet"]
    m4 = mp + spec.arm_mass_kg + spec.payload_kg
    x4 = (spec.arm_mass_kg * L2 / 2 + spec.payload_kg * L2) / m4
    j4 = (jp + mp * (cp @ cp + x4**2) + spec.arm_mass_kg * (L2**2 / 12 + (L2 / 2 - x4) ** 2)
          + spec.payload_kg * (L2 - x4) ** 2)

    def rot(t):
        return np.array([[np.cos(t), -np.sin(t)], [np.sin(t), np.cos(t)]])

    def perp(v):
        return np.array([-v[1], v[0]])

    # body angles at psi = 0: theta_c = carrier0, theta_23 = theta_c - u, theta_4 = arm
    u0 = float(U(0.0))
    # gears 2-3 body frame in the world at psi = 0: its contact body angle faces O
    th = np.array([c0, c0 + off + np.pi - float(train.gear2_contact0), arm0])
    k23 = th[1] - (c0 - u0)  # u = theta_c - theta_23 + k23
    du = float(U(0.0, 1)) * omega
    w = np.array([-omega, -omega - du, -omega + float(V(u0, 1)) * du])
    shaft = a1 * np.array([np.cos(c0 + off), np.sin(c0 + off)])
    axis = L1 * np.array([np.cos(c0), np.sin(c0)])
    p23 = shaft + rot(th[1]) @ c23
    p4 = axis + x4 * np.array([np.cos(th[2]), np.sin(th[2])])
    v23 = w[0] * perp(shaft) + w[1] * perp(p23 - shaft)
    v4 = w[0] * perp(axis) + w[2] * perp(p4 - axis)

    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    ground = mbs.AddObject(ObjectGround())
    nodes = [mbs.AddNode(NodeRigidBody2D(referenceCoordinates=[0.0, 0.0, th[0]],
                                         initialVelocities=[0.0, 0.0, w[0]])),
             mbs.AddNode(NodeRigidBody2D(referenceCoordinates=[*p23, th[1]],
                                         initialVelocities=[*v23, w[1]])),
             mbs.AddNode(NodeRigidBody2D(referenceCoordinates=[*p4, th[2]],
                                         initialVelocities=[*v4, w[2]]))]
    masses = [1.0, m23, m4]
    inertias = [0.1, j23, j4]
    bodies = [mbs.AddObject(ObjectRigidBody2D(nodeNumber=n, mass=m, inertia=j))
              for n, m, j in zip(nodes, masses, inertias, strict=True)]
    body_c, body_23, body_4 = bodies
    for b0, p0, b1, p1 in ((ground, [0, 0, 0], body_c, [0, 0, 0]),
                           (body_c, [a1 * np.cos(off), a1 * np.sin(off), 0], body_23,
                            [*(-c23), 0]),
                           (body_c, [L1, 0, 0], body_4, [-x4, 0, 0])):
        mk0 = mbs.AddMarker(MarkerBodyPosition(bodyNumber=b0, localPosition=p0))
        mk1 = mbs.AddMarker(MarkerBodyPosition(bodyNumber=b1, localPosition=p1))
        mbs.AddObject(ObjectJointRevolute2D(markerNumbers=[mk0, mk1]))
    n_ground = mbs.AddNode(NodePointGround())
    m_ground = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=n_ground, coordinate=0))
    m_thc = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=nodes[0], coordinate=2))
    # node coordinates are displacements from the reference: theta_c - carrier0 = -omega t
    drive = mbs.AddObject(ObjectConnectorCoordinate(
        markerNumbers=[m_ground, m_thc],
        offsetUserFunction=lambda mbs_, t, item, off: -omega * t,
        offsetUserFunction_t=lambda mbs_, t, item, off: -omega))
    # the three nodes' 9 coordinates as one marker, through a massless generic object
    holder = mbs.AddObject(ObjectGenericODE2(nodeNumbers=nodes))
    m_all = mbs.AddMarker(MarkerObjectODE2Coordinates(objectNumber=holder))
    m_none = mbs.AddMarker(MarkerNodeCoordinates(nodeNumber=n_ground))

    def angles(q):
        # the user functions get total coordinates (reference + displacement)
        return q[2], q[5], q[8]

    def c1(mbs_, t, item, q, q_t, vel):
        if vel:  # index-2 form: the time derivative (scleronomic: jacobian x velocities)
            return [float(j1(mbs_, t, item, q, q_t, vel)[0] @ np.asarray(q_t))]
        tc, t23, _ = angles(q)
        return [float((tc - t23 + k23) - U(c0 - tc))]

    def j1(mbs_, t, item, q, q_t, vel):
        tc, _, _ = angles(q)
        jac = np.zeros((1, 9))
        jac[0, 2] = 1.0 + float(U(c0 - tc, 1))
        jac[0, 5] = -1.0
        return jac

    def c2(mbs_, t, item, q, q_t, vel):
        if vel:
            return [float(j2(mbs_, t, item, q, q_t, vel)[0] @ np.asarray(q_t))]
        tc, t23, t4 = angles(q)
        return [float(t4 - tc - V(tc - t23 + k23) - (arm0 - c0))]

    def j2(mbs_, t, item, q, q_t, vel):
        tc, t23, _ = angles(q)
        d = float(V(tc - t23 + k23, 1))
        jac = np.zeros((1, 9))
        jac[0, 2] = -1.0 - d
        jac[0, 5] = d
        jac[0, 8] = 1.0
        return jac

    meshes = [mbs.AddObject(ObjectConnectorCoordinateVector(
        markerNumbers=[m_none, m_all], scalingMarker0=np.zeros((1, 9)),
        constraintUserFunction=cf, jacobianUserFunction=jf)) for cf, jf in ((c1, j1), (c2, j2))]
    if spec.gravity:
        for b, m in ((body_23, m23), (body_4, m4)):
            mk = mbs.AddMarker(MarkerBodyPosition(bodyNumber=b, localPosition=[0, 0, 0]))
            mbs.AddLoad(Force(markerNumber=mk, loadVector=[0.0, -m * G, 0.0]))
    ov = exu.OutputVariableType
    sens = {"q": [mbs.AddSensor(SensorNode(nodeNumber=n, storeInternal=True,
                                           outputVariableType=ov.Coordinates))
                  for n in nodes],
            "v": [mbs.AddSensor(SensorNode(nodeNumber=n, storeInternal=True,
                                           outputVariableType=ov.Coordinates_t))
                  for n in nodes],
            "lam": [mbs.AddSensor(SensorObject(objectNumber=o, storeInternal=True,
                                               outputVariableType=ov.Force))
                    for o in [drive, *meshes]]}
    mbs.Assemble()
    sim = exu.SimulationSettings()
    # two turns: the first lets the start-up transient of the multipliers die out
    sim.timeIntegration.numberOfSteps = 2 * steps
    sim.timeIntegration.endTime = 2 * period
    sim.timeIntegration.verboseMode = 0
    sim.timeIntegration.newton.relativeTolerance = 1e-10
    sim.timeIntegration.newton.absoluteTolerance = 1e-10
    sim.timeIntegration.generalizedAlpha.spectralRadius = 0.5
    sim.timeIntegration.generalizedAlpha.useIndex2Constraints = True
    sim.timeIntegration.generalizedAlpha.useNewmark = True
    sim.timeIntegration.generalizedAlpha.newmarkGamma = 0.6
    sim.timeIntegration.generalizedAlpha.newmarkBeta = 0.3025
    sim.solution.file.write = False
    sim.solution.sensors.writePeriod = period / steps
    mbs.SolveDynamic(sim)
    q = [np.asarray(mbs.GetSensorStoredData(s)) for s in sens["q"]]
    v = [np.asarray(mbs.GetSensorStoredData(s)) for s in sens["v"]]
    lam = [np.asarray(mbs.GetSensorStoredData(s)) for s in sens["lam"]]
    t = q[0][:, 0]
    last = t >= period - 0.5 * period / steps  # the second turn
    q, v, lam = ([a[last] for a in arr] for arr in (q, v, lam))
    t = t[last]
    ref = [np.r_[0.0, 0.0, th[0]], np.r_[p23, th[1]], np.r_[p4, th[2]]]
    pos = [q[i][:, 1:4] + ref[i] for i in range(3)]
    vel = [v[i][:, 1:4] for i in range(3)]
    ke = sum(0.5 * m * (vv[:, 0] ** 2 + vv[:, 1] ** 2) + 0.5 * j * vv[:, 2] ** 2
             for m, j, vv in zip(masses, inertias, vel, strict=True))
    pe = sum(m * G * p[:, 1] for m, p in ((m23, pos[1]), (m4, pos[2]))) if spec.gravity \
        else np.zeros_like(t)
    energy = ke + pe
    # the drive constraint's multiplier acts on theta_c with the sign of its equation;
    # the torque the motor applies is the generalised force that keeps the law
    tau = -lam[0][:, 1]
    power = tau * vel[0][:, 2]
    work = np.r_[0.0, np.cumsum(0.5 * (power[1:] + power[:-1]) * np.diff(t))]
    change = energy - energy[0]
    # relative to the energy's swing, or to the mean kinetic energy where it hardly
    # swings (a train turning at constant speeds)
    span = max(float(np.ptp(change)), float(np.mean(ke)))
    # a toothless dwell starts and ends with a jump of gears 2-3's speed (an impact of
    # the rigid model): the balance is checked between the impacts, each impact's
    # energy jump is reported
    psi_run = omega * (t - t[0])
    cuts = []
    impacts = []
    if train.dwell_start is not None and train.dwell_theta1 > 0:
        cuts = [float(train.dwell_start), float(train.dwell_start + train.dwell_theta1)]
    seg = np.zeros(len(t), dtype=int)
    for c in cuts:
        seg += psi_run >= c
    seg[seg == len(cuts)] = 0 if cuts else seg[seg == len(cuts)]  # the turn wraps around
    win = np.radians(1.0)
    near = np.zeros(len(t), dtype=bool)
    for c in cuts:
        near |= np.abs(psi_run - c) < win
        before = np.flatnonzero(psi_run < c - win)[-1]
        after = np.flatnonzero(psi_run > c + win)[0]
        impacts.append({"carrier_angle_deg": float(np.degrees(c)),
                        "kinetic_energy_jump_J": float(ke[after] - ke[before]),
                        "drive_work_J": float(work[after] - work[before]),
                        "peak_input_torque_N_m": float(np.abs(tau[before:after + 1]).max())})
    err = 0.0
    for k in np.unique(seg):
        idx = np.flatnonzero((seg == k) & ~near)
        if len(idx) < 2:
            continue
        # within a run the drive's work and the energy change move together
        runs = np.split(idx, np.flatnonzero(np.diff(idx) > 1) + 1)
        for r in runs:
            d = (work[r] - work[r[0]]) - (change[r] - change[r[0]])
            err = max(err, float(np.abs(d).max()) / span)
    psi = omega * (t - t[0])
    th23 = pos[1][:, 2]
    ucur = pos[0][:, 2] - th23 + k23
    r2 = train.gear2(train.gear2_contact0 + ucur) * 1e-3  # pitch radii at the contacts
    r3 = train.gear3(train.gear3_contact0 + ucur) * 1e-3
    r4 = train.a2 * 1e-3 - r3
    t1, t2 = lam[1][:, 1], lam[2][:, 1]
    return {
        "model": "exudyn " + exu.config.Version() + ": 3 planar rigid bodies, 3 revolute "
                 "joints, driven carrier, 2 mesh constraints (pitch-curve laws)",
        "inputs": spec.model_dump(),
        "masses_kg": {"gears_2_3": m23, "planet_arm_payload": m4, "gear2": ma, "gear3": mb,
                      "planet": mp},
        "inertias_kg_m2": {"gears_2_3_about_centroid": j23, "planet_arm_payload_about_com": j4},
        "steps": steps,
        "input_torque_N_m": {"min": float(tau.min()), "max": float(tau.max()),
                             "rms": float(np.sqrt(np.mean(tau**2)))},
        "mesh_torque_N_m": {"sun_gear2": float(np.abs(t1).max()),
                            "gear3_planet": float(np.abs(t2).max())},
        "tangential_tooth_force_N": {"sun_gear2_max": float(np.max(np.abs(t1) / r2)),
                                     "gear3_planet_max": float(np.max(np.abs(t2) / r4))},
        "dwell_impacts": impacts,
        "energy_balance": {"max_error_fraction_of_energy_range": err,
                           "checked": "over the whole turn" if not cuts else
                           "between the dwell's impacts (1 deg either side left out)",
                           "energy_range_J": float(np.ptp(change)),
                           "mean_kinetic_energy_J": float(np.mean(ke)),
                           "work_over_cycle_J": float(work[-1]),
                           "energy_change_over_cycle_J": float(change[-1])},
        "series": {"carrier_angle_deg": np.degrees(psi), "input_torque_N_m": tau,
                   "tooth_force_sun_gear2_N": np.abs(t1) / r2,
                   "tooth_force_gear3_planet_N": np.abs(t2) / r4,
                   "work_J": work, "energy_change_J": change},
    }
