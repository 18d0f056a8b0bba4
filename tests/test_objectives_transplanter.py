import numpy as np
import pytest

from plantmech.gears.internal import internal_perimeter, lobed_internal_pair
from plantmech.mechanisms.transplanter import ArmGeometry, simulate_differential
from plantmech.objectives.transplanter import FieldSetup, TransplanterLimits, evaluate

PH = np.radians(np.arange(12) * 30.0)
PHI0, BETA = np.radians(40.0), np.radians(-40.0)
ARM = ArmGeometry(150.0, 80.0, BETA)


def circle_case(alpha_deg=30.0, depth=20.0, samples=7200):
    """Circular internal gear, swinging arm: the tip runs clockwise on a circle of radius
    a = 67.5 mm about c = S e^{i(phi0 + beta)} with a constant needle direction."""
    pair = lobed_internal_pair(PH, np.full(12, 90.0), 4)
    mo = simulate_differential(pair, 0.75, PHI0, ARM, samples=samples)
    a = pair.a[0]
    c = 150 * np.exp(1j * (PHI0 + BETA))
    al = np.radians(alpha_deg)
    door = c + a * np.exp(1j * al)  # box floor radial through the circle centre
    setup = FieldSetup(box_x=door.real, box_y=door.imag, box_inclination_deg=alpha_deg,
                       planting_depth=depth, spacing_nominal=120.0)
    ev = evaluate(mo, setup, TransplanterLimits(), internal_perimeter(pair), 80,
                  gearbox_radius=np.array([100.0]), interference=False)
    return mo, ev, a, c, al, setup


def value(ev, name):
    return ev.values[0, ev.names.index(name)]


def test_circle_angles_height_and_module_are_analytic():
    mo, ev, a, c, al, setup = circle_case()
    theta = PHI0 + BETA
    needle = np.degrees(np.angle(150 * np.exp(1j * theta)
                                 - 80 * np.exp(1j * (theta + np.arccos(80 / 150))))) % 360
    assert value(ev, "picking_angle") == pytest.approx(needle, abs=1e-6)
    assert value(ev, "pushing_angle") == pytest.approx(needle, abs=1e-6)
    assert value(ev, "angle_difference") == pytest.approx(0.0, abs=1e-6)
    assert value(ev, "trajectory_height") == pytest.approx(2 * a - 20.0, abs=1e-3)
    assert value(ev, "module") == pytest.approx(2 * np.pi * 90 / (np.pi * 80), rel=1e-9)
    assert not ev.ok[0, ev.names.index("module")]  # 2.25 mm < 2.5 mm
    # needle vs the seedlings' growth direction (normal to the floor, -v = alpha - 90)
    exp = np.degrees(np.arccos(abs(np.cos(np.radians(needle) - (al - np.pi / 2)))))
    assert value(ev, "needle_seedling_angle") == pytest.approx(exp, abs=1e-6)
    # gearbox radius 100 mm, ground 20 mm above the lowest point (c_y - a)
    assert value(ev, "gearbox_clearance") == pytest.approx(-100 - (c.imag - a + 20), abs=1e-3)


def test_circle_stages_and_block_skew_are_analytic():
    mo, ev, a, c, al, setup = circle_case(samples=36000)
    pick = ev.metrics["stages_deg"]["picking"][0, 0]
    plant = ev.metrics["stages_deg"]["planting"][0, 0]
    # in the mat from v = 20 to v = 0: the circle turns asin(20 / a)
    assert np.mod(pick[1] - pick[0], 360) == pytest.approx(np.degrees(np.arcsin(20 / a)),
                                                           abs=0.02)
    # entering the ground (20 mm above the bottom) to the bottom: acos(1 - 20 / a)
    assert np.mod(plant[1] - plant[0], 360) == pytest.approx(
        np.degrees(np.arccos(1 - 20 / a)), abs=0.02)
    # the top surface is crossed at u = sqrt(a^2 - 20^2) - a from the door, the floor at 0
    assert value(ev, "seedling_block_skew") == pytest.approx(a - np.sqrt(a**2 - 400), abs=1e-3)


def test_hole_width_and_forward_inclination_by_brute_force():
    mo, ev, a, c, al, setup = circle_case(samples=36000)
    psi = np.linspace(0, 2 * np.pi, 200001)
    B = c + a * np.exp(1j * (PHI0 - psi))
    ground = c.imag - a + 20.0
    kb = np.argmin(B.imag)
    # the tip moves in -x at the bottom of a clockwise circle: the machine moves +x
    assert ev.metrics["forward_sign"][0] == 1.0
    for spacing, width in zip(ev.metrics["spacings_mm"], ev.metrics["hole_widths_mm"][0],
                              strict=True):
        x = B.real + 3 * spacing * psi / (2 * np.pi)
        below = B.imag < ground
        assert width == pytest.approx(np.ptp(x[below]), abs=0.05)
    # chord from leaving the ground to 100 mm above it, at the nominal spacing
    x = B.real + 3 * 120.0 * psi / (2 * np.pi)
    k0 = kb + np.flatnonzero(B.imag[kb:] >= ground)[0]
    k1 = kb + np.flatnonzero(B.imag[kb:] >= ground + 100)[0]
    exp = np.degrees(np.arctan2(B.imag[k1] - B.imag[k0], x[k1] - x[k0]))
    assert value(ev, "forward_inclination") == pytest.approx(exp, abs=0.05)


def test_interference_detects_crossing_arms():
    from plantmech.design import load_design
    from plantmech.workflows import run_transplanter

    from .conftest import EXAMPLES

    d = load_design(EXAMPLES / "rice_transplanter.toml")
    job = run_transplanter(d)
    i = job.evaluation.names.index("arms_clearance")
    assert job.evaluation.values[0, i] > 0
    # one layer only (housing and fork drawn as one outline): the arms cross
    from plantmech.objectives.transplanter import default_outline

    both = default_outline(job.motion.arm_geometry)
    one = np.vstack([both["housing"], both["fork"]])
    from shapely.geometry import MultiPoint

    hull = np.asarray(MultiPoint([tuple(p) for p in one]).convex_hull.exterior.coords)[:-1]
    d2 = d.model_copy(deep=True)
    d2.arm.outline = {"whole": [tuple(p) for p in hull]}
    job2 = run_transplanter(d2)
    assert job2.evaluation.values[0, i] < 0
