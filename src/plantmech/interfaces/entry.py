"""``plantmech``, the program: the console script's entry point (``[project.scripts]``).

A signal is an exit status from the first line of plantmech's own code on. The command's
modules take some 70 ms and more to import (argparse, the design model): a Ctrl-C then
ended in a KeyboardInterrupt traceback (exit -2) before ``cli.main`` installed its
handling. Here the three signals are caught before anything else is imported, with the
interpreter's built-in ``_signal`` (already loaded at start-up: ``signal`` itself imports
``enum``, some milliseconds more), until ``outputs.signals.handled`` takes over; a signal
before the command runs is then "interrupted (SIGINT): nothing written" and 130 (143, 129).
The interpreter's own start-up before this module runs (its ``site`` imports, some 20 ms)
is CPython's: a signal there ends the way CPython ends it.
"""

import _signal

_SIGNALS = tuple(getattr(_signal, n) for n in ("SIGINT", "SIGTERM", "SIGHUP")
                 if hasattr(_signal, n))


def main() -> int:
    """Run ``plantmech`` with the arguments of the command line; returns the exit status."""
    got: list[int] = []

    def early(signum, frame):  # until outputs.signals is imported: record and stop
        if not got:
            got.append(signum)
        raise KeyboardInterrupt

    for s in _SIGNALS:
        _signal.signal(s, early)
    try:
        from plantmech.outputs import signals
    except KeyboardInterrupt:
        for s in _SIGNALS:  # ending anyway: a further signal changes nothing now
            _signal.signal(s, _signal.SIG_IGN)
        from plantmech.outputs import signals

        return signals.stopped(signals.Interrupted(got[0] if got else _signal.SIGINT))
    # the command's own handling (cli.main) nests in this one: both leave the three signals
    # ignored at the end, as a program that ends right after does
    with signals.handled(restore=False):
        try:
            from plantmech.interfaces.cli import main as command

            return command()
        except KeyboardInterrupt as exc:  # while the command's modules were imported
            return signals.stopped(exc)
