"""geometry.polygons: clearance of rigidly moving polygons, against closed forms and
against shapely (the reference the compiled kernel replaced)."""

import numpy as np
import pytest
import shapely

from plantmech.geometry.polygons import bounding_capsule, smallest_clearance

SQUARE = np.array([0, 1, 1 + 1j, 1j])  # unit square, counter-clockwise


def one(a, b, rot_b=1.0, shift_b=0.0):
    """Clearance of a (fixed) and b placed at one pose."""
    pose_b = (np.array([[rot_b]]), np.array([[shift_b]]))
    return smallest_clearance([(a, b)], (1.0, 0.0), pose_b)[0]


def test_closed_forms():
    assert one(SQUARE, SQUARE, shift_b=4.0) == pytest.approx(3.0, abs=1e-12)
    # corner to corner along the diagonal: (1,1) to (3,3)
    assert one(SQUARE, SQUARE, shift_b=3 + 3j) == pytest.approx(2 * np.sqrt(2), abs=1e-12)
    # a square turned -45 deg (a diamond to the right of its first corner) with that
    # corner at (1 + d, 0.5): the corner is nearest
    rot = np.exp(-1j * np.pi / 4)
    d = 0.25
    assert one(SQUARE, SQUARE, rot, 1 + d + 0.5j) == pytest.approx(d, abs=1e-12)
    # overlap, touching edge, touching corner, containment either way: -1
    assert one(SQUARE, SQUARE, shift_b=0.5 + 0.5j) == -1.0
    assert one(SQUARE, SQUARE, shift_b=1.0) == -1.0
    assert one(SQUARE, SQUARE, shift_b=1 + 1j) == -1.0
    big = 10 * SQUARE - 5 - 5j
    assert one(big, SQUARE) == -1.0
    assert one(SQUARE, big) == -1.0
    # a cross through a thin bar (no vertex of either inside the other): -1
    bar = np.array([-5 + 0.4j, 5 + 0.4j, 5 + 0.6j, -5 + 0.6j])
    assert one(SQUARE, bar) == -1.0


def test_smallest_over_poses_and_designs():
    """A unit square carried round the origin at radius 3 (design 0) or 6 (design 1),
    turning with the radius, past a fixed 2 x 2 square: the smallest over poses equals
    the smallest of single-pose clearances; designs are independent rows; a non-finite
    pose gives NaN."""
    t = np.linspace(0, 2 * np.pi, 73)
    rot = np.exp(1j * t)[None]
    centred = SQUARE - (0.5 + 0.5j)
    shifts = np.array([[3.0], [6.0]]) * rot  # two designs
    fixed = 2 * SQUARE - (1 + 1j)  # 2 x 2 square about the origin
    got = smallest_clearance([(fixed, centred)], (1.0, 0.0), (rot, shifts))
    each = [[one(fixed, centred, rot[0, m], shifts[p, m]) for m in range(t.size)]
            for p in range(2)]
    assert got == pytest.approx(np.min(each, axis=1), abs=1e-12)
    # design 0: the near edge lies on a line 2.5 from the origin, normal to e^{it}; the
    # fixed square reaches |cos t| + |sin t| <= sqrt 2 towards it, sqrt 2 at t = 45 deg
    # (a sample) where its corner faces the edge's middle: 2.5 - sqrt 2
    assert got[0] == pytest.approx(2.5 - np.sqrt(2), abs=1e-12)
    bad = shifts.copy()
    bad[1, 5] = np.nan
    assert np.isnan(smallest_clearance([(fixed, centred)], (1.0, 0.0), (rot, bad))[1])


def test_bounding_capsule_holds_the_polygon():
    rng = np.random.default_rng(3)
    z = rng.normal(size=(50, 7)) + 1j * rng.normal(size=(50, 7)) * 0.3
    c0, c1, r = bounding_capsule(z)
    e = (c1 - c0)[:, None]
    t = np.clip(((z - c0[:, None]) * np.conj(e)).real / np.abs(e) ** 2, 0, 1)
    assert (np.abs(z - c0[:, None] - t * e) <= r[:, None] + 1e-12).all()


def star(rng, k):
    """A random simple (star-shaped, often non-convex) polygon of k vertices."""
    ang = (np.arange(k) + rng.uniform(0, 0.8, k)) * 2 * np.pi / k  # gaps < pi (k >= 4)
    return rng.uniform(0.3, 1.0, k) * np.exp(1j * ang) * rng.uniform(2, 8)


def shapely_clearance(a, b):
    pa = shapely.polygons(np.stack([a.real, a.imag], -1))
    pb = shapely.polygons(np.stack([b.real, b.imag], -1))
    return np.where(shapely.intersects(pa, pb), -1.0, shapely.distance(pa, pb))


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_against_shapely_on_random_polygons(seed):
    """Seeded random star polygons (4-9 vertices) moved along random paths: the same
    verdicts (overlap or not) and clearances as shapely's, pose by pose and minimised."""
    rng = np.random.default_rng(seed)
    P, M = 40, 60
    for _ in range(3):
        a = star(rng, rng.integers(4, 10))
        b = np.stack([star(rng, 6) for _ in range(P)])  # a polygon per design
        rot_a = np.exp(1j * rng.uniform(0, 6.3, (P, M)))
        shift_a = rng.normal(0, 6, (P, M)) + 1j * rng.normal(0, 6, (P, M))
        rot_b = np.exp(1j * rng.uniform(0, 6.3, (P, M)))
        shift_b = rng.normal(0, 6, (P, M)) + 1j * rng.normal(0, 6, (P, M)) + 8
        wa = rot_a[..., None] * a[None, None] + shift_a[..., None]
        wb = rot_b[..., None] * b[:, None] + shift_b[..., None]
        ref = shapely_clearance(wa.reshape(-1, a.size), wb.reshape(-1, b.shape[-1]))
        ref = ref.reshape(P, M)
        assert 0 < (ref < 0).mean() < 0.9  # both verdicts occur
        per_pose = np.array([[one(wa[p, m], wb[p, m]) for m in range(M)] for p in range(P)])
        assert np.array_equal(per_pose < 0, ref < 0)
        assert per_pose == pytest.approx(ref, abs=1e-9)
        got = smallest_clearance([(a, b)], (rot_a, shift_a), (rot_b, shift_b))
        assert got == pytest.approx(ref.min(axis=1), abs=1e-9)
        # far apart: every design clear, the minimum a positive distance
        got = smallest_clearance([(a, b)], (rot_a, shift_a + 60), (rot_b, shift_b))
        ref = shapely_clearance(wa.reshape(-1, a.size) + 60, wb.reshape(-1, b.shape[-1]))
        assert got == pytest.approx(ref.reshape(P, M).min(axis=1), abs=1e-9)
        assert (got > 0).all()


def test_numba_stays_out_of_the_cli_start_up():
    """`plantmech --help` builds the parser only: the compiled kernels' numba is not
    imported (it costs about half a second)."""
    import subprocess
    import sys

    code = ("import sys; from plantmech.interfaces.cli import build_parser; "
            "build_parser().format_help(); import plantmech.objectives.transplanter; "
            "print('numba' in sys.modules, 'plantmech.geometry.polygons' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout.split()
    assert out == ["False", "False"]
