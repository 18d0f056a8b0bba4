"""Background tasks of the app: optimization and gear cutting in child processes.

Each task runs ``plantmech.optimize.jobs.optimize`` or ``plantmech.workflows.run_gears``
in its own process (spawned), writing into a server-side temporary directory, and
reports progress through a queue. A task over its time limit is killed and reported
as failed; files are served only by the names the task itself listed.
"""

from __future__ import annotations

import csv
import multiprocessing as mp
import os
import queue
import shutil
import signal
import tempfile
import threading
import time
import uuid
from pathlib import Path

OPTIMIZE_LIMIT_S = 900.0
GEARS_LIMIT_S = 300.0
MAX_RUNNING = 2


class _ProgressBar:
    """Stands in for tqdm in the child: each generation's update and postfix (best
    violation, designs meeting every objective) go to the parent's queue."""

    q = None

    def __init__(self, total=None, desc="", **_):
        self.total, self.desc, self.n = total, desc, 0

    def update(self, k=1):
        self.n += k

    def set_postfix(self, **kw):
        if self.q is not None:
            self.q.put(("progress", {"stage": self.desc, "generation": self.n,
                                     "generations": self.total,
                                     "best_violation": float(kw.get("best_violation", "nan")),
                                     "feasible_in_population": int(kw.get("feasible", 0)),
                                     "t": time.time()}))

    def close(self):
        pass


def _load(design_json: dict, out: Path):
    import tomli_w

    from plantmech.design import load_design

    path = out / "design.toml"
    path.write_text(tomli_w.dumps(design_json), encoding="utf-8")
    return load_design(path)


def _read_csv(path: Path) -> dict[str, list[float]]:
    with path.open(encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    if not rows:
        return {}
    return {k: [float(r[k]) for r in rows] for k in rows[0]}


def _own_group() -> None:
    """Put the child in its own process group, so that stopping a task also stops the
    worker pool an optimizer starts (``_kill``)."""
    if hasattr(os, "setpgrp"):
        os.setpgrp()


def _kill(process) -> None:
    """Kill a task's process and its own children (its process group). Called only while
    the task process is not reaped (:func:`_alive` never reaps it), so that its process
    group id cannot belong to anything else yet."""
    if process.pid is None:
        return
    try:
        if hasattr(os, "killpg"):
            os.killpg(process.pid, signal.SIGKILL)
        else:
            process.kill()
    except (ProcessLookupError, PermissionError):
        pass


def _alive(process) -> bool:
    """Whether the task process still runs, without reaping it (``is_alive`` would, and
    its process group id could then be reused before :func:`_end` kills the group)."""
    if not hasattr(os, "waitid"):
        return process.is_alive()
    try:
        return os.waitid(os.P_PID, process.pid,
                         os.WEXITED | os.WNOHANG | os.WNOWAIT) is None
    except ChildProcessError:  # reaped already
        return False


def _end(task) -> None:
    """A task whose result (or failure, or cancellation) is in: kill its whole process
    group and reap its process. Nothing of it outlives it: a finished optimization's
    process waited at exit for its pool's workers, which waited for work, and both
    stayed (about 500 MB) until the server stopped."""
    with task.ending:
        if task.reaped:
            return
        _kill(task.process)
        task.process.join(timeout=10)
        task.reaped = True


def failure(exc: Exception) -> str:
    """What the page says of a task that failed: the reason a design cannot be optimized or
    cut (a ValueError, DesignError included, says it in words: "the trajectory's inverse
    design is infeasible: run layer 1 first") as it is; anything else with its kind, as an
    error of the program. Never a traceback."""
    if isinstance(exc, ValueError):
        return str(exc)
    return f"internal error ({type(exc).__name__}: {exc})"


def _optimize_child(design_json: dict, problem: str, out: str, opts: dict, q) -> None:
    import tqdm

    _own_group()
    _ProgressBar.q = q
    tqdm.tqdm = _ProgressBar  # the runner builds its bar from tqdm.tqdm at run time
    try:
        from plantmech.optimize.jobs import make_problem, optimize

        out = Path(out)
        design = _load(design_json, out)
        run_dir = out / "run"
        run_dir.mkdir()
        outcome = optimize(design, problem, run_dir, "the app's design", progress=True,
                           **opts)
        rec = outcome.record
        hist = _read_csv(run_dir / "history.csv")
        pareto = _read_csv(run_dir / "pareto.csv")
        best = (run_dir / "best.toml").read_text(encoding="utf-8")
        # Pareto designs: decoded by the problem when it is the one the front belongs to
        # (NSGA-II problems without staging); otherwise the front is the best design.
        designs = None
        # the transplanter's staged tooth-fit job (a ring scale, choices of its own) keeps
        # its best design only: its front is best.toml, not a decode of the user's design
        staged = "design_choices" in rec
        if problem in ("transplanter", "seeder-layer2") and pareto and not staged:
            p = make_problem(design, problem)
            names = [f"{v.name}_{v.unit}" for v in p.variables]
            import numpy as np

            X = np.array([pareto[n] for n in names]).T
            designs = [p.decode(x).model_dump(mode="json", exclude_none=True) for x in X]
            objectives = list(p.objective_names)
        else:
            objectives = [k for k in pareto if k in (rec.get("objectives_minimized") or [])]
        files = ["best.toml", "run.json", "history.csv", "pareto.csv"]
        # nothing meets everything: the run's trade-off archive (agronomic against
        # manufacturability) is what the page draws
        tradeoff = None
        for rel in ("tradeoff.csv", "layer2/tradeoff.csv"):
            if (run_dir / rel).is_file():
                tradeoff = _read_csv(run_dir / rel)
                if "/" not in rel:
                    files.append(rel)
                break
        from plantmech.optimize.jobs import summary_lines

        verified = rec.get("verified_full_resolution")
        from plantmech.design import load_design

        best_json = load_design(run_dir / "best.toml").model_dump(mode="json",
                                                                  exclude_none=True)
        q.put(("done", {"feasible": bool(outcome.feasible),
                        "evaluations": rec.get("evaluations"), "wall_s": rec.get("wall_s"),
                        "history": hist, "pareto": pareto, "objectives": objectives,
                        "pareto_designs": designs, "best_design": best_json,
                        "best_toml": best, "files": files,
                        "note": rec.get("note"), "tradeoff": tradeoff,
                        # the rows the run's verdict judges, and its printed summary
                        "result_checks": (verified or {}).get("objectives")
                        or rec.get("objectives") or [],
                        "summary": summary_lines(rec)}))
    except Exception as exc:  # noqa: BLE001 - reported to the page, never a traceback
        q.put(("error", failure(exc)))


def _gears_child(design_json: dict, out: str, opts: dict, q) -> None:
    _own_group()
    try:
        from plantmech.workflows import run_gears

        out = Path(out)
        design = _load(design_json, out)
        files_dir = out / "gears"
        files_dir.mkdir()
        q.put(("progress", {"stage": "cutting teeth", "t": time.time()}))
        outlines: dict = {}
        rec = run_gears(design, files_dir, outlines=outlines, **opts)
        q.put(("progress", {"stage": "placing the teeth on the drawn gears", "t": time.time()}))
        try:  # the cut outlines in the body frames of the gears the page animates
            from plantmech.app import scene, server

            drawn = server.evaluate(design, "full").get("gears", [])
            teeth = scene.teeth_for_scene(drawn, outlines)
        except Exception as exc:  # noqa: BLE001 - the page then draws pitch curves only
            teeth = {"error": f"{type(exc).__name__}: {exc}"}
        from plantmech.gears.findings import describe

        # the verdict of verification.json as `plantmech gears` prints it, with its findings
        q.put(("done", {"record": rec, "files": list(rec["files"]) + ["verification.json"],
                        "all_pairs_mesh": bool(rec["all_pairs_mesh"]), "teeth": teeth,
                        "verdict": rec["verdict"], "headline": rec["verdict"]["text"],
                        "findings": [{"gear": f["gear"], "check": f["check"],
                                      "text": describe(f)} for f in rec["findings"]]}))
    except Exception as exc:  # noqa: BLE001 - reported to the page, never a traceback
        q.put(("error", failure(exc)))


class Task:
    def __init__(self, kind: str, limit_s: float):
        self.id = uuid.uuid4().hex[:12]
        self.kind, self.limit_s = kind, limit_s
        self.dir = Path(tempfile.mkdtemp(prefix=f"plantmech-app-{kind}-"))
        self.state = "running"
        self.progress: list[dict] = []
        self.result: dict | None = None
        self.error: str | None = None
        self.started = time.time()
        self.process = None
        self.queue = None
        self.ending = threading.Lock()
        self.reaped = False
        self.files_dir = self.dir / ("gears" if kind == "gears" else "run")


class TaskManager:
    """Starts, watches and cleans up the background tasks."""

    def __init__(self):
        self.ctx = mp.get_context("spawn")
        self.tasks: dict[str, Task] = {}
        self.lock = threading.Lock()

    def _running(self) -> int:
        return sum(t.state == "running" for t in self.tasks.values())

    def _start(self, kind: str, limit: float, target, args) -> str:
        from plantmech.app.server import AppError

        with self.lock:
            if self._running() >= MAX_RUNNING:
                raise AppError(429, f"{MAX_RUNNING} background tasks are running already: "
                               "wait for one or cancel it")
            task = Task(kind, limit)
            task.queue = self.ctx.Queue()
            # target(*head, out_dir, opts, queue)
            head, opts = args[:-1], args[-1]
            task.process = self.ctx.Process(
                target=target, args=(*head, str(task.dir), opts, task.queue), daemon=False)
            task.process.start()
            self.tasks[task.id] = task
        threading.Thread(target=self._watch, args=(task,), daemon=True).start()
        return task.id

    def start_optimize(self, design_json: dict, problem: str, **opts) -> str:
        return self._start("optimize", OPTIMIZE_LIMIT_S, _optimize_child,
                           (design_json, problem, opts))

    def start_gears(self, design_json: dict, **opts) -> str:
        return self._start("gears", GEARS_LIMIT_S, _gears_child, (design_json, opts))

    def _watch(self, task: Task) -> None:
        while task.state == "running":
            try:
                kind, payload = task.queue.get(timeout=0.2)
            except queue.Empty:
                if time.time() - task.started > task.limit_s:
                    _kill(task.process)
                    task.state, task.error = "failed", (
                        f"time limit of {task.limit_s:g} s exceeded: the task was stopped")
                elif not _alive(task.process) and task.queue.empty():
                    task.state = "failed"
                    task.error = task.error or (
                        f"the worker process ended without a result (exit code "
                        f"{task.process.exitcode})")
                continue
            if kind == "progress":
                task.progress.append(payload)
            elif kind == "done":
                task.result, task.state = payload, "done"
            else:
                task.error, task.state = payload, "failed"
        _end(task)

    def status(self, task_id: str) -> dict | None:
        t = self.tasks.get(task_id)
        if t is None:
            return None
        return {"id": t.id, "kind": t.kind, "state": t.state, "error": t.error,
                "elapsed_s": round(time.time() - t.started, 2),
                "progress": t.progress[-1] if t.progress else None,
                "history": t.progress[-200:], "result": t.result}

    def cancel(self, task_id: str) -> bool:
        t = self.tasks.get(task_id)
        if t is None or t.state != "running":
            return False
        _kill(t.process)
        t.state, t.error = "failed", "cancelled"
        return True

    def file(self, task_id: str, name: str) -> Path | None:
        t = self.tasks.get(task_id)
        if t is None or t.result is None or name not in t.result.get("files", []):
            return None
        path = t.files_dir / name
        return path if path.is_file() else None

    def shutdown(self) -> None:
        for t in self.tasks.values():
            if t.process is not None:
                _end(t)
            shutil.rmtree(t.dir, ignore_errors=True)
