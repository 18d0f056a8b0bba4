"""Multibody loads (plantmech.contact.loads, exudyn) against an analytic case: circular
gears with unit stage ratios keep the arm's attitude fixed (it translates on a circle)
and turn gears 2-3 at a constant speed, so at constant carrier speed only gravity needs
torque: tau = g cos(theta_c) (m4 L1 + m23 a1); and the planet body's mesh torque is
m4 x4 e_arm x (g y - omega^2 L1 e_c)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from plantmech.contact.loads import LoadSpec, polygon_mass_properties, seeder_loads
from plantmech.geometry.periodic import RadiusCurve
from plantmech.mechanisms.seeder_forward import SeederTrain, simulate


def _disc(r_mm, n=720):
    a = np.linspace(0, 2 * np.pi, n, endpoint=False)
    return SimpleNamespace(rings=[np.c_[r_mm * np.cos(a), r_mm * np.sin(a)]])


def test_polygon_mass_properties_of_an_annulus():
    outer, inner = _disc(50.0, 4000).rings[0], _disc(10.0, 4000).rings[0][::-1]
    m, c, j = polygon_mass_properties([outer, inner], 0.01, 7850.0)
    area = np.pi * (0.05**2 - 0.01**2)
    assert m == pytest.approx(7850 * 0.01 * area, rel=1e-5)
    assert np.abs(c).max() < 1e-12
    assert j == pytest.approx(0.5 * m * (0.05**2 + 0.01**2), rel=1e-5)


@pytest.mark.parametrize("gravity", [True, False])
def test_circular_train_torque_is_gravity_alone(gravity):
    L1, L2 = 240.0, 400.0
    a = L1 / 2
    ang = np.radians(np.arange(0, 360, 45.0))
    half = RadiusCurve.from_samples(ang, np.full(8, a / 2))
    train = SeederTrain(L1=L1, L2=L2, a1=a, a2=a, gear2=half, gear3=half, gear2_contact0=0.0,
                        gear3_contact0=np.pi, carrier0=np.radians(30.0),
                        arm0=np.radians(-60.0))
    nom = simulate(train, samples=3600)
    gears = {n: _disc(a / 2) for n in ("gear2", "gear3", "planet", "sun")}
    spec = LoadSpec(arm_mass_kg=1.2, payload_kg=0.4, gravity=gravity)
    res = seeder_loads(train, nom, gears, spec, steps=720)
    s = res["series"]
    psi = np.radians(s["carrier_angle_deg"])
    th_c = train.carrier0 - psi
    m23 = res["masses_kg"]["gears_2_3"]
    m4 = res["masses_kg"]["planet_arm_payload"]
    g = 9.81 if gravity else 0.0
    expected = g * np.cos(th_c) * (m4 * L1 * 1e-3 + m23 * a * 1e-3)
    scale = max(np.abs(expected).max(), 1.0)
    assert np.abs(s["input_torque_N_m"] - expected).max() < 0.01 * scale
    # the planet's mesh torque keeps the translating arm from turning
    omega = np.radians(360.0)
    x4 = (1.2 * L2 / 2 + 0.4 * L2) * 1e-3 / m4
    e_arm = np.array([np.cos(train.arm0), np.sin(train.arm0)])
    e_c = np.c_[np.cos(th_c), np.sin(th_c)]
    acc = np.c_[np.zeros_like(psi), np.full_like(psi, g)] - omega**2 * L1 * 1e-3 * e_c
    t2 = m4 * x4 * (e_arm[0] * acc[:, 1] - e_arm[1] * acc[:, 0])
    force = np.abs(t2) / (a / 2 * 1e-3)
    assert np.abs(s["tooth_force_gear3_planet_N"] - force).max() < 0.01 * force.max()
    assert res["energy_balance"]["max_error_fraction_of_energy_range"] < 0.01
