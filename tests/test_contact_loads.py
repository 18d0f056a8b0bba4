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


def test_dwell_impacts_accounting_across_the_turns_start():
    """``loads.dwell_impacts`` on a made-up turn with two impacts, one 0.2 deg after the
    turn's start (its window closes through the turn's last step): kinetic energy 1 J
    jumping +2 J at 0.2 deg and -2 J at 45 deg, potential 0.5 sin(psi) J, the drive's work
    the energy change plus 0.3 J and 0.1 J lost at the impacts. Expected: each jump, the
    drive's work across the 1 deg windows (the energy change there plus the loss), the
    loss itself, and an exact balance between the impacts."""
    from plantmech.contact.loads import dwell_impacts

    n, omega = 360, np.radians(360.0)
    psi = np.radians(np.arange(n, dtype=float))
    t = psi / omega
    c1, c2 = np.radians(0.2), np.radians(45.0)
    ke = 1.0 + 2.0 * ((psi >= c1) & (psi < c2))
    pe = 0.5 * np.sin(psi)
    change = ke + pe - (ke[0] + pe[0])
    work = change + 0.3 * (psi >= c1) + 0.1 * (psi >= c2)
    power = 0.5 * np.cos(psi) * omega  # the smooth part's rate (the closing step's)
    torque = np.zeros(n)
    torque[[0, 45]] = [50.0, -70.0]
    res = {"psi": psi, "t": t, "kinetic": ke, "work": work, "energy_change": change,
           "power": power, "input_torques": [torque], "error": 1.0}
    span = float(np.ptp(change))
    impacts, err = dwell_impacts(res, [c2, c1 + 2 * np.pi], span)
    first, second = impacts
    assert first["carrier_angle_deg"] == pytest.approx(0.2)
    assert first["kinetic_energy_jump_J"] == pytest.approx(2.0)
    # from 359 deg (1.2 deg before) to 2 deg (1.8 deg after)
    e_change = 2.0 + 0.5 * (np.sin(np.radians(2.0)) - np.sin(np.radians(359.0)))
    assert first["energy_change_J"] == pytest.approx(e_change, abs=1e-12)
    assert first["drive_work_J"] == pytest.approx(e_change + 0.3, abs=1e-6)
    assert first["dissipated_J"] == pytest.approx(0.3, abs=1e-6)
    assert first["peak_input_torque_N_m"] == 50.0
    assert second["kinetic_energy_jump_J"] == pytest.approx(-2.0)
    assert second["dissipated_J"] == pytest.approx(0.1, abs=1e-12)
    assert second["peak_input_torque_N_m"] == 70.0
    assert err == pytest.approx(0.0, abs=1e-12)
    # without cuts: the whole turn's figure
    assert dwell_impacts(res, [], span) == ([], 1.0)


def test_seeder_file_frames_are_the_general_trains():
    """The dedicated seeder's gear-file frames on the shaft and the arm
    (``contact.seeder.file_frames``, as ``analyse_seeder`` poses the outlines), which place
    gear 3's and the planet's centroids in the loads' bodies, against the general train
    model's (``trains``: gear 1b's phase on gear 1's shaft, the planet's body angle less
    the arm's) for Table 4: the same to 1e-9 rad. The loads used to take gear 3's frame as
    gear 2's (74.41 deg off) and the planet's centroid on the arm line."""
    from plantmech.contact.seeder import file_frames, seeder_train
    from plantmech.design import load_design
    from plantmech.trains.gearing import built_train
    from plantmech.trains.model import simulate as simulate_train
    from tests.conftest import EXAMPLES

    train = seeder_train(load_design(EXAMPLES / "sugarcane_table4.toml"))
    frames = file_frames(train, simulate(train, samples=720))
    m = simulate_train(built_train(load_design(EXAMPLES / "planetary" / "sugarcane_table4.toml")),
                       samples=720)
    phase = m.driver_angles[1][0, 0, 0] - m.gear_angles[1][0, 0, 0]
    planet = m.carrier[0, 0, 0] + m.gear_angles[2][0, 0, 0] - m.arm_angle[0, 0, 0]

    def same(a, b):
        return abs(np.angle(np.exp(1j * (a - b)))) < 1e-9

    assert same(frames["gear3_minus_gear2"], phase)
    assert same(frames["planet_minus_arm"], planet)
    assert same(frames["gear2"], m.gear_angles[1][0, 0, 0])
    assert abs(np.degrees(np.angle(np.exp(1j * frames["gear3_minus_gear2"]))) - 74.408) < 1e-3
