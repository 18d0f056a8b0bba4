"""Loads of a planetary train over a carrier turn at constant input speeds, computed by
the multibody engine exudyn and cross-checked against an energy balance: the engine
(``Body``, ``MeshLaw``, ``solve_loads``; the transplanters' trains use it too, in
``contact/transplanter_loads.py``) and the seeder's train.

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
polar moment), each centroid placed in the frame its gear file is cut in
(``contact.seeder.file_frames``: gear 3's file frame is turned from gear 2's on their
shaft, the planet's from the arm's), the arm as a slender rod L2 long, the payload (cane /
seedling) a point mass at the tip. The carrier is balanced and turns at constant speed:
its inertia does no work, so its kinetic energy is left out of the balance (its 1 kg and
0.1 kg m^2 only keep the solver's mass matrix regular). The check: the drive's work W(t) =
integral of torque x carrier speed equals the change of kinetic + potential energy at
every step (< 1 % of the energy's range over the turn, or of the mean kinetic energy if
that is larger).
"""

from __future__ import annotations

from bisect import bisect_right
from dataclasses import dataclass, field

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


@dataclass
class Body:
    """One rigid body: mass (kg), inertia about its centroid (kg m^2), its frame's angle
    at t = 0 and angular velocity (rad, rad/s), its centroid in its frame relative to its
    pivot (m), the pivot: on the ground at ``pivot`` (world, m) or on the carrier at
    ``pivot`` (carrier frame, m)."""

    name: str
    mass: float
    inertia: float
    angle0: float
    omega0: float
    centroid: np.ndarray
    pivot: np.ndarray
    on_carrier: bool


@dataclass
class MeshLaw:
    """sum_i a_i theta_i + b - F(sum_i w_i theta_i + x0) = 0 over body angles (indices
    into the body list); ``radius`` (T,) m: the driven gear's pitch radius at the contact
    over the carrier turn's samples (for the tooth force)."""

    name: str
    a: dict
    b: float
    w: dict
    x0: float
    F: PeriodicLaw
    radius: np.ndarray = field(repr=False)


def _rot(t: float) -> np.ndarray:
    return np.array([[np.cos(t), -np.sin(t)], [np.sin(t), np.cos(t)]])


def _perp(v: np.ndarray) -> np.ndarray:
    return np.array([-v[1], v[0]])


def solve_loads(bodies: list[Body], drives: list[int], laws: list[MeshLaw], spec: LoadSpec,
                steps: int, gamma: float = 0.52) -> dict:
    """Integrate two turns of the carrier (index-2 Newmark: ``gamma`` > 1/2 damps the
    high-frequency response, beta = (gamma + 1/2)^2 / 4) and report the second: input
    torques (N m) of the driven bodies ``drives`` (body 0 is the carrier), mesh torques and
    tangential tooth forces, the energy balance."""
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

    omega = np.radians(spec.carrier_speed_deg_s)
    period = TWO_PI / omega
    carrier = bodies[0]
    wc = carrier.omega0
    c0 = carrier.angle0
    SC = exu.SystemContainer()
    mbs = SC.AddSystem()
    ground = mbs.AddObject(ObjectGround())
    nodes, objs, refs = [], [], []
    for b in bodies:
        piv = b.pivot if not b.on_carrier else _rot(c0) @ b.pivot
        vpiv = np.zeros(2) if not b.on_carrier else wc * _perp(piv)
        off = _rot(b.angle0) @ b.centroid
        pos = piv + off
        vel = vpiv + b.omega0 * _perp(off)
        refs.append(np.r_[pos, b.angle0])
        nodes.append(mbs.AddNode(NodeRigidBody2D(referenceCoordinates=[*pos, b.angle0],
                                                 initialVelocities=[*vel, b.omega0])))
        objs.append(mbs.AddObject(ObjectRigidBody2D(nodeNumber=nodes[-1], mass=b.mass,
                                                    inertia=b.inertia)))
    for b, o in zip(bodies, objs, strict=True):
        mk1 = mbs.AddMarker(MarkerBodyPosition(bodyNumber=o,
                                               localPosition=[*(-b.centroid), 0.0]))
        mk0 = mbs.AddMarker(MarkerBodyPosition(
            bodyNumber=objs[0] if b.on_carrier else ground,
            localPosition=[*(b.pivot - (carrier.centroid if b.on_carrier else 0.0)), 0.0]))
        mbs.AddObject(ObjectJointRevolute2D(markerNumbers=[mk0, mk1]))
    n_ground = mbs.AddNode(NodePointGround())
    m_ground = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=n_ground, coordinate=0))
    drive_objs = []
    for i in drives:
        w = bodies[i].omega0
        mk = mbs.AddMarker(MarkerNodeCoordinate(nodeNumber=nodes[i], coordinate=2))
        # node coordinates are displacements from the reference: theta - theta(0) = w t
        drive_objs.append(mbs.AddObject(ObjectConnectorCoordinate(
            markerNumbers=[m_ground, mk],
            offsetUserFunction=lambda mbs_, t, item, off, w=w: w * t,
            offsetUserFunction_t=lambda mbs_, t, item, off, w=w: w)))
    holder = mbs.AddObject(ObjectGenericODE2(nodeNumbers=nodes))
    m_all = mbs.AddMarker(MarkerObjectODE2Coordinates(objectNumber=holder))
    m_none = mbs.AddMarker(MarkerNodeCoordinates(nodeNumber=n_ground))
    nq = 3 * len(bodies)
    mesh_objs = []
    for law in laws:
        a = [(3 * i + 2, v) for i, v in law.a.items()]
        w = [(3 * i + 2, v) for i, v in law.w.items()]

        def jac(mbs_, t, item, q, q_t, vel, a=a, w=w, law=law):
            d = law.F(sum(v * q[k] for k, v in w) + law.x0, 1)
            out = np.zeros((1, nq))
            for k, v in a:
                out[0, k] += v
            for k, v in w:
                out[0, k] -= d * v
            return out

        def con(mbs_, t, item, q, q_t, vel, a=a, w=w, law=law, jac=jac):
            if vel:  # index-2 form: the time derivative (scleronomic: jacobian x velocities)
                return [float(jac(mbs_, t, item, q, q_t, vel)[0] @ np.asarray(q_t))]
            return [sum(v * q[k] for k, v in a) + law.b
                    - law.F(sum(v * q[k] for k, v in w) + law.x0)]

        mesh_objs.append(mbs.AddObject(ObjectConnectorCoordinateVector(
            markerNumbers=[m_none, m_all], scalingMarker0=np.zeros((1, nq)),
            constraintUserFunction=con, jacobianUserFunction=jac)))
    if spec.gravity:
        for b, o in zip(bodies, objs, strict=True):
            if b.mass > 0 and b is not carrier:
                mk = mbs.AddMarker(MarkerBodyPosition(bodyNumber=o, localPosition=[0, 0, 0]))
                mbs.AddLoad(Force(markerNumber=mk, loadVector=[0.0, -b.mass * G, 0.0]))
    ov = exu.OutputVariableType
    s_q = [mbs.AddSensor(SensorNode(nodeNumber=n, storeInternal=True,
                                    outputVariableType=ov.Coordinates)) for n in nodes]
    s_v = [mbs.AddSensor(SensorNode(nodeNumber=n, storeInternal=True,
                                    outputVariableType=ov.Coordinates_t)) for n in nodes]
    s_l = [mbs.AddSensor(SensorObject(objectNumber=o, storeInternal=True,
                                      outputVariableType=ov.Force))
           for o in drive_objs + mesh_objs]
    mbs.Assemble()
    sim = exu.SimulationSettings()
    sim.timeIntegration.numberOfSteps = 2 * steps
    sim.timeIntegration.endTime = 2 * period
    sim.timeIntegration.verboseMode = 0
    sim.timeIntegration.newton.relativeTolerance = 1e-10
    sim.timeIntegration.newton.absoluteTolerance = 1e-10
    sim.timeIntegration.generalizedAlpha.spectralRadius = 0.5
    sim.timeIntegration.generalizedAlpha.useIndex2Constraints = True
    sim.timeIntegration.generalizedAlpha.useNewmark = True
    sim.timeIntegration.generalizedAlpha.newmarkGamma = gamma
    sim.timeIntegration.generalizedAlpha.newmarkBeta = 0.25 * (gamma + 0.5) ** 2
    sim.solution.file.write = False
    sim.solution.sensors.writePeriod = period / steps
    mbs.SolveDynamic(sim)
    q = [np.asarray(mbs.GetSensorStoredData(s)) for s in s_q]
    v = [np.asarray(mbs.GetSensorStoredData(s)) for s in s_v]
    lam = [np.asarray(mbs.GetSensorStoredData(s)) for s in s_l]
    t = q[0][:, 0]
    last = t >= period - 0.5 * period / steps  # the second turn
    q, v, lam = ([x[last] for x in arr] for arr in (q, v, lam))
    t = t[last]
    pos = [q[i][:, 1:4] + refs[i] for i in range(len(bodies))]
    vel = [x[:, 1:4] for x in v]
    ke = sum(0.5 * b.mass * (x[:, 0] ** 2 + x[:, 1] ** 2) + 0.5 * b.inertia * x[:, 2] ** 2
             for b, x in zip(bodies, vel, strict=True) if b is not carrier)
    pe = (sum(b.mass * G * p[:, 1] for b, p in zip(bodies, pos, strict=True)
              if b is not carrier) if spec.gravity else np.zeros_like(t))
    energy = ke + pe
    # a drive's multiplier acts on its angle with the sign of its equation: the torque
    # the motor applies is the generalised force that keeps the law
    taus = [-lam[k][:, 1] for k in range(len(drives))]
    power = sum(tau * vel[i][:, 2] for tau, i in zip(taus, drives, strict=True))
    work = np.r_[0.0, np.cumsum(0.5 * (power[1:] + power[:-1]) * np.diff(t))]
    change = energy - energy[0]
    span = max(float(np.ptp(change)), float(np.mean(ke)))
    err = float(np.abs(work - change).max()) / span
    psi = omega * (t - t[0])
    # the samples of the second turn are those of the first: psi on the laws' grid
    mesh = [lam[len(drives) + k][:, 1] for k in range(len(laws))]
    forces = {}
    for law, tq in zip(laws, mesh, strict=True):
        r = np.interp(psi, np.linspace(0.0, TWO_PI, len(law.radius), endpoint=False),
                      law.radius, period=TWO_PI)
        forces[law.name] = np.abs(tq) / r
    return {
        "t": t, "psi": psi, "input_torques": taus, "mesh_torques": mesh,
        "tooth_forces": forces, "work": work, "power": power, "energy_change": change,
        "kinetic": ke,
        "error": err, "version": exu.config.Version()}


def dwell_impacts(res: dict, cuts: list[float], span: float, window_deg: float = 1.0
                  ) -> tuple[list[dict], float]:
    """A toothless dwell's ends are impacts of the rigid model (the held gear's speed
    relative to the carrier jumps): (one record per impact at the carrier angles ``cuts``
    (rad, in the carrier's sense from the start): the kinetic-energy jump, the kinetic +
    potential energy's change, the drive's work and what the work leaves over (dissipated)
    (J) from ``window_deg`` before to as far after it, the peak input torque (N m) over
    that window; the energy balance's largest error between the impacts, a
    fraction of ``span`` (J)). ``res``: ``solve_loads``'s result (one turn, periodic: a
    window across the turn's start is closed through its last step). Without cuts: the
    balance over the whole turn (``res["error"]``)."""
    if not cuts:
        return [], float(res["error"])
    psi, ke = res["psi"], res["kinetic"]
    work, change = res["work"], res["energy_change"]
    tau = sum(res["input_torques"])
    n = len(psi)
    # the work of the step closing the turn (last sample -> the first, one turn on)
    closing = 0.5 * (res["power"][-1] + res["power"][0]) * (res["t"][1] - res["t"][0])
    win = np.radians(window_deg)
    cuts = sorted(float(np.mod(c, TWO_PI)) for c in cuts)
    near = np.zeros(n, dtype=bool)
    impacts = []
    for c in cuts:
        d = np.angle(np.exp(1j * (psi - c)))  # (-pi, pi]: signed distance from the impact
        near |= np.abs(d) < win
        before = int(np.flatnonzero(d < -win)[np.argmax(d[d < -win])])
        after = int(np.flatnonzero(d > win)[np.argmin(d[d > win])])
        if after > before:
            w = work[after] - work[before]
            span_idx = np.arange(before, after + 1)
        else:  # across the turn's start
            w = work[-1] - work[before] + closing + work[after]
            span_idx = np.r_[np.arange(before, n), np.arange(0, after + 1)]
        de = float(change[after] - change[before])
        impacts.append({"carrier_angle_deg": round(float(np.degrees(c)), 9),
                        "kinetic_energy_jump_J": float(ke[after] - ke[before]),
                        "energy_change_J": de,
                        "drive_work_J": float(w),
                        # the integrator's damping of the unresolved jump (the smooth
                        # law's exact motion keeps work = energy change)
                        "dissipated_J": float(w) - de,
                        "peak_input_torque_N_m": float(np.abs(tau[span_idx]).max())})
    seg = np.zeros(n, dtype=int)
    for c in cuts:
        seg += psi >= c
    seg[seg == len(cuts)] = 0  # the turn wraps around
    err = 0.0
    for k in np.unique(seg):
        idx = np.flatnonzero((seg == k) & ~near)
        if len(idx) < 2:
            continue
        # within a run the drive's work and the energy change move together
        for r in np.split(idx, np.flatnonzero(np.diff(idx) > 1) + 1):
            dev = (work[r] - work[r[0]]) - (change[r] - change[r[0]])
            err = max(err, float(np.abs(dev).max()) / span)
    return impacts, err


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
    turn (``steps`` time steps), and the energy balance: the seeder's three bodies and two
    meshes handed to ``solve_loads`` (the engine of the transplanters' loads too)."""
    from plantmech.contact.seeder import file_frames
    from plantmech.contact.transplanter_loads import _arm_body
    from plantmech.mechanisms.seeder_forward import shaft_offset

    # the gear 2-3 shaft on the carrier: off the carrier line by this angle at O (CCW side,
    # as outputs/seeder_report places it), on it when a1 + a2 = L1
    off = shaft_offset(train)
    omega = np.radians(spec.carrier_speed_deg_s)
    L1, L2, a1 = train.L1 * 1e-3, train.L2 * 1e-3, train.a1 * 1e-3
    c0, arm0 = float(train.carrier0), float(train.arm0)
    U, V = _laws(nominal)
    thick = spec.face_width_mm * 1e-3
    props = {n: polygon_mass_properties(gears[n].rings, thick, spec.density_kg_m3)
             for n in ("gear2", "gear3", "planet")}
    (ma, ca, ja), (mb, cb, jb) = props["gear2"], props["gear3"]
    # gears 2 and 3 are cut each in its own mesh frame (``contact/seeder.py``: the contact
    # at body angle gear2_contact0 faces O, gear3_contact0 faces the planet axis at the
    # start): on their common shaft gear 3's file frame is turned from gear 2's by the
    # angle between those two directions less the contacts' difference
    frames = file_frames(train, nominal)
    cb = _rot(frames["gear3_minus_gear2"]) @ cb
    m23 = ma + mb
    c23 = (ma * ca + mb * cb) / m23  # in gear 2's file frame (the body frame)
    j23 = ja + ma * (ca - c23) @ (ca - c23) + jb + mb * (cb - c23) @ (cb - c23)
    # body angles at psi = 0: theta_c = carrier0, theta_23 = theta_c - u, theta_4 = arm;
    # gears 2-3's body frame: its contact body angle faces O
    u0 = float(U(0.0))
    th23 = c0 + off + np.pi - float(train.gear2_contact0)
    k23 = th23 - (c0 - u0)  # u = theta_c - theta_23 + k23
    du = float(U(0.0, 1)) * omega
    bodies = [Body("carrier", 1.0, 0.1, c0, -omega, np.zeros(2), np.zeros(2), False),
              Body("gears_2_3", m23, float(j23), th23, -omega - du, c23,
                   a1 * np.array([np.cos(off), np.sin(off)]), True),
              # planet + arm + payload, the body frame along the arm: the planet's
              # centroid placed by its file's frame (a constant angle from the arm's)
              _arm_body("planet_arm_payload", props["planet"], spec, L2, arm0,
                        -omega + float(V(u0, 1)) * du, np.array([L1, 0.0]),
                        frames["planet_minus_arm"])]
    m4, j4 = bodies[2].mass, bodies[2].inertia
    # pitch radii at the contacts over the nominal turn (u = U(psi) on its samples)
    r2 = train.gear2(train.gear2_contact0 + nominal.gear2_angle) * 1e-3
    r3 = train.gear3(train.gear3_contact0 + nominal.gear2_angle) * 1e-3
    laws = [  # C1: u - U(psi) = 0, psi = carrier0 - theta_c
            MeshLaw("sun_gear2", {0: 1.0, 1: -1.0}, k23, {0: -1.0}, c0, U, r2),
            # C2: theta_4 - theta_c - V(u) - (arm0 - carrier0) = 0
            MeshLaw("gear3_planet", {2: 1.0, 0: -1.0}, -(arm0 - c0), {0: 1.0, 1: -1.0}, k23,
                    V, train.a2 * 1e-3 - r3)]
    dwell = train.dwell_start is not None and train.dwell_theta1 > 0
    # a dwell's ends are impacts of the rigid model (gears 2-3's speed jumps): gamma 0.6
    # damps the ringing they start (the peak torque at an impact is the solver's, spread
    # over its steps); without impacts the transplanters' lighter 0.52
    res = solve_loads(bodies, [0], laws, spec, steps, gamma=0.6 if dwell else 0.52)
    ke, work, change = res["kinetic"], res["work"], res["energy_change"]
    tau = res["input_torques"][0]
    # relative to the energy's swing, or to the mean kinetic energy where it hardly
    # swings (a train turning at constant speeds)
    span = max(float(np.ptp(change)), float(np.mean(ke)))
    # a toothless dwell starts and ends with a jump of gears 2-3's speed (an impact of
    # the rigid model): the balance is checked between the impacts, each impact's
    # energy jump is reported
    psi_run = res["psi"]
    cuts = []
    if dwell:
        cuts = [float(train.dwell_start), float(train.dwell_start + train.dwell_theta1)]
    impacts, err = dwell_impacts(res, cuts, span)
    t1, t2 = res["mesh_torques"]
    f1, f2 = res["tooth_forces"]["sun_gear2"], res["tooth_forces"]["gear3_planet"]
    return {
        "model": "exudyn " + res["version"] + ": 3 planar rigid bodies, 3 revolute "
                 "joints, driven carrier, 2 mesh constraints (pitch-curve laws)",
        "inputs": spec.model_dump(),
        "masses_kg": {"gears_2_3": m23, "planet_arm_payload": m4, "gear2": ma, "gear3": mb,
                      "planet": props["planet"][0]},
        "inertias_kg_m2": {"gears_2_3_about_centroid": j23, "planet_arm_payload_about_com": j4},
        "steps": steps,
        "input_torque_N_m": {"min": float(tau.min()), "max": float(tau.max()),
                             "rms": float(np.sqrt(np.mean(tau**2)))},
        "mesh_torque_N_m": {"sun_gear2": float(np.abs(t1).max()),
                            "gear3_planet": float(np.abs(t2).max())},
        "tangential_tooth_force_N": {"sun_gear2_max": float(f1.max()),
                                     "gear3_planet_max": float(f2.max())},
        "dwell_impacts": impacts,
        "energy_balance": {"max_error_fraction_of_energy_range": err,
                           "checked": "over the whole turn" if not cuts else
                           "between the dwell's impacts (1 deg either side left out)",
                           "energy_range_J": float(np.ptp(change)),
                           "mean_kinetic_energy_J": float(np.mean(ke)),
                           "work_over_cycle_J": float(work[-1]),
                           "energy_change_over_cycle_J": float(change[-1])},
        "series": {"carrier_angle_deg": np.degrees(psi_run), "input_torque_N_m": tau,
                   "tooth_force_sun_gear2_N": f1, "tooth_force_gear3_planet_N": f2,
                   "work_J": work, "energy_change_J": change},
    }
