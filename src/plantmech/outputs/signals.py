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
with its result and says so with its own exit status.

Worker processes of a pool call :func:`worker_init`: they ignore SIGINT and SIGHUP (the
terminal sends them to the whole process group; the parent decides and stops its pool) and
end on SIGTERM as by default (how a pool is stopped).
"""

from __future__ import annotations

import contextlib
import signal

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


@contextlib.contextmanager
def handled(restore: bool = True):
    """Install the handler of the three signals for one command (main thread only; in
    another thread this does nothing). ``restore=False`` leaves it installed after the block
    (a program that ends right after: a signal between the block's end and the exit is then
    recorded, not a kill with the results already in place)."""
    global _received, _finished
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield
        return
    _received, _finished = None, False
    old = {s: signal.signal(s, _handler) for s in SIGNALS}
    try:
        yield
    finally:
        if restore:
            for s, h in old.items():
                signal.signal(s, h)
            _received, _finished = None, False
        else:
            _finished = True  # the command has ended: a signal now is recorded only


def worker_init() -> None:
    """Initializer of a pool's worker processes: SIGINT and SIGHUP ignored, SIGTERM default."""
    global _received, _finished
    _received, _finished = None, False
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGHUP, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
