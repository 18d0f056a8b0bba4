"""The local study cluster (``studies.engine.dask_client``): every listener on the
loopback address (the dashboard listened on every interface), and a multi-start of the
seeder's layer 1 runs inside the daemonic Dask workers (every start failed with
"daemonic processes are not allowed to have children") with the result of the same start
run here."""

from __future__ import annotations

from pathlib import Path

import pytest

psutil = pytest.importorskip("psutil")

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"


def _listeners(procs) -> list[tuple[int, str, int]]:
    out = []
    for p in procs:
        try:
            conns = p.net_connections(kind="inet")
        except (psutil.NoSuchProcess, psutil.AccessDenied):
            continue
        out += [(p.pid, c.laddr.ip, c.laddr.port) for c in conns
                if c.status == psutil.CONN_LISTEN]
    return out


def _resource_tracker(p) -> bool:
    try:
        return "resource_tracker" in " ".join(p.cmdline())
    except psutil.Error:  # gone, or defunct (a zombie has no command line): not it
        return False


def test_a_local_study_cluster_listens_on_loopback_only():
    """As ``ss -ltnp`` during a study: the listening sockets of this process and of every
    process the cluster started (scheduler, nannies, workers, dashboard)."""
    from plantmech.studies.engine import LOOPBACK, dask_client

    me = psutil.Process()
    before = {(ip, port) for _, ip, port in _listeners([me])}
    # processes this worker had already (another test's server fixture) are not the study's
    earlier = {p.pid for p in me.children(recursive=True)}
    with dask_client(workers=2) as client:
        procs = [me, *me.children(recursive=True)]
        found = [x for x in _listeners(procs) if (x[1], x[2]) not in before]
        dashboard = client.dashboard_link
        addresses = [client.scheduler.address, *client.nthreads()]
    # the scheduler, its dashboard and each worker (and nanny) listen: the test sees them
    assert len(found) >= 4, found
    assert all(ip == LOOPBACK for _, ip, _ in found), found
    assert f"//{LOOPBACK}:" in dashboard
    assert all(a.startswith(f"tcp://{LOOPBACK}:") for a in addresses), addresses
    dash_port = int(dashboard.split(":")[2].split("/")[0])
    assert dash_port in {port for _, _, port in found}
    # and closed with the study: no process of it is left (nor a defunct one); the one
    # resource tracker of multiprocessing stays for the interpreter's life
    import time

    t0 = time.time()
    while time.time() - t0 < 10:
        left = [p for p in me.children(recursive=True)
                if p.pid not in earlier and not _resource_tracker(p)]
        if not left:
            break
        time.sleep(0.2)
    assert left == [], [(p.pid, p.status()) for p in left]


def test_multi_start_of_layer_1_runs_in_the_daemonic_workers(tmp_path):
    """A start on a Dask worker (daemonic: no process pool, so the population is
    evaluated one part after another) gives the run of the same seed in this process
    (with its pool)."""
    from plantmech.design import load_design
    from plantmech.optimize.jobs import optimize
    from plantmech.studies.engine import read_results
    from plantmech.studies.multistart import run_multistart
    from plantmech.studies.spec import MultiStartSpec

    design = load_design(EXAMPLES / "sugarcane_seeder.toml")
    spec = MultiStartSpec(kind="multi-start", problem="seeder-layer1", starts=1, seed=3,
                          generations=1, pop=4)
    out = tmp_path / "study"
    out.mkdir()
    outcome = run_multistart(design, spec, out, "fp", "sugarcane_seeder.toml", workers=1,
                             progress=False)
    assert outcome.stats.complete and not outcome.stats.failed, outcome.stats.failed
    row = read_results(out)
    (tmp_path / "here").mkdir()
    here = optimize(design, "seeder-layer1", tmp_path / "here", "sugarcane_seeder.toml",
                    seed=3, generations=1, pop=4, progress=False).record
    assert int(row["evaluations"][0]) == here["evaluations"] > 0
    assert float(row["total_violation"][0]) == pytest.approx(here["total_violation"],
                                                             rel=1e-12, abs=1e-12)
    assert (out / "starts" / "best_seed3.toml").is_file()
