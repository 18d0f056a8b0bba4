"""One output discipline for every command (issue 29): ``--out`` written whole or not at all
(``OutputRun`` / ``OutputFile``), never the working directory or a parent of it, never a
device, FIFO or link, existing files only with --force; SIGINT, SIGTERM and SIGHUP at any
moment leave an existing --out byte-identical (or the run finished with its result, never
both a signal exit and a changed directory); a full disk is exit 5 with nothing written; the
verdict is the last line and the JSON record holds the same one."""

from __future__ import annotations

import errno
import json
import os
import random
import shutil
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from plantmech.interfaces.cli import main
from plantmech.outputs import signals
from tests.conftest import EXAMPLES

TRANSPLANTER = str(EXAMPLES / "rice_transplanter.toml")
ELLIPTIC = str(EXAMPLES / "rotary_transplanter_elliptic.toml")  # 3 gears of 25 teeth
SEEDER = str(EXAMPLES / "sugarcane_seeder_optimized.toml")
SWEEP = """kind = "sweep"
method = "grid"
chunk = 3
cycle_samples = 180
dense = 512
[parameters.L2_mm]
low = 485.0
high = 495.0
levels = 3
[parameters.backlash_deg]
low = 0.0
high = 0.4
levels = 2
"""


def snapshot(d: Path) -> dict:
    """Every entry under ``d`` (relative path -> bytes, link target or 'dir')."""
    out = {}
    for root, dirs, files in os.walk(d):
        for n in dirs + files:
            p = Path(root) / n
            rel = str(p.relative_to(d))
            out[rel] = (f"link:{os.readlink(p)}" if p.is_symlink() else
                        "dir" if p.is_dir() else p.read_bytes())
    return out


def leftovers(d: Path) -> list[str]:
    return sorted(p.name for p in d.iterdir() if p.name.startswith(".plantmech"))


@pytest.fixture(scope="module")
def gears_dir(tmp_path_factory):
    """The elliptic rotary transplanter's gear files (the cheapest set to cut)."""
    out = tmp_path_factory.mktemp("gears") / "g"
    assert main(["gears", ELLIPTIC, "--out", str(out)]) == 0
    return out


def _argv(command: str, tmp: Path, out: str, gears: Path | None = None) -> list[str]:
    """A cheap run of ``command`` writing to ``out``."""
    spec = tmp / "sweep.toml"
    spec.write_text(SWEEP, encoding="utf-8")
    return {"forward": ["forward", TRANSPLANTER, "--out", out, "--no-plots"],
            "gears": ["gears", ELLIPTIC, "--out", out],
            "verify": ["verify", ELLIPTIC, "--gears", str(gears or tmp), "--out", out,
                       "--steps", "60", "--no-loads", "--no-plots"],
            "study": ["study", SEEDER, "--spec", str(spec), "--out", out, "--workers", "1",
                      "--quiet", "--no-plots"],
            "design": ["design", TRANSPLANTER, "--out", out, "--generations", "1", "--quiet"],
            }[command]


@pytest.mark.parametrize("command", ["forward", "gears", "verify", "study", "design"])
def test_out_is_never_the_working_directory_or_a_parent(command, tmp_path, monkeypatch,
                                                        capsys):
    """The case that deleted a user's files: ``--out .. --force`` from a subdirectory."""
    work = tmp_path / "a" / "b"
    work.mkdir(parents=True)
    (tmp_path / "a" / "mine.txt").write_text("mine")
    monkeypatch.chdir(work)
    argvs = {out: _argv(command, tmp_path, out) + ["--force"]
             for out in ("..", "../..", ".", str(tmp_path / "a"))}
    before = snapshot(tmp_path)
    for out, argv in argvs.items():
        assert main(argv) == 2, out
        err = capsys.readouterr().err
        assert "a directory of its own" in err, err
    assert snapshot(tmp_path) == before


def test_verify_refuses_existing_files_and_links_into_its_gears(gears_dir, tmp_path, capsys):
    gears_before = snapshot(gears_dir)
    out = tmp_path / "v"
    out.mkdir()
    (out / "verification.json").write_text("mine")
    argv = _argv("verify", tmp_path, str(out), gears_dir)
    assert main(argv) == 2
    assert "already holds" in capsys.readouterr().err
    assert (out / "verification.json").read_text() == "mine"
    # a link in --out into the gears directory it reads (its own input)
    (out / "verification.json").unlink()
    os.symlink(gears_dir / "verification.json", out / "verification.json")
    assert main(argv + ["--force"]) == 2
    assert "link to it" in capsys.readouterr().err
    # --out is the gears directory, or holds it
    assert main(_argv("verify", tmp_path, str(gears_dir), gears_dir) + ["--force"]) == 2
    assert main(_argv("verify", tmp_path, str(gears_dir.parent), gears_dir) + ["--force"]) == 2
    assert snapshot(gears_dir) == gears_before
    # with --force and a plain old file: replaced as a whole, verdict last and recorded
    (out / "verification.json").unlink()
    (out / "old.txt").write_text("old")
    capsys.readouterr()
    rc = main(argv + ["--force"])
    lines = capsys.readouterr().out.strip().splitlines()
    rec = json.loads((out / "verification.json").read_text())
    assert sorted(p.name for p in out.iterdir()) == ["verification.json"]
    assert rec["verdict"]["exit_code"] == rc and rc in (0, 4)
    assert lines[-1].startswith("verdict: " + ("ok" if rc == 0 else "NOT MET"))
    assert "loads not checked (--no-loads)" in lines[-1] or rc == 4
    assert rec["not_checked"] == ["loads not checked (--no-loads)"]
    assert f"wrote: {out / 'verification.json'}" in "\n".join(lines)
    assert snapshot(gears_dir) == gears_before and leftovers(tmp_path) == []


def test_verify_leaves_nothing_when_the_gears_cannot_be_read(tmp_path, capsys):
    empty = tmp_path / "g"
    empty.mkdir()
    rc = main(_argv("verify", tmp_path, str(tmp_path / "v"), empty))
    assert rc == 2 and "gear file not found" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["g", "sweep.toml"]


def test_study_resumes_its_own_out_and_refuses_another_commands(tmp_path, capsys):
    user = tmp_path / "user.json"
    user.write_text('{"mine": 1}')
    out = tmp_path / "s"
    out.mkdir()
    os.symlink(user, out / "summary.json")
    argv = _argv("study", tmp_path, str(out))
    assert main(argv) == 2
    assert "already holds" in capsys.readouterr().err
    # --force replaces the link itself (never writes through it): the user's file is kept
    assert main(argv + ["--max-chunks", "1", "--force"]) == 4
    assert user.read_text() == '{"mine": 1}' and not (out / "summary.json").is_symlink()
    state = json.loads((out / "study.json").read_text())
    assert state["complete"] is False
    lines = capsys.readouterr().out.strip().splitlines()
    s = json.loads((out / "summary.json").read_text())
    assert s["verdict"]["exit_code"] == 4 and lines[-1] == "verdict: " + s["verdict"]["text"]
    assert s["verdict"]["text"].startswith("INCOMPLETE")
    # the same study again: resumed without --force, the finished chunk kept
    chunk = (out / "chunks" / "chunk_00000.parquet").read_bytes()
    assert main(argv) == 0
    out_text = capsys.readouterr().out
    assert "1 computed, 1 already done" in out_text
    assert (out / "chunks" / "chunk_00000.parquet").read_bytes() == chunk
    assert json.loads((out / "study.json").read_text())["complete"] is True
    s = json.loads((out / "summary.json").read_text())
    assert s["verdict"] == {"status": "ok", "ok": True, "exit_code": 0, "failed": [],
                            "style": "info", "text": s["verdict"]["text"]}
    assert out_text.strip().splitlines()[-1] == "verdict: ok - " + s["verdict"]["text"]
    # another command's directory: refused without --force
    other = tmp_path / "f"
    assert main(_argv("forward", tmp_path, str(other))) == 4
    before = snapshot(other)
    assert main(_argv("study", tmp_path, str(other))) == 2
    assert "summary.json" in capsys.readouterr().err and snapshot(other) == before
    assert leftovers(tmp_path) == []


def test_report_never_replaces_a_users_page_a_link_or_a_fifo(tmp_path, capsys):
    spec = tmp_path / "sweep.toml"
    spec.write_text(SWEEP)
    study = tmp_path / "s"
    assert main(["study", SEEDER, "--spec", str(spec), "--out", str(study), "--workers", "1",
                 "--quiet", "--no-plots"]) == 0
    page = tmp_path / "page.html"
    page.write_text("<!doctype html><p>my page</p>")
    link = tmp_path / "link.html"
    os.symlink(page, link)
    fifo = tmp_path / "fifo.html"
    os.mkfifo(fifo)
    for target, force, words in ((page, False, "not a report"), (link, True, "link"),
                                 (fifo, True, "FIFO"), (tmp_path, True, "directory")):
        argv = ["report", str(study), "--out", str(target)] + (["--force"] if force else [])
        assert main(argv) == 2, target
        assert words in capsys.readouterr().err
    assert page.read_text() == "<!doctype html><p>my page</p>" and fifo.is_fifo()
    capsys.readouterr()
    assert main(["report", str(study), "--out", str(page), "--force"]) == 0
    assert f"report: {page}" in capsys.readouterr().out
    assert "plantmech report" in page.read_text()
    # its own report is rebuilt without --force; the plots it drew join the study
    assert main(["report", str(study)]) == 0
    assert main(["report", str(study)]) == 0
    assert (study / "sweep.png").read_bytes()[:4] == b"\x89PNG"
    assert leftovers(tmp_path) == [] and leftovers(study) == []


def test_schema_and_init_never_replace_a_device_a_fifo_or_a_link(tmp_path, capsys):
    mine = tmp_path / "mine.json"
    mine.write_text("mine")
    os.symlink(mine, tmp_path / "link.json")
    os.mkfifo(tmp_path / "fifo.json")
    for target in (tmp_path / "link.json", tmp_path / "fifo.json", Path("/dev/null")):
        assert main(["schema", "--out", str(target), "--force"]) == 2, target
        capsys.readouterr()
    assert mine.read_text() == "mine" and (tmp_path / "fifo.json").is_fifo()
    assert Path("/dev/null").is_char_device()
    assert main(["schema", "--out", str(mine)]) == 2
    assert "--force" in capsys.readouterr().err and mine.read_text() == "mine"
    assert main(["schema", "--out", str(mine), "--force"]) == 0
    assert json.loads(mine.read_text())["$schema"].startswith("https://json-schema.org")
    # init: --name is a file name in DIR, never a path out of it
    d = tmp_path / "d" / "e"
    for name in ("../../x.toml", str(tmp_path / "abs.toml"), "..", "sub/x.toml"):
        assert main(["init", "seeder", str(d), "--name", name]) == 2, name
        assert "not a path" in capsys.readouterr().err
    assert not (tmp_path / "x.toml").exists() and not (tmp_path / "abs.toml").exists()
    assert not (tmp_path / "d").exists()  # the directory made for it is gone again
    os.symlink(mine, tmp_path / "seeder.toml")
    assert main(["init", "seeder", str(tmp_path)]) == 2
    assert "link" in capsys.readouterr().err and mine.read_text().startswith("{")
    assert leftovers(tmp_path) == []


def test_write_json_is_whole_or_not_at_all(tmp_path, monkeypatch):
    from plantmech.outputs.files import write_json

    p = tmp_path / "a.json"
    write_json(p, {"x": 1})
    os.symlink(p, tmp_path / "b.json")
    write_json(tmp_path / "b.json", {"x": 2})  # replaces the link, not its target
    assert json.loads(p.read_text()) == {"x": 1} and not (tmp_path / "b.json").is_symlink()

    def full(*a, **k):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(os, "replace", full)
    with pytest.raises(OSError):
        write_json(p, {"x": 3})
    assert json.loads(p.read_text()) == {"x": 1}
    assert sorted(q.name for q in tmp_path.iterdir()) == ["a.json", "b.json"]


class _Sender:
    """Send ``signum`` to this process after ``delay`` s, from a thread (the handler runs in
    the main thread, wherever the command is). Around the trial a recording handler stands
    in for pytest's, so a signal landing after the command returned is harmless. ``probe()``
    is asked when the signal is sent (``seen``: e.g. whether the gears were being cut)."""

    def __init__(self, signum: int, delay: float, probe=None):
        self.signum, self.delay, self.late = signum, delay, []
        self.probe, self.seen = probe, None
        self._stop = threading.Event()

    def __enter__(self):
        self._old = {s: signal.signal(s, lambda n, f: self.late.append(n))
                     for s in signals.SIGNALS}
        self._t = threading.Thread(target=self._run, daemon=True)
        self._t.start()
        return self

    def _run(self):
        if not self._stop.wait(self.delay):
            if self.probe is not None:
                self.seen = self.probe()
            os.kill(os.getpid(), self.signum)

    def __exit__(self, *exc):
        self._stop.set()
        self._t.join()
        time.sleep(0.01)  # let a signal already sent reach its handler
        for s, h in self._old.items():
            signal.signal(s, h)
        return False


def _signal_trials(argv_of, out: Path, moments: list[float], capsys) -> list[tuple]:
    """Run ``argv_of(out)`` with --force over the existing ``out``, a signal at each moment;
    every time: a signal exit with ``out`` byte-identical, or the result in place."""
    kinds = [signal.SIGTERM, signal.SIGINT, signal.SIGHUP]
    results = []
    for i, t in enumerate(moments):
        before = snapshot(out)
        signum = kinds[i % 3]
        with _Sender(signum, t):
            rc = main(argv_of(out) + ["--force"])
        err = capsys.readouterr().err
        assert "Traceback" not in err
        if rc == 128 + signum:
            assert snapshot(out) == before, (t, signum)
            assert "interrupted" in err and signals.NAMES[signum] in err
        else:
            assert rc in (0, 4), (t, rc, err)  # finished with its result
        assert leftovers(out.parent) == [], (t, signum)
        results.append((t, signum, rc))
    return results


def test_signals_at_random_moments_of_forward(tmp_path, capsys):
    out = tmp_path / "f"
    argv_of = lambda o: ["forward", TRANSPLANTER, "--out", str(o)]  # noqa: E731
    assert main(argv_of(out)) == 4  # the existing --out (plots included)
    t0 = time.perf_counter()
    assert main(argv_of(out) + ["--force"]) == 4
    full = time.perf_counter() - t0
    (out / "mine.txt").write_text("the user's")
    rng = random.Random(29)
    moments = sorted(rng.uniform(0.0, 1.1 * full) for _ in range(10))
    res = _signal_trials(argv_of, out, moments, capsys)
    assert sum(rc >= 128 for _, _, rc in res) >= 5  # most moments land inside the run


def test_signals_at_random_moments_of_gear_cutting(gears_dir, tmp_path, capsys):
    out = tmp_path / "g"
    shutil.copytree(gears_dir, out, symlinks=True)
    (out / "mine.txt").write_text("the user's")
    rng = random.Random(2929)
    # the cutting takes seconds: each moment falls in it (at worst a run finished: checked)
    moments = sorted(rng.uniform(0.05, 1.0) for _ in range(10))
    res = _signal_trials(lambda o: _argv("gears", tmp_path, str(o)), out, moments, capsys)
    assert sum(rc == 128 + s for _, s, rc in res) >= 8
    assert (out / "mine.txt").read_text() == "the user's"


def test_a_swallowed_signal_cannot_commit(tmp_path, capsys):
    """A library that catches KeyboardInterrupt (or a callback where it is "Exception
    ignored") does not turn a signal into a result: the record stays, nothing is moved in."""
    from argparse import Namespace

    from plantmech.interfaces.cli import run_command

    out = tmp_path / "o"
    out.mkdir()
    (out / "old.json").write_text("{}")

    def swallowing(args, design, run):
        (run.path / "summary.json").write_text("{}")
        try:
            os.kill(os.getpid(), signal.SIGTERM)
            time.sleep(1)
        except KeyboardInterrupt:
            pass  # swallowed
        return 0

    args = Namespace(design=TRANSPLANTER, out=str(out), force=True)
    with signals.handled():
        assert run_command(args, swallowing) == 143
        assert signals.received() == signal.SIGTERM
    assert "interrupted (SIGTERM)" in capsys.readouterr().err
    assert snapshot(out) == {"old.json": b"{}"} and leftovers(tmp_path) == []


def _pid_alive_after_signals(_):
    os.kill(os.getpid(), signal.SIGINT)
    os.kill(os.getpid(), signal.SIGHUP)
    time.sleep(0.05)
    return "alive"


def test_pool_workers_ignore_sigint_and_sighup():
    import multiprocessing as mp
    from concurrent.futures import ProcessPoolExecutor

    with ProcessPoolExecutor(1, mp_context=mp.get_context("spawn"),
                             initializer=signals.worker_init) as ex:
        assert ex.submit(_pid_alive_after_signals, 0).result(timeout=60) == "alive"


@pytest.mark.parametrize("command", ["forward", "verify", "study"])
def test_a_full_disk_is_exit_5_and_nothing_written(command, gears_dir, tmp_path, monkeypatch,
                                                    capsys):
    """ENOSPC simulated where the record is written (the last file of each run)."""
    import plantmech.outputs.files as files

    def full(path, data):
        raise OSError(errno.ENOSPC, "No space left on device", str(path))

    real = files.write_json
    for mod in list(sys.modules.values()):  # every module that imported it by name
        if getattr(mod, "write_json", None) is real:
            monkeypatch.setattr(mod, "write_json", full)
    out = tmp_path / "o"
    out.mkdir()
    (out / "mine.txt").write_text("the user's")
    rc = main(_argv(command, tmp_path, str(out), gears_dir) + ["--force"])
    err = capsys.readouterr().err
    assert rc == 5 and "no space left on the device" in err and "nothing was written" in err
    assert "Traceback" not in err
    assert snapshot(out) == {"mine.txt": b"the user's"} and leftovers(tmp_path) == []


def test_a_full_disk_on_a_real_tmpfs(tmp_path, capsys):
    """A 64 KiB tmpfs: the transplanter's forward run does not fit (exit 5), the existing
    --out on it is untouched. Needs root to mount (skipped otherwise)."""
    mnt = tmp_path / "mnt"
    mnt.mkdir()
    r = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", str(mnt)],
                       capture_output=True)
    if r.returncode != 0:
        pytest.skip("cannot mount a tmpfs here (needs root)")
    try:
        out = mnt / "o"
        out.mkdir()
        (out / "mine.txt").write_text("the user's")
        rc = main(["forward", TRANSPLANTER, "--out", str(out), "--force"])
        err = capsys.readouterr().err
        assert rc == 5 and "no space left on the device" in err, err
        assert snapshot(out) == {"mine.txt": b"the user's"} and leftovers(mnt) == []
    finally:
        subprocess.run(["umount", str(mnt)], check=True)


@pytest.mark.parametrize("command,signum", [("verify", signal.SIGINT),
                                            ("study", signal.SIGINT),
                                            ("study", signal.SIGHUP)])
def test_a_signal_to_the_program_is_its_exit_status_without_traceback(command, signum,
                                                                      gears_dir, tmp_path):
    """The real program (its handler stays to the exit): a signal while it works, in verify
    and in study (its Dask cluster started and stopped), where SIGINT was a traceback."""
    out = tmp_path / "v"
    out.mkdir()
    (out / "mine.txt").write_text("the user's")
    argv = _argv(command, tmp_path, str(out), gears_dir)
    if command == "verify":
        argv[argv.index("60")] = "720"
    p = subprocess.Popen([sys.executable, "-m", "plantmech.interfaces.cli", *argv, "--force"],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    t0 = time.perf_counter()
    while not leftovers(tmp_path) and p.poll() is None and time.perf_counter() - t0 < 50:
        time.sleep(0.02)  # until its temporary directory exists: it is working
    time.sleep(0.3)
    p.send_signal(signum)
    _, err = p.communicate(timeout=50)
    assert "Traceback" not in err and leftovers(tmp_path) == []
    if p.returncode == 4 and command == "study":  # it was computing: a stop kept its chunks
        assert f"stopped by {signals.NAMES[signum]}" in err
        assert json.loads((out / "study.json").read_text())["complete"] is False
        return
    assert p.returncode == 128 + signum, err
    assert f"interrupted ({signals.NAMES[signum]})" in err
    assert snapshot(out) == {"mine.txt": b"the user's"}


def test_a_signal_while_a_study_computes_keeps_its_finished_chunks(tmp_path, monkeypatch,
                                                                    capsys):
    """The documented stop of a study (docs/studies.md): a signal while its chunks are
    computed keeps the finished ones, summarised (complete = false, exit 4), and the same
    command resumes from them."""
    import plantmech.studies.engine as engine

    real = engine.write_chunk

    def write_then_signal(out, index, columns, extras):
        real(out, index, columns, extras)
        os.kill(os.getpid(), signal.SIGTERM)
        time.sleep(2)  # the handler raises here

    monkeypatch.setattr(engine, "write_chunk", write_then_signal)
    out = tmp_path / "s"
    argv = _argv("study", tmp_path, str(out))
    assert main(argv) == 4
    assert "stopped by SIGTERM: the finished chunks are kept" in capsys.readouterr().err
    assert json.loads((out / "study.json").read_text())["complete"] is False
    kept = [p.name for p in (out / "chunks").iterdir()]
    assert len(kept) == 1 and kept[0] in ("chunk_00000.parquet", "chunk_00001.parquet")
    monkeypatch.undo()
    assert main(argv) == 0
    assert "1 computed, 1 already done" in capsys.readouterr().out
    assert leftovers(tmp_path) == []


@pytest.mark.skipif(__import__("importlib").util.find_spec("build123d") is not None,
                    reason="build123d installed: STEP files are written")
def test_gears_step_without_the_extra_is_a_finding(tmp_path, capsys):
    """--step asked for and not written: a finding, exit 4 ("files not written"), never
    "every file is what it claims"."""
    out = tmp_path / "g"
    rc = main(_argv("gears", tmp_path, str(out)) + ["--step"])
    lines = capsys.readouterr().out.strip().splitlines()
    rec = json.loads((out / "verification.json").read_text())
    assert rc == 4 and rec["step"].startswith("build123d is not installed")
    assert rec["verdict"]["label"] == "files not written" and not rec["verdict"]["ok"]
    assert [f["check"] for f in rec["findings"]] == ["files_not_written"]
    assert lines[-1].startswith("verdict: NOT MET - files not written")


def test_report_prints_where_the_report_is_after_the_run(tmp_path, monkeypatch, capsys):
    """--report names the report's place in --out, never the temporary directory it was
    written into (which is gone when the command returns)."""
    import plantmech.outputs.report as report

    def page(path, *a, **k):  # the page itself: tests/test_report.py
        Path(path).write_text("<!doctype html>")
        return [Path(path)]

    monkeypatch.setattr(report, "write_report", page)
    out = tmp_path / "f"
    assert main(["forward", TRANSPLANTER, "--out", str(out), "--no-plots", "--report"]) == 4
    printed = capsys.readouterr().out
    assert f"report: {out / 'report.html'}\n" in printed and ".plantmech" not in printed
    assert (out / "report.html").read_text() == "<!doctype html>"


def test_the_gears_report_mesh_row_follows_the_findings(tmp_path, monkeypatch):
    """A pair whose interference is fine (the mesh check's own ok) but whose backlash band
    fails is not "ok" in the report; a pair without a finding stays ok."""
    from argparse import Namespace

    import plantmech.interfaces.report_cli as report_cli
    import plantmech.outputs.report as report
    from plantmech.outputs.report import check_rows

    seen = {}
    monkeypatch.setattr(report, "write_report", lambda path, summary, *a, **k: seen.update(
        summary=summary, verdict=k["verdict"]) or [Path(path)])
    monkeypatch.setattr(report_cli, "design_animation", lambda d: None)
    rec = {"verdict": {"status": "not met", "ok": False, "exit_code": 4,
                       "failed": ["a_b backlash_min"], "label": "not manufacturable",
                       "text": "NOT MET - not manufacturable: 1 findings on 1 gears or pairs"},
           "files": [], "gears": [],
           "all_pairs_mesh": True,
           "mesh": [{"pair": "a_b", "ok": True, "max_interference_mm": 0.0},
                    {"pair": "b_c", "ok": True, "max_interference_mm": 0.0}],
           "findings": [{"gear": "a_b", "check": "backlash_min", "value": 0.01, "limit": 0.05,
                         "unit": "mm", "where": {}, "why": "the teeth bind"}]}
    design = Namespace(name="d")
    report_cli.gears_report(Namespace(command="gears"), tmp_path, design, rec)
    rows = {r["pair"]: r["ok"] for r in check_rows(seen["summary"]) if "pair" in r}
    assert rows == {"a_b": False, "b_c": True}
    assert seen["summary"]["all_pairs_mesh"] is False and seen["verdict"][0] is False
    assert seen["verdict"][1] == "verdict: " + rec["verdict"]["text"]  # the record's words
    assert rec["mesh"][0]["ok"] is True  # the record itself is not changed


def test_gears_records_the_one_verdict_of_every_command(shared):
    """`plantmech gears` records its verdict as forward and verify do (``outputs.verdict``:
    status, ok, exit_code, failed), not as a bare string ("ok" / "not manufacturable", kept
    as its ``label``), with the line it printed (``text``) and the caveats it rests on."""
    from plantmech.outputs.verdict import verdict
    from tests.conftest import gears_cut

    out, rc = gears_cut(shared, "rotary_transplanter_elliptic", ELLIPTIC)
    rec = json.loads((out / "verification.json").read_text())
    v = rec["verdict"]
    assert isinstance(v, dict) and rec["findings"] == [] and rc == 0
    assert v == {**verdict(), "label": "ok", "caveats": [c["text"] for c in rec["caveats"]],
                 "text": "ok - every gear can be cut, the pairs mesh, every file is what it "
                         "claims"}


def test_design_accepts_report():
    from plantmech.interfaces.cli import build_parser

    args = build_parser().parse_args(["design", TRANSPLANTER, "--out", "o", "--report"])
    assert args.report is True


def _link_cases(tmp_path: Path, shared) -> dict:
    """Every command that writes, with ``{out}`` where its output directory (or file) goes."""
    from tests.conftest import gears_cut

    spec = tmp_path / "sweep.toml"
    spec.write_text(SWEEP, encoding="utf-8")
    study = tmp_path / "study"
    return {
        "forward": lambda o: ["forward", TRANSPLANTER, "--out", o, "--no-plots"],
        "gears": lambda o: ["gears", ELLIPTIC, "--out", o],
        "inverse": lambda o: ["inverse", str(EXAMPLES / "sugarcane_seeder.toml"), "--out", o],
        "optimize": lambda o: ["optimize", SEEDER, "--problem", "seeder-layer2",
                               "--generations", "1", "--out", o],
        "design": lambda o: ["design", TRANSPLANTER, "--out", o, "--generations", "1"],
        "verify": lambda o: ["verify", ELLIPTIC, "--gears",
                             str(gears_cut(shared, "rotary_transplanter_elliptic", ELLIPTIC)[0]),
                             "--out", o],
        "study": lambda o: ["study", SEEDER, "--spec", str(spec), "--out", o],
        "report": lambda o: ["report", str(study), "--out", o],
        "schema": lambda o: ["schema", "--out", o],
        "init": lambda o: ["init", "seeder", o],
    }, study


@pytest.mark.parametrize("command", ["forward", "gears", "inverse", "optimize", "design",
                                     "verify", "study", "report", "schema", "init"])
def test_an_out_that_is_a_symbolic_link_is_refused(command, shared, tmp_path, capsys):
    """A --out (or init's DIR) that is a link, to a directory of the user's, to a file or to
    nothing, is refused by name (exit 2) before any work: nothing is written through it, the
    link and what it points to stay as they were (before: a link to a directory was followed
    and the run's results replaced the directory it pointed to)."""
    cases, study = _link_cases(tmp_path, shared)
    if command == "report":  # a study directory to report on (its summary is what is read)
        shutil.copytree(_finished_study(shared), study)
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "notes.txt").write_text("the user's")
    (tmp_path / "file.html").write_text("the user's page")
    os.symlink(mine, tmp_path / "to-dir")
    os.symlink(tmp_path / "file.html", tmp_path / "to-file")
    os.symlink(tmp_path / "nowhere", tmp_path / "dangling")
    before = snapshot(tmp_path)
    for link in ("to-dir", "to-file", "dangling"):
        out = str(tmp_path / link)
        for force in ([], ["--force"]) if command != "init" else ([],):
            assert main(cases[command](out) + force) == 2, (link, force)
            err = capsys.readouterr().err
            assert f"{out} is a symbolic link" in err and "nothing is written through a link" \
                in err, err
    assert snapshot(tmp_path) == before and leftovers(tmp_path) == []


def _finished_study(shared) -> Path:
    from tests.test_signal_moments import _study_dir

    return _study_dir(shared)


def test_a_link_below_out_is_still_followed_as_a_path(tmp_path, capsys):
    """Only --out itself is never a link: a directory reached through a linked parent (the
    user's own layout, e.g. a linked home) is a place like any other."""
    real = tmp_path / "real"
    real.mkdir()
    os.symlink(real, tmp_path / "via")
    assert main(["schema", "--out", str(tmp_path / "via" / "s.json")]) == 0
    assert json.loads((real / "s.json").read_text())["$schema"]


@pytest.mark.parametrize("name", ["", " ", "\t"])
def test_init_refuses_an_empty_name(name, tmp_path, capsys):
    """``--name ""`` fell back silently to the default name: now exit 2 naming the option."""
    d = tmp_path / "d"
    assert main(["init", "seeder", str(d), "--name", name]) == 2
    err = capsys.readouterr().err
    assert f"--name {name!r}: empty; give a file name" in err and "seeder.toml" in err
    assert not d.exists()
    assert main(["init", "seeder", str(d), "--name", "mine.toml"]) == 0
    assert sorted(p.name for p in d.iterdir()) == ["mine.toml"]


def test_report_writes_its_record_with_the_one_verdict(shared, tmp_path, capsys):
    """``plantmech report`` records its run like every command: report.json beside the page,
    holding the verdict ``plantmech study`` recorded (the same dict, built once by
    ``study_report.study_verdict_record``), the one its last line prints; it appears with
    the page, and a user's file of that name is never replaced without --force."""
    from plantmech.outputs.study_report import study_verdict_line

    study = tmp_path / "s"
    shutil.copytree(_finished_study(shared), study)
    summary = json.loads((study / "summary.json").read_text())
    capsys.readouterr()
    assert main(["report", str(study)]) == summary["verdict"]["exit_code"] == 0
    lines = capsys.readouterr().out.strip().splitlines()
    rec = json.loads((study / "report.json").read_text())
    assert rec["verdict"] == summary["verdict"]
    assert lines[-1] == study_verdict_line(rec["verdict"]) == "verdict: ok - " + \
        summary["verdict"]["text"]
    assert lines[:2] == [f"report: {study / 'report.html'}",
                         f"record: {study / 'report.json'}"]
    assert rec["record_of"] == "plantmech report" and rec["study"] == str(study)
    assert rec["report"] == str(study / "report.html")
    assert rec["command"].startswith("plantmech ")  # sys.argv: pytest's here
    assert rec["plots_added_to_study"] == ["sweep.png"] and (study / "sweep.png").is_file()
    # rerun: its own record replaced without --force (nothing left to add to the study)
    assert main(["report", str(study)]) == 0
    assert json.loads((study / "report.json").read_text())["plots_added_to_study"] == []
    # --out elsewhere: the record is that file's name with .json
    page = tmp_path / "page.html"
    assert main(["report", str(study), "--out", str(page)]) == 0
    assert json.loads((tmp_path / "page.json").read_text())["verdict"] == summary["verdict"]
    # a user's file where the record goes: refused whole (no page either) without --force
    other = tmp_path / "other.html"
    (tmp_path / "other.json").write_text('{"mine": 1}')
    capsys.readouterr()
    assert main(["report", str(study), "--out", str(other)]) == 2
    assert "record" in capsys.readouterr().err and not other.exists()
    assert (tmp_path / "other.json").read_text() == '{"mine": 1}'
    assert main(["report", str(study), "--out", str(tmp_path / "r.json")]) == 2
    assert "an .html name" in capsys.readouterr().err
    # a study whose requirement is not met: the record says so, exit 4, as the summary
    summary["verdict"] = None
    summary["complete"] = False
    (study / "summary.json").write_text(json.dumps(summary))
    assert main(["report", str(study)]) == 4
    rec = json.loads((study / "report.json").read_text())
    assert rec["verdict"]["status"] == "not met" and rec["verdict"]["exit_code"] == 4
    assert rec["verdict"]["text"].startswith("INCOMPLETE")
    assert capsys.readouterr().out.strip().splitlines()[-1] == "verdict: " + \
        rec["verdict"]["text"]
    assert leftovers(tmp_path) == [] and leftovers(study) == []


def test_a_signal_after_the_page_is_in_place_still_brings_its_record(tmp_path, monkeypatch):
    """Two files of one command (the page and its record, nested OutputFile blocks): once the
    first is in place the command ends with its result, so a signal between the two commits
    does not leave a page without its record."""
    from plantmech.outputs.files import OutputFile

    page, record = tmp_path / "p.html", tmp_path / "p.json"
    real, sent = signals.finish, []

    def finish_then_signal():  # the inner (page's) commit done: a signal now
        real()
        if not sent:
            sent.append(os.kill(os.getpid(), signal.SIGTERM))
            time.sleep(0.05)

    with signals.handled():
        with OutputFile(record) as tmp_record, OutputFile(page) as tmp_page:
            tmp_page.write_text("page")
            tmp_record.write_text("record")
            monkeypatch.setattr(signals, "finish", finish_then_signal)
        assert signals.received() == signal.SIGTERM and sent
    assert page.read_text() == "page" and record.read_text() == "record"
    assert leftovers(tmp_path) == []


class _Finalized:
    """Its finalizer is where a signal lands (a weakref or gc callback alike): Python prints
    what is raised there as "Exception ignored in ..." with a traceback and goes on."""

    def __del__(self):
        os.kill(os.getpid(), signal.SIGTERM)
        time.sleep(0.5)  # the handler runs here, inside the finalizer


def test_a_signal_in_a_finalizer_prints_no_traceback_and_still_stops(capfd):
    """Seen in the 20 moments of design: "Exception ignored in: <function WeakKeyDictionary
    ... remove> ... Interrupted: SIGTERM" (the issue's "Exception ignored ...
    KeyboardInterrupt"). Now nothing is printed and the signal is raised again: the
    command stops at its next step instead of running on to a refused commit."""
    t0 = time.perf_counter()
    with signals.handled():
        with pytest.raises(signals.Interrupted) as stopped:
            x = _Finalized()
            del x  # the signal raised in __del__: ignored by Python, raised again by us
            time.sleep(5)  # stopped here at once
        assert stopped.value.signum == signal.SIGTERM == signals.received()
    assert time.perf_counter() - t0 < 3
    err = capfd.readouterr().err
    assert "Exception ignored" not in err and "Traceback" not in err, err
    # anything else raised in a finalizer still reaches the previous hook
    seen = []
    old = sys.unraisablehook
    sys.unraisablehook = seen.append
    try:
        with signals.handled():
            class Bad:
                def __del__(self):
                    raise ValueError("mine")
            b = Bad()
            del b
    finally:
        sys.unraisablehook = old
    assert [type(u.exc_value) for u in seen] == [ValueError]
