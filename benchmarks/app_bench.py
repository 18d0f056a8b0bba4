"""Benchmarks of the app (``make bench`` runs them after the engine's figures).

- ``load_test``: 20 concurrent clients on loopback sending seeder edit requests (a moved
  type-value point, evaluated at the drag's working resolution) to a server in its own
  process; bounded (a fixed number of requests per client and a wall-time cap), it stops
  by itself. Two patterns: every client sending its next edit as soon as the previous
  answer arrived (closed loop, the worst case), and every client editing once every
  ``pace_s`` (designers working side by side).
- ``browser_drag``: drag -> redraw of the mechanism and the objectives in a real browser
  (Debian's chromium driven by Playwright): the page's own performance measures from the
  pointer move to the drawn answer, at the app's working resolution.
"""

from __future__ import annotations

import http.client
import json
import os
import socket
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
from figures import figure

ROOT = Path(__file__).resolve().parents[1]
CHROMIUM = "/usr/bin/chromium"


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Server:
    """``plantmech app`` in a child process on a free loopback port; ``args``: more of the
    command's options (``--workers 0``); ``src``: another checkout's ``src`` directory to
    serve from (its page and its server: the side-by-side comparison)."""

    def __init__(self, *args: str, src: str | None = None):
        self.args = list(args)
        self.src = src

    def __enter__(self):
        self.port = _free_port()
        argv = ["app", "--no-browser", "--port", str(self.port), *self.args]
        code = ("from plantmech.interfaces.cli import main; import sys; "
                f"sys.exit(main({argv!r}))")
        env = dict(os.environ)
        if self.src:
            env["PYTHONPATH"] = os.pathsep.join(filter(None, (self.src,
                                                               env.get("PYTHONPATH"))))
        self.proc = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.DEVNULL,
                                     stderr=subprocess.DEVNULL, env=env)
        t0 = time.time()
        while time.time() - t0 < 60:
            try:
                c = http.client.HTTPConnection("127.0.0.1", self.port, timeout=2)
                c.request("GET", "/api/examples")
                if c.getresponse().status == 200:
                    break
            except OSError:
                time.sleep(0.2)
        while time.time() - t0 < 120:  # measure once every compute worker is up
            try:
                c = http.client.HTTPConnection("127.0.0.1", self.port, timeout=2)
                c.request("GET", "/api/compute")
                r = c.getresponse()
                st = json.loads(r.read()) if r.status == 200 else {}
                if r.status == 404 or st.get("ready") == st.get("workers"):
                    break  # (404: a server without compute workers)
            except OSError:
                pass
            time.sleep(0.2)
        self.url = f"http://127.0.0.1:{self.port}"
        return self

    def __exit__(self, *exc):
        self.proc.terminate()
        try:
            self.proc.wait(10)
        except subprocess.TimeoutExpired:
            self.proc.kill()


def process_cpu_split_s(pid: int) -> tuple[float, float]:
    """CPU seconds (user + system) of process ``pid`` itself and of its live children (the
    app's compute workers), from /proc; (0.0, 0.0) where /proc is missing."""
    tick = os.sysconf("SC_CLK_TCK") if hasattr(os, "sysconf") else 100
    own = children = 0.0
    try:
        names = os.listdir("/proc")
    except OSError:
        return 0.0, 0.0
    for name in names:
        if not name.isdigit():
            continue
        try:
            with open(f"/proc/{name}/stat") as fh:
                fields = fh.read().rsplit(")", 1)[1].split()
        except OSError:  # ended meanwhile
            continue
        cpu = (int(fields[11]) + int(fields[12])) / tick  # utime, stime
        if int(name) == pid:
            own += cpu
        elif int(fields[1]) == pid:  # a child of the server
            children += cpu
    return own, children


def process_cpu_s(pid: int) -> float:
    """CPU seconds (user + system) of process ``pid`` and its live children (the app's
    compute workers), from /proc; 0.0 where /proc is missing."""
    return sum(process_cpu_split_s(pid))


def _example(port: int, name: str) -> dict:
    c = http.client.HTTPConnection("127.0.0.1", port, timeout=30)
    c.request("GET", f"/api/examples/{name}")
    return json.loads(c.getresponse().read())["design"]


def _edit_bodies(base: dict, rng, count: int) -> list[bytes]:
    """``count`` seeder drag-edit request bodies, each with one type-value point away from
    the seeding section moved by up to 3 mm (a fresh copy of only the points list)."""
    import orjson

    out = []
    for _ in range(count):
        points = [list(p) for p in base["trajectory"]["points"]]
        j = int(rng.integers(8, 18))  # a point away from the seeding section
        points[j][0] += float(rng.uniform(-3, 3))
        points[j][1] += float(rng.uniform(-3, 3))
        d = {**base, "trajectory": {**base["trajectory"], "points": points}}
        out.append(orjson.dumps({"design": d, "quality": "drag"}))
    return out


async def _read_response(reader) -> tuple[int, int]:
    """(status, body bytes) of one HTTP/1.1 response with a Content-Length, read whole."""
    head = await reader.readuntil(b"\r\n\r\n")
    lines = head.split(b"\r\n")
    status = int(lines[0].split(b" ", 2)[1])
    length = 0
    for line in lines[1:]:
        name, _, value = line.partition(b":")
        if name.strip().lower() == b"content-length":
            length = int(value)
    body = await reader.readexactly(length)
    return status, len(body)


def load_test(clients: int = 20, requests: int = 10, pace_s: float | None = None,
              cap_s: float = 90.0, port: int | None = None, server_pid: int | None = None
              ) -> dict:
    """Latencies (ms) of seeder drag-edit requests from ``clients`` concurrent clients,
    ``requests`` each; ``pace_s``: seconds between one client's edits (None: closed loop).

    The clients are ``clients`` keep-alive connections driven by one asyncio event loop in
    this process (plain HTTP/1.1 on a socket: the load generator takes as little of the
    shared cores as it can). Each latency runs from writing the request to the last byte
    of its answer. Bounded: ``requests`` per client and ``cap_s`` seconds of wall time
    (no request starts after it; one in flight then is given 30 s more). With
    ``server_pid``: the server's CPU (its process and its compute workers) per answer,
    ms; always: the load generator's own CPU per request, ms."""
    import asyncio

    base = _example(port, "sugarcane_seeder")
    lat: list[float] = []
    errors: list[str] = []

    async def client(k: int, stop_at: float):
        rng = np.random.default_rng(k)
        bodies = _edit_bodies(base, rng, requests)  # built before the clock starts
        reader, writer = await asyncio.open_connection("127.0.0.1", port)
        await asyncio.sleep(rng.uniform(0, pace_s or 0.05))  # do not start in lockstep
        try:
            for body in bodies:
                if time.perf_counter() > stop_at:
                    return
                head = (f"POST /api/evaluate HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\n"
                        f"Content-Type: application/json\r\nContent-Length: {len(body)}"
                        "\r\n\r\n").encode()
                t0 = time.perf_counter()
                writer.write(head + body)
                try:
                    status, _ = await asyncio.wait_for(_read_response(reader), 30)
                except (TimeoutError, asyncio.IncompleteReadError, OSError) as exc:
                    errors.append(type(exc).__name__)
                    return
                dt = (time.perf_counter() - t0) * 1e3
                (lat.append(dt) if status == 200 else errors.append(str(status)))
                if pace_s:
                    await asyncio.sleep(max(0.0, pace_s - dt / 1e3))
        finally:
            writer.close()

    async def run_all():
        stop_at = time.perf_counter() + cap_s
        await asyncio.wait_for(asyncio.gather(*(client(k, stop_at) for k in range(clients))),
                               cap_s + 30)

    split0 = process_cpu_split_s(server_pid) if server_pid else (0.0, 0.0)
    own0 = time.process_time()
    t0 = time.time()
    asyncio.run(run_all())
    wall = time.time() - t0
    own = time.process_time() - own0
    split1 = process_cpu_split_s(server_pid) if server_pid else (0.0, 0.0)
    proc, workers = split1[0] - split0[0], split1[1] - split0[1]
    cpu = proc + workers
    a = np.array(lat)
    n = len(a) + len(errors)

    def per(x: float) -> float | None:  # ms per answer
        return x / len(a) * 1e3 if len(a) and server_pid else None

    return {"clients": clients, "requests": len(a), "errors": len(errors),
            "wall_s": wall, "server_cpu_ms_per_answer": per(cpu),
            "server_process_cpu_ms_per_answer": per(proc),
            "workers_cpu_ms_per_answer": per(workers),
            "client_cpu_ms_per_request": own / n * 1e3 if n else None,
            "p50_ms": float(np.percentile(a, 50)) if len(a) else None,
            "p95_ms": float(np.percentile(a, 95)) if len(a) else None,
            "max_ms": float(a.max()) if len(a) else None}


def browser_drag(url: str, moves: int = 60, interval_ms: int = 40) -> dict | str:
    """Drag a type-value point of the seeder in chromium: input -> drawn answer (ms),
    from the page's performance measures ("drag-redraw")."""
    if not Path(CHROMIUM).exists():
        return f"skipped: {CHROMIUM} is not installed (apt-get install chromium)"
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        return "skipped: the playwright package is not installed"
    with sync_playwright() as p:
        b = p.chromium.launch(executable_path=CHROMIUM)
        pg = b.new_page(viewport={"width": 1400, "height": 1100})
        pg.goto(url)
        pg.wait_for_function("window.__plantmech && window.__plantmech.result"
                             " && window.__plantmech.result.quality === 'full'"
                             " && window.__plantmech.view", timeout=60000)
        box = pg.locator("#mech").bounding_box()
        x0, y0 = pg.evaluate("""() => { const s = window.__plantmech;
            const p = s.design.trajectory.points[12]; const [x, y] = s.view.toPx(p[0], p[1]);
            const c = document.getElementById('mech'), r = c.getBoundingClientRect();
            return [x * r.width / c.width, y * r.height / c.height]; }""")  # CSS-scaled
        x0, y0 = box["x"] + x0, box["y"] + y0
        pg.evaluate("window.__dragTimes.length = 0")
        pg.mouse.move(x0, y0)
        pg.mouse.down()
        for k in range(moves):  # a slow circle of ~4 mm radius around the point
            a = 2 * np.pi * k / moves
            pg.mouse.move(x0 + 3 * np.sin(a), y0 + 3 * (1 - np.cos(a)))
            pg.wait_for_timeout(interval_ms)
        pg.mouse.up()
        pg.wait_for_function("!window.__plantmech.inflight && !window.__plantmech.pending",
                             timeout=60000)
        times = pg.evaluate("performance.getEntriesByName('drag-redraw').map(e => e.duration)")
        parts = pg.evaluate("window.__dragBreakdown")
        b.close()
    a = np.array(times)
    if not len(a):
        return "no drag answer was drawn"
    keys = ("queued", "compute", "server", "browser_http", "body", "parse", "send_next",
            "draw", "draw_mechanism", "draw_checks", "draw_plots", "bytes")
    median = {k: float(np.median([p[k] for p in parts if p.get(k) is not None] or [np.nan]))
              for k in keys}
    return {"samples": len(a), "p50_ms": float(np.percentile(a, 50)),
            "p95_ms": float(np.percentile(a, 95)), "max_ms": float(a.max()),
            "median_parts_ms": median,
            "transports": sorted({p.get("transport") or "http" for p in parts})}


def drag_cpu_ms(repeat: int = 40) -> tuple[float, float]:
    """(median CPU ms, median wall ms) of one seeder drag answer in-process: validation
    through load_design, inverse design at the working resolution, drawing data, JSON.
    CPU time is what a loaded machine's other processes change least. One answer first,
    not counted: imports and the numba kernels (loaded from their cache), as a compute
    worker's warm-up does."""
    from plantmech.app import server
    from plantmech.design import load_design

    base = load_design(ROOT / "examples" / "sugarcane_seeder.toml").model_dump(
        mode="json", exclude_none=True)
    server.warm_up()
    cpu, wall = [], []
    rng = np.random.default_rng(0)
    for _ in range(repeat):
        d = json.loads(json.dumps(base))
        d["trajectory"]["points"][12][0] += float(rng.uniform(-2, 2))
        raw = json.dumps({"design": d, "quality": "drag"}).encode()
        c0, w0 = time.process_time(), time.perf_counter()
        server.evaluate_request(raw)  # what a compute worker does for one edit
        cpu.append(time.process_time() - c0)
        wall.append(time.perf_counter() - w0)
    return float(np.median(cpu) * 1e3), float(np.median(wall) * 1e3)


def _load() -> str:
    return f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores"


def report(runs: int = 1) -> None:
    """Print the app's figures (called by benchmarks/bench.py). ``runs``: how many times
    the browser drag and the closed-loop load test are repeated on the same server (the
    summary gives each run and their median). Ends with issue 14's two figures on lines
    of their own."""
    cpu, wall = drag_cpu_ms()
    print(f"app seeder drag answer in-process (validation, inverse design at 360 samples, "
          f"Table 1, attitude and speed objectives, drawing data, JSON): median {cpu:.1f} ms "
          f"CPU, {wall:.1f} ms wall ({_load()})")
    figure("app_seeder_drag_answer_cpu_ms", cpu, "ms", wall_ms=wall)
    drags: list[dict] = []
    loops: list[dict] = []
    with Server() as srv:
        for run in range(runs):
            tag = f" [run {run + 1}/{runs}]" if runs > 1 else ""
            r = browser_drag(srv.url)
            if isinstance(r, str):
                print(f"app drag -> redraw (browser): {r}")
            else:
                r["load"] = os.getloadavg()[0]
                drags.append(r)
                ok = "met" if r["p95_ms"] < 50 else "NOT met"
                print(f"app drag -> redraw of mechanism and objectives in chromium{tag}, seeder at "
                      f"the working resolution (360 samples): p50 {r['p50_ms']:.0f} ms, p95 "
                      f"{r['p95_ms']:.0f} ms over {r['samples']} drawn answers (target p95 < 50"
                      f" ms: {ok}; {_load()})")
                parts = ", ".join(f"{k} {v:.1f}" for k, v in r["median_parts_ms"].items()
                                  if k != "bytes")
                print(f"  where a drawn drag answer's time went (medians, ms): {parts}; answer "
                      f"{r['median_parts_ms']['bytes'] / 1e3:.0f} kB over "
                      f"{'/'.join(r['transports'])}")
            paces = (None, 1.0) if run == 0 else (None,)
            for pace in paces:
                r = load_test(pace_s=pace, port=srv.port, server_pid=srv.proc.pid)
                r["load"] = os.getloadavg()[0]
                ok = "met" if r["p95_ms"] is not None and r["p95_ms"] < 100 else "NOT met"
                what = "closed loop" if pace is None else f"one edit per client every {pace:g} s"
                rate = r["requests"] / r["wall_s"]
                r["rate"] = rate
                cpu = r["server_cpu_ms_per_answer"]
                print(f"app load test{tag}, {r['clients']} clients on loopback ({what}), seeder "
                      f"drag edits: {r['requests']} answers, {r['errors']} errors, p50 "
                      f"{r['p50_ms']:.0f} ms, p95 {r['p95_ms']:.0f} ms, max {r['max_ms']:.0f} ms"
                      f" in {r['wall_s']:.1f} s, {rate:.0f} answers/s, server CPU "
                      f"{cpu:.1f} ms per answer (server process "
                      f"{r['server_process_cpu_ms_per_answer']:.1f}, compute workers "
                      f"{r['workers_cpu_ms_per_answer']:.1f}), load generator CPU "
                      f"{r['client_cpu_ms_per_request']:.2f} ms per request (target p95 < 100 "
                      f"ms: {ok}; {_load()})")
                if pace is None:
                    loops.append(r)
                else:
                    figure("app_load_test_paced_p95_ms",
                           r["p95_ms"] if r["p95_ms"] is not None else float("inf"), "ms",
                           100.0, answers_per_s=rate, server_cpu_ms_per_answer=cpu,
                           errors=r["errors"], clients=r["clients"],
                           client_cpu_ms_per_request=r["client_cpu_ms_per_request"])
                if pace is None and cpu:
                    # closed loop: every client waits for its answer, so the mean latency is
                    # clients / throughput (Little's law); p95 < 100 ms needs more than that
                    need = r["clients"] / 0.1
                    print(f"  closed loop needs > {need:.0f} answers/s for a mean under 100 ms "
                          f"({r['clients']} clients / 0.1 s); at {cpu:.1f} ms server CPU per "
                          f"answer {os.cpu_count()} idle cores give at most "
                          f"{os.cpu_count() * 1e3 / cpu:.0f} answers/s")
    _summary(drags, loops)


def _summary(drags: list[dict], loops: list[dict]) -> None:
    """Issue 14's two speed figures, each on a line of its own (the median over runs
    when there are several, every run's value beside it), recorded as figures."""
    print("app: issue 14's two speed figures")
    if drags:
        p95 = [r["p95_ms"] for r in drags]
        med = float(np.median(p95))
        runs = ", ".join(f"{v:.0f}" for v in p95)
        print(f"  FIGURE drag -> redraw p95 (chromium, seeder, 360 samples/turn): {med:.0f} ms "
              f"(runs: {runs} ms; target < 50 ms: {'met' if med < 50 else 'NOT met'}; "
              f"load average {np.median([r['load'] for r in drags]):.1f})")
        figure("app_drag_redraw_chromium_p95_ms", med, "ms", 50.0,
               p50_ms=float(np.median([r["p50_ms"] for r in drags])), runs_p95_ms=p95,
               answers=int(sum(r["samples"] for r in drags)))
    else:
        print("  FIGURE drag -> redraw p95: not measured (see above)")
    if loops:
        p95 = [r["p95_ms"] if r["p95_ms"] is not None else float("inf") for r in loops]
        med = float(np.median(p95))
        cpu = [r["server_cpu_ms_per_answer"] for r in loops]
        rate = [r["rate"] for r in loops]
        print(f"  FIGURE 20 clients closed loop p95 (edit requests on loopback): {med:.0f} ms "
              f"(runs: {', '.join(f'{v:.0f}' for v in p95)} ms; target < 100 ms: "
              f"{'met' if med < 100 else 'NOT met'}); {np.median(rate):.0f} answers/s, server "
              f"CPU {np.median(cpu):.1f} ms per answer (load average "
              f"{np.median([r['load'] for r in loops]):.1f})")
        figure("app_load_test_closed_loop_p95_ms", med, "ms", 100.0,
               runs_p95_ms=p95, answers_per_s=float(np.median(rate)),
               server_cpu_ms_per_answer=float(np.median(cpu)),
               server_process_cpu_ms_per_answer=float(np.median(
                   [r["server_process_cpu_ms_per_answer"] for r in loops])),
               client_cpu_ms_per_request=float(np.median(
                   [r["client_cpu_ms_per_request"] for r in loops])),
               errors=int(sum(r["errors"] for r in loops)), clients=loops[0]["clients"])


def compare(other_src: str, runs: int = 3) -> None:
    """drag -> redraw in chromium, this checkout's page and server against another
    checkout's (``other_src``: its ``src`` directory), after one uncounted drag on each,
    runs alternating (and which goes first) so that both see the same machine load; each
    run's p50/p95, the medians and their ratio."""
    got: dict[str, list[dict]] = {"this": [], "other": []}
    with Server() as ours, Server(src=other_src) as theirs:
        for srv in (ours, theirs):  # one drag each not counted: whichever went first lost
            browser_drag(srv.url, moves=20)  # 2-3x its p95 to the warm-up otherwise
        for run in range(runs):
            order = (("this", ours), ("other", theirs))
            for tag, srv in order if run % 2 == 0 else order[::-1]:  # first place alternates
                r = browser_drag(srv.url)
                if isinstance(r, str):
                    print(f"app drag -> redraw ({tag}): {r}")
                    return
                r["load"] = os.getloadavg()[0]
                got[tag].append(r)
                where = ROOT / "src" if tag == "this" else other_src
                print(f"run {run + 1}/{runs} {tag:>5} ({where}): p50 {r['p50_ms']:.0f} ms, "
                      f"p95 {r['p95_ms']:.0f} ms over "
                      f"{r['samples']} drawn answers, draw {r['median_parts_ms']['draw']:.1f} ms"
                      f" (mechanism {r['median_parts_ms']['draw_mechanism']:.1f}, checks "
                      f"{r['median_parts_ms']['draw_checks']:.1f}, plots "
                      f"{r['median_parts_ms']['draw_plots']:.1f}), compute "
                      f"{r['median_parts_ms']['compute']:.1f} ms; {_load()}")
    med = {k: (float(np.median([r["p50_ms"] for r in v])),
               float(np.median([r["p95_ms"] for r in v]))) for k, v in got.items()}
    loads = [r["load"] for v in got.values() for r in v]
    print(f"FIGURE drag -> redraw side by side (median of {runs} runs each): this p50 "
          f"{med['this'][0]:.0f} / p95 {med['this'][1]:.0f} ms, other p50 {med['other'][0]:.0f}"
          f" / p95 {med['other'][1]:.0f} ms, ratio this/other p95 "
          f"{med['this'][1] / med['other'][1]:.2f} (target p95 < 50 ms: "
          f"{'met' if med['this'][1] < 50 else 'NOT met'}; load average "
          f"{min(loads):.1f}..{max(loads):.1f} on {os.cpu_count()} cores)")


if __name__ == "__main__":
    import argparse

    ap = argparse.ArgumentParser(description="the app's speed figures (issue 14)")
    ap.add_argument("--runs", type=int, default=3,
                    help="repetitions of the browser drag and the closed-loop load test "
                         "(the summary gives their median; default 3)")
    ap.add_argument("--compare", metavar="SRC",
                    help="only the browser drag, side by side with another checkout's src "
                         "directory (e.g. /work/main/src), runs alternating")
    args = ap.parse_args()
    if args.runs < 1:
        ap.error("argument --runs: at least 1")
    if args.compare:
        compare(args.compare, args.runs)
    else:
        report(args.runs)
