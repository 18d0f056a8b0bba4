"""SIGINT, SIGTERM and SIGHUP end a command the same way: nothing half-written, ``--out`` as it
was, exit 128 + the signal's number (130, 143, 129).

:func:`handled` installs one handler for the three signals. The first signal is recorded
(:func:`received`) and raised as :class:`Interrupted` (a ``KeyboardInterrupt``, so code that
already cleans up on Ctrl-C does so on every signal). Because the record stays, a signal
that some library swallowed (``except KeyboardInterrupt: ...``, or "Exception ignored" in a
callback) still stops the results from being committed: :class:`~plantmech.outputs.files.
OutputRun` and :class:`~plantmech.outputs.files.OutputFile` check :func:`received` before
they move anything into place, and move it with the signals blocked (:func:`blocked`). Once a
run's results are in place (:func:`finish`), a late signal is recorded only: the run ended
with its result and says so with its own exit status. A signal that lands in a finalizer or a
weakref callback (where Python prints "Exception ignored" with a traceback and goes on) is
not printed and is raised again a moment later (:func:`_unraisable`).

Worker processes of a pool call :func:`worker_init`: they ignore SIGINT and SIGHUP (the
terminal sends them to the whole process group; the parent decides and stops its pool) and
end on SIGTERM as by default (how a pool is stopped). A pool that starts its workers itself (a
local Dask cluster) is started in :func:`kept_from_children`, to the same effect.
"""

from __future__ import annotations

import contextlib
import functools
import signal
import sys

SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)
NAMES = {signal.SIGINT: "SIGINT", signal.SIGTERM: "SIGTERM", signal.SIGHUP: "SIGHUP"}

_received: int | None = None
_finished = False
_defer = 0


class Interrupted(KeyboardInterrupt):
    """A SIGINT, SIGTERM or SIGHUP reached the command (``exit_code`` = 128 + its number)."""

    def __init__(self, signum: int):
        super().__init__(NAMES.get(signum, str(signum)))
        self.signum = signum
        self.exit_code = 128 + int(signum)


def _handler(signum, frame) -> None:
    global _received
    if _received is None:
        _received = signum
    if not _finished and not _defer:
        raise Interrupted(signum)


def stopped(exc: KeyboardInterrupt) -> int:
    """Say on stderr that a signal (``exc``: an :class:`Interrupted`, or a bare
    ``KeyboardInterrupt``: Ctrl-C) stopped the command before its results were in place,
    and return its exit status (130, 143, 129)."""
    signum = getattr(exc, "signum", signal.SIGINT)
    print(f"interrupted ({NAMES.get(signum, signum)}): nothing written, --out left as it was",
          file=sys.stderr)
    return getattr(exc, "exit_code", 128 + int(signum))


def received() -> int | None:
    """The first of the three signals since :func:`handled` began, or None."""
    return _received


def finished() -> bool:
    """True once a run's results are in place (:func:`finish`)."""
    return _finished


def finish() -> None:
    """The results are in place: a signal from now on is recorded, not raised."""
    global _finished
    _finished = True


def consume() -> int | None:
    """Forget the signal received (and return it): the command handled it as a documented
    stop with a result (a study keeps its finished chunks to resume), so the results may
    be committed; a further signal interrupts as usual."""
    global _received
    got, _received = _received, None
    return got


def check() -> None:
    """Raise :class:`Interrupted` if a signal was received (and swallowed) before the
    results are in place."""
    if _received is not None and not _finished:
        raise Interrupted(_received)


@contextlib.contextmanager
def blocked():
    """The three signals held back: for the few system calls that move results into place
    or clean up, which must not be cut in half. A signal in the block is recorded, not
    raised (the Python handler always runs in the main thread, whichever thread the signal
    reached); after the block the caller asks :func:`check`."""
    global _defer
    _defer += 1
    try:
        yield
    finally:
        _defer -= 1


def _unraisable(previous, unraisable) -> None:
    """``sys.unraisablehook`` while a command runs: the signal's :class:`Interrupted` raised
    where Python cannot pass it on (a finalizer, a weakref or gc callback: it printed
    "Exception ignored in ... Traceback ... Interrupted" and the run went on) is not printed
    and the signal is raised again, so that the command stops at its next step (its record
    stays: nothing is committed either way); anything else goes to the ``previous`` hook."""
    exc = unraisable.exc_value
    if not isinstance(exc, Interrupted):
        previous(unraisable)
        return
    if _received is not None and not _finished:
        import os
        import threading
        import time

        def again():  # from another thread, a moment later: raised here, it was ignored again
            time.sleep(0.005)
            if signal.getsignal(exc.signum) is _handler and not _finished:  # still running
                os.kill(os.getpid(), exc.signum)

        threading.Thread(target=again, daemon=True).start()


@contextlib.contextmanager
def handled(restore: bool = True):
    """Install the handler of the three signals for one command (main thread only; in
    another thread this does nothing), and :func:`_unraisable` as ``sys.unraisablehook``.
    ``restore=False``: the three signals are ignored after the block (a program that ends
    right after: a signal between the block's end and the exit is then ignored, not a kill
    with the results already in place)."""
    global _received, _finished
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield
        return
    _received, _finished = None, False
    old = {s: signal.signal(s, _handler) for s in SIGNALS}
    old_hook = sys.unraisablehook
    sys.unraisablehook = functools.partial(_unraisable, old_hook)
    try:
        yield
    finally:
        if restore:
            for s, h in old.items():
                signal.signal(s, h)
            sys.unraisablehook = old_hook
            _received, _finished = None, False
        else:
            # the program has ended: a signal now changes nothing. Ignored, not only recorded:
            # the interpreter puts the default actions back while it shuts down, and a
            # signal then killed it (exit -2 after the results were in place: both a signal
            # exit and a changed --out)
            _finished = True
            for s in SIGNALS:
                signal.signal(s, signal.SIG_IGN)


@contextlib.contextmanager
def kept_from_children():
    """SIGINT and SIGHUP kept from the processes started in the block, and later by the
    threads started in it: for a pool whose worker processes are not started through
    :func:`worker_init` (a local Dask cluster: its nanny starts and restarts the workers from
    threads of its own). The block holds the two signals back in this thread (its signal
    mask); a thread inherits the mask of the thread that starts it and a process the mask of
    the thread that forks it, through ``exec``, so those workers never see a Ctrl-C or a
    closed terminal sent to the whole process group (before: each printed a
    KeyboardInterrupt traceback and the cluster lost its data): the parent decides and stops
    them (SIGTERM reaches them as before). The parent still gets both signals in the block
    (through another thread, or held until its end), and its handler runs as usual."""
    import threading

    if (not hasattr(signal, "pthread_sigmask")
            or threading.current_thread() is not threading.main_thread()):
        yield
        return
    from multiprocessing import resource_tracker

    kept = {signal.SIGINT, signal.SIGHUP}
    old = signal.pthread_sigmask(signal.SIG_BLOCK, kept)
    try:
        # multiprocessing's resource tracker started here (if it is not running) with the two
        # held back as well: it ignores SIGINT and SIGTERM but died of a SIGHUP to the group
        # (then "process died unexpectedly" and KeyError tracebacks); starting it unblocks
        # SIGINT and SIGTERM in the thread that starts it (CPython's ensure_running), which
        # then started the next worker with SIGINT: held back again
        resource_tracker.ensure_running()
        signal.pthread_sigmask(signal.SIG_BLOCK, kept)
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


def worker_init() -> None:
    """Initializer of a pool's worker processes: SIGINT and SIGHUP ignored, SIGTERM default."""
    global _received, _finished
    _received, _finished = None, False
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGHUP, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
