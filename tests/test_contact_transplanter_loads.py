"""Multibody loads of the rice transplanter's trains (plantmech.contact.transplanter_loads,
exudyn) against analytic cases: with circular gears every arm translates on a circle
(its planet turns back what the carrier turns) and every gear turns at a constant speed,
so at constant input speeds only gravity and the planet axis's centripetal acceleration
need torque:
- a planet's mesh torque keeps its translating arm from turning:
  m4 x4 e_arm x (g y - omega^2 r_axis e_line);
- K-H-V (one arm): the middle passes it on unchanged (sun-middle force = middle-planet
  force, all radii equal) and the carrier needs g cos(theta_c) (2 a m4 + a m_middle);
- differential: the internal gear takes R / r_p times each planet's torque,
  tau_1 = (R / r_p) sum_j lambda_j, and the carrier the rest of the energy balance,
  tau_c = m4 g a sum_j cos(line_j) - k tau_1."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from plantmech.contact.loads import LoadSpec
from plantmech.contact.transplanter_loads import PeriodicLaw, differential_loads, khv_loads
from plantmech.design import load_design
from tests.conftest import EXAMPLES

OMEGA = np.radians(360.0)


def _disc(r_mm, hole_mm=None, n=720):
    a = np.linspace(0, 2 * np.pi, n, endpoint=False)
    rings = [np.c_[r_mm * np.cos(a), r_mm * np.sin(a)]]
    if hole_mm:
        rings.append(np.c_[hole_mm * np.cos(a), hole_mm * np.sin(a)][::-1])
    return SimpleNamespace(rings=rings)


def _mesh_torque(m4, x4, e_arm, g, axis_radius, line):
    """Torque (N m, CCW) the mesh puts on a translating arm body: m4 x4 e_arm x
    (g y - omega^2 r e_line)."""
    acc = np.c_[np.zeros_like(line), np.full_like(line, g)] \
        - OMEGA**2 * axis_radius * np.c_[np.cos(line), np.sin(line)]
    return m4 * x4 * (e_arm[0] * acc[:, 1] - e_arm[1] * acc[:, 0])


def test_periodic_law_is_the_spline_plus_turns():
    x = np.linspace(0, 2 * np.pi, 64, endpoint=False)
    law = PeriodicLaw(x, x + 0.3 * np.sin(x), 1.0)
    for v in (-7.0, 0.1, 3.0, 12.5):
        assert law(v) == pytest.approx(v + 0.3 * np.sin(v), abs=2e-5)
        assert law(v, 1) == pytest.approx(1 + 0.3 * np.cos(v), abs=2e-4)
        assert law(v, 2) == pytest.approx(-0.3 * np.sin(v), abs=5e-3)


@pytest.mark.parametrize("gravity", [True, False])
def test_khv_circular_one_arm(gravity):
    R = 30.0  # every pitch radius; centre distance 2 R, planet axis at 4 R
    d = load_design(EXAMPLES / "rice_transplanter_khv.toml")
    d.sun_gear.radii_mm = [R] * len(d.sun_gear.radii_mm)
    d.carrier.arms = 1
    gears = {"middle": _disc(R), "planet": _disc(R)}
    spec = LoadSpec(arm_mass_kg=1.2, payload_kg=0.4, gravity=gravity)
    res = khv_loads(d, gears, spec, steps=720)
    s = res["series"]
    psi = np.radians(s["carrier_angle_deg"])
    th_c = np.radians(d.carrier.initial_angle_deg) - psi
    m4, mm = res["masses_kg"]["planet_arm_1"], res["masses_kg"]["middle_1"]
    a = 2 * R * 1e-3
    g = 9.81 if gravity else 0.0
    expected = g * np.cos(th_c) * (2 * a * m4 + a * mm)
    scale = max(np.abs(expected).max(), 1.0)
    assert np.abs(s["input_torque_carrier_N_m"] - expected).max() < 0.01 * scale
    S = d.arm.S_mm * 1e-3
    x4 = (1.2 * S / 2 + 0.4 * S) / m4
    from plantmech.workflows import simulate_transplanter

    _, motion, *_ = simulate_transplanter(d, samples=360)
    arm = motion.arm_angle[0, 0]
    assert np.ptp(arm) < 1e-6  # the arm translates
    e_arm = np.array([np.cos(arm[0]), np.sin(arm[0])])
    force = np.abs(_mesh_torque(m4, x4, e_arm, g, 2 * a, th_c)) / (R * 1e-3)
    for name in ("middle_planet_1", "sun_middle_1"):
        got = s[f"tooth_force_{name}_N"]
        assert np.abs(got - force).max() < 0.01 * force.max()
    assert res["energy_balance"]["max_error_fraction_of_energy_range"] < 0.01


@pytest.mark.parametrize("arms", [1, 3])
def test_differential_circular(arms):
    """One arm: every torque in full; three arms: their torques on the internal gear
    cancel (attitudes 120 deg apart), the sum checked against one planet's."""
    from tests.test_contact_transplanter import LOBES, R, circular_design

    d = circular_design()  # internal R = 60 mm, 2 lobes, k = 1/2: planets R / 2
    d.carrier.arms = arms
    r_p = R / LOBES
    gears = {"internal": _disc(R + 20.0, R), "planet": _disc(r_p)}
    spec = LoadSpec(arm_mass_kg=1.2, payload_kg=0.4)
    res = differential_loads(d, gears, spec, steps=720)
    s = res["series"]
    psi = np.radians(s["carrier_angle_deg"])
    th_c = np.radians(d.carrier.initial_angle_deg) - psi
    m4 = res["masses_kg"]["planet_arm_1"]
    a = (R - r_p) * 1e-3
    S = d.arm.S_mm * 1e-3
    x4 = (1.2 * S / 2 + 0.4 * S) / m4
    from plantmech.workflows import simulate_transplanter

    _, motion, *_ = simulate_transplanter(d, samples=360)
    J = d.carrier.arms
    lam = []
    for j in range(J):
        arm = motion.arm_angle[0, j]
        assert np.ptp(arm) < 1e-5  # every arm translates
        e_arm = np.array([np.cos(arm[0]), np.sin(arm[0])])
        line = th_c - 2 * np.pi * j / J
        lam.append(_mesh_torque(m4, x4, e_arm, 9.81, a, line))
        force = np.abs(lam[-1]) / (r_p * 1e-3)
        got = s[f"tooth_force_internal_planet_{j + 1}_N"]
        assert np.abs(got - force).max() < 0.01 * force.max()
    tau_1 = (R / r_p) * np.sum(lam, axis=0)
    k = d.drive.speed_ratio
    tau_c = m4 * 9.81 * a * sum(np.cos(th_c - 2 * np.pi * j / J) for j in range(J)) \
        - k * tau_1
    one = (R / r_p) * np.abs(lam[0]).max()  # one planet's torque on the internal gear
    for got, want in ((s["input_torque_internal_N_m"], tau_1),
                      (s["input_torque_carrier_N_m"], tau_c)):
        assert np.abs(got - want).max() < 0.01 * max(np.abs(want).max(), one)
    assert res["energy_balance"]["max_error_fraction_of_energy_range"] < 0.01
