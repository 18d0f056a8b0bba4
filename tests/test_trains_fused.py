"""The fused population passes (trains/fused.py) against the NumPy path they replace for
populations: the manufacturability rules' verdicts of every pair (``trains.gearing.
fused_verdicts`` vs ``assess_pair`` of ``pair_shapes``) on an external chain with a
dwell (Table 4), an idler chain (the elliptic transplanter) and a ring (the differential
transplanter), and the tip path's self-crossings against the all-pairs count."""

from __future__ import annotations

import numpy as np
import pytest

from plantmech.design import load_design
from tests.conftest import EXAMPLES


def _population(name: str, P: int, seed: int = 0) -> list:
    """P variants of a bundled general-train file: every given radii table + uniform(-1.5,
    1.5) mm (solved centre distances), an ellipse's A and e moved (elliptic)."""
    rng = np.random.default_rng(seed)
    base = load_design(EXAMPLES / name)
    out = []
    for _ in range(P):
        d = base.model_copy(deep=True)
        for pair in d.train.pairs:
            for curve in (pair.driver, pair.follower):
                if curve is None:
                    continue
                if curve.family == "radii":
                    curve.radii_mm = [float(r) for r in np.asarray(curve.radii_mm)
                                      + rng.uniform(-1.5, 1.5, len(curve.radii_mm))]
                    pair.centre_distance_mm = None
                elif curve.family == "ellipse":
                    curve.semi_major_mm = float(rng.uniform(22, 28))
                    curve.eccentricity = float(rng.uniform(0.1, 0.3))
        out.append(d)
    return out


FILES = ["planetary/sugarcane_table4.toml", "rotary_transplanter_elliptic.toml",
         "planetary/rice_transplanter.toml"]


@pytest.mark.parametrize("name", FILES)
def test_fused_verdicts_equal_the_sampled_shapes(name):
    """Every module bound of every gear equal to the last bit (minima of the same per-point
    numbers) but the tooth-count bound (a perimeter summed in another order: 1e-14
    relative), each bound's place the same body angle, the module and the working pressure
    angle the same; the place of the largest |mu| may be another of two maxima equal to the
    last bit (a symmetric curve's), never another value."""
    from plantmech.gears.manufacturability import assess_pair, rules_for
    from plantmech.trains import gearing
    from plantmech.trains.spec import build_from_designs

    designs = _population(name, 12)
    built = build_from_designs(designs)
    names = gearing.gear_names(designs[0])
    rules = rules_for(designs[0])
    shapes = gearing.pair_shapes(built, names)
    fused = gearing.fused_verdicts(built, names, rules)
    assert len(fused) == len(shapes) == len(designs[0].train.pairs)
    ring = False
    for shape, v in zip(shapes, fused, strict=True):
        ref = assess_pair(shape, rules)
        assert v.name == ref.name and list(v.bounds) == list(ref.bounds)
        assert list(v.where) == list(ref.where)
        for key, b in ref.bounds.items():
            ring |= key.startswith("internal difference")
            if key.startswith("teeth"):
                np.testing.assert_allclose(v.bounds[key], b, rtol=1e-14)
            else:
                np.testing.assert_array_equal(v.bounds[key], b)
            np.testing.assert_array_equal(v.where[key][1], ref.where[key][1])
        np.testing.assert_allclose(v.module, ref.module, rtol=1e-14)
        np.testing.assert_allclose(v.module_high, ref.module_high, rtol=1e-14)
        np.testing.assert_allclose(v.working_pressure_angle_deg,
                                   ref.working_pressure_angle_deg, rtol=0, atol=1e-12)
        mu = np.abs(shape.mu)
        at = np.radians(v.where["working pressure angle"][1])
        k = np.rint(at / (2 * np.pi / mu.shape[1])).astype(int) % mu.shape[1]
        np.testing.assert_array_equal(mu[np.arange(len(k)), k], mu.max(axis=1))
    assert ring == (name == "planetary/rice_transplanter.toml")


def test_population_rows_take_the_fused_path_and_equal_single_designs():
    """A population above ``curves.KERNEL_POINTS`` grid points is judged by the fused
    passes; every row equals the design's own single evaluation (the NumPy path) to
    1e-12 relative."""
    from plantmech.objectives.planetary import population_evaluation
    from plantmech.trains.curves import KERNEL_POINTS

    designs = _population("planetary/sugarcane_table4.toml", 4, seed=3)
    for d in designs:
        d.train.grid = 16384
    assert len(designs) * 16384 >= KERNEL_POINTS > 16384
    together = population_evaluation(designs, 360)
    for d, rows in zip(designs, together, strict=True):
        alone = population_evaluation([d], 360)[0]
        assert [r["name"] for r in rows] == [r["name"] for r in alone]
        for r, s in zip(rows, alone, strict=True):
            assert r["ok"] == s["ok"]
            assert r["value"] == pytest.approx(s["value"], rel=1e-12, abs=1e-12)


def test_crossings_equal_the_all_pairs_count():
    """Closed polylines with a known number of proper self-crossings (the limacon-like
    r = 1 + b cos(k t) curves walked k times round: a figure eight, a trefoil's knots)
    and random polygons: the fused sweep's count equals every non-adjacent segment pair's
    exact test."""
    from plantmech.trains.fused import crossings

    rng = np.random.default_rng(5)
    t = np.linspace(0, 2 * np.pi, 240, endpoint=False)
    paths = [np.sin(t) + 1j * np.sin(2 * t),  # figure eight: 1
             np.cos(t) + 1j * np.sin(t),  # circle: 0
             np.cos(2 * t) * np.exp(1j * t) + 0.2 * np.exp(1j * t)]  # four-petal rose
    paths += [rng.normal(size=240) + 1j * rng.normal(size=240) for _ in range(3)]
    z = np.array(paths)

    def all_pairs(p):
        n = len(p)
        a, b = p, np.roll(p, -1)
        count = 0
        for i in range(n):
            for j in range(i + 2, n):
                if j == (i - 1) % n or (i == 0 and j == n - 1):
                    continue

                def side(u, s, e):
                    d = e - s
                    return d.real * (u.imag - s.imag) - d.imag * (u.real - s.real)
                if side(a[i], a[j], b[j]) * side(b[i], a[j], b[j]) < 0 and \
                        side(a[j], a[i], b[i]) * side(b[j], a[i], b[i]) < 0:
                    count += 1
        return count

    got = crossings(np.ascontiguousarray(z.real), np.ascontiguousarray(z.imag))
    assert got[0] == 1 and got[1] == 0
    assert list(got) == [all_pairs(p) for p in z]


@pytest.mark.parametrize("kind, q", [("external", 1.0), ("internal", 2.0),
                                     ("internal_ring_follower", 0.5), ("external", 2.0)])
def test_fused_laws_equal_the_numpy_laws(kind, q, monkeypatch):
    """A population's pair laws by ``fused.pair_laws`` (closure solve, ratio, the spline's
    running integral by a cyclic tridiagonal solve) against the NumPy path (bisection and
    Newton on (P, N) tables, the FFT): centre distances, ratio tables, F's periodic part and
    the turns to 1e-13, for a solved and a given centre distance, every kind."""
    from plantmech.trains import pairs
    from plantmech.trains.curves import ellipse, fourier

    rng = np.random.default_rng(2)
    P = 20
    if q == 1.0:
        curve = ellipse(rng.uniform(20, 30, P), rng.uniform(0.05, 0.3, P), 2048)
    else:  # repeats every half turn
        curve = fourier(rng.uniform(30, 40, P), np.stack([np.zeros(P), rng.uniform(1, 4, P)],
                                                         1), np.zeros((P, 0)), 2048)
    monkeypatch.setattr(pairs, "use_kernels", lambda n: False)
    ref = pairs.pair_law(kind, curve, q)
    monkeypatch.setattr(pairs, "use_kernels", lambda n: True)
    for given in (None, ref.a):
        law = pairs.pair_law(kind, curve, q, given)
        np.testing.assert_allclose(law.a, ref.a, rtol=1e-14)
        for name in ("g", "dg", "Fp", "q_e"):
            np.testing.assert_allclose(getattr(law, name), getattr(ref, name), rtol=0,
                                       atol=1e-13, err_msg=name)
    with pytest.raises(pairs.PairError, match="does not close"):  # refused by name as before
        pairs.pair_law(kind, curve, q, ref.a * 1.01)


TRAINS = FILES + ["planetary/rice_transplanter_khv.toml",
                  "planetary/sugarcane_seeder_optimized.toml"]


@pytest.mark.parametrize("name", TRAINS)
def test_fused_tips_equal_the_simulated_chain(name):
    """``model.simulate_tips`` (one fused pass per design over the chain) against
    ``model.simulate`` on five trains (a derived sun with its toothless dwell and a
    compound gear; two idler chains; a driven ring sun; a given follower with a derived
    mate on the next shaft), two arms where the file has them: tips and their rates to
    1e-9 mm (measured 3e-11: the arms of a fixed sun are one arm shifted, 1.3e-13 with one
    arm), the arm's angle and rate to 1e-12 rad."""
    from plantmech.trains.model import simulate, simulate_tips
    from plantmech.trains.spec import build_from_designs

    designs = _population(name, 8, seed=7)
    for d in designs:
        d.train.grid = 4096  # 8 x 4096 points: the fused pass's population
    built = build_from_designs(designs)
    ref, got = simulate(built, 720), simulate_tips(built, 720)
    assert got is not None and got.tip.shape == ref.tip.shape
    assert np.abs(got.tip - ref.tip).max() < 1e-9
    assert np.abs(got.tip_rate - ref.tip_rate).max() < 1e-9
    assert np.abs(got.arm_angle - ref.arm_angle).max() < 1e-12
    assert np.abs(got.arm_rate - ref.arm_rate).max() < 1e-12
    assert np.abs(got.centre - ref.centre).max() < 1e-9
    # a single design is not a population: simulate's own path
    assert simulate_tips(build_from_designs(designs[:1]), 720) is None


def test_sub_populations_on_two_threads_give_the_same_rows(monkeypatch):
    """PLANTMECH_KERNEL_THREADS = 2 maps the sub-populations on two threads: the rows are
    those of one thread, in the designs' order."""
    from plantmech.objectives import planetary

    designs = _population("rotary_transplanter_elliptic.toml", 6, seed=4)
    for d in designs:
        d.train.grid = 4096
    monkeypatch.setattr(planetary, "CHUNK_POINTS", 2 * 4096)  # 3 sub-populations of 2
    monkeypatch.setenv("PLANTMECH_KERNEL_THREADS", "1")
    one = planetary.population_evaluation(designs, 360)
    monkeypatch.setenv("PLANTMECH_KERNEL_THREADS", "2")
    calls = []
    real = planetary._evaluate_group
    monkeypatch.setattr(planetary, "_evaluate_group",
                        lambda ds, n, m=None: calls.append(len(ds)) or real(ds, n, m))
    assert planetary.population_evaluation(designs, 360) == one
    assert calls == [2, 2, 2]


def test_fused_table4_population_equals_the_dedicated_seeder_model():
    """Table 4's general file as a population (two copies: 2 x 16384 grid points, the
    fused pass) against the dedicated seeder model (mechanisms/seeder_forward, independent
    code): tip and tip rate to 1e-6 mm, the arm angle to 1e-6 rad, and the arm held in the
    carrier (its rate the carrier's own, exactly) on exactly the 450 samples of the 45 deg
    dwell where the seeder's model says so."""
    from plantmech.mechanisms.seeder_forward import simulate as seeder_simulate
    from plantmech.trains.model import simulate_tips
    from plantmech.trains.spec import build_from_designs
    from plantmech.workflows import train_from_design as seeder_train

    tr, _ = seeder_train(load_design(EXAMPLES / "sugarcane_table4.toml"))
    d = load_design(EXAMPLES / "planetary" / "sugarcane_table4.toml")
    ref = seeder_simulate(tr, d.samples)
    m = simulate_tips(build_from_designs([d, d.model_copy(deep=True)]), d.samples)
    assert m is not None
    for p in range(2):
        assert np.abs(m.tip[p, 0] - (ref.tip[:, 0] + 1j * ref.tip[:, 1])).max() < 1e-6
        assert np.abs(m.arm_angle[p, 0] - ref.arm_angle).max() < 1e-6
        assert np.abs(m.tip_rate[p, 0] - (ref.tip_rate[:, 0] + 1j * ref.tip_rate[:, 1])
                      ).max() < 1e-6
        held = m.arm_rate[p, 0] == -1.0  # clockwise carrier: s = -1, the gears at rest
        assert np.array_equal(held, ref.in_dwell) and held.sum() == 450
