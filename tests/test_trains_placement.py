"""trains/placement.py: every gear of a general planetary train placed per carrier sample,
against a hand computation (circles), the pairs' own geometry (centre distances, contact
points on both pitch curves) on the bundled trains and a derived driver on a later shaft,
and its three readers (the app's scene, the report's animation, the forward plot) drawing
the same gears at the same places."""

from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from plantmech.design import load_design
from plantmech.trains.curves import ellipse, fourier
from plantmech.trains.model import PairSpec, Train, build, simulate
from plantmech.trains.placement import place_gears

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"


def _cis(a):
    return np.exp(1j * np.asarray(a, dtype=float))


def test_a_two_pair_circular_train_by_hand():
    """Fixed sun R0 = 30, idler R1 = 20, planet R2 = 25 (mm), lines of centres at 0.4 and
    -0.5 rad, carrier from 0.2 rad clockwise, two arms. By hand: the carrier line of arm j
    is C_j = 0.2 - (psi + pi j); the shafts at 0, 50 e^{0.4 i}, + 45 e^{-0.5 i} in the
    carrier frame; the sun keeps its absolute angle 0.3; each follower rolls on its driver
    from the body angles 0 that touch (theta_f = -(R_d / R_f) theta_d), its contact seen
    at delta + pi from its centre."""
    R0, R1, R2, d1, d2, C0, phi0 = 30.0, 20.0, 25.0, 0.4, -0.5, 0.2, 0.3
    train = Train([PairSpec("external", fourier(R0, [], [], 2048), phase=phi0,
                            direction=d1, follower_turns=R0 / R1),
                   PairSpec("external", None, direction=d2, follower_turns=R1 / R2)],
                  carrier0=C0, carrier_sense=-1, arm_length=120.0, arms=2)
    motion = simulate(build(train), 360)
    psi = motion.carrier_angle
    placed = place_gears(motion)
    assert [(g.label, g.side, g.pair) for g in placed] == [
        ("sun", "driver", 0), ("idler1 1", "follower", 0), ("planet 1", "follower", 1),
        ("idler1 2", "follower", 0), ("planet 2", "follower", 1)]
    by = {g.label: g for g in placed}
    S1 = (R0 + R1) * np.exp(1j * d1)
    S2 = S1 + (R1 + R2) * np.exp(1j * d2)
    for j in range(2):
        C = C0 - (psi + np.pi * j)
        alpha0 = phi0 - C  # the sun relative to this arm's carrier line
        theta_d1 = d1 - alpha0
        alpha1 = d1 + np.pi + (R0 / R1) * theta_d1
        theta_d2 = d2 - alpha1
        alpha2 = d2 + np.pi + (R1 / R2) * theta_d2
        for name, shaft, alpha in (("idler1", S1, alpha1), ("planet", S2, alpha2)):
            g = by[f"{name} {j + 1}"]
            assert np.abs(g.centre[0] - shaft * _cis(C)).max() < 1e-9
            assert np.abs(_cis(g.angle[0]) - _cis(C + alpha)).max() < 1e-9
    sun = by["sun"]
    assert np.abs(sun.centre).max() == 0.0
    assert np.abs(_cis(sun.angle[0]) - _cis(phi0)).max() < 1e-12  # fixed in the frame


def _derived_driver_on_a_later_shaft() -> Train:
    """Sun -> gear 1 (identical ellipses), then on gear 1's shaft a driver derived from a
    given planet (``follower``): the case the report's animation used to leave out."""
    A, e = 30.0, 0.25
    return Train([PairSpec("external", ellipse(A, e, 2048), phase=0.1, follower_turns=1.0),
                  PairSpec("external", follower=ellipse(A, 0.15, 2048), phase=0.2,
                           direction=-0.6, follower_turns=1.0)],
                 carrier0=0.3, carrier_sense=-1, arm_length=130.0, arm_angle=0.5, arms=2)


def _motions():
    from plantmech.trains.gearing import gear_names
    from plantmech.trains.spec import build_from_design

    out = {}
    for f in ("rotary_transplanter_elliptic.toml", "planetary/sugarcane_seeder_optimized.toml",
              "planetary/rice_transplanter.toml", "planetary/rice_transplanter_khv.toml"):
        design = load_design(EXAMPLES / f)
        out[f] = simulate(build_from_design(design), 720)
        # the placement names its gears from the built train: the names the teeth are cut
        # under (``plantmech gears`` reads the design file's)
        assert gear_names(out[f].built) == gear_names(design)
    out["derived driver on shaft 1"] = simulate(build(_derived_driver_on_a_later_shaft()), 720)
    return out


@pytest.fixture(scope="module")
def motions():
    return _motions()


# contact side of each gear of a pair along u (driver -> follower centre): the driver's
# contact at c_d + s_d r_d u, the follower's at c_f + s_f r_f u
SIDES = {"external": (1.0, -1.0), "internal": (1.0, 1.0), "internal_ring_follower": (-1.0, -1.0)}


def _pairs_placed(motion, placed):
    """(pair spec, law, driver gear, follower gear) of every pair of every arm."""
    built = motion.built
    out = []
    for j in range(motion.carrier.shape[1]):
        mine = [g for g in placed if g.arm == j or g.name == "sun"]
        for i, spec in enumerate(built.train.pairs):
            fol = next(g for g in mine if g.pair == i and g.side == "follower")
            drv = [g for g in mine if g.pair == i and g.side == "driver"]
            drv = drv[0] if drv else next(g for g in mine if g.pair == i - 1
                                          and g.side == "follower")  # an idler drives
            out.append((spec, built.laws[i], drv, fol))
    return out


def test_every_pair_is_at_its_centre_distance_and_touches_on_both_pitch_curves(motions):
    """On the elliptic example (three identical ellipses about their foci: a = 2A), seed
    000's train (the sun derived from gear 2, gear 3 compound), seed 001's differential
    train (a driven ring, three arms), the K-H-V train (idler, two arms) and a derived
    driver on a later shaft: every pair's centres are its centre distance apart, and the
    point of the driver's pitch curve on the line of centres is the follower's (1e-6 mm),
    at every sample of every arm."""
    for name, motion in motions.items():
        placed = place_gears(motion)
        J = motion.carrier.shape[1]
        K = len(motion.built.train.pairs)
        assert len({g.label for g in placed}) == len(placed), name  # each gear once
        for spec, law, drv, fol in _pairs_placed(motion, placed):
            d = fol.centre - drv.centre
            a = np.abs(d)
            assert np.abs(a - law.a[:, None]).max() < 1e-9, (name, spec.name)
            u = d / a
            s_d, s_f = SIDES[spec.kind]
            th_d = np.angle(s_d * u) - drv.angle
            th_f = np.angle(s_f * u) - fol.angle
            r_d = drv.curve(th_d)[0]
            r_f = fol.curve(th_f)[0]
            gap = np.abs(drv.centre + s_d * r_d * u - (fol.centre + s_f * r_f * u))
            assert gap.max() < 1e-6, (name, spec.name, gap.max())
        # the sun once, every other gear once per arm
        assert sum(g.name == "sun" for g in placed) == 1, name
        assert len(placed) == 1 + J * (len({g.name for g in placed}) - 1), name
        assert {g.pair for g in placed} == set(range(K)), name
    elliptic = motions["rotary_transplanter_elliptic.toml"]
    A = load_design(EXAMPLES / "rotary_transplanter_elliptic.toml").train.pairs[0]
    A = A.driver.semi_major_mm
    assert np.allclose(elliptic.built.centre_distances, 2 * A, atol=1e-6)
    derived = [g for g in place_gears(motions["derived driver on shaft 1"])
               if g.pair == 1 and g.side == "driver"]
    assert [g.label for g in derived] == ["gear1b 1", "gear1b 2"]


def _design_stub(motion):
    return SimpleNamespace(name="placement test", carrier=SimpleNamespace(speed_deg_s=360.0))


@pytest.mark.parametrize("case", ["rotary_transplanter_elliptic.toml",
                                  "planetary/sugarcane_seeder_optimized.toml",
                                  "derived driver on shaft 1"])
def test_the_scene_the_animation_and_the_plot_draw_the_placed_gears(motions, case):
    """The app's scene, the report's animation and the forward plot read the one placement:
    the same gears (a derived driver on a later shaft too), at the same centres and
    angles."""
    from plantmech.app.scene import frame_index, planetary_scene
    from plantmech.outputs.planetary_plots import plot_paths
    from plantmech.outputs.report import FRAMES, _frame_index, planetary_animation

    motion = motions[case]
    design = _design_stub(motion)
    n = len(motion.carrier_angle)

    scene = planetary_scene(design, motion, frames=90, detail=360)
    placed = place_gears(motion, frame_index(n, 90))
    assert [g["name"] for g in scene["gears"]] == [p.label for p in placed]
    for g, p in zip(scene["gears"], placed, strict=True):
        centre = np.asarray(g["centre"], float)
        assert np.abs(centre[:, 0] + 1j * centre[:, 1] - p.centre[0]).max() < 1e-3  # rounded
        assert np.abs(np.asarray(g["rot"]) - p.angle[0]).max() < 1e-5

    anim = planetary_animation(design, motion)
    curves = [lk for lk in anim.links if lk["label"] == ""]
    placed = place_gears(motion, _frame_index(n, FRAMES))
    assert len(curves) == len(placed)
    th = 2 * np.pi * np.arange(181) / 180
    for lk, p in zip(curves, placed, strict=True):
        z = p.outline(th)[0]
        assert np.abs(lk["points"][..., 0] + 1j * lk["points"][..., 1] - z).max() < 1e-9

    fig = plot_paths(motion, "t")
    lines = [ln for ln in fig.axes[0].get_lines() if ln.get_color() == "tab:gray"]
    start = [p for p in place_gears(motion, [0]) if p.arm == 0]
    assert len(lines) == len(start)
    for ln, p in zip(lines, start, strict=True):
        z = p.outline()[0, 0]
        x, y = ln.get_data()
        assert np.abs(np.asarray(x)[:-1] + 1j * np.asarray(y)[:-1] - z).max() < 1e-9


def test_p_designs_are_placed_as_p_single_designs():
    """Population-first: three designs at once (per-design ellipses, phases, directions and
    carrier starts) give each design's own placement (P = 1) to 1e-12."""
    A, e = np.array([30.0, 28.0, 33.0]), np.array([0.2, 0.3, 0.1])
    phase, direction, C0 = np.array([0.1, -0.4, 0.6]), np.array([0.0, 0.3, -0.2]), \
        np.array([0.3, 0.0, -1.0])

    def train(rows):
        return Train([PairSpec("external", ellipse(A[rows], e[rows], 1024), phase=phase[rows],
                               direction=direction[rows], follower_turns=1.0),
                      PairSpec("external", None, direction=-direction[rows],
                               follower_turns=1.0)],
                     carrier0=C0[rows], carrier_sense=-1, arm_length=120.0, arms=2)

    all3 = place_gears(simulate(build(train(slice(None))), 180))
    for p in range(3):
        one = place_gears(simulate(build(train(slice(p, p + 1))), 180))
        assert [g.label for g in one] == [g.label for g in all3]
        for g1, g3 in zip(one, all3, strict=True):
            assert np.abs(g1.centre[0] - g3.centre[p]).max() < 1e-12
            assert np.abs(g1.angle[0] - g3.angle[p]).max() < 1e-12
            assert np.abs(g1.outline()[0] - g3.outline()[p]).max() < 1e-9
