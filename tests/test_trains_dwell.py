"""The toothless dwell of the general train model (trains/model.py, ``PairSpec.dwell``;
seed 000's sector over cd, Eq. 5) and the one pair mapping ``trains.model.mesh``.

Independent expectations: a circular gear 2 rolled on a fixed sun has a constant ratio, so
its turn relative to the carrier is the meshing carrier angle (held through the dwell,
theta_1 behind after it) times 2 pi / (2 pi - theta_1) in closed form; the sun rolls the
same arc over 360 - theta_1 deg, so its radius is R2 2 pi / (2 pi - theta_1) and the
centre distance R2 (1 + 2 pi / (2 pi - theta_1)). Seed 000's Table 4 train against
mechanisms/seeder_forward: tests/test_planetary_examples.py.
"""

from __future__ import annotations

import copy
import tomllib

import numpy as np
import pytest

from plantmech.design import load_design
from plantmech.trains.curves import ellipse, fourier
from plantmech.trains.model import PairSpec, Train, build, forward, mesh, simulate
from plantmech.trains.pairs import PairError
from tests.conftest import EXAMPLES, assert_file_refused

TWO_PI = 2 * np.pi
TABLE4 = EXAMPLES / "planetary" / "sugarcane_table4.toml"


def meshing_angle(psi, start, sector):
    """Seed 000's meshing carrier angle, written out: psi before the dwell, the start
    through it, psi - theta_1 after it (one turn, 0 <= psi < 2 pi)."""
    return np.where(psi < start, psi, np.where(psi < start + sector, start, psi - sector))


def _circle_train(R2=40.0, start=1.0, sector=np.pi / 4, sense=-1, arms=1, L=200.0):
    gear2 = fourier(R2, [], [], 2048)
    return Train([PairSpec("external", follower=gear2, phase=0.3, dwell=(start, sector))],
                 carrier0=0.2, carrier_sense=sense, arm_length=L, arm_angle=0.5, arms=arms)


@pytest.mark.parametrize("sense", [-1, 1])
def test_circular_gear_rolls_the_meshing_angle_and_stops_in_the_dwell(sense):
    start, sector, R2 = 1.0, np.radians(45.0), 40.0
    m = forward(_circle_train(R2, start, sector, sense), 3600)
    law = m.built.laws[0]
    ratio = TWO_PI / (TWO_PI - sector)  # gear 2 turns once while the sun meshes 360 - 45
    # equal arcs: r_sun (2 pi - theta_1) = R2 2 pi, so r_sun = R2 ratio
    assert law.a[0] == pytest.approx(R2 + R2 * ratio, abs=1e-9)
    assert abs(law.closure_error[0]) < 1e-12
    psi = m.carrier_angle
    held = (psi >= start) & (psi < start + sector)
    # sun relative to the carrier: -s psi; an external pair turns gear 2 the other way
    expected = m.gear_angles[1][0, 0, 0] + sense * ratio * meshing_angle(psi, start, sector)
    assert np.abs(m.gear_angles[1][0, 0] - expected).max() < 1e-9
    assert np.all(m.gear_rates[1][0, 0][held] == 0.0)
    assert np.array_equal(m.meshes[0][0, 0], ~held)  # where the teeth mesh
    assert np.allclose(m.gear_rates[1][0, 0][~held], sense * ratio, atol=1e-9)
    # the arm on gear 2 is carried rigidly by the carrier through the dwell
    assert np.allclose(m.arm_rate[0, 0][held], sense, atol=1e-12)
    # the derived sun is the circle of radius R2 ratio, its toothless arc at the same radius
    assert np.allclose(m.built.drivers[0].r, R2 * ratio, atol=1e-9)
    assert np.allclose(m.built.drivers[0].dr, 0.0, atol=1e-9)


def test_the_sun_drawn_is_the_sun_that_meshes_and_its_toothless_arc_faces_the_lock():
    """An elliptic gear 2 (its sun non-circular): at every carrier angle the derived sun
    (``BuiltTrain.drivers[0]``, its real body) posed at its real body angle
    (``driver_angles[0]``) has the contact radius the law gives, through the dwell too
    (the lock radius on its toothless arc), and the arc spans theta_1 of the sun's body."""
    start, sector = 2.0, np.radians(60.0)
    tr = Train([PairSpec("external", follower=ellipse(30.0, 0.2, 4096), phase=1.1,
                         dwell=(start, sector))], carrier_sense=-1, arm_length=150.0)
    m = forward(tr, 3600)
    sun = m.built.drivers[0]
    theta = (0.0 + 0.0 - m.driver_angles[0]).reshape(1, -1)  # delta + eps_d - alpha
    r_sun, _ = sun(theta)
    err = np.abs(r_sun.ravel() - m.contact_radii[0][0].ravel())
    # the sun turns with the carrier angle; the Hermite cell across an end of the toothless
    # arc (where the slope steps) reads the curve to ~1e-3 mm, the rest to round-off
    cell = TWO_PI / 4096
    psi = m.carrier_angle
    edge = (np.abs(psi - start) < cell) | (np.abs(psi - start - sector) < cell)
    assert err[~edge].max() < 1e-9 and err[edge].max() < 1e-3
    assert np.abs(m.contact_radii[0][0] + m.contact_radii[0][1] - m.built.laws[0].a[0]).max() \
        < 1e-9
    flat = np.isclose(sun.dr[0], 0.0, atol=0.0) & np.isclose(sun.r[0], sun.r[0][
        np.argmin(np.abs(sun.dr[0]))])
    assert flat.sum() / flat.size == pytest.approx(sector / TWO_PI, abs=2 / flat.size)


def test_every_arm_meets_the_sectors_at_its_own_carrier_angle():
    """Two arms at 180 deg on a fixed sun: the toothless arc is a region of the sun, so
    arm 2 stops half a carrier turn before arm 1 (mod one turn)."""
    start, sector = np.radians(200.25), np.radians(40.0)  # off the 0.5 deg samples
    m = forward(_circle_train(start=start, sector=sector, arms=2), 720)
    psi = m.carrier_angle
    for j, offset in enumerate((0.0, np.pi)):
        u = np.mod(psi + offset, TWO_PI)
        held = (u >= start) & (u < start + sector)
        assert np.array_equal(m.gear_rates[1][0, j] == 0.0, held)


def test_a_population_of_dwells_gives_the_single_runs_numbers():
    start = np.array([1.0, 0.2, 3.0])
    sector = np.radians([45.0, 30.0, 90.0])
    e = np.array([0.1, 0.2, 0.15])
    phase = np.array([0.3, 1.0, 4.0])

    def train(s):
        return Train([PairSpec("external", follower=ellipse(30.0, e[s], 2048), phase=phase[s],
                               dwell=(start[s], sector[s])),
                      PairSpec("external", fourier(25.0, [2.0], [1.0], 2048), phase=0.4)],
                     arm_length=200.0, arm_angle=0.1)

    many = forward(train(slice(None)), 720)
    for k in range(3):
        one = forward(train(slice(k, k + 1)), 720)
        assert np.abs(one.tip[0] - many.tip[k]).max() < 1e-12
        assert np.abs(one.arm_angle[0] - many.arm_angle[k]).max() < 1e-12
        assert np.abs(one.tip_rate[0] - many.tip_rate[k]).max() < 1e-12
        assert np.abs(one.built.drivers[0].r[0] - many.built.drivers[0].r[k]).max() < 1e-12


@pytest.mark.parametrize("edit, message", [
    (lambda p, t: p.__setattr__("dwell", (1.0, 0.0)), r"pair\.dwell: .*inside one carrier"),
    (lambda p, t: p.__setattr__("dwell", (6.0, 1.0)), r"pair\.dwell: .*inside one carrier"),
    (lambda p, t: t.__setattr__("sun_speed_ratio", 0.5), r"pair\.dwell: .*fixed sun"),
    (lambda p, t: (p.__setattr__("driver", p.follower), p.__setattr__("follower", None)),
     r"pair\.dwell: give the follower's pitch curve"),
])
def test_a_dwell_the_model_cannot_take_is_refused_by_name(edit, message):
    tr = _circle_train()
    edit(tr.pairs[0], tr)
    with pytest.raises(PairError, match=message):
        build(tr)


def test_a_dwell_on_a_later_pair_is_refused_by_name():
    tr = _circle_train()
    tr.pairs.append(PairSpec("external", fourier(20.0, [], [], 2048), dwell=(1.0, 0.5),
                             name="second"))
    with pytest.raises(PairError, match=r"second\.dwell: .*first pair"):
        build(tr)


def test_simulate_is_mesh_pair_by_pair_bit_for_bit():
    """``simulate`` maps every pair through ``mesh`` (the one pair mapping, also the
    contact loads'): its angles, rates and contact radii are ``mesh``'s, bit for bit, for
    the bundled planetary examples (given drivers and followers, idlers, compound shafts,
    an internal driven sun, a dwell)."""
    from plantmech.trains.spec import build_from_design

    for name in ("rice_transplanter.toml", "rice_transplanter_khv.toml",
                 "sugarcane_seeder_optimized.toml", "sugarcane_table4.toml"):
        built = build_from_design(load_design(EXAMPLES / "planetary" / name))
        m = simulate(built, 360)
        for k, (law, spec) in enumerate(zip(built.laws, built.train.pairs, strict=True)):
            got = mesh(law, spec, m.driver_angles[k], m.gear_rates[k], built.toothless[k])
            assert np.array_equal(got.follower_angle, m.gear_angles[k + 1]), name
            assert np.array_equal(got.follower_rate, m.gear_rates[k + 1]), name
            assert np.array_equal(got.driver_radius, m.contact_radii[k][0]), name
            assert np.array_equal(got.follower_radius, m.contact_radii[k][1]), name


def test_contact_law_samples_hold_the_follower_on_the_toothless_arc():
    """contact/planetary's mesh law (``_mesh_law_samples``: the follower's angle as a
    function of its driver's over one driver turn) is ``mesh``'s: gear 2 of the Table 4
    file turns once per sun turn and stands still over theta_1 = 45 deg of it."""
    from plantmech.contact.planetary import _mesh_law_samples
    from plantmech.trains.spec import build_from_design

    built = build_from_design(load_design(TABLE4))
    m = simulate(built, 360)
    u, alpha_f, slope = _mesh_law_samples(built.laws[0], built.train.pairs[0],
                                          float(m.driver_angles[0][0, 0, 0]), 3600,
                                          built.toothless[0])
    assert slope == pytest.approx(-1.0, abs=1e-9)  # once per sun turn, the other way
    still = np.abs(np.diff(alpha_f)) < 1e-12
    assert still.sum() == pytest.approx(3600 * 45 / 360, abs=1)


def _table4() -> dict:
    return tomllib.loads(TABLE4.read_text())


@pytest.mark.parametrize("edit, field", [
    (lambda d: d["train"]["pairs"][0]["dwell"].update(sector_deg=0.0),
     r"train\.pairs\.0\.dwell\.sector_deg"),
    (lambda d: d["train"]["pairs"][0]["dwell"].update(start_deg=330.0),
     r"train\.pairs\.0\.dwell.*runs past the end of the carrier turn"),
    (lambda d: d["train"]["pairs"][0]["dwell"].update(start_deg=-1.0),
     r"train\.pairs\.0\.dwell\.start_deg"),
    (lambda d: d["train"]["pairs"][1].update(dwell={"start_deg": 1.0, "sector_deg": 5.0}),
     r"pairs\.1\.dwell: .*first pair"),
    (lambda d: d["train"].update(sun_speed_ratio=0.5), r"pairs\.0\.dwell: .*fixed sun"),
    (lambda d: d["train"]["pairs"][0].update(driver=d["train"]["pairs"][0].pop("follower")),
     r"pairs\.0\.dwell: give the follower's pitch curve"),
])
def test_bad_dwells_in_a_file_name_the_field_and_exit_2(edit, field, tmp_path, capsys):
    doc = copy.deepcopy(_table4())
    edit(doc)
    assert_file_refused(doc, field, tmp_path, capsys)
