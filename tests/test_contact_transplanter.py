"""Tooth-contact analysis of the differential transplanter's train
(plantmech.contact.transplanter) against independent expectations: a circular internal
pair (constant internal radius R, n lobes: an internal spur pair R / (R / n), gears from
the involute generator of tests/test_contact.py) turns at the exact ratio with the cut
backlash as free play on every arm, and the tip band is the chord the arm's play sweeps
at the tip; a planet turned by half a tooth is caught on every arm."""

from __future__ import annotations

import numpy as np
import pytest

from plantmech.contact.outlines import outline_from_rings
from plantmech.contact.transplanter import analyse_transplanter, transplanter_record
from plantmech.design import load_design
from tests.conftest import EXAMPLES
from tests.test_contact import ALPHA, inv, involute_gear

R, LOBES, M, J = 60.0, 2, 2.0, 0.2  # internal pitch radius (mm), lobes, module, backlash


def circular_design():
    d = load_design(EXAMPLES / "rice_transplanter_manufacturable.toml")
    g = d.internal_gear
    g.lobes = LOBES
    g.radii_mm = [R] * len(g.radii_mm)
    g.phases_deg = None
    g.centre_distance_mm = None
    g.teeth = None
    d.drive.speed_ratio = (LOBES - 1) / LOBES  # the mesh point passes one lobe per turn
    return d


def involute_ring(z: int, m: float, backlash: float, n_flank: int = 60) -> np.ndarray:
    """The toothed hole (N, 2) of an internal involute gear: tips at rp - m, roots at
    rp + 1.25 m, a tooth centred at body angle 0; each space is an external involute tooth
    of the same base circle turned inside out, widened by backlash / 2 at the pitch
    circle. Its half-angle at radius r: s / (2 rp) + inv(alpha) - inv(alpha_r)."""
    rp = m * z / 2
    rb = rp * np.cos(ALPHA)
    r_tip, r_root = rp - m, rp + 1.25 * m
    assert r_tip > rb
    half = (np.pi * m / 2 + backlash / 2) / (2 * rp)
    r = np.linspace(r_tip, r_root, n_flank)
    t = half + inv(ALPHA) - inv(np.arccos(rb / r))
    pitch = 2 * np.pi / z
    pts = []
    for k in range(z):
        c = (k + 0.5) * pitch  # a space between tooth k and tooth k + 1
        root = np.linspace(c - t[-1], c + t[-1], 8)[1:-1]
        tip = np.linspace(c + t[0], c + pitch - t[0], 10)[1:-1]
        ang = np.r_[c - t, root, (c + t)[::-1], tip]
        rad = np.r_[r, np.full(len(root), r_root), r[::-1], np.full(len(tip), r_tip)]
        pts.append(np.c_[rad * np.cos(ang), rad * np.sin(ang)])
    return np.vstack(pts)


def circular_gears(planet_turn: float = 0.0):
    """The internal gear (z = 2 R / M) with a tooth at body angle 0 and the planet
    (z / n) with a space there, as ``plantmech gears`` phases them; circumferential
    backlash J in all (half from each gear)."""
    z_int, z_pl = int(round(2 * R / M)), int(round(2 * R / M / LOBES))
    hole = involute_ring(z_int, M, J)
    rp = M * z_int / 2
    rim = np.c_[(rp + 8 * M) * np.cos(np.linspace(0, 2 * np.pi, 200, endpoint=False)),
                (rp + 8 * M) * np.sin(np.linspace(0, 2 * np.pi, 200, endpoint=False))]
    internal = outline_from_rings("internal", [rim, hole])
    planet = outline_from_rings("planet", [involute_gear(z_pl, M, J)])
    planet = planet.rotated(np.pi / z_pl + planet_turn)
    return {"internal": internal, "planet": planet}


@pytest.fixture(scope="module")
def circular():
    d = circular_design()
    gears = circular_gears()
    assert gears["internal"].internal and gears["internal"].teeth == 60
    return d, analyse_transplanter(d, gears, steps=120)


def test_circular_internal_pair_exact_ratio_and_backlash(circular):
    d, c = circular
    r_pl = R / LOBES
    assert len(c.arms) == d.carrier.arms == 3
    for fp in c.arms:
        assert not fp.jammed.any() and np.isfinite(fp.lo).all() and np.isfinite(fp.hi).all()
        # transmission error 0: the free play is centred on the rigid ratio
        assert np.abs(0.5 * (fp.lo + fp.hi)).max() < 2e-5  # rad
        # the angular free play is the circumferential backlash over the planet's radius
        np.testing.assert_allclose(fp.hi - fp.lo, J / r_pl, rtol=0.02)
    # tip band: the chord the arm's play sweeps at the tip, 2 S sin(play / 2)
    band = np.hypot(*(c.tip_hi - c.tip_lo).transpose(2, 0, 1))
    play = c.planet_hi - c.planet_lo
    np.testing.assert_allclose(band, 2 * d.arm.S_mm * np.sin(play / 2), rtol=1e-9)
    assert band.max() == pytest.approx(d.arm.S_mm * J / r_pl, rel=0.02)
    rec = transplanter_record(c, {"transmission_error_deg": 0.5, "attitude_error_deg": 1.0,
                                  "tip_band_mm": 5.0})
    assert rec["ok"] and len(rec["pairs"]) == 3 and len(rec["arms"]) == 3


def test_nominal_tip_is_the_pitch_curve_model(circular):
    from plantmech.workflows import simulate_transplanter

    d, c = circular
    _, motion, *_ = simulate_transplanter(d, samples=120)
    B = motion.B[0]
    np.testing.assert_allclose(c.tip_nominal[..., 0], B.real, atol=1e-9)
    np.testing.assert_allclose(c.tip_nominal[..., 1], B.imag, atol=1e-9)


def test_planet_turned_by_half_a_tooth_is_caught_on_every_arm():
    d = circular_design()
    z_pl = int(round(2 * R / M / LOBES))
    c = analyse_transplanter(d, circular_gears(planet_turn=np.pi / z_pl), steps=40)
    rec = transplanter_record(c, {"transmission_error_deg": 0.5, "attitude_error_deg": 1.0,
                                  "tip_band_mm": 5.0})
    for fp in c.arms:
        assert fp.overlapped.all()  # tooth on tooth at the nominal pose
        np.testing.assert_allclose(np.abs(0.5 * (fp.lo + fp.hi)), np.pi / z_pl, rtol=0.02)
    assert not rec["ok"]
    te = next(ch for ch in rec["checks"] if ch["name"].startswith("transmission error"))
    assert te["ok"] is False and te["value"] == pytest.approx(180.0 / z_pl, rel=0.02)


def test_sweep_gives_the_search_result_inside_a_ring(monkeypatch):
    """An internal gear's teeth wrap round the planet beyond the analysis window, so the
    sweep cannot settle every step alone: where it cannot prove its answer it defers to
    the midpoint search, and the result is the search's."""
    import plantmech.contact.tca as tca

    d = circular_design()
    gears = circular_gears(planet_turn=0.4 * 2 * np.pi / 30)
    swept = analyse_transplanter(d, gears, steps=12).arms[0]
    monkeypatch.setattr(tca, "_free_offsets",
                        lambda *a: tca._free_offsets_search(*a[:13]))
    searched = analyse_transplanter(d, gears, steps=12).arms[0]
    assert swept.overlapped.all()
    for key in ("reference", "jammed", "lo", "hi"):
        np.testing.assert_array_equal(getattr(swept, key), getattr(searched, key))
