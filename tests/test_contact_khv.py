"""Tooth-contact analysis of the K-H-V train (plantmech.contact.khv) against independent
expectations: a circular sun (constant radius R) makes every gear of the train a spur
gear of radius R (centre distance 2 R, middle and planet both R): gears from the involute
generator of tests/test_contact.py turn at the exact ratio with the cut backlash as each
pair's free play, the arm's play through the whole train is both pairs' together (the
middle-planet ratio is 1), and the tip band is the chord that play sweeps at the tip; a
middle gear turned by half a tooth and a planet with teeth removed are caught on every
arm, located."""

from __future__ import annotations

import numpy as np
import pytest

from plantmech.contact.khv import analyse_khv, khv_record
from plantmech.contact.outlines import outline_from_rings
from plantmech.design import load_design
from tests.conftest import EXAMPLES
from tests.test_contact import involute_gear

Z, M, J = 20, 2.0, 0.2  # teeth of every gear, module (mm), circumferential backlash (mm)
R = M * Z / 2  # pitch radius (mm)
LIMITS = {"transmission_error_deg": 0.5, "attitude_error_deg": 1.0, "tip_band_mm": 5.0}


def circular_design():
    d = load_design(EXAMPLES / "rice_transplanter_khv.toml")
    d.sun_gear.radii_mm = [R] * len(d.sun_gear.radii_mm)
    return d


def circular_gears(middle_turn: float = 0.0, planet_missing=()):
    """Sun, middle and planet in the body frames ``plantmech gears`` cuts them in (module
    docstring of contact.khv): the sun's frame is the absolute frame (a tooth at 0 deg);
    the middle's body angle 0 faces the sun at the sun's first pitch-curve sample at or
    above 0 deg, th0 = carrier0 - sigma_k on the 4096-sample grid (carrier0 = 40 deg:
    k = 455), where it needs a space; with every ratio 1 its contact is at th0 - theta
    when the sun's is at theta, and the planet's at theta - th0, opposite the middle's
    planet contact (a space there too: Z is even): the planet has a tooth there."""
    th0 = np.radians(40.0) - 455 * 2 * np.pi / 4096
    pitch = 2 * np.pi / Z
    sun = outline_from_rings("sun", [involute_gear(Z, M, J)])
    middle = outline_from_rings("middle", [involute_gear(Z, M, J)]).rotated(
        th0 + pitch / 2 + middle_turn)
    planet = outline_from_rings("planet", [involute_gear(Z, M, J, planet_missing)]).rotated(
        -th0)
    return {"sun": sun, "middle": middle, "planet": planet}


@pytest.fixture(scope="module")
def circular():
    d = circular_design()
    return d, analyse_khv(d, circular_gears(), steps=90)


def test_circular_train_exact_ratio_and_backlash(circular):
    d, c = circular
    assert len(c.stage1) == d.carrier.arms == 2
    for fp in c.stage1 + c.stage2 + c.stage2_lo + c.stage2_hi:
        assert not fp.jammed.any() and not fp.overlapped.any()
        assert np.isfinite(fp.lo).all() and np.isfinite(fp.hi).all()
    for fp in c.stage1 + c.stage2:
        # transmission error 0: the free play is centred on the rigid ratio
        assert np.abs(0.5 * (fp.lo + fp.hi)).max() < 2e-5  # rad
        # the angular free play is the circumferential backlash over the pitch radius
        np.testing.assert_allclose(fp.hi - fp.lo, J / R, rtol=0.02)
    # the arm: the middle's play passes to the planet at ratio 1, plus the planet's own
    np.testing.assert_allclose(c.planet_hi - c.planet_lo, 2 * J / R, rtol=0.02)
    np.testing.assert_allclose(c.planet_hi + c.planet_lo, 0.0, atol=4e-5)
    band = np.hypot(*(c.tip_hi - c.tip_lo).transpose(2, 0, 1))
    np.testing.assert_allclose(band, 2 * d.arm.S_mm * np.sin((c.planet_hi - c.planet_lo) / 2),
                               rtol=1e-9)
    assert band.max() == pytest.approx(d.arm.S_mm * 2 * J / R, rel=0.02)
    rec = khv_record(c, LIMITS)
    assert rec["ok"] and len(rec["pairs"]) == 4 and len(rec["arms"]) == 2


def test_nominal_tip_is_the_pitch_curve_model_a_translating_arm(circular):
    """Every ratio 1: the planet turns back what the carrier turns, the arm translates
    (the tip stays at S along the arm's start direction from the planet axis)."""
    from plantmech.workflows import simulate_transplanter

    d, c = circular
    _, motion, *_ = simulate_transplanter(d, samples=90)
    np.testing.assert_allclose(c.tip_nominal[..., 0], motion.B[0].real, atol=1e-9)
    np.testing.assert_allclose(c.tip_nominal[..., 1], motion.B[0].imag, atol=1e-9)
    arm = c.tip_nominal - np.stack([motion.centre[0].real, motion.centre[0].imag], axis=-1)
    np.testing.assert_allclose(arm - arm[:, :1], 0.0, atol=1e-6)


def test_middle_turned_by_half_a_tooth_is_caught_on_every_arm():
    d = circular_design()
    pitch = 2 * np.pi / Z
    c = analyse_khv(d, circular_gears(middle_turn=pitch / 2), steps=30)
    rec = khv_record(c, LIMITS)
    assert not rec["ok"]
    for j in range(2):
        fp1, fp2 = c.stage1[j], c.stage2[j]
        assert fp1.overlapped.all() and fp2.overlapped.all()  # tooth on tooth
        # the middle sits half a tooth off the sun's law, the planet half a tooth off its
        # (nominally placed) middle's
        np.testing.assert_allclose(np.abs(0.5 * (fp1.lo + fp1.hi)), pitch / 2, rtol=0.02)
        np.testing.assert_allclose(np.abs(0.5 * (fp2.lo + fp2.hi)), pitch / 2, rtol=0.02)
    te = next(ch for ch in rec["checks"] if ch["name"].startswith("transmission error"))
    assert te["ok"] is False and te["value"] == pytest.approx(180.0 / Z, rel=0.02)
    at = rec["pairs"][0]["transmission_error_deg"]["max_abs_mid_at"]
    assert set(at) == {"carrier_angle_deg", "middle_body_angle_deg", "middle_tooth"}


def test_planet_teeth_removed_located():
    """Planet teeth 3 and 4 cut to the root: contact is lost only where that gap faces the
    middle, and the record names the planet's teeth there."""
    d = circular_design()
    c = analyse_khv(d, circular_gears(planet_missing=(3, 4)), steps=180)
    rec = khv_record(c, LIMITS)
    assert not rec["ok"]
    for j in range(2):
        p = rec["pairs"][2 * j + 1]
        assert p["pair"] == f"middle -> planet (arm {j + 1})"
        assert p["contact_lost_steps"] > 0
        teeth = {s["planet_tooth"] for s in p["contact_lost"]}
        # tooth k of the generator (0-based, at 2 pi k / Z) is tooth k + 1 counted from
        # body angle 0 (the planet's turn -th0 is a hundredth of a degree); the contact
        # is lost facing them or the tooth either side
        assert teeth and teeth <= {3, 4, 5, 6}
        assert rec["pairs"][2 * j]["contact_lost_steps"] == 0  # the sun-middle pair is whole
    lost = next(ch for ch in rec["checks"] if ch["name"].startswith("contact lost"))
    assert lost["ok"] is False
