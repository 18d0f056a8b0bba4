"""Chunked, resumable execution of a study on Dask, results streamed to Parquet.

A study is a list of chunks (index, payload). Each chunk runs on a Dask worker as one
task (``work(shared, payload)``: many designs through the population API) and returns
(columns, extras); the client writes ``chunks/chunk_NNNNN.parquet`` (columns, one row per
design) and ``chunks/chunk_NNNNN.npz`` (extras) as each result arrives. The Parquet file is
written last, through a temporary name: its presence marks the chunk done, so a stopped
study restarted with the same inputs and --out skips it. ``study.json`` holds the inputs'
fingerprint: --out cannot resume a different study.

Cluster: ``scheduler`` (an address such as tcp://host:8786) connects to a running Dask
cluster, whose workers need plantmech installed; otherwise a local cluster of ``workers``
processes (one thread each) is started and closed with the study, every listener of it
(scheduler, workers, nannies, dashboard) on the loopback address only.
"""

from __future__ import annotations

import contextlib
import json
import logging
import os
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from plantmech.inputs import InputFileError

CHUNK_DIR = "chunks"
#: the only address a local study cluster (scheduler, workers, nannies, dashboard) binds
LOOPBACK = "127.0.0.1"


class StudyStateError(InputFileError):
    """--out holds another study, or its files cannot be used (names the file)."""


@dataclass
class RunStats:
    total_chunks: int
    skipped_chunks: int = 0
    computed_chunks: int = 0
    failed: list = field(default_factory=list)  # (chunk, message)
    evaluations: int = 0  # designs evaluated in this run
    wall_s: float = 0.0  # from the first task sent to the last result written
    cluster_start_s: float = 0.0
    workers: int = 0
    stopped_early: bool = False

    @property
    def complete(self) -> bool:
        return not self.failed and not self.stopped_early

    def as_dict(self) -> dict:
        return {"total_chunks": self.total_chunks, "skipped_chunks": self.skipped_chunks,
                "computed_chunks": self.computed_chunks, "evaluations": self.evaluations,
                "failed_chunks": [{"chunk": c, "error": m} for c, m in self.failed],
                "wall_s": round(self.wall_s, 3), "cluster_start_s": round(self.cluster_start_s, 3),
                "workers": self.workers, "stopped_early": self.stopped_early,
                "designs_per_s": (round(self.evaluations / self.wall_s, 2) if self.wall_s > 0
                                  else None)}


def chunk_path(out: Path, index: int, ext: str = "parquet") -> Path:
    return out / CHUNK_DIR / f"chunk_{index:05d}.{ext}"


def claim_out_dir(out: Path, fingerprint: str, info: dict) -> None:
    """Record (or check) which study --out holds."""
    state = out / "study.json"
    if state.exists() or state.is_symlink():
        from plantmech.studies.summary import read_state

        try:
            old = read_state(out)
        except StudyStateError as exc:
            raise StudyStateError(f"--out {out}: study.json cannot be read ({exc})") from None
        if old.get("fingerprint") != fingerprint:
            raise StudyStateError(
                f"--out {out} holds a study of another design or study file (study.json); "
                "its chunks would not belong to this one: choose another directory")
    else:
        (out / CHUNK_DIR).mkdir(parents=True, exist_ok=True)
        state.write_text(json.dumps({"fingerprint": fingerprint, **info}, indent=2) + "\n",
                         encoding="utf-8")
    (out / CHUNK_DIR).mkdir(parents=True, exist_ok=True)


def done_chunks(out: Path) -> set[int]:
    return {int(p.stem.split("_")[1]) for p in (out / CHUNK_DIR).glob("chunk_*.parquet")}


def write_chunk(out: Path, index: int, columns: dict, extras: dict | None) -> None:
    import pyarrow as pa
    import pyarrow.parquet as pq

    extras = dict(extras or {})
    for name, text in extras.pop("_files", {}).items():  # text files a task produced
        (out / name).parent.mkdir(parents=True, exist_ok=True)
        (out / name).write_text(text, encoding="utf-8")
    if extras:
        tmp = chunk_path(out, index, "tmp.npz")
        np.savez(tmp, **extras)
        os.replace(tmp, chunk_path(out, index, "npz"))
    table = pa.table({k: np.asarray(v) for k, v in columns.items()})
    tmp = chunk_path(out, index, "parquet.tmp")
    pq.write_table(table, tmp)
    os.replace(tmp, chunk_path(out, index))


#: largest Parquet chunk file read back (bytes): a chunk of the largest size (100,000
#: designs) of a few hundred columns is well under it
MAX_CHUNK_BYTES = 512_000_000


def _read_chunk(f: Path, rows_left: int):
    """One Parquet chunk file, bounded (a regular file, MAX_CHUNK_BYTES, at most
    ``rows_left`` rows, numeric or boolean columns): StudyStateError naming the file."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    from plantmech.inputs import read_input_bytes
    from plantmech.studies.spec import MAX_DESIGNS

    data = read_input_bytes(f, "Parquet chunk of a study", MAX_CHUNK_BYTES, StudyStateError)
    try:
        reader = pq.ParquetFile(pa.BufferReader(data))
        rows = reader.metadata.num_rows
        if rows > rows_left:
            raise StudyStateError(f"{f}: {rows:,} rows, more than the chunks of one study "
                                  f"hold in all ({MAX_DESIGNS:,} designs); not a chunk of a study")
        table = reader.read()
    except (pa.ArrowException, OSError, ValueError) as exc:
        if isinstance(exc, StudyStateError):
            raise
        raise StudyStateError(f"{f}: not a Parquet chunk of a study "
                              f"({type(exc).__name__}: {str(exc)[:200]})") from None
    for col in table.schema:
        t = col.type
        if not (pa.types.is_integer(t) or pa.types.is_floating(t) or pa.types.is_boolean(t)):
            raise StudyStateError(f"{f}: column {col.name!r} holds {t}, not numbers (not a "
                                  "chunk of a study)")
    return table


def read_results(out: Path) -> dict[str, np.ndarray]:
    """Every finished chunk's rows, in chunk order: column -> array. Each chunk is read
    bounded (``_read_chunk``), at most MAX_DESIGNS rows in all, every chunk with the same
    columns (StudyStateError naming the file otherwise)."""
    import pyarrow as pa

    from plantmech.studies.spec import MAX_DESIGNS

    files = sorted((out / CHUNK_DIR).glob("chunk_*.parquet"))
    if not files:
        return {}
    tables, left = [], MAX_DESIGNS
    for f in files:
        tables.append(_read_chunk(f, left))
        left -= tables[-1].num_rows
        if tables[-1].schema.names != tables[0].schema.names:
            raise StudyStateError(f"{f}: its columns differ from {files[0].name}'s (not a "
                                  "chunk of the same study)")
    try:
        table = pa.concat_tables(tables, promote_options="permissive")
    except pa.ArrowException as exc:
        raise StudyStateError(f"{out / CHUNK_DIR}: the chunks' columns do not match "
                              f"({str(exc)[:200]})") from None
    return {n: table.column(n).to_numpy() for n in table.column_names}


def read_extras(out: Path) -> list[dict]:
    """The chunks' extra arrays (``.npz``), each read bounded as a chunk is."""
    import io
    import zipfile

    from plantmech.inputs import read_input_bytes

    extras = []
    for f in sorted((out / CHUNK_DIR).glob("chunk_*.npz")):
        data = read_input_bytes(f, "chunk extras file (.npz)", MAX_CHUNK_BYTES,
                                StudyStateError)
        try:
            with np.load(io.BytesIO(data), allow_pickle=False) as z:
                extras.append({k: z[k] for k in z.files})
        except (OSError, ValueError, zipfile.BadZipFile, EOFError) as exc:
            raise StudyStateError(f"{f}: not a chunk extras file ({exc})") from None
    return extras


@contextlib.contextmanager
def dask_client(scheduler: str | None = None, workers: int = 2):
    """A Dask client: on ``scheduler`` (address) or on a new local cluster of ``workers``
    processes with one thread each."""
    from distributed import Client, LocalCluster

    if scheduler:
        try:
            client = Client(scheduler, timeout="20s")
        except (OSError, TimeoutError, ValueError) as exc:
            raise StudyStateError(f"--scheduler {scheduler}: cannot connect to a Dask "
                                  f"scheduler there ({type(exc).__name__}: {exc})") from None
        try:
            yield client
        finally:
            client.close()
        return
    from plantmech.outputs import signals

    # loopback only, the dashboard included (":0" listened on every interface); the worker
    # processes never get a Ctrl-C or SIGHUP sent to the process group (each printed a
    # KeyboardInterrupt traceback): the parent stops them. A signal while the cluster starts
    # or stops is held until it has (cut in half, its atexit hook failed on the remains with
    # a traceback), then ends the run as usual. Its own logs are silenced to CRITICAL: a
    # cluster stopped soon after its start had a worker log its heartbeat to the closed
    # scheduler as an ERROR traceback (dask/distributed issue 7105); a chunk that fails is
    # reported by the study with its exception (``RunStats.failed``). A cluster that failed
    # to start because a SIGTERM to the process group ended its workers is that signal's
    # stop (before: a "Nanny failed to start" traceback)
    with signals.kept_from_children(), signals.blocked():
        try:
            cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                   host=LOOPBACK, dashboard_address=f"{LOOPBACK}:0",
                                   silence_logs=logging.CRITICAL)
        except Exception:  # it has closed what it started (SpecCluster)
            signals.check()
            raise
        try:
            client = Client(cluster)
        except BaseException:
            cluster.close()
            signals.check()
            raise
    try:
        signals.check()
        yield client
    finally:
        with signals.blocked():
            client.close()
            cluster.close()


def _run_task(work, shared, payload):
    return work(shared, payload)


def run_chunks(out: Path, work, shared, chunks: list[tuple[int, object, int]],
               scheduler: str | None = None, workers: int = 2, progress: bool = True,
               max_chunks: int | None = None, label: str = "designs") -> RunStats:
    """Run every chunk (index, payload, designs in it) not yet done in ``out``.
    ``max_chunks``: stop after writing that many new chunks (the rest stays for a resume)."""
    from distributed import as_completed
    from tqdm import tqdm

    done = done_chunks(out)
    pending = [c for c in chunks if c[0] not in done]
    stats = RunStats(total_chunks=len(chunks), skipped_chunks=len(chunks) - len(pending))
    if not pending:
        return stats
    t0 = time.perf_counter()
    with dask_client(scheduler, workers) as client:
        stats.cluster_start_s = time.perf_counter() - t0
        stats.workers = len(client.nthreads())
        t1 = time.perf_counter()
        # a key of its own (hash=False): with the content's hash as its key, a study rerun on
        # the same scheduler right after a stopped one scattered the key the stopped
        # client was releasing, and its tasks were cancelled (FutureCancelledError; CI of
        # this round; dask/distributed issues 4612 and 8576, whose workaround this is)
        from plantmech.outputs import signals

        with signals.blocked():  # a signal cutting the scatter in half: scheduler tracebacks
            shared_f = client.scatter(shared, broadcast=True, hash=False)
            futures = {client.submit(_run_task, work, shared_f, payload, pure=False): (i, n)
                       for i, payload, n in pending}
        signals.check()
        done_n = sum(c[2] for c in chunks if c[0] in done)
        bar = tqdm(total=sum(c[2] for c in chunks), initial=done_n, unit=label,
                   disable=not progress, smoothing=0.1)
        try:
            for fut in as_completed(futures):
                i, n = futures[fut]
                try:
                    columns, extras = fut.result()
                except Exception as exc:  # a chunk that fails is reported, not fatal
                    stats.failed.append((i, f"{type(exc).__name__}: {exc}"))
                    continue
                write_chunk(out, i, columns, extras)
                stats.computed_chunks += 1
                stats.evaluations += n
                bar.update(n)
                if max_chunks is not None and stats.computed_chunks >= max_chunks:
                    stats.stopped_early = stats.computed_chunks < len(pending)
                    for f in futures:
                        f.cancel()
                    break
        except KeyboardInterrupt:  # Ctrl-C: the written chunks stay; rerun to resume
            stats.stopped_early = True
            for f in futures:
                f.cancel()
        finally:
            bar.close()
        stats.wall_s = time.perf_counter() - t1
    return stats
