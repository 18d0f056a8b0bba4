"""Tooth-contact analysis (plantmech.contact) against independent expectations:
circular involute gears from an involute generator written here (transmission error 0,
angular free play = cut backlash / pitch radius, double contact over the contact ratio
minus one), an elliptical pair turning about its foci (closed-form law), and faulty
gear files (turned by half a tooth, teeth removed)."""

from __future__ import annotations

import numpy as np
import pytest

from plantmech.contact.outlines import outline_from_rings, read_gear_dxf
from plantmech.contact.tca import free_play

ALPHA = np.radians(20.0)


def inv(a):
    return np.tan(a) - a


def involute_gear(z: int, m: float, backlash: float, missing=(), n_flank: int = 60):
    """Closed outline (N, 2) of an external involute spur gear: addendum m, dedendum
    1.25 m, tooth k centred at body angle 2 pi k / z, each tooth thinned by backlash/2
    (circumferential, at the pitch circle); teeth in ``missing`` cut down to the root."""
    rp = m * z / 2
    rb = rp * np.cos(ALPHA)
    ra, rf = rp + m, rp - 1.25 * m
    half = (np.pi * m / 2 - backlash / 2) / (2 * rp)  # half thickness angle at rp

    def theta(r):
        ar = np.arccos(np.clip(rb / r, -1, 1))
        return half + inv(ALPHA) - inv(ar)

    r_inv = np.linspace(max(rb, rf), ra, n_flank)
    flank_r = np.r_[rf, r_inv] if rf < rb else r_inv
    flank_t = np.r_[theta(max(rb, rf)), theta(r_inv)] if rf < rb else theta(r_inv)
    pts = []
    pitch = 2 * np.pi / z
    for k in range(z):
        c = k * pitch
        if k in missing:
            ang = np.linspace(c - pitch / 2, c + pitch / 2, 40, endpoint=False)
            pts.append(np.c_[rf * np.cos(ang), rf * np.sin(ang)])
            continue
        a_up = c - flank_t
        tip = np.linspace(c - theta(ra), c + theta(ra), 12)[1:-1]
        a_dn = (c + flank_t)[::-1]
        ang = np.r_[a_up, tip, a_dn]
        rad = np.r_[flank_r, np.full(len(tip), ra), flank_r[::-1]]
        root = np.linspace(c + flank_t[0], c + pitch - flank_t[0], 12)[1:-1]
        ang = np.r_[ang, root]
        rad = np.r_[rad, np.full(len(root), rf)]
        pts.append(np.c_[rad * np.cos(ang), rad * np.sin(ang)])
    return np.vstack(pts)


def _pair(z1=20, z2=30, m=2.0, j=0.2, steps=90, missing=(), turn2=0.0):
    g1 = outline_from_rings("g1", [involute_gear(z1, m, j)])
    g2 = outline_from_rings("g2", [involute_gear(z2, m, j, missing)])
    if turn2:
        g2 = g2.rotated(turn2)
    a = m * (z1 + z2) / 2
    th = np.linspace(-2 * np.pi / z1 * 4, 2 * np.pi / z1 * 4, steps)  # eight driver teeth
    q1 = th
    q2 = np.pi + np.pi / z2 - th * z1 / z2  # a space of gear 2 faces gear 1's tooth 0
    fp = free_play(g2, g1, (a, 0.0), (0.0, 0.0), q2, q1)
    return fp, g1, g2, th


def test_outline_teeth_found():
    g = outline_from_rings("g", [involute_gear(23, 3.0, 0.1)])
    assert g.teeth == 23 and not g.internal
    # tooth k is centred at 2 pi k / z, within the outline's resampling for the search
    # (4096 points along the boundary; a run's ends each within one of them)
    ring = g.ring
    step = np.hypot(*(np.roll(ring, -1, axis=0) - ring).T).sum() / 4096 / (3.0 * 23 / 2)
    want = 2 * np.pi * np.arange(23) / 23
    d = np.abs(np.angle(np.exp(1j * (g.tip_angles[:, None] - want[None, :])))).min(axis=0)
    assert d.max() < 1.5 * step
    assert (g.tooth_at(want) == np.arange(23) + 1).all() or len(set(g.tooth_at(want))) == 23


@pytest.mark.parametrize("missing", [range(5, 11), range(5, 14)])
def test_no_tooth_found_on_a_toothless_arc(missing):
    """Teeth cut down to the root leave an arc of constant radius (a partial gear's
    locking arc): its radius equals its running mean there, and a dent of 0.01 mm on it
    once made it a "tooth" (6 teeth missing: 18 found for 17; 9 missing and the dent:
    15 for 14). Every tip found is a real tooth's centre, one per tooth."""
    z, m = 23, 3.0
    ring = involute_gear(z, m, 0.1, tuple(missing))
    dented = ring.copy()
    r, a = np.hypot(*ring.T), np.arctan2(ring[:, 1], ring[:, 0])
    near = np.abs(np.angle(np.exp(1j * (a - 2 * np.pi * (missing[-1] - 0.6) / z)))) < 0.01
    assert near.any() and np.allclose(r[near], m * z / 2 - 1.25 * m)  # on the root arc
    dented[near] *= (1 - 0.01 / r[near])[:, None]
    want = 2 * np.pi * np.array([k for k in range(z) if k not in missing]) / z
    for g in (outline_from_rings("g", [ring]), outline_from_rings("g", [dented])):
        assert g.teeth == z - len(missing)
        d = np.abs(np.angle(np.exp(1j * (np.sort(g.tip_angles)[:, None] - want[None, :]))))
        assert d.min(axis=1).max() < 0.01  # rad: each tip on a tooth (pitch 0.27 rad)


def test_circular_involute_pair_transmission_error_and_backlash():
    m, z1, z2, j = 2.0, 20, 30, 0.2
    fp, *_ = _pair(z1, z2, m, j)
    assert np.isfinite(fp.lo).all() and np.isfinite(fp.hi).all()
    assert not fp.jammed.any() and not fp.overlapped.any()
    # transmission error: the free play is centred on the rigid law
    mid = 0.5 * (fp.lo + fp.hi)
    assert np.abs(mid).max() < 2e-5  # rad (0.001 deg)
    # angular backlash band = circumferential backlash / pitch radius of the driven gear
    rp2 = m * z2 / 2
    np.testing.assert_allclose(fp.hi - fp.lo, j / rp2, rtol=0.01)
    # two tooth pairs touch together over (contact ratio - 1) of the cycle
    rb1, rb2 = m * z1 / 2 * np.cos(ALPHA), rp2 * np.cos(ALPHA)
    ra1, ra2 = m * z1 / 2 + m, rp2 + m
    eps = (np.sqrt(ra1**2 - rb1**2) + np.sqrt(ra2**2 - rb2**2)
           - m * (z1 + z2) / 2 * np.sin(ALPHA)) / (np.pi * m * np.cos(ALPHA))
    assert fp.double_hi.mean() == pytest.approx(eps - 1.0, abs=0.06)
    assert fp.double_lo.mean() == pytest.approx(eps - 1.0, abs=0.06)


def test_gear_turned_by_half_a_tooth_fails_and_says_so():
    z2 = 30
    fp, *_ = _pair(z2=z2, turn2=np.pi / z2)
    assert fp.overlapped.all()  # the nominal pose puts tooth on tooth
    mid = 0.5 * (fp.lo + fp.hi)
    np.testing.assert_allclose(np.abs(mid), np.pi / z2, rtol=0.01)


def test_tooth_removed_flank_error_where_it_is_missing():
    z1, z2, j, m = 20, 30, 0.2, 2.0
    fp, *_ = _pair(z1, z2, m, j, steps=180, missing=(0,))
    # one tooth gone (contact ratio 1.6): where it would carry alone, the neighbours catch
    # the driven gear late, on their tip corners; elsewhere each flank sits at half the
    # band (faultless: constant to 1e-5 rad)
    worst = np.fmax(np.abs(fp.lo), np.abs(fp.hi))
    bad = worst - np.median(worst) > 0.2 * j / (m * z2 / 2)
    assert bad.any()
    ang = np.angle(np.exp(1j * fp.mesh_driven_angle[bad]))
    assert np.abs(ang).max() < 1.5 * 2 * np.pi / z2  # the gap at body angle 0 faces gear 1
    far = np.abs(np.angle(np.exp(1j * fp.mesh_driven_angle))) > 2.5 * 2 * np.pi / z2
    assert far.any() and not bad[far].any()


def test_teeth_removed_contact_lost_where_they_are_missing():
    z1, z2 = 20, 30
    fp, *_ = _pair(z1, z2, steps=180, missing=(29, 0, 1))
    lost = ~np.isfinite(fp.lo) | ~np.isfinite(fp.hi)
    assert lost.any()
    # where contact is lost, the gap in gear 2 (teeth 29, 0, 1) faces gear 1
    ang = np.angle(np.exp(1j * fp.mesh_driven_angle[lost]))
    assert np.abs(ang).max() < 2.5 * 2 * np.pi / z2
    far = np.abs(np.angle(np.exp(1j * fp.mesh_driven_angle))) > 3.5 * 2 * np.pi / z2
    assert far.any() and not lost[far].any()


def test_elliptical_pair_follows_the_closed_form_law():
    from plantmech.gears.teeth import ToothSpec, make_pair

    A, e, j = 60.0, 0.3, 0.1
    p = A * (1 - e * e)
    th = np.linspace(0.0, 2 * np.pi, 1201)
    r = p / (1 + e * np.cos(th))
    perimeter_guess = 2 * np.pi * A * (1 - e * e / 4)
    spec = ToothSpec(module=perimeter_guess / (np.pi * 30), backlash_mm=j)
    pair = make_pair("ellipse", th, r, 2 * A, spec, samples=2000)
    ga = outline_from_rings("a", [np.asarray(pair.gear_a.exterior.coords)])
    gb = outline_from_rings("b", [np.asarray(pair.gear_b.exterior.coords)])
    steps = 96
    t1 = np.linspace(0.0, 2 * np.pi, steps, endpoint=False)
    # exact law of two equal ellipses turning about their foci: d turn_b / d t1 = r_a /
    # (2A - r_a) = (1 - e^2) / (1 + e^2 + 2 e cos t1), so
    # turn_b = 2 arctan((1 - e) / (1 + e) tan(t1 / 2))
    turn_b = np.unwrap(2 * np.arctan((1 - e) / (1 + e) * np.tan(t1 / 2)))
    phi_b = -turn_b
    fp = free_play(gb, ga, (2 * A, 0.0), (0.0, 0.0), np.pi - phi_b, -t1)
    assert np.isfinite(fp.lo).all() and np.isfinite(fp.hi).all() and not fp.jammed.any()
    rb = 2 * A - p / (1 + e * np.cos(t1))  # B's pitch radius at the contact
    mid = 0.5 * (fp.lo + fp.hi)
    # the free play is centred on the exact law to within a tenth of the backlash
    assert np.abs(mid * rb).max() < 0.1 * j
    # and its width is the cut backlash along the pitch curve, within 30 %
    np.testing.assert_allclose((fp.hi - fp.lo) * rb, j, rtol=0.3)


def test_read_gear_dxf_round_trip_and_errors(tmp_path):
    import shapely

    from plantmech.contact.outlines import GearFileError
    from plantmech.outputs.gear_files import write_dxf

    ring = involute_gear(25, 2.0, 0.1)
    poly = shapely.Polygon(ring, [10 * np.c_[np.cos(np.linspace(0, 6.28, 64, endpoint=False)),
                                              np.sin(np.linspace(0, 6.28, 64, endpoint=False))]])
    write_dxf(tmp_path / "g.dxf", {"g": poly})
    g = read_gear_dxf(tmp_path / "g.dxf", "g")
    assert g.teeth == 25 and len(g.rings) == 2
    np.testing.assert_allclose(g.ring, ring, atol=1e-9)
    with pytest.raises(GearFileError, match="not found"):
        read_gear_dxf(tmp_path / "missing.dxf")
    with pytest.raises(GearFileError, match="no layer 'x'"):
        read_gear_dxf(tmp_path / "g.dxf", "x")
    (tmp_path / "bad.dxf").write_text("not a dxf")
    with pytest.raises(GearFileError, match="bad.dxf"):
        read_gear_dxf(tmp_path / "bad.dxf")


@pytest.mark.parametrize("turn_teeth", [0.25, 0.5, 0.9])
def test_sweep_gives_the_midpoint_search_result(turn_teeth, monkeypatch):
    """The parity sweep that finds the free rotation nearest an overlapping reference
    returns what the one-by-one midpoint search (point-in-polygon at every candidate)
    returns: the same offsets and jams, on gears turned off their phase (every step
    overlaps) and a pair set closer than its centre distance (some steps jam)."""
    import plantmech.contact.tca as tca

    z2 = 30
    swept, *_ = _pair(z2=z2, turn2=turn_teeth * 2 * np.pi / z2)
    assert swept.overlapped.all()

    def search_only(rows, pn, en1, ring_d, vd, q_n, q_d, c_n, c_d, max_turn, poly_n,
                    poly_d, reach, in_n, in_d):
        return tca._free_offsets_search(rows, pn, en1, ring_d, vd, q_n, q_d, c_n, c_d,
                                        max_turn, poly_n, poly_d, reach)

    monkeypatch.setattr(tca, "_free_offsets", search_only)
    searched, *_ = _pair(z2=z2, turn2=turn_teeth * 2 * np.pi / z2)
    np.testing.assert_array_equal(swept.reference, searched.reference)
    np.testing.assert_array_equal(swept.jammed, searched.jammed)
    np.testing.assert_array_equal(swept.lo, searched.lo)
    np.testing.assert_array_equal(swept.hi, searched.hi)


def test_sweep_jams_where_the_search_jams(monkeypatch):
    import plantmech.contact.tca as tca

    m, z1, z2 = 2.0, 20, 30
    g1 = outline_from_rings("g1", [involute_gear(z1, m, 0.2)])
    g2 = outline_from_rings("g2", [involute_gear(z2, m, 0.2)])
    th = np.linspace(0.0, 2 * np.pi / z1 * 3, 60)
    q2 = np.pi + np.pi / z2 - th * z1 / z2
    a = np.linspace(m * (z1 + z2) / 2 - 1.6 * m, m * (z1 + z2) / 2, 60)  # tip on root
    results = []
    for fn in (tca._free_offsets, None):
        if fn is None:
            monkeypatch.setattr(tca, "_free_offsets", lambda *a_, **k: tca._free_offsets_search(
                *a_[:13]))
        fps = [free_play(g2, g1, (aa, 0.0), (0.0, 0.0), q2[i:i + 1], th[i:i + 1])
               for i, aa in enumerate(a[::6])]
        results.append((np.r_[[f.jammed[0] for f in fps]], np.r_[[f.reference[0] for f in fps]]))
    assert results[0][0].any() and not results[0][0].all()
    np.testing.assert_array_equal(results[0][0], results[1][0])
    np.testing.assert_array_equal(results[0][1], results[1][1])
