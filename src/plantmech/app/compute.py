"""The app's edit computations in worker processes (one per core the server may use).

An edit request's whole computation — JSON parse, validation, the engine, drawing data,
the answer's JSON — runs in a worker process (``server.evaluate_request``): the
server's own process only moves bytes, so the HTTP and WebSocket traffic never waits
for the GIL behind a computation, and two edits compute at once on two cores.

Admission is first come, first served (a FIFO of waiters for an idle worker). The
compute time limit covers the wait and the computation; a worker over it is killed
(its computation really stops) and replaced, and the request gets a clear error. A
worker that dies is replaced the same way.
"""

from __future__ import annotations

import asyncio
import collections
import multiprocessing as mp
import os
import time


class ComputeError(Exception):
    """An edit that got no answer from a worker: HTTP status and message."""

    def __init__(self, status: int, message: str):
        super().__init__(message)
        self.status, self.message = status, message


def worker_count() -> int:
    """Worker processes sized to the machine: the cores this process may run on."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # not on Linux
        return max(1, os.cpu_count() or 1)


def _worker_main(conn, warm: bool) -> None:
    """A worker: answers (status, body bytes, compute ms) to each request body (bytes)."""
    from plantmech.app import server

    if warm:
        server.warm_up()
    conn.send(("ready", os.getpid()))
    while True:
        try:
            raw = conn.recv_bytes()
        except (EOFError, OSError):
            return
        t0 = time.perf_counter()
        status, body = server.evaluate_request(raw)
        conn.send((status, body, (time.perf_counter() - t0) * 1e3))


class _Worker:
    def __init__(self, ctx, warm: bool):
        self.conn, child = ctx.Pipe()
        self.process = ctx.Process(target=_worker_main, args=(child, warm), daemon=True,
                                   name="plantmech-app-compute")
        self.process.start()
        child.close()

    def kill(self) -> None:
        if self.process.is_alive():
            self.process.kill()
        self.process.join(5)
        self.conn.close()


async def _readable(conn) -> None:
    """Wait until ``conn`` has data (or was closed) without a thread. The pipe is left
    blocking, as ``Connection.recv`` needs it (uvloop's reader makes it non-blocking)."""
    loop = asyncio.get_running_loop()
    if conn.poll():
        return
    fut = loop.create_future()
    fd = conn.fileno()
    try:
        loop.add_reader(fd, lambda: fut.done() or fut.set_result(None))
    except NotImplementedError:  # an event loop without add_reader (Windows' proactor)
        await loop.run_in_executor(None, conn.poll, None)
        return
    try:
        await fut
    finally:
        loop.remove_reader(fd)
        os.set_blocking(fd, True)


class ComputePool:
    """``workers`` processes (default: ``worker_count()``) computing edit requests.

    ``warm``: each worker evaluates the seeder example once before it takes requests,
    so that the first drag does not pay for imports and first calls."""

    def __init__(self, workers: int | None = None, warm: bool = True,
                 start_method: str = "spawn"):
        self.size = workers or worker_count()
        self.warm = warm
        self._ctx = mp.get_context(start_method)
        self._idle: list[_Worker] = []
        self._waiters: collections.deque[asyncio.Future] = collections.deque()
        self._all: set[_Worker] = set()
        self._ready: set[_Worker] = set()
        self._closed = False

    @property
    def ready(self) -> int:
        """Workers that have started and taken (or can take) edits."""
        return len(self._ready)

    # -- workers -----------------------------------------------------------------------------

    def start(self) -> None:
        """Start the workers (returns at once; each takes requests once it is ready)."""
        while len(self._all) < self.size and not self._closed:
            self._spawn()

    def _spawn(self) -> None:
        w = _Worker(self._ctx, self.warm)
        self._all.add(w)
        asyncio.get_running_loop().create_task(self._boot(w))

    async def _boot(self, w: _Worker) -> None:
        try:
            await _readable(w.conn)
            w.conn.recv()  # ("ready", pid)
        except (EOFError, OSError):  # died while starting: not replaced (would loop)
            self._retire(w)
            return
        self._ready.add(w)
        self._release(w)

    def _retire(self, w: _Worker) -> None:
        self._all.discard(w)
        self._ready.discard(w)
        w.kill()

    def _replace(self, w: _Worker) -> None:
        self._retire(w)
        if not self._closed:
            self._spawn()

    def _release(self, w: _Worker) -> None:
        if self._closed:
            self._retire(w)
            return
        while self._waiters:
            fut = self._waiters.popleft()
            if not fut.done():
                fut.set_result(w)
                return
        self._idle.append(w)

    async def _acquire(self, timeout: float) -> _Worker:
        if self._idle:
            return self._idle.pop()
        if not self._all:
            self.start()
        fut = asyncio.get_running_loop().create_future()
        self._waiters.append(fut)
        try:
            return await asyncio.wait_for(asyncio.shield(fut), timeout)
        except (TimeoutError, asyncio.CancelledError):
            if fut.done() and not fut.cancelled():  # a worker came as the wait ended
                self._release(fut.result())
            else:
                fut.cancel()
            raise

    # -- requests ----------------------------------------------------------------------------

    async def run(self, body: bytes, timeout: float) -> tuple[int, bytes, float]:
        """(HTTP status, answer JSON bytes, compute ms) of one edit request body. Raises
        ComputeError(503) when the wait and the computation exceed ``timeout`` seconds,
        ComputeError(500) when the worker died."""
        loop = asyncio.get_running_loop()
        deadline = loop.time() + timeout
        try:
            w = await self._acquire(timeout)
        except TimeoutError:
            raise ComputeError(503, f"computation exceeded the {timeout:g} s limit "
                               "(waiting for a free worker)") from None
        try:
            w.conn.send_bytes(body)
            await asyncio.wait_for(_readable(w.conn), max(0.0, deadline - loop.time()))
            status, answer, ms = w.conn.recv()
        except TimeoutError:
            self._replace(w)  # the computation stops with its process
            raise ComputeError(503, f"computation exceeded the {timeout:g} s limit "
                               "(lower the samples per turn)") from None
        except (EOFError, OSError):
            self._replace(w)
            raise ComputeError(500, "the computation's worker process died; "
                               "a new one was started") from None
        except asyncio.CancelledError:  # the client went away: the worker finishes first
            loop.create_task(self._drain(w, deadline))
            raise
        self._release(w)
        return status, answer, ms

    async def _drain(self, w: _Worker, deadline: float) -> None:
        loop = asyncio.get_running_loop()
        try:
            await asyncio.wait_for(_readable(w.conn), max(0.0, deadline - loop.time()))
            w.conn.recv()
        except (TimeoutError, EOFError, OSError):
            self._replace(w)
            return
        self._release(w)

    def shutdown(self) -> None:
        self._closed = True
        for fut in self._waiters:
            fut.cancel()
        for w in list(self._all):
            self._retire(w)
        self._idle.clear()


class ThreadCompute:
    """Edits computed in the server's own threads (``plantmech app --workers 0``): no
    worker processes (and no start-up time), at most ``slots`` at once, admitted first
    come first served. The computation holds the GIL for most of its time, so the HTTP
    and WebSocket traffic waits behind it, and a computation over the time limit cannot
    be stopped (it finishes on its own; its slot stays taken until then)."""

    def __init__(self, slots: int = 2):
        import threading

        self.size = 0
        self.ready = 0
        self._admission: asyncio.Semaphore | None = None
        self._slots = threading.BoundedSemaphore(slots)
        self._n = slots

    def start(self) -> None:
        pass

    def shutdown(self) -> None:
        pass

    async def run(self, body: bytes, timeout: float) -> tuple[int, bytes, float]:
        from plantmech.app import server

        if self._admission is None:
            self._admission = asyncio.Semaphore(self._n)

        def guarded():
            with self._slots:
                t0 = time.perf_counter()
                status, answer = server.evaluate_request(body)
                return status, answer, (time.perf_counter() - t0) * 1e3

        async def admitted():
            async with self._admission:
                return await asyncio.to_thread(guarded)
        try:
            return await asyncio.wait_for(admitted(), timeout)
        except TimeoutError:
            raise ComputeError(503, f"computation exceeded the {timeout:g} s limit "
                               "(lower the samples per turn)") from None
