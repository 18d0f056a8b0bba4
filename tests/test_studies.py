"""Design studies (plantmech.studies): the population extension against the single-design
path, Monte Carlo against first-order sensitivities, a real two-worker Dask cluster,
resume, distributions and summary statistics."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from plantmech.design import load_design
from plantmech.studies import distributions as dist
from plantmech.studies.engine import done_chunks, read_results
from plantmech.studies.parameters import StudyInputError, chunk_outputs, make_model
from plantmech.studies.runner import (
    first_order,
    run_study,
    standardized_regression,
    tolerance_chunk,
    wilson,
)
from plantmech.studies.spec import Distribution, ToleranceSpec
from plantmech.workflows import run_seeder_forward, run_transplanter

ROOT = Path(__file__).resolve().parents[1]
SEEDER = ROOT / "examples" / "sugarcane_seeder_optimized.toml"
RICE = ROOT / "examples" / "rice_transplanter_toothed.toml"


@pytest.fixture(scope="module")
def seeder():
    d = load_design(SEEDER)
    d.train.samples = 720
    return d


# --- the population path with per-design parameters == the single-design path ----------

SEEDER_STEPS = {"gear2_radius_mm": 0.5, "gear3_radius_mm": 0.5, "a1_mm": 1.0, "a2_mm": 1.0,
                "L2_mm": 2.0, "sun_phase_deg": 1.0, "arm_phase_deg": 1.0,
                "gear2_phase_deg": 2.0, "gear3_phase_deg": 2.0, "travel_speed_m_s": 0.1}


def _changed(design, name, h):
    """The design file with one parameter moved by h, as a designer would edit it."""
    v = design.model_copy(deep=True)
    t = v.train
    if name == "gear2_radius_mm":
        t.gear2.radii_mm = [r + h for r in t.gear2.radii_mm]
    elif name == "gear3_radius_mm":
        t.gear3.radii_mm = [r + h for r in t.gear3.radii_mm]
    elif name in ("a1_mm", "a2_mm"):  # collinear carrier: the planet axis moves out too
        setattr(t, name, getattr(t, name) + h)
        t.L1_mm += h
    elif name == "L2_mm":
        t.L2_mm += h
    elif name == "sun_phase_deg":
        t.initial_carrier_angle_deg += h
        t.initial_arm_angle_deg += h
    elif name == "arm_phase_deg":
        t.initial_arm_angle_deg += h
    elif name == "gear2_phase_deg":
        t.gear2.contact_angle_deg += h
    elif name == "gear3_phase_deg":
        t.gear3.contact_angle_deg += h
    elif name == "travel_speed_m_s":
        v.operation.travel_speed_m_s += h
    return type(v).model_validate(v.model_dump())


def test_seeder_variants_equal_single_design_path(seeder):
    names = list(SEEDER_STEPS)
    model = make_model(seeder, names, 720, 4096)
    fixed = seeder.model_copy(deep=True)
    fixed.operation.travel_speed_m_s = model.travel0  # the study's fixed travel
    base = run_seeder_forward(fixed)
    deltas = np.vstack([np.zeros(len(names)), np.diag(list(SEEDER_STEPS.values()))])
    ev = model.evaluate(deltas)
    assert np.abs(ev.tip[0] - base.result.tip).max() < 1e-5
    for k, name in enumerate(names):
        one = run_seeder_forward(_changed(fixed, name, SEEDER_STEPS[name]))
        # the whole tip path at equal carrier angles (mm), and every section-4.1 objective
        assert np.abs(ev.tip[k + 1] - one.result.tip).max() < 1e-5, name
        moved = np.abs(one.result.tip - base.result.tip).max()
        assert name == "travel_speed_m_s" or moved > 0.5, name  # the parameter matters
        by = {c.name: c.value for c in one.checks}
        for j, obj in enumerate(ev.names[:6]):
            assert ev.values[k + 1, j] == pytest.approx(by[obj], abs=2e-4), (name, obj)
    travel = run_seeder_forward(_changed(fixed, "travel_speed_m_s", 0.1))
    k = names.index("travel_speed_m_s")
    dyn = {c.name: c.value for c in travel.checks}["return_min_speed_dynamic"]
    assert ev.values[k + 1, 5] == pytest.approx(dyn, abs=2e-4)
    assert abs(dyn - {c.name: c.value for c in base.checks}["return_min_speed_dynamic"]) > 1e-3


def test_backlash_moves_the_arm_by_half_the_play(seeder):
    model = make_model(seeder, ["backlash_deg"], 720, 2048)
    ev = model.evaluate(np.array([[0.0], [0.4]]))
    diff = ev.attitude_deg[1] - ev.attitude_deg[0]
    assert np.allclose(np.abs(diff), 0.2, atol=1e-9)  # +-play / 2 everywhere
    assert (diff > 0).any() and (diff < 0).any()  # both flanks are used over a cycle


def test_collinear_carrier_refuses_L1(seeder):
    with pytest.raises(StudyInputError, match="collinear"):
        make_model(seeder, ["L1_mm"])
    with pytest.raises(StudyInputError, match="not a study parameter"):
        make_model(seeder, ["L3_mm"])


def test_transplanter_variants_equal_single_design_path():
    rice = load_design(RICE)
    rice.samples = 720
    names = ["gear_radius_mm", "S_mm", "beta_deg", "carrier_phase_deg", "ring_phase_deg"]
    steps = [0.3, 2.0, 1.0, 1.0, 1.0]
    model = make_model(rice, names, 720)
    ev = model.evaluate(np.vstack([np.zeros(5), np.diag(steps)]))
    for k, (name, h) in enumerate(zip(names, steps, strict=True)):
        v = rice.model_copy(deep=True)
        if name == "gear_radius_mm":
            v.internal_gear.radii_mm = [r + h for r in v.internal_gear.radii_mm]
        elif name == "S_mm":
            v.arm.S_mm += h
        elif name == "beta_deg":
            v.arm.beta_deg += h
        elif name == "carrier_phase_deg":
            v.carrier.initial_angle_deg += h
        else:
            v.internal_gear.initial_phase_deg += h
        one = run_transplanter(type(v).model_validate(v.model_dump()))
        tip = one.motion.B[0, 0]
        # single path: dense 4096 nodes; population: 1024
        assert np.abs(ev.tip[k + 1, :, 0] + 1j * ev.tip[k + 1, :, 1] - tip).max() < 0.05, name
        assert np.abs(tip - run_transplanter(rice).motion.B[0, 0]).max() > 0.2, name


def test_khv_carrier_phase_per_design_equals_the_edited_file():
    """A K-H-V's sun is fixed: a carrier phase per design reads the sun's pitch curve from
    each design's own start (it failed to broadcast before)."""
    from plantmech.workflows import evaluate_transplanter_population

    khv = load_design(ROOT / "examples" / "rice_transplanter_khv.toml")
    model = make_model(khv, ["carrier_phase_deg", "gear_radius_mm"], 720)
    steps = np.array([[0.0, 0.0], [1.5, 0.0], [-2.0, 0.2]])
    ev = model.evaluate(steps)
    for k, (dphi, dr) in enumerate(steps):
        v = khv.model_copy(deep=True)
        v.carrier.initial_angle_deg += dphi
        v.sun_gear.radii_mm = [r + dr for r in v.sun_gear.radii_mm]
        motion, one = evaluate_transplanter_population(type(v).model_validate(v.model_dump()),
                                                       samples=720)
        tip = motion.B[0, 0]
        assert np.abs(ev.tip[k, :, 0] + 1j * ev.tip[k, :, 1] - tip).max() < 1e-9, k
        np.testing.assert_allclose(ev.values[k], [one.values[0, one.names.index(n)]
                                                  for n in ev.names], atol=1e-9)
    assert np.abs(ev.tip[1] - ev.tip[0]).max() > 1.0


# --- the transplanter's carrier length, backlash and travel speed ------------------------

RICE_MFG = ROOT / "examples" / "rice_transplanter_manufacturable.toml"
KHV = ROOT / "examples" / "rice_transplanter_khv.toml"
# objectives the gears decide (the carrier and the planet's play leave the gears alone)
GEAR_OBJECTIVES = ("module", "equivalent_teeth", "internal_teeth_difference",
                   "working_pressure_angle", "cuttable_module_margin")


def _scaled(design, factor):
    """The design file with its gear's radii scaled: the pair closes at factor x a, and
    its ratio (r / a) is the same, so the planet axis is factor x farther from O."""
    v = design.model_copy(deep=True)
    g = v.internal_gear if v.mechanism == "rice_transplanter" else v.sun_gear
    g.radii_mm = [r * factor for r in g.radii_mm]
    return type(v).model_validate(v.model_dump())


@pytest.mark.parametrize("path", [RICE_MFG, KHV])
def test_transplanter_carrier_length_is_the_scaled_pair(path):
    from plantmech.workflows import evaluate_transplanter_population

    rice = load_design(path)
    rice.samples = 720
    model = make_model(rice, ["carrier_length_mm"], 720)
    L = model.nominal("carrier_length_mm")
    assert L == pytest.approx(run_transplanter(rice).pair.a[0]
                              * (1 if rice.mechanism == "rice_transplanter" else 2), rel=1e-4)
    dL = 0.6
    ev = model.evaluate(np.array([[0.0], [dL]]))
    scaled = _scaled(model.design, (L + dL) / L)
    motion, same = evaluate_transplanter_population(scaled, samples=720)
    tip = motion.B[0, 0]
    # the same population path on the scaled design file: the same motion ...
    assert np.abs(ev.tip[1, :, 0] + 1j * ev.tip[1, :, 1] - tip).max() < 1e-6
    assert np.abs(ev.tip[1] - ev.tip[0]).max() > 0.5 * dL
    # ... and the single-design path (4096 pitch-curve nodes, the population 1024)
    one = run_transplanter(scaled)
    assert np.abs(ev.tip[1, :, 0] + 1j * ev.tip[1, :, 1] - one.motion.B[0, 0]).max() < 0.05
    for k, name in enumerate(ev.names):
        if name in GEAR_OBJECTIVES or name == "gearbox_clearance":
            continue  # the scaled file has larger gears; the study's are the nominal ones
        j = same.names.index(name)
        # (the K-H-V example's tip misses the mat: its picking objectives are NaN in both)
        np.testing.assert_allclose(ev.values[1, k], same.values[0, j], atol=1e-6,
                                   err_msg=name)
    for name in GEAR_OBJECTIVES:
        if name in ev.names:
            k = ev.names.index(name)
            assert ev.values[1, k] == ev.values[0, k], name
    # the gearbox stays where it is: its clearance changes by the ground's move only (the
    # lowest point located between the samples with the tip's rate, as the objectives do)
    from plantmech.geometry.refine import cyclic_extreme

    k = ev.names.index("gearbox_clearance")
    lowest = cyclic_extreme(ev.tip[:, :, 1], ev.tip_rate[:, :, 1], 2 * np.pi / 720,
                            largest=False)
    assert np.all(lowest <= ev.tip[:, :, 1].min(axis=1))
    assert ev.values[1, k] - ev.values[0, k] == pytest.approx(-(lowest[1] - lowest[0]),
                                                              abs=1e-9)


@pytest.mark.parametrize("path", [RICE_MFG, KHV])
def test_transplanter_backlash_turns_the_planet_by_half_the_play(path):
    rice = load_design(path)
    model = make_model(rice, ["backlash_deg"], 720)
    play = 0.4
    ev = model.evaluate(np.array([[0.0], [play]]))
    diff = np.mod(ev.attitude_deg[1] - ev.attitude_deg[0] + 180, 360) - 180
    assert np.allclose(np.abs(diff), play / 2, atol=1e-9)  # +-play / 2 everywhere
    assert (diff > 0).any() and (diff < 0).any()  # both flanks over a cycle
    # the planet lags (-) while its turn relative to the carrier speeds up
    from plantmech.workflows import simulate_transplanter

    _, motion, _, _ = simulate_transplanter(model.design, samples=720, dense=1024)
    rate = motion.planet_rate[0, 0]
    slope = np.roll(rate, -1) - np.roll(rate, 1)
    assert np.array_equal(np.sign(diff), -np.sign(slope))
    # it turns about the planet axis: the tip stays S from it
    centre = motion.centre[0, 0]
    tip = ev.tip[1, :, 0] + 1j * ev.tip[1, :, 1]
    assert np.allclose(np.abs(tip - centre), rice.arm.S_mm, atol=1e-9)


def test_transplanter_travel_speed_sets_the_spacing():
    from plantmech.workflows import evaluate_transplanter_population, transplanter_travel_speed

    rice = load_design(RICE_MFG)
    rice.samples = 720
    v0 = transplanter_travel_speed(rice)  # 120 mm x 3 arms x 1 turn/s
    assert v0 == pytest.approx(0.120 * 3 * rice.drive.carrier_speed_deg_s / 360)
    model = make_model(rice, ["travel_speed_m_s"], 720)
    dv = 0.06
    ev = model.evaluate(np.array([[0.0], [dv]]))
    v = rice.model_copy(deep=True)
    v.field.plant_spacing_mm *= (v0 + dv) / v0  # the spacing at that speed, set by hand
    v = type(v).model_validate(v.model_dump())
    _, same = evaluate_transplanter_population(v, samples=720)
    one = run_transplanter(v)
    by = {c.name: c.value for c in one.evaluation.checks()}
    k = ev.names.index("forward_inclination")
    assert ev.values[1, k] == pytest.approx(same.values[0, same.names.index(
        "forward_inclination")], abs=1e-9)
    assert ev.values[1, k] == pytest.approx(by["forward_inclination"], abs=0.2)
    assert abs(ev.values[1, k] - ev.values[0, k]) > 0.5  # faster: a flatter exit
    moved = [n for j, n in enumerate(ev.names) if ev.values[1, j] != ev.values[0, j]]
    assert moved == ["forward_inclination"]  # (ix) covers the whole spacing range
    assert np.array_equal(ev.tip[1], ev.tip[0])


@pytest.mark.parametrize("name", ["sugarcane_seeder_optimized.toml", "sugarcane_table4.toml",
                                  "rice_transplanter_manufacturable.toml",
                                  "rice_transplanter_toothed.toml", "rice_transplanter_khv.toml"])
def test_every_bundled_design_with_a_train_takes_every_tolerance(name):
    """Any seeder design file with a [train] and any transplanter: every study parameter
    the design admits, in one population; the nominal row is the design's own path."""
    from plantmech.studies.parameters import parameters_of

    design = load_design(ROOT / "examples" / name)
    names = list(parameters_of(design))
    if design.mechanism == "sugarcane_seeder":
        t = design.train
        if abs(t.a1_mm + t.a2_mm - t.L1_mm) <= 1e-6 * t.L1_mm:
            names.remove("L1_mm")
    elif design.mechanism != "rice_transplanter":
        names.remove("ring_phase_deg")
    model = make_model(design, names, 180, 512)
    rng = np.random.default_rng(4)
    deltas = np.vstack([np.zeros(len(names)), 0.02 * rng.standard_normal((3, len(names)))])
    deltas[:, names.index("backlash_deg")] = np.abs(deltas[:, names.index("backlash_deg")])
    ev = model.evaluate(deltas)
    assert np.isfinite(ev.tip).all() and ev.values.shape == (4, len(ev.names))
    assert np.abs(ev.tip[1:] - ev.tip[:1]).max() > 1e-3  # the deviations move the tip
    again = model.evaluate(np.zeros((1, len(names))))
    assert np.abs(again.tip[0] - ev.tip[0]).max() < 1e-9  # alone or in a population


# --- Monte Carlo vs first order -----------------------------------------------------------


def test_monte_carlo_band_matches_first_order_on_small_tolerances(seeder):
    names = ["gear2_radius_mm", "a1_mm", "L2_mm", "sun_phase_deg", "gear3_phase_deg"]
    dists = [Distribution(distribution="normal", sigma=0.01),
             Distribution(distribution="uniform", plus_minus=0.02),
             Distribution(distribution="normal", sigma=0.05),
             Distribution(distribution="truncated_normal", sigma=0.02, limit=0.03),
             Distribution(distribution="normal", sigma=0.02)]
    model = make_model(seeder, names, 360, 1024)
    N = 1500
    cols, band = tolerance_chunk(model, (0, 0, N, 7, dists))
    mc_std = np.sqrt(band["sumsq"] / N - (band["sum"] / N) ** 2)
    stds = np.array([dist.std(d) for d in dists])
    fo = first_order(model, stds)
    fo_std = np.sqrt(((fo["grad_normal"] * stds[:, None]) ** 2).sum(axis=0))
    # sampling error of a std from N samples ~ 1 / sqrt(2 N) = 1.8 %
    rel = np.abs(mc_std - fo_std) / fo_std
    assert np.median(rel) < 0.04 and rel.max() < 0.12
    for k, name in enumerate(fo["names"][:6]):
        g = np.abs(fo["grad_objectives"][:, k]) * stds
        pred = np.sqrt((g**2).sum())
        if pred > 1e-6:
            assert np.std(cols[name], ddof=1) == pytest.approx(pred, rel=0.12), name


def test_transplanter_monte_carlo_matches_first_order_on_small_tolerances():
    """The same check on the manufacturable transplanter, with its carrier length,
    backlash and travel speed among small tolerances."""
    rice = load_design(RICE_MFG)
    names = ["gear_radius_mm", "S_mm", "beta_deg", "carrier_phase_deg", "carrier_length_mm",
             "travel_speed_m_s", "backlash_deg"]
    dists = [Distribution(distribution="normal", sigma=0.01),
             Distribution(distribution="normal", sigma=0.05),
             Distribution(distribution="truncated_normal", sigma=0.02, limit=0.03),
             Distribution(distribution="normal", sigma=0.02),
             Distribution(distribution="uniform", plus_minus=0.03),
             Distribution(distribution="normal", sigma=0.01),
             Distribution(distribution="uniform", low=0.0, high=0.04)]
    model = make_model(rice, names, 360)
    N = 1500
    cols, band = tolerance_chunk(model, (0, 0, N, 7, dists))
    mc_mean = band["sum"] / N
    mc_std = np.sqrt(band["sumsq"] / N - mc_mean**2)
    stds = np.array([dist.std(d) for d in dists])
    means = np.array([dist.mean(d) for d in dists])
    fo = first_order(model, stds)
    fo_std = np.sqrt(((fo["grad_normal"] * stds[:, None]) ** 2).sum(axis=0))
    rel = np.abs(mc_std - fo_std) / fo_std
    assert np.median(rel) < 0.04 and rel.max() < 0.12
    # the mean deviation (the backlash's half play is a bias) within sampling error
    fo_mean = (fo["grad_normal"] * means[:, None]).sum(axis=0)
    assert np.abs(mc_mean - fo_mean).max() < 5 * fo_std.max() / np.sqrt(N)
    # the new tolerances move what they should: the path (carrier, play), the exit (speed)
    g = dict(zip(names, np.abs(fo["grad_normal"]).max(axis=1), strict=True))
    assert g["carrier_length_mm"] > 0.5 and g["backlash_deg"] > 0.5
    assert g["travel_speed_m_s"] == 0.0
    k = fo["names"].index("forward_inclination")
    assert abs(fo["grad_objectives"][names.index("travel_speed_m_s"), k]) > 1.0  # deg/(m/s)
    for k, name in enumerate(fo["names"]):
        pred = np.sqrt(((fo["grad_objectives"][:, k] * stds) ** 2).sum())
        if pred > 1e-6:
            assert np.std(cols[name], ddof=1) == pytest.approx(pred, rel=0.12), name


# --- distributions and statistics ---------------------------------------------------------


@pytest.mark.parametrize("d", [
    Distribution(distribution="normal", sigma=0.3, mean=1.0),
    Distribution(distribution="uniform", plus_minus=0.5),
    Distribution(distribution="uniform", low=0.0, high=0.2),
    Distribution(distribution="truncated_normal", sigma=1.0, limit=1.5),
])
def test_distribution_samples_have_the_stated_moments(d):
    u = np.random.default_rng(3).random(400_000)
    x = dist.sample(d, u)
    assert x.mean() == pytest.approx(dist.mean(d), abs=4e-3 * max(dist.std(d), 1))
    assert x.std() == pytest.approx(dist.std(d), rel=5e-3)
    if d.distribution == "truncated_normal":
        assert np.abs(x - d.mean).max() <= d.limit
        # closed form against numerical integration of the truncated density
        t = np.linspace(-1.5, 1.5, 200001)
        w = np.exp(-0.5 * t * t)
        var = np.trapezoid(t * t * w, t) / np.trapezoid(w, t)
        assert dist.std(d) == pytest.approx(np.sqrt(var), rel=1e-8)


def test_latin_hypercube_fills_every_stratum():
    u = dist.latin_hypercube(50, 3, np.random.default_rng(0))
    for k in range(3):
        assert sorted(np.floor(u[:, k] * 50).astype(int)) == list(range(50))


def test_standardized_regression_and_wilson():
    rng = np.random.default_rng(1)
    X = rng.normal(size=(20000, 3)) * [1.0, 2.0, 0.5]
    y = 3.0 * X[:, 0] - 1.0 * X[:, 1]  # exact: SRC_i = b_i std(x_i) / std(y)
    src, r2 = standardized_regression(X, y)
    sx, sy = X.std(axis=0), y.std()
    assert src == pytest.approx([3 * sx[0] / sy, -sx[1] / sy, 0.0], abs=1e-9)
    assert src[:2] == pytest.approx([3 / np.sqrt(13), -2 / np.sqrt(13)], abs=0.01)
    assert r2 == pytest.approx(1.0)
    lo, hi = wilson(50, 100)
    assert lo == pytest.approx(0.4038, abs=1e-4) and hi == pytest.approx(0.5962, abs=1e-4)


# --- Dask: a real two-worker local cluster, resume -----------------------------------------


def _spec(**kw):
    raw = {"kind": "tolerance", "samples": 120, "chunk": 30, "seed": 5, "cycle_samples": 180,
           "dense": 512, "parameters": {
               "L2_mm": {"distribution": "normal", "sigma": 0.1},
               "gear2_phase_deg": {"distribution": "normal", "sigma": 0.05},
               "backlash_deg": {"distribution": "uniform", "low": 0.0, "high": 0.2}}}
    raw.update(kw)
    return ToleranceSpec.model_validate(raw)


def test_two_worker_local_cluster_runs_the_chunks(seeder, tmp_path):
    spec = _spec()
    out = run_study(seeder, spec, tmp_path, "fp", workers=2, progress=False)
    assert outcome_ok(out) and out.stats.workers == 2
    assert out.stats.computed_chunks == 4 and out.stats.evaluations == 120
    data = read_results(tmp_path)
    assert list(data["sample"]) == list(range(120))
    # what the workers wrote is what the same chunk gives in this process
    model = make_model(seeder, list(spec.parameters), 180, 512)
    cols, _ = tolerance_chunk(model, (2, 60, 30, 5, list(spec.parameters.values())))
    for k in ("picking_swing", "sowing_angle", "path_deviation_mm", "d_L2_mm"):
        assert np.array_equal(data[k][60:90], cols[k])
    s = out.summary
    assert 0.0 <= s["probability_nominal_met_kept"] <= 1.0
    assert s["samples"] == 120 and len(s["objectives"]) == 10  # 6 objectives, 2 x 2 gear rows


def outcome_ok(out) -> bool:
    return out.stats.complete and not out.stats.failed


def test_stopped_study_resumes_without_recomputing(seeder, tmp_path):
    from distributed import LocalCluster

    spec = _spec()
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=":0") as cluster:
        first = run_study(seeder, spec, tmp_path / "a", "fp", scheduler=cluster.scheduler_address,
                          progress=False, max_chunks=1)
        assert first.stats.stopped_early and first.stats.evaluations == 30
        assert first.summary["complete"] is False and first.summary["samples"] == 30
        assert len(done_chunks(tmp_path / "a")) == 1
        again = run_study(seeder, spec, tmp_path / "a", "fp",
                          scheduler=cluster.scheduler_address, progress=False)
        assert again.stats.skipped_chunks == 1 and again.stats.computed_chunks == 3
        assert again.stats.evaluations == 90  # only the unfinished chunks were evaluated
        whole = run_study(seeder, spec, tmp_path / "b", "fp",
                          scheduler=cluster.scheduler_address, progress=False)
        assert whole.stats.evaluations == 120
        third = run_study(seeder, spec, tmp_path / "a", "fp",
                          scheduler=cluster.scheduler_address, progress=False)
        assert third.stats.evaluations == 0 and third.stats.skipped_chunks == 4
    a, b = read_results(tmp_path / "a"), read_results(tmp_path / "b")
    for k in b:
        assert np.array_equal(a[k], b[k], equal_nan=True), k
    assert again.summary["probability_all_ok"] == whole.summary["probability_all_ok"]
    assert again.summary["complete"] is True


def test_chunk_outputs_of_the_nominal_are_zero(seeder):
    model = make_model(seeder, ["L2_mm"], 180, 512)
    cols, band = chunk_outputs(model, np.zeros((2, 1)))
    assert np.all(cols["tip_deviation_mm"] == 0) and np.all(band["max"] == 0)
    assert np.all(cols["attitude_error_deg"] == 0)
