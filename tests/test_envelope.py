"""Rack-cut teeth by the envelope condition (gears/envelope.py) against independent
references: the analytic involute of a spur gear, the simulated cut (teeth.cut_gear with
method="simulated", Boolean union of rack positions) and the undercut limit of a rack
computed by hand."""

from dataclasses import replace

import numpy as np
import pytest
import shapely
from scipy.special import ellipe

from plantmech.gears.envelope import rack_space_polygons
from plantmech.gears.outline import fold_backs, teeth_on_outline
from plantmech.gears.teeth import (
    PitchPolyline,
    ToothSpec,
    cut_gear,
    inv,
    make_pair,
    mesh_check,
)
from tests.conftest import hausdorff_distance

M = 2.0


def circle(z: int, m: float = M) -> PitchPolyline:
    rp = m * z / 2
    th = np.linspace(0.0, 2 * np.pi, 3000, endpoint=False)
    return PitchPolyline(np.c_[rp * np.cos(th), rp * np.sin(th)])


RACK = ToothSpec(module=M, backlash_mm=0.1, cutter="rack")


def test_circle_flanks_are_the_analytic_involute():
    """A 30-tooth spur gear (m 2, 20 deg, 0.1 mm backlash): every outline vertex between the
    base (or form) circle and the tip lies on the involute whose half tooth angle at radius
    r is t / (2 rp) + inv(alpha) - inv(alpha_r), t = pi m / 2 - backlash / 2 (tooth centred
    at angle 0): within 0.1 um of arc (the simulated cut is 1-2 um off)."""
    z = 30
    gear = cut_gear(circle(z), RACK)
    rp, al = M * z / 2, RACK.alpha
    rb, ra = rp * np.cos(al), rp + M
    xy = np.asarray(gear.exterior.coords)
    r, ang = np.hypot(*xy.T), np.arctan2(xy[:, 1], xy[:, 0])
    # flank points: above the fillet (the rack's tip corner reaches 1.25 m below pitch;
    # its straight flank's contact is on the involute above rp - 1.25 m ... use rp - 0.9 m)
    sel = (r > max(rb, rp - 0.9 * M) + 0.05) & (r < ra - 0.05)
    assert sel.sum() > 20 * z
    psi = (np.pi * M / 2 - 0.1 / 2) / (2 * rp) + inv(al) - inv(np.arccos(rb / r[sel]))
    local = ang[sel] - np.round(ang[sel] / (2 * np.pi / z)) * 2 * np.pi / z
    err = (np.abs(local) - psi) * r[sel]
    assert np.abs(err).max() < 1e-4


def test_circle_matches_the_simulated_cut_and_converges_to_it():
    """Hausdorff distance to the simulated cut at 48 rack positions per pitch < 0.01 mm
    (the simulated cut's scallops shrink as 1 / positions: 0.019 mm at 12, 0.005 at 48)."""
    pitch = circle(30)
    env = cut_gear(pitch, RACK)
    sim12 = cut_gear(pitch, replace(RACK, method="simulated"))
    sim48 = cut_gear(pitch, replace(RACK, method="simulated"), steps_per_pitch=48)
    d12 = hausdorff_distance(env.exterior, sim12.exterior, densify=0.02)
    d48 = hausdorff_distance(env.exterior, sim48.exterior, densify=0.02)
    assert d48 < 0.01
    assert d48 < 0.5 * d12 < 0.015
    # the simulated cut leaves scallops: material, never less than the envelope's cut
    assert sim48.area >= env.area - 1e-3
    assert abs(sim48.area - env.area) < 2e-3 * env.area


@pytest.mark.parametrize("z, cusped", [(14, True), (19, True), (24, False), (40, False)])
def test_undercut_cusp_where_the_rack_limit_says(z, cusped):
    """The flank envelope of a rack whose straight flank reaches h_f = 1.25 m below the
    pitch line turns back (a cusp on the base circle: undercut) exactly when the spur gear
    has fewer than 2 h_f / sin^2(alpha) = 21.4 teeth (20 deg): the line of action
    leaves the base circle's tangent point before the rack's tip corner."""
    assert 2 * 1.25 / np.sin(np.radians(20)) ** 2 == pytest.approx(21.37, abs=0.01)
    pitch = circle(z)
    centres = RACK.pitch / 2 + RACK.pitch * np.arange(z)
    _, _, cusp = rack_space_polygons(pitch, RACK, centres)
    assert cusp.all() if cusped else not cusp.any()


def test_undercut_gear_matches_the_simulated_cut():
    """On an undercut 14-tooth spur gear the envelope outline (flank up to the cusp, then the
    tip corner's trochoid) is the simulated cut's, to its scallop size (48 positions per
    pitch: 0.010 mm on this small gear, 0.005 at 96, 0.0025 at 192), and the teeth keep
    their tip lands."""
    pitch = circle(14)
    env = cut_gear(pitch, RACK)
    sim = cut_gear(pitch, replace(RACK, method="simulated"), steps_per_pitch=48)
    assert hausdorff_distance(env.exterior, sim.exterior, densify=0.02) < 0.015
    assert sim.area >= env.area - 1e-3  # the scallops are material the envelope cuts
    teeth = teeth_on_outline(env, pitch.xy, M, 1.0)
    assert len(teeth["angle_deg"]) == 14


def ellipse_pair(z: int, e: float, method: str = "envelope"):
    th = np.linspace(0, 2 * np.pi, 3001)
    a_semi = np.pi * M * z / (4 * ellipe(e**2))
    r = a_semi * (1 - e**2) / (1 - e * np.cos(th))
    return make_pair("ellipse", th, r, 2 * a_semi,
                     ToothSpec(module=M, backlash_mm=0.1, method=method))


def test_ellipse_about_its_focus_both_gears():
    """Twin ellipses (e 0.3, 31 teeth) turning about their foci: both gears are rack-cut by
    the envelope (convex curves), each within 0.025 mm of the simulated rack cut (12
    positions per pitch); B's working flanks (from 0.6 m below its pitch curve to 0.9 m
    above; A's tip reaches 1 m below) within 5 um of the simulated B that A's teeth cut
    (measured 0.75 um: the two are conjugate to A; below 0.8 m the fillets differ, A's tip
    corners trace the simulated one, the rack's the envelope's); the twins identical (one
    rack on one curve; 31 teeth: both have a tooth on the major axis), no fold-backs, and
    the pair meshes without interference with a free play near the 0.1 mm asked for."""
    env = ellipse_pair(31, 0.3)
    sim = ellipse_pair(31, 0.3, "simulated")
    assert env.spec.cutter == "rack" and not env.b_cut_by_a and sim.b_cut_by_a
    rack_sim = replace(env.spec, method="simulated")
    b_rack = cut_gear(env.pitch_b, rack_sim, tooth_at=env.tooth_at_b)
    for g_env, g_sim in ((env.gear_a, sim.gear_a), (env.gear_b, b_rack)):
        assert hausdorff_distance(g_env.exterior, g_sim.exterior, densify=0.02) < 0.025
        assert len(fold_backs(g_env)) == 0
    base = shapely.Polygon(env.pitch_b.xy)
    band = base.buffer(0.9 * M).difference(base.buffer(-0.6 * M))
    flanks_env = env.gear_b.exterior.intersection(band)
    flanks_sim = sim.gear_b.exterior.intersection(band)
    assert hausdorff_distance(flanks_env, flanks_sim, densify=0.02) < 0.005
    # the twin: B turned so its major axis (focus -> centroid) lies along A's (+x) is A
    c = shapely.Polygon(env.pitch_b.xy).centroid
    b = shapely.affinity.rotate(env.gear_b, -np.arctan2(c.y, c.x), origin=(0, 0),
                                use_radians=True)
    twin = hausdorff_distance(env.gear_a.exterior, b.exterior, densify=0.05)
    assert twin < 0.01
    assert abs(env.gear_a.area - b.area) < 0.05
    mesh = mesh_check(env, 240)
    assert mesh["max_interference_mm"] == 0.0
    assert 0.09 < mesh["min_circumferential_backlash_mm"] < 0.11
    assert mesh["max_circumferential_backlash_mm"] < 0.13


def test_fewer_vertices_than_the_simulated_cut():
    env = ellipse_pair(31, 0.3)
    sim = ellipse_pair(31, 0.3, "simulated")
    assert len(env.gear_b.exterior.coords) < 0.8 * len(sim.gear_b.exterior.coords)


def test_unknown_method_is_refused():
    with pytest.raises(ValueError, match="method"):
        cut_gear(circle(20), replace(RACK, method="boolean"))
