"""Benchmarks (``make bench``): wall times on this machine, printed with units."""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

import numpy as np

from plantmech.design import load_design
from plantmech.workflows import run_seeder_inverse

sys.path.insert(0, str(Path(__file__).resolve().parent))
from figures import figure, write_json  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def _flag(name: str, default: int) -> int:
    """Integer value of a ``--name N`` command-line flag."""
    if name in sys.argv:
        return int(sys.argv[sys.argv.index(name) + 1])
    return default


def timeit(fn, repeat=5):
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def bench_verify() -> None:
    """plantmech verify: the full analysis of a two-pair seeder set (Table 4 gears, written
    by plantmech gears first, not timed) at 0.5 deg steps: tooth contact of both pairs
    through the train (4 free-play runs), the record, and the exudyn loads."""
    import statistics
    import tempfile

    from plantmech.contact.loads import LoadSpec, seeder_loads
    from plantmech.contact.outlines import read_gear_dxf
    from plantmech.contact.seeder import analyse_seeder, seeder_record, seeder_train
    from plantmech.mechanisms.seeder_forward import simulate
    from plantmech.workflows import run_gears

    d = load_design(ROOT / "examples" / "sugarcane_table4.toml")
    with tempfile.TemporaryDirectory() as tmp:
        run_gears(d, Path(tmp))
        gears = {n: read_gear_dxf(Path(tmp) / f"{n}.dxf", n)
                 for n in ("gear2", "sun", "gear3", "planet")}
    limits = {"transmission_error_deg": 0.5, "attitude_error_deg": 1.0, "tip_band_mm": 5.0}
    times = {"contact": [], "loads": [], "cpu": []}
    for _ in range(3):
        c0 = time.process_time()
        t0 = time.perf_counter()
        train = seeder_train(d)
        c = analyse_seeder(train, gears, steps=720)
        seeder_record(c, train, limits)
        t1 = time.perf_counter()
        seeder_loads(train, simulate(train, samples=3600), gears, LoadSpec())
        t2 = time.perf_counter()
        times["contact"].append(t1 - t0)
        times["loads"].append(t2 - t1)
        times["cpu"].append(time.process_time() - c0)
    tc, tl = statistics.median(times["contact"]), statistics.median(times["loads"])
    cpu = statistics.median(times["cpu"])
    print(f"verify: two-pair seeder (Table 4 gear files), 720 steps (0.5 deg): tooth contact "
          f"through the train {tc:.1f} s + exudyn loads {tl:.1f} s = {tc + tl:.1f} s wall, "
          f"{cpu:.1f} s CPU (median of 3; load average {os.getloadavg()[0]:.1f} on "
          f"{os.cpu_count()} cores; target < 30 s)")
    figure("verify_two_pair_seeder_720_steps_s", tc + tl, "s", 30.0, cpu_s=cpu)


def cli_startup(runs: int = 9) -> None:
    """``plantmech --help`` in fresh processes (median of ``runs``), as an installed user
    runs it: bytecode compiled once (here into a temporary PYTHONPYCACHEPREFIX, the source
    tree is left alone; this machine sets PYTHONDONTWRITEBYTECODE, which makes every start
    compile ~60 ms of source), and a bare interpreter start side by side."""
    import statistics
    import subprocess
    import tempfile

    exe = Path(sys.executable).with_name("plantmech")
    with tempfile.TemporaryDirectory() as cache:
        env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
        env["PYTHONPYCACHEPREFIX"] = cache

        def median(cmd):
            subprocess.run(cmd, env=env, capture_output=True, check=True)  # warm the cache
            times = []
            for _ in range(runs):
                t0 = time.perf_counter()
                subprocess.run(cmd, env=env, capture_output=True, check=True)
                times.append(time.perf_counter() - t0)
            return statistics.median(times)

        bare = median([sys.executable, "-c", "pass"])
        helped = median([str(exe), "--help"])
    print(f"plantmech --help: {helped * 1e3:.0f} ms median of {runs} fresh processes "
          f"(bare interpreter start {bare * 1e3:.0f} ms; load average "
          f"{os.getloadavg()[0]:.1f})")
    figure("cli_help_ms", helped * 1e3, "ms", 150.0, bare_interpreter_ms=bare * 1e3)


def wall_cpu_median(fn, repeat: int) -> tuple[float, float]:
    """(median wall s, median CPU s) of ``repeat`` calls of ``fn``."""
    import statistics

    wall, cpu = [], []
    for _ in range(repeat):
        c0, t0 = time.process_time(), time.perf_counter()
        fn()
        wall.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    return statistics.median(wall), statistics.median(cpu)


def bench_transplanter(rng, P: int = 1000) -> None:
    """The transplanter: the single-design job and the population evaluation (the
    published design's internal-gear radii + uniform(-1.5, 1.5) mm noise), medians of
    repeated runs with their CPU time and the machine's load (``--transplanter-only``)."""

    from plantmech.workflows import evaluate_transplanter_population, run_transplanter

    def load():
        return f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores"

    rice = load_design(ROOT / "examples" / "rice_transplanter.toml")
    run_transplanter(rice)  # compiled kernels loaded once (numba's cache), as in a session
    t, c = wall_cpu_median(lambda: run_transplanter(rice), 5)
    print(f"transplanter job (3 arms, 3600 samples, all 12 objectives incl. interference): "
          f"{t * 1e3:.1f} ms ({c * 1e3:.1f} ms CPU; median of 5; {load()})")
    figure("transplanter_job_3600_ms", t * 1e3, "ms", cpu_ms=c * 1e3)
    R = np.asarray(rice.internal_gear.radii_mm) + rng.uniform(-1.5, 1.5, (P, 12))
    for samples in (360, 720):
        t, c = wall_cpu_median(
            lambda s=samples: evaluate_transplanter_population(rice, R, samples=s), 3)
        print(f"transplanter population evaluation (no interference), {P} designs x 3 arms x "
              f"{samples} samples: {t:.2f} s ({P / t:.0f} designs/s; {P / c:.0f} per CPU "
              f"second; median of 3; {load()})")
        figure(f"transplanter_population_{samples}_designs_per_s", P / t, "designs/s",
               better="higher", designs=P)
    for n in (100, P):
        t, c = wall_cpu_median(lambda n=n: evaluate_transplanter_population(
            rice, R[:n], samples=360, interference=True), 5 if n == 100 else 3)
        print(f"transplanter population evaluation with interference, {n} designs x 360 "
              f"samples: {t:.2f} s ({n / t:.0f} designs/s; {n / c:.0f} per CPU second; "
              f"median of {5 if n == 100 else 3}; {load()}; target >= 1000 designs/s)")
        figure(f"transplanter_population_interference_{n}_designs_per_s", n / t, "designs/s",
               1000.0, "higher", designs=n, samples=360)


def bench_seeder_population(rng, P: int = 1000) -> None:
    """The seeder's population figures: forward simulation alone (1000 x 360 and 3600) and
    the population evaluation of issue 16's acceptance (1000 x 360, 720 and 3600, target
    >= 20,000 designs/s at 720): wall time (median of 5) beside CPU time, as the machine is
    shared; with one kernel thread and with one per core (the target figure)."""
    from plantmech.mechanisms.seeder_batch import simulate_population

    nodes = np.radians(np.arange(8) * 45.0)
    R2 = 60 + rng.uniform(-5, 5, (P, 8))
    R3 = 60 + rng.uniform(-5, 5, (P, 8))
    for samples, dense in ((360, 1024), (3600, 4096)):
        t = timeit(lambda s=samples, d=dense: simulate_population(
            nodes, R2, R3, 240.0, 450.0, 120.0, 120.0, 0.3, 0.3, samples=s, dense=d),
            repeat=2)
        print(f"population forward simulation, {P} designs x {samples} samples: "
              f"{t:.2f} s ({P / t:.0f} designs/s)")
        figure(f"seeder_population_simulation_{samples}_designs_per_s", P / t, "designs/s",
               better="higher", designs=P)

    from plantmech.workflows import run_seeder_forward

    t4 = load_design(ROOT / "examples" / "sugarcane_table4.toml")
    t = timeit(lambda: run_seeder_forward(t4))
    print(f"forward job on the Table 4 train (closure, simulation, every objective and gear "
          f"check), 3600 samples: {t * 1e3:.1f} ms")
    figure("forward_job_table4_3600_ms", t * 1e3, "ms")
    R2 = np.asarray(t4.train.gear2.radii_mm) + rng.uniform(-2, 2, (P, 8))
    R3 = np.asarray(t4.train.gear3.radii_mm) + rng.uniform(-2, 2, (P, 8))
    # one kernel thread (the library's default) and one per core (PLANTMECH_KERNEL_THREADS,
    # as a user running a large population alone on the machine sets it); the target
    # figure is the machine's: every core
    cores = os.cpu_count() or 1
    saved = os.environ.get("PLANTMECH_KERNEL_THREADS")
    try:
        for threads in sorted({1, cores}):
            os.environ["PLANTMECH_KERNEL_THREADS"] = str(threads)
            for samples, dense in ((360, 1024), (720, 2048), (3600, 4096)):
                _population_figure(t4, R2, R3, samples, dense, P, threads == cores)
    finally:
        if saved is None:
            os.environ.pop("PLANTMECH_KERNEL_THREADS", None)
        else:
            os.environ["PLANTMECH_KERNEL_THREADS"] = saved


def _population_figure(t4, R2, R3, samples: int, dense: int, P: int, named: bool) -> None:
    """One population evaluation figure (median of 5, wall and CPU) at the kernel threads
    PLANTMECH_KERNEL_THREADS sets; ``named``: the figure the issue's target reads, else
    the one-thread figure beside it."""
    from plantmech.mechanisms.seeder_kernel import kernel_threads
    from plantmech.workflows import evaluate_seeder_population

    evaluate_seeder_population(t4, R2, R3, samples=samples, dense=dense)  # compiled
    wall, cpu = [], []
    for _ in range(5):
        c0, t0 = time.process_time(), time.perf_counter()
        evaluate_seeder_population(t4, R2, R3, samples=samples, dense=dense)
        wall.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    t, c = float(np.median(wall)), float(np.median(cpu))
    print(f"population evaluation (Hermite, dwell, solved centre distances, located "
          f"sections, every objective), {P} designs x {samples} samples: {t:.3f} s "
          f"({P / t:.0f} designs/s, median of 5; CPU {c:.3f} s, {P / c:.0f} designs per "
          f"CPU second; {kernel_threads()} kernel thread(s); load average "
          f"{os.getloadavg()[0]:.1f})")
    name = f"seeder_population_{samples}_designs_per_s"
    figure(name if named else name.replace("_designs", "_one_thread_designs"), P / t,
           "designs/s", 20000.0 if samples == 720 and named else None, "higher", designs=P,
           designs_per_cpu_s=P / c, kernel_threads=kernel_threads())


def general_population_variants(which: str, P: int, rng) -> list:
    """P design files of the general train model (``mechanism = "planetary"``) around a
    bundled one: ``table4`` (examples/planetary/sugarcane_table4.toml, with its toothless
    dwell, grid 16384): gear 2's and gear 3's eight radii + uniform(-2, 2) mm, both centre
    distances solved; ``elliptic`` (examples/rotary_transplanter_elliptic.toml, no dwell,
    grid 8192, two arms): A uniform(22, 28) mm, e uniform(0.1, 0.3), arm uniform(140, 180)
    mm; ``table4_grid2048``: Table 4's at a 2048-point grid (the dense grid of the seeder's
    own population kernel at 720 samples: the same work per design as that figure's);
    ``differential`` (examples/planetary/rice_transplanter.toml, the differential
    transplanter as a general train: a driven 4-lobed ring, three arms, grid 16384): the
    ring's twelve radii + uniform(-1.5, 1.5) mm, its centre distance solved."""
    if which.startswith("table4"):
        base = load_design(ROOT / "examples" / "planetary" / "sugarcane_table4.toml")
    elif which == "differential":
        base = load_design(ROOT / "examples" / "planetary" / "rice_transplanter.toml")
    else:
        base = load_design(ROOT / "examples" / "rotary_transplanter_elliptic.toml")
    out = []
    for _ in range(P):
        d = base.model_copy(deep=True)
        if which.startswith("table4"):
            p0, p1 = d.train.pairs
            p0.follower.radii_mm = [float(v) for v in np.asarray(p0.follower.radii_mm)
                                    + rng.uniform(-2, 2, 8)]
            p1.driver.radii_mm = [float(v) for v in np.asarray(p1.driver.radii_mm)
                                  + rng.uniform(-2, 2, 8)]
            p0.centre_distance_mm = p1.centre_distance_mm = None
            if which == "table4_grid2048":
                d.train.grid = 2048
        elif which == "differential":
            ring = d.train.pairs[0]
            ring.driver.radii_mm = [float(v) for v in np.asarray(ring.driver.radii_mm)
                                    + rng.uniform(-1.5, 1.5, len(ring.driver.radii_mm))]
            ring.centre_distance_mm = None
        else:
            drv = d.train.pairs[0].driver
            drv.semi_major_mm = float(rng.uniform(22, 28))
            drv.eccentricity = float(rng.uniform(0.1, 0.3))
            d.arm.length_mm = float(rng.uniform(140, 180))
        out.append(d)
    return out


def _threads(n: int):
    """A context setting PLANTMECH_KERNEL_THREADS to ``n`` (restored after)."""
    import contextlib

    @contextlib.contextmanager
    def ctx():
        saved = os.environ.get("PLANTMECH_KERNEL_THREADS")
        os.environ["PLANTMECH_KERNEL_THREADS"] = str(n)
        try:
            yield
        finally:
            if saved is None:
                os.environ.pop("PLANTMECH_KERNEL_THREADS", None)
            else:
                os.environ["PLANTMECH_KERNEL_THREADS"] = saved
    return ctx()


def uptime_load() -> str:
    """The machine's load as ``uptime`` prints it (1, 5 and 15 minute averages) and its
    cores: other engineers share them, so every speed figure is read beside it."""
    one, five, fifteen = os.getloadavg()
    return (f"load average {one:.2f}, {five:.2f}, {fifteen:.2f} (uptime) on "
            f"{os.cpu_count()} cores")


def train_pass(designs: list, samples: int) -> None:
    """The general population's compiled work without its rows: per sub-population, the
    build (tabulation, laws), the fused tip pass and the fused gear-rule extremes
    (``objectives.planetary``'s groups, as ``population_evaluation`` runs them); the rows
    (the [limits] checks' and rules' dicts per design) are what it leaves out."""
    from plantmech.objectives.planetary import chunk_designs
    from plantmech.trains.gearing import assess
    from plantmech.trains.model import simulate, simulate_tips
    from plantmech.trains.spec import build_from_designs

    size = chunk_designs(designs[0].train.grid)
    for start in range(0, len(designs), size):
        part = designs[start:start + size]
        built = build_from_designs(part, grouped=True)
        simulate_tips(built, samples) or simulate(built, samples)
        assess(part[0], built)


def bench_general_population(rng, P: int = 1000, repeat: int = 5) -> None:
    """The general train model (trains/, ``objectives.planetary.population_evaluation``):
    P designs x 720 samples, every objective (build: tabulation, closure, centre distances;
    simulation; the [limits] checks and each pair's pitch-curve rules; the fused passes of
    ``trains.fused`` for populations), for Table 4 (with its dwell, its file's 16384-point
    grid; and at a 2048-point grid, the seeder kernel's own dense grid at 720 samples),
    the elliptic rotary transplanter (no dwell, two arms, grid 8192) and the differential
    transplanter as a general train (a driven ring, three arms, grid 16384; the general
    objective set: no interference, which the general path does not compute); with one
    kernel thread and two (PLANTMECH_KERNEL_THREADS: the sub-populations on threads);
    issue 28's targets >= 20,000 designs/s for Table 4 with two threads (>= 10,000 with
    one) and for the elliptic example. Beside them, in the same run: the train pass alone
    (``train_pass``: the compiled work without the rows) and the dedicated seeder kernel
    (``workflows.evaluate_seeder_population``, dense 2048) on the very designs of Table
    4's 2048-point population, one and two threads, with the ratio of the two (wall and
    CPU). Then the single design (P = 1: the file as bundled, at 720 samples and at its own
    3600, what the CLI and the app pay) and one design forward. Wall medians of
    ``repeat`` runs with the CPU time's median and the machine's load as ``uptime`` gives
    it (``--general-population-only``)."""

    from plantmech.objectives.planetary import population_evaluation
    from plantmech.workflows import evaluate_seeder_population

    print(f"general train populations: {P} designs, medians of {repeat}; {uptime_load()}")
    general: dict = {}
    for which in ("table4", "table4_grid2048", "elliptic", "differential"):
        designs = general_population_variants(which, P, rng)
        population_evaluation(designs[:64], 720)  # imports, compiled kernels loaded
        for threads in (1, 2):
            with _threads(threads):
                t, c = wall_cpu_median(lambda d=designs: population_evaluation(d, 720), repeat)
            target = (None if which in ("table4_grid2048", "differential") else
                      20000.0 if threads == 2 or which == "elliptic" else 10000.0)
            print(f"general train population ({which}, grid {designs[0].train.grid}), {P} "
                  f"designs x 720 samples, every objective, {threads} kernel thread(s): "
                  f"{t:.2f} s ({P / t:.0f} designs/s; {P / c:.0f} per CPU second; "
                  f"{uptime_load()}" + (f"; target >= {target:.0f} designs/s)" if target
                                        else ")"))
            name = f"general_population_{which}_720_designs_per_s"
            figure(name if threads == 1 else name.replace("_720_", "_720_threads2_"), P / t,
                   "designs/s", target, "higher", designs=P, designs_per_cpu_s=P / c,
                   grid=designs[0].train.grid, kernel_threads=threads, repeats=repeat)
            general[which, threads] = (t, c)
        t, c = wall_cpu_median(lambda d=designs: train_pass(d, 720), repeat)
        print(f"  its train pass alone (build, fused tips, fused gear-rule extremes; no rows), "
              f"one thread: {t:.2f} s ({P / t:.0f} designs/s; {P / c:.0f} per CPU second): "
              f"the rows and objectives around it take {general[which, 1][1] - c:.2f} s CPU "
              f"of {general[which, 1][1]:.2f}")
        figure(f"general_train_pass_{which}_720_designs_per_s", P / t, "designs/s",
               better="higher", designs=P, designs_per_cpu_s=P / c, repeats=repeat)
        if which == "table4_grid2048":  # the dedicated kernel on the same designs
            R2 = np.array([d.train.pairs[0].follower.radii_mm for d in designs])
            R3 = np.array([d.train.pairs[1].driver.radii_mm for d in designs])
            t4 = load_design(ROOT / "examples" / "sugarcane_table4.toml")
            evaluate_seeder_population(t4, R2, R3, samples=720, dense=2048)
            for threads in (1, 2):
                with _threads(threads):
                    t, c = wall_cpu_median(
                        lambda t4=t4, R2=R2, R3=R3: evaluate_seeder_population(
                            t4, R2, R3, samples=720, dense=2048), repeat)
                gt, gc = general[which, threads]
                print(f"  beside it, the dedicated seeder kernel on the same {P} designs "
                      f"(dense 2048, 720 samples, {threads} kernel thread(s)): {t:.3f} s "
                      f"({P / t:.0f} designs/s; {P / c:.0f} per CPU second); the general "
                      f"train takes {gt / t:.1f}x its wall time, {gc / c:.1f}x its CPU time "
                      f"({uptime_load()})")
                name = "seeder_kernel_table4_grid2048_720_designs_per_s"
                figure(name if threads == 1 else name.replace("_720_", "_720_threads2_"),
                       P / t, "designs/s", better="higher", designs=P,
                       designs_per_cpu_s=P / c, kernel_threads=threads, repeats=repeat)
                if threads == 1:
                    figure("general_over_seeder_kernel_table4_720_cpu_ratio", gc / c, "x",
                           1.0, "lower", wall_ratio=gt / t)
            continue
        if which == "differential":
            continue
        one = load_design(ROOT / "examples" / ("planetary/sugarcane_table4.toml"
                                               if which == "table4"
                                               else "rotary_transplanter_elliptic.toml"))
        for samples in (720, one.samples):
            t, c = wall_cpu_median(lambda s=samples, o=one: population_evaluation([o], s), 7)
            print(f"general train single design ({which} as bundled), {samples} samples, "
                  f"every objective: {t * 1e3:.1f} ms ({c * 1e3:.1f} ms CPU; median of 7; "
                  f"{uptime_load()})")
            figure(f"general_single_{which}_{samples}_ms", t * 1e3, "ms", cpu_ms=c * 1e3)
        if which == "table4":  # one design forward (build + simulate), as `forward` runs it
            from plantmech.trains.model import simulate
            from plantmech.trains.spec import build_from_design

            t, c = wall_cpu_median(lambda o=one: simulate(build_from_design(o), o.samples), 7)
            print(f"general train one design forward (Table 4 as bundled, grid "
                  f"{one.train.grid}), {one.samples} samples: {t * 1e3:.1f} ms "
                  f"({c * 1e3:.1f} ms CPU; median of 7; target <= 5 ms; {uptime_load()})")
            figure("general_forward_table4_3600_ms", t * 1e3, "ms", 5.0, cpu_ms=c * 1e3)


#: the peer of ``--pair`` (issue 35), in the benchmark's own environment
NCGEARS = "ncgears==0.3.1"
NCGEARS_VENV = ROOT / "benchmarks" / ".venv-ncgears"


def _ncgears_python() -> Path:
    """The benchmark environment's Python with ncgears (created on first use: a venv
    beside this file and ``pip install ncgears``; never plantmech's own environment)."""
    import subprocess

    py = NCGEARS_VENV / "bin" / "python"
    if not py.exists():
        print(f"creating {NCGEARS_VENV} with {NCGEARS} (once)")
        subprocess.run([sys.executable, "-m", "venv", str(NCGEARS_VENV)], check=True)
        subprocess.run([str(py), "-m", "pip", "install", "-q", NCGEARS], check=True)
    return py


def bench_pair(runs: int = 3) -> None:
    """Issue 35: one 32-tooth elliptic pair (two identical ellipses about their foci,
    e = 0.35, module 1, 20 deg, backlash 0.1 mm) generated, cut and mesh-checked by
    plantmech (the pair file's law through the one engine, ``trains.gearing.gear_pairs``,
    ``gears.teeth.mesh_check``) and generated by ncgears (which checks its own pair as it
    generates: interference, transmission error), each timed in its own process over
    ``runs`` runs (median; the first run, cold, reported too). Both meshes are then judged
    by plantmech's mesh check (interference, circumferential backlash range). ncgears's
    clearance (per-face inward offset / module) is set to the normal gap plantmech's
    0.1 mm backlash leaves (0.1 cos 20 deg / 2 per face: 0.047 mm between the faces)."""
    import json
    import statistics
    import subprocess
    import tempfile
    from dataclasses import replace

    import shapely
    import shapely.affinity

    from plantmech.gears.teeth import mesh_check
    from plantmech.trains.gearing import gear_pairs

    e, teeth, module, alpha, backlash = 0.35, 32, 1.0, 20.0, 0.1
    clearance = float(backlash * np.cos(np.radians(alpha)) / 2 / 2 / module)
    d = load_design(ROOT / "examples" / "planetary" / "elliptic_pair.toml")
    data = d.model_dump()
    data["train"]["pairs"][0]["teeth"] = teeth
    d = d.model_validate(data)
    load0 = os.getloadavg()[0]
    times, cut_times, cpu = [], [], []
    for _ in range(runs):
        t0, c0 = time.perf_counter(), time.process_time()
        ((pair, spec),) = gear_pairs(d, backlash=backlash, tooth={"pressure_angle_deg": alpha})
        t1 = time.perf_counter()
        ours = mesh_check(pair)
        times.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
        cut_times.append(t1 - t0)
    py = _ncgears_python()
    with tempfile.TemporaryDirectory() as tmp:
        npz = Path(tmp) / "pair.npz"
        r = subprocess.run([str(py), str(ROOT / "benchmarks" / "ncgears_pair.py"), str(npz),
                            str(runs), str(e), str(teeth), str(module), str(alpha),
                            repr(clearance)], capture_output=True, text=True, check=True)
        peer = json.loads(r.stdout.strip().splitlines()[-1])
        z = np.load(npz)
        # ncgears: the drive about the origin, the driven placed at (a, 0) unturned (its
        # placed outline = its outline + (a, 0)), both with their largest radius on the
        # line of centres at the start, as plantmech's gear A at phi_a = 0; plantmech's B
        # at phi_b = 0 is its body frame turned by pi: so B = the driven turned by pi
        shift = z["placed"] - z["driven"]
        assert np.allclose(shift, [float(z["a"]), 0.0]), "ncgears placed its driven gear " \
            "otherwise than this benchmark reads it"
        theirs_pair = replace(pair, gear_a=shapely.Polygon(z["drive"]),
                              gear_b=shapely.affinity.rotate(shapely.Polygon(z["driven"]),
                                                             180.0, origin=(0, 0)))
        theirs_pair.spec = pair.spec
        theirs = mesh_check(theirs_pair)
    load1 = os.getloadavg()[0]
    ours_t, theirs_t = statistics.median(times), statistics.median(peer["times_s"])
    ratio = theirs_t / ours_t
    print(f"elliptic pair, {teeth} teeth, e = {e}, module {module} mm, {alpha:g} deg, "
          f"backlash {backlash} mm ({runs} runs each, load {load0:.2f} -> {load1:.2f}):")
    print(f"  {'':34} {'plantmech':>14} {'ncgears ' + peer['version']:>14}")
    print(f"  {'wall time, median (s)':34} {ours_t:14.2f} {theirs_t:14.2f}")
    print(f"  {'wall time, first run (s)':34} {times[0]:14.2f} {peer['times_s'][0]:14.2f}")
    # (CPU time: what each process itself spent, the fairer figure on a shared machine
    # whose load changes between the two runs)
    ours_c, theirs_c = statistics.median(cpu), statistics.median(peer["cpu_s"])
    print(f"  {'CPU time, median (s)':34} {ours_c:14.2f} {theirs_c:14.2f}")
    print(f"  {'  of which cutting, median (s)':34} {statistics.median(cut_times):14.2f} "
          f"{'-':>14}")
    print(f"  {'centre distance (mm)':34} {pair.a:14.4f} {peer['centre_distance_mm']:14.4f}")
    for key, label in (("max_interference_mm", "interference, plantmech check (mm)"),
                       ("min_circumferential_backlash_mm", "backlash min, plantmech (mm)"),
                       ("max_circumferential_backlash_mm", "backlash max, plantmech (mm)")):
        a, b = ours[key], theirs[key]
        print(f"  {label:34} {a if a is not None else float('nan'):14.4f} "
              f"{b if b is not None else float('nan'):14.4f}")
    print(f"  ncgears is {ratio:.1f}x slower in wall time, {theirs_c / ours_c:.1f}x in CPU time "
          f"(target: plantmech >= 10x faster)")
    figure("pair_plantmech_generate_cut_check_s", ours_t, "s", load_start=round(load0, 2))
    figure("pair_ncgears_generate_s", theirs_t, "s", load_start=round(load0, 2))
    figure("pair_speedup_over_ncgears", ratio, "x", target=10.0, better="higher",
           cpu_ratio=theirs_c / ours_c, plantmech_cpu_s=ours_c, ncgears_cpu_s=theirs_c,
           plantmech_interference_mm=ours["max_interference_mm"],
           ncgears_interference_mm=theirs["max_interference_mm"],
           plantmech_backlash_mm=[ours["min_circumferential_backlash_mm"],
                                  ours["max_circumferential_backlash_mm"]],
           ncgears_backlash_mm=[theirs["min_circumferential_backlash_mm"],
                                theirs["max_circumferential_backlash_mm"]])


def main() -> None:
    if "--pair" in sys.argv:  # make bench-pair: the gear pair against ncgears alone
        bench_pair(_flag("--pair-runs", 3))
        return
    if "--verify-only" in sys.argv:
        bench_verify()
        return
    if "--transplanter-only" in sys.argv:  # the transplanter's job and populations alone
        bench_transplanter(np.random.default_rng(0))
        return
    if "--seeder-population-only" in sys.argv:  # the seeder population figures alone
        bench_seeder_population(np.random.default_rng(0))
        return
    if "--general-population-only" in sys.argv:  # the general train's population figures
        bench_general_population(np.random.default_rng(0), _flag("--designs", 1000),
                                 _flag("--repeat", 5))
        return
    if "--study-only" in sys.argv:  # make bench-study: the Dask scaling alone
        study_scaling(_flag("--study-samples", 0), repeat=_flag("--study-repeat", 1))
        return
    cli_startup()
    design = load_design(ROOT / "examples" / "sugarcane_seeder.toml")
    for samples in (3600, 36000):
        d = design.model_copy(deep=True)
        d.trajectory.samples = samples
        run_seeder_inverse(d)  # first call: imports, numba kernels loaded from their cache
        wall, cpu = [], []
        for _ in range(25 if samples <= 3600 else 5):
            c0, t0 = time.process_time(), time.perf_counter()
            run_seeder_inverse(d)
            wall.append(time.perf_counter() - t0)
            cpu.append(time.process_time() - c0)
        # judged by the median (a best-of-N says what the machine can do, not what it does)
        med = float(np.median(wall))
        ok = "met" if med < 0.010 else "NOT met"
        print(f"inverse design (checks included), {samples} samples: median {med * 1e3:.1f} "
              f"ms wall, {np.median(cpu) * 1e3:.1f} ms CPU (best {min(wall) * 1e3:.1f} ms of "
              f"{len(wall)}"
              + (f"; target < 10 ms: {ok}" if samples == 3600 else "")
              + f"; load average {os.getloadavg()[0]:.1f})")
        figure(f"inverse_design_{samples}_ms", med * 1e3, "ms",
               10.0 if samples == 3600 else None, best_wall_ms=min(wall) * 1e3,
               median_cpu_ms=float(np.median(cpu)) * 1e3, runs=len(wall))
    from plantmech.mechanisms.seeder_forward import simulate
    from plantmech.verification import train_from_inverse

    job = run_seeder_inverse(design)
    train = train_from_inverse(job.result)
    t = timeit(lambda: simulate(train, samples=3600))
    print(f"forward simulation from pitch curves, 3600 samples: {t * 1e3:.1f} ms")
    figure("forward_simulation_3600_ms", t * 1e3, "ms")

    rng = np.random.default_rng(0)
    P = 1000
    bench_seeder_population(rng, P)
    bench_transplanter(rng, P)
    bench_general_population(rng, P)
    # teeth: generate and mesh-check one 60-tooth non-circular pair (ellipse about a focus)
    from scipy.special import ellipe

    from plantmech.gears.teeth import ToothSpec, make_pair, mesh_check

    th = np.linspace(0, 2 * np.pi, 3001)
    e = 0.35
    A = np.pi * 2 * 60 / (4 * ellipe(e**2))
    r = A * (1 - e**2) / (1 - e * np.cos(th))

    def teeth_pair(method):
        t0 = time.perf_counter()
        pair = make_pair("ellipse60", th, r, 2 * A,
                         ToothSpec(module=2.0, backlash_mm=0.1, method=method))
        t1 = time.perf_counter()
        m = mesh_check(pair, 360)
        return t1 - t0, time.perf_counter() - t1, m, pair

    runs = [teeth_pair("envelope") for _ in range(3)]  # medians of three
    gen, chk = np.median([x[0] for x in runs]), np.median([x[1] for x in runs])
    m, pair = runs[-1][2], runs[-1][3]
    print(f"teeth: 60-tooth elliptic pair generated in {gen:.2f} s, mesh-checked over a "
          f"turn (360 steps) in {chk:.2f} s (interference {m['max_interference_mm']:.4f} mm, "
          f"free play {m['min_circumferential_backlash_mm']:.3f}..."
          f"{m['max_circumferential_backlash_mm']:.3f} mm; envelope teeth, median of 3, "
          f"{len(pair.gear_a.exterior.coords)} outline vertices)")
    figure("teeth_60_tooth_pair_generate_and_check_s", gen + chk, "s", 2.0,
           generate_s=float(gen), mesh_check_s=float(chk))
    gen, chk, m, pair = teeth_pair("simulated")
    print(f"teeth (reference): the same pair by simulated cutting generated in {gen:.2f} s, "
          f"mesh-checked in {chk:.2f} s (interference {m['max_interference_mm']:.4f} mm, "
          f"free play {m['min_circumferential_backlash_mm']:.3f}..."
          f"{m['max_circumferential_backlash_mm']:.3f} mm, "
          f"{len(pair.gear_b.exterior.coords)} outline vertices of gear B)")
    figure("teeth_60_tooth_pair_simulated_generate_s", gen, "s", mesh_check_s=chk)

    # teeth of the toothed transplanter: ring shaper-cut, planet cut by the ring (envelope)
    from plantmech.workflows import gear_pairs

    toothed = load_design(ROOT / "examples" / "rice_transplanter_toothed.toml")
    t0 = time.perf_counter()
    (pair, _), = gear_pairs(toothed)
    t1 = time.perf_counter()
    m = mesh_check(pair, 360)
    t2 = time.perf_counter()
    print(f"teeth: toothed transplanter ring (80 teeth) and planet (20, cut by the ring: "
          f"{pair.made_b['method']}) generated in {t1 - t0:.2f} s, mesh-checked over a "
          f"cycle (360 steps) in {t2 - t1:.2f} s (interference "
          f"{m['max_interference_mm']:.4f} mm)")
    figure("teeth_toothed_transplanter_generate_s", t1 - t0, "s", mesh_check_s=t2 - t1)

    # layer-1 evaluation rate (inverse design + every layer-1 check, one process)
    from plantmech.workflows import seeder_inverse_checks

    t = timeit(lambda: seeder_inverse_checks(design, 360), repeat=20)
    print(f"seeder layer-1 evaluation, one design (inverse design, Table 1, attitude, "
          f"speeds), 360 samples: {t * 1e3:.1f} ms ({1 / t:.0f} designs/s per core)")
    figure("seeder_layer1_one_design_360_ms", t * 1e3, "ms")
    from plantmech.optimize.problems import SeederLayer1
    from plantmech.workflows import seeder_inverse_checks_population

    pts = np.asarray(design.trajectory.points)
    X = pts[None] + rng.uniform(-3, 3, (40,) + pts.shape)
    t = timeit(lambda: seeder_inverse_checks_population(design, X, 360), repeat=7)
    print(f"seeder layer-1 population evaluation (the same, vectorized), 40 designs x 360 "
          f"samples: {t * 1e3:.0f} ms ({40 / t:.0f} designs/s, one process)")
    figure("seeder_layer1_population_designs_per_s", 40 / t, "designs/s", better="higher")
    p1 = SeederLayer1(design)
    Xv = rng.normal(0, 3, (40, p1.n_var))
    t = timeit(lambda: p1.evaluate_batch(Xv), repeat=7)
    print(f"seeder layer-1 problem, 40 candidates split over {p1.workers} processes: "
          f"{t * 1e3:.0f} ms ({40 / t:.0f} designs/s)")
    figure("seeder_layer1_problem_designs_per_s", 40 / t, "designs/s", better="higher")

    bench_verify()

    # optimization: wall time to the first design meeting every objective
    from plantmech.optimize.problems import Transplanter
    from plantmech.optimize.runner import run

    rice = load_design(ROOT / "examples" / "rice_transplanter.toml")
    for seed in (1, 2):
        r = run(Transplanter(rice), "de", seed, 40, 40, progress=False, stop_when_feasible=True)
        print(f"optimize transplanter (DE, seed {seed}): first design meeting every objective "
              f"after {r.first_feasible_s:.1f} s / {r.first_feasible_evaluations} evaluations"
              if r.first_feasible_s is not None else
              f"optimize transplanter (DE, seed {seed}): none in {r.wall_s:.1f} s")
        figure(f"optimize_transplanter_de_seed{seed}_first_feasible_s",
               r.first_feasible_s if r.first_feasible_s is not None else float("inf"), "s",
               evaluations=r.first_feasible_evaluations)
    r = run(SeederLayer1(design, speed_constraints=False), "cmaes", 0, 100, 40,
            progress=False, stop_when_feasible=True)
    print("optimize seeder layer 1, attitude and Table 1 (CMA-ES, seed 0): " + (
        f"first design meeting them after {r.first_feasible_s:.1f} s / "
        f"{r.first_feasible_evaluations} evaluations" if r.first_feasible_s is not None
        else f"none in {r.wall_s:.1f} s"))
    figure("optimize_seeder_layer1_cmaes_first_feasible_s",
           r.first_feasible_s if r.first_feasible_s is not None else float("inf"), "s",
           evaluations=r.first_feasible_evaluations)
    # Dask: one and two local workers (--study-samples N, --study-repeat R)
    study_scaling(_flag("--study-samples", 0), repeat=_flag("--study-repeat", 1))
    if "--layered" in sys.argv:  # minutes: the whole layered job from the bundled example
        import tempfile

        from plantmech.optimize.jobs import optimize

        with tempfile.TemporaryDirectory() as tmp:
            o = optimize(design, "seeder-layered", Path(tmp), "sugarcane_seeder.toml",
                         seed=0, progress=False, manufacturability=False)
        rec = o.record
        print("optimize seeder layered from examples/sugarcane_seeder.toml (seed 0, "
              "--no-manufacturability): " + (
            f"first design meeting every agronomic objective after {rec['first_feasible_s']:.1f} s"
            if rec["first_feasible_s"] is not None else "none")
            + f", {rec['evaluations']} evaluations in {rec['wall_s']:.1f} s")

    if "--design" in sys.argv:  # minutes: plantmech design end to end (issue 13 targets)
        design_benchmarks()


def design_benchmarks() -> None:
    """`plantmech design` end to end, as a user runs it (a fresh process, start-up and files
    included): the bundled seeder (target < 120 s), the manufacturable transplanter and the
    published transplanter, re-optimized by the staged tooth-fit search (targets < 60 s)."""
    import subprocess
    import tempfile

    exe = Path(sys.executable).with_name("plantmech")
    for example, target in (("sugarcane_seeder.toml", 120),
                            ("rice_transplanter_manufacturable.toml", 60),
                            ("rice_transplanter.toml", 60)):
        with tempfile.TemporaryDirectory() as tmp:
            t0 = time.perf_counter()
            p = subprocess.run([str(exe), "design", str(ROOT / "examples" / example), "--out",
                                str(Path(tmp) / "o"), "--quiet"], capture_output=True,
                               text=True)
            wall = time.perf_counter() - t0
        last = p.stdout.strip().splitlines()[-1] if p.stdout.strip() else p.stderr[-200:]
        print(f"plantmech design {example}: {wall:.1f} s end to end (target < {target} s), "
              f"exit {p.returncode}: {last}")
        figure(f"design_end_to_end_{Path(example).stem}_s", wall, "s", float(target),
               exit=p.returncode)


STUDIES = (  # (label, design, study file, samples): the bundled ones; the samples give
    # each run ~5-10 s on one worker of this machine (the population kernels run the seeder
    # at ~1,500 samples/s per worker, the transplanter with its interference checks at ~180/s)
    ("seeder", "sugarcane_seeder_optimized.toml", "seeder_tolerance.toml", 9000),
    ("transplanter", "rice_transplanter_manufacturable.toml", "transplanter_tolerance.toml", 1200),
)


def study_scaling(samples: int = 0, repeat: int = 1) -> None:
    """Tolerance studies of the bundled seeder and transplanter on a local Dask cluster of
    one and of two worker processes: samples/s from the first task sent to the last chunk
    written (cluster start-up excluded, printed apart), the scaling two / one, and the
    machine's 1-minute load average before and after each run (the machine is shared:
    a rate means little without it). ``samples`` 0: each study's own count (STUDIES);
    the chunks are a sixth of the samples (three per worker on two)."""
    import tempfile

    from plantmech.studies.runner import run_study
    from plantmech.studies.spec import load_spec

    for label, design_file, spec_file, own_samples in STUDIES:
        n = samples or own_samples
        chunk = max(1, n // 6)
        design = load_design(ROOT / "examples" / design_file)
        spec = load_spec(ROOT / "examples" / "studies" / spec_file)
        spec = spec.model_copy(update={"samples": n, "chunk": chunk})
        rates = {}
        for workers in (1, 2):
            runs = []
            for _ in range(repeat):
                load0 = os.getloadavg()[0]
                with tempfile.TemporaryDirectory() as tmp:
                    out = run_study(design, spec, Path(tmp), "bench", workers=workers,
                                    progress=False)
                st = out.stats
                runs.append((st.evaluations / st.wall_s, st.cluster_start_s, load0,
                             os.getloadavg()[0]))
            rate = float(np.median([r[0] for r in runs]))
            rates[workers] = rate
            print(f"tolerance study ({label}, {design_file}, {len(spec.parameters)} "
                  f"tolerances, {n} samples in chunks of {chunk}, {spec.cycle_samples} "
                  f"cycle samples), local cluster of {workers} worker(s): {rate:.1f} "
                  f"samples/s (median of {repeat}: "
                  + ", ".join(f"{r[0]:.1f}" for r in runs)
                  + f"; cluster start {np.median([r[1] for r in runs]):.1f} s; load average "
                  + ", ".join(f"{r[2]:.1f}->{r[3]:.1f}" for r in runs) + ")")
            figure(f"study_{label}_{workers}_workers_samples_per_s", rate, "samples/s",
                   better="higher", samples=n, chunk=chunk)
        print(f"study scaling ({label}), two workers / one: {rates[2] / rates[1]:.2f}x "
              f"({os.cpu_count()} cores; load average now {os.getloadavg()[0]:.1f})")
        figure(f"study_{label}_scaling_two_over_one", rates[2] / rates[1], "x", better="higher")


def app_figures() -> None:
    """The app's drag -> redraw latency in chromium and its 20-client load test
    (benchmarks/app_bench.py); skipped with a reason when a piece is missing."""
    try:
        sys.path.insert(0, str(Path(__file__).resolve().parent))
        import app_bench
    except ImportError as exc:  # fastapi / uvicorn missing
        print(f"app benchmarks skipped: {exc}")
        return
    app_bench.report()


def _json_path() -> Path | None:
    """``--json PATH`` checked before any benchmark runs (they take minutes): the path's
    folder must exist; exits 2 naming the option otherwise."""
    if "--json" not in sys.argv:
        return None
    i = sys.argv.index("--json")
    if i + 1 >= len(sys.argv) or sys.argv[i + 1].startswith("--"):
        print("error: option --json: give the path of the file to write (--json PATH)",
              file=sys.stderr)
        sys.exit(2)
    out = Path(sys.argv[i + 1])
    if not out.parent.is_dir() or out.is_dir():
        print(f"error: option --json: {out} cannot be written (its folder does not exist or "
              "it is a folder)", file=sys.stderr)
        sys.exit(2)
    return out


USAGE = """usage: bench.py [--json PATH] [--verify-only | --transplanter-only |
                            --seeder-population-only | --general-population-only |
                            --study-only | --pair [--pair-runs N]]
                [--designs N] [--repeat N] [--study-samples N] [--study-repeat N]
                [--layered] [--design]

Without an --*-only flag every benchmark runs (minutes), then the app's (app_bench.py);
--layered and --design add the long end-to-end jobs to that run. --json PATH also writes
the named figures (value, unit, target, met, load, commit). --designs N: the general
train population's size (default 1000); --repeat N: its runs per figure (median; 5).
--pair: issue 35's elliptic gear pair against ncgears (installed on first use in
benchmarks/.venv-ncgears, never a plantmech dependency), --pair-runs N runs each (default 3)."""
KNOWN = {"--json", "--verify-only", "--transplanter-only", "--seeder-population-only",
         "--study-only", "--study-samples", "--study-repeat", "--layered", "--design",
         "--general-population-only", "--designs", "--repeat", "--pair", "--pair-runs"}


def _check_arguments() -> None:
    """``--help`` prints the usage; an unknown option exits 2 naming it (each run takes
    minutes: a typo must not start them all)."""
    if {"-h", "--help"} & set(sys.argv):
        print(USAGE)
        sys.exit(0)
    for a in sys.argv[1:]:
        if a.startswith("-") and a not in KNOWN:
            print(f"error: unknown option {a}\n{USAGE}", file=sys.stderr)
            sys.exit(2)


if __name__ == "__main__":
    _check_arguments()
    json_out = _json_path()
    main()
    if not {"--study-only", "--transplanter-only", "--seeder-population-only",
            "--general-population-only", "--pair"} & set(sys.argv):
        app_figures()
    if json_out is not None:  # --json PATH: the named figures, for comparing runs by name
        write_json(json_out)
        print(f"named figures written to {json_out}")
