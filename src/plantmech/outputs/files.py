"""Safe writing of output files: nothing the user gave is overwritten, and a run's files
appear in ``--out`` all together or not at all (:class:`OutputRun`)."""

from __future__ import annotations

import contextlib
import csv
import errno
import json
import math
import os
import shutil
import stat
import tempfile
from pathlib import Path

import numpy as np

#: exit statuses after which a run's files are moved into ``--out`` (done, infeasible,
#: not met); any other status, an exception or Ctrl-C discards them.
RESULT_EXIT_CODES = (0, 3, 4)


def is_no_space(exc: BaseException) -> bool:
    """``exc`` says the device (or the user's quota) is full."""
    return isinstance(exc, OSError) and (exc.errno in (errno.ENOSPC, errno.EDQUOT)
                                         or "No space left on device" in str(exc))


class OutputError(RuntimeError):
    """An output directory cannot be used (the message names it and says why)."""


class NonFiniteOutput(ValueError):
    """A value about to be written is NaN or infinite (the message names the field)."""


def _identity(path: Path) -> tuple[int, int] | None:
    """(st_dev, st_ino) of ``path`` following symlinks, or None if it does not exist."""
    try:
        st = os.stat(path)
    except OSError:
        return None
    return st.st_dev, st.st_ino


def _probe(path: Path, what: str) -> os.stat_result | None:
    """lstat ``path``: None if it does not exist; OutputError for an unusable name."""
    try:
        return os.lstat(path)
    except FileNotFoundError:
        return None
    except NotADirectoryError:
        raise OutputError(f"{what} {path}: a parent of it is a file, not a directory") from None
    except OSError as exc:
        if exc.errno == errno.ENAMETOOLONG:
            raise OutputError(f"{what} {path}: the name is too long for the file system") from None
        raise OutputError(f"{what} {path}: cannot be used ({exc.strerror})") from None


def refuse_link(path: Path, what: str) -> os.stat_result | None:
    """``path``'s lstat (None if it does not exist); OutputError naming it if it is a symbolic
    link: an output is never written through a link (nor does it replace one), whatever it
    points to. The one rule of every command's ``--out`` (directory or file) and ``init``'s
    DIR."""
    st = _probe(Path(path), what)
    if st is not None and stat.S_ISLNK(st.st_mode):
        try:
            target = f" (to {os.readlink(path)})"
        except OSError:
            target = ""
        raise OutputError(f"{what} {path} is a symbolic link{target}: nothing is written "
                          "through a link nor replaces it; give the directory or file itself")
    return st


def _check_out(out: Path, inputs: list[Path], force: bool,
               resume=None) -> tuple[Path, bool]:
    """Validate ``--out``; return the directory the results will be moved to and whether the
    run resumes what it holds (``resume(out)`` true: no --force needed). A ``--out`` that is
    a symbolic link (to a directory or anything else) is refused (:func:`refuse_link`)."""
    if str(out).strip() in ("", "."):
        raise OutputError(f"--out {str(out)!r}: give the name of a new directory (a run "
                          "needs a directory of its own)")
    for part in out.parts:
        if len(part.encode("utf-8", "surrogateescape")) > 255:
            raise OutputError(f"--out {out}: a name is longer than 255 bytes")
    st = refuse_link(out, "--out")
    out = Path(os.path.abspath(out))
    if out == Path(out.anchor) or out == Path(os.path.abspath(".")):
        raise OutputError(f"--out {out}: a run needs a directory of its own (not the current "
                          "directory or the file-system root)")
    out_id = _identity(out)
    cwd = Path(os.path.abspath("."))
    if out_id is not None and any(_identity(a) == out_id for a in [cwd, *cwd.parents]):
        raise OutputError(f"--out {out}: it holds the current directory {cwd}; a run needs "
                          "a directory of its own (never the current directory or one of its "
                          "parents, even with --force)")
    # the nearest existing ancestor must be a writable directory
    parent = out.parent
    while _probe(parent, "--out") is None:
        parent = parent.parent
    if not parent.is_dir():
        raise OutputError(f"--out {out}: {parent} is a file, not a directory")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise OutputError(f"--out {out}: {parent} is not writable")
    in_ids = {i for i in (_identity(p) for p in inputs) if i is not None}
    for p in inputs:
        # the input (as given, and through its links) must not live under --out
        for d in [Path(os.path.abspath(p)).parent, Path(os.path.realpath(p)).parent]:
            for anc in [d, *d.parents]:
                if out_id is not None and _identity(anc) == out_id:
                    raise OutputError(f"--out {out} would hold or overwrite the input {p}; "
                                      "choose another directory")
        if _identity(p) is not None and _identity(p) == out_id:
            raise OutputError(f"--out {out} would hold or overwrite the input {p} (it is "
                              "the input)")
    if st is None:
        return out, False
    if not stat.S_ISDIR(st.st_mode):
        raise OutputError(f"--out {out} exists and is not a directory")
    try:
        entries = sorted(os.listdir(out))
    except OSError as exc:
        raise OutputError(f"--out {out}: cannot be read ({exc.strerror})") from None
    in_dirs = {_identity(p) for p in inputs if p.is_dir()}
    for root, dirs, files in os.walk(out):
        for f in files + dirs:
            p = Path(root) / f
            target = Path(os.path.realpath(p))
            if _identity(p) in in_ids or (p.is_symlink() and any(
                    _identity(a) in in_dirs for a in [target, *target.parents])):
                raise OutputError(f"--out {out} would hold or overwrite the input: "
                                  f"{p} is a link to it; choose another directory")
            mode = os.lstat(p).st_mode
            if not (stat.S_ISREG(mode) or stat.S_ISDIR(mode) or stat.S_ISLNK(mode)):
                raise OutputError(f"--out {out} holds {p}, a device, FIFO or socket: it is "
                                  "never replaced; choose another directory")
    if entries and not force and resume is not None and resume(out):
        return out, True
    if entries and not force:
        shown = ", ".join(entries[:6]) + (f" and {len(entries) - 6} more" if len(entries) > 6
                                          else "")
        raise OutputError(f"--out {out} already holds {len(entries)} entries ({shown}); "
                          "add --force to replace them, or choose another directory")
    return out, False


class OutputRun:
    """Atomic output directory for one command.

    Usage (the CLI's ``run_command`` helper wraps this)::

        with OutputRun(args.out, [Path(args.design)], force=args.force) as run:
            ...write every file into run.path (a fresh temporary directory beside --out)...
            run.exit_code = rc        # 0, 3 or 4: the files are moved into --out

    On leaving the block the files move into ``--out`` only if ``exit_code`` is one of
    :data:`RESULT_EXIT_CODES`, no exception (nor a signal) is propagating and no signal was
    received and swallowed on the way (:mod:`plantmech.outputs.signals`: then the block
    raises :class:`~plantmech.outputs.signals.Interrupted`); otherwise the temporary
    directory is deleted and an existing ``--out`` is left untouched. An existing ``--out``
    with entries is refused unless ``force`` (or ``resume(out)`` says it holds this very run
    to continue: its files are then copied into the temporary directory first, the chunk
    files of a study hard-linked); with ``force`` its old contents are replaced as a whole
    (renamed away, the new directory renamed in, the old one deleted), so old and new files
    never mix. ``--out`` is never the current directory, one of its parents or the root,
    never a symbolic link (not even to a directory: :func:`refuse_link`), and never holds a
    device, FIFO or socket. Inputs are compared by file identity (st_dev,
    st_ino, following symlinks and hard links): a ``--out`` that holds an input or a link to
    one is refused, and files are only ever created in the fresh temporary directory, so
    nothing is written through a link. ``final(p)`` maps a path in ``run.path`` to its place
    in ``--out`` (for messages).
    """

    def __init__(self, out: str | Path, inputs: list[Path], force: bool = False,
                 resume=None):
        if str(out).strip() == "":
            raise OutputError("--out is empty: give the name of a new directory")
        self.requested = Path(out)
        self.out, self.resuming = _check_out(self.requested, [Path(p) for p in inputs], force,
                                             resume)
        self.force = force
        self.exit_code: int | None = None
        self.path: Path | None = None
        self._created: Path | None = None

    def __enter__(self) -> OutputRun:
        from plantmech.outputs import signals

        parent = self.out.parent
        missing = [d for d in [parent, *parent.parents] if not d.exists()]
        self._created = missing[-1] if missing else None  # removed again if the run fails
        with signals.blocked():
            try:
                parent.mkdir(parents=True, exist_ok=True)
                self.path = Path(tempfile.mkdtemp(prefix=".plantmech-", dir=parent))
            except OSError as exc:
                self._remove_created_parents()
                raise OutputError(f"--out {self.requested}: cannot create a directory in "
                                  f"{parent} ({exc.strerror})") from None
        if signals.received() is not None and not signals.finished():
            self._discard()
            signals.check()
        if self.resuming:
            try:
                _seed(self.out, self.path)
            except BaseException:
                self._discard()
                raise
        return self

    def final(self, p: str | Path) -> Path:
        """Where ``p`` (a path inside ``run.path``) will be once the run is committed."""
        p = Path(p)
        try:
            return self.requested / p.relative_to(self.path)
        except ValueError:
            return p

    def __exit__(self, exc_type, exc, tb) -> bool:
        from plantmech.outputs import signals

        with signals.blocked():
            ok = (exc_type is None and self.exit_code in RESULT_EXIT_CODES
                  and signals.received() is None)
            if not ok:
                self._discard()
            else:
                self._commit()
                signals.finish()
        if exc_type is None and self.exit_code in RESULT_EXIT_CODES:
            signals.check()  # a signal swallowed on the way: nothing was committed
        return False

    def _discard(self) -> None:
        shutil.rmtree(self.path, ignore_errors=True)
        self._remove_created_parents()

    def _remove_created_parents(self) -> None:
        """Remove the (empty) parent directories this run created for --out."""
        if self._created is None:
            return
        d = self.out.parent
        while True:
            try:
                d.rmdir()
            except OSError:
                return
            if d == self._created:
                return
            d = d.parent

    def _commit(self) -> None:
        out = self.out
        old = None
        if _probe(out, "--out") is not None:
            if os.listdir(out) and not (self.force or self.resuming):  # filled during the run
                self._discard()
                raise OutputError(f"--out {out} was filled by something else during the run; "
                                  "nothing written")
            old = Path(tempfile.mkdtemp(prefix=".plantmech-old-", dir=out.parent))
            os.rmdir(old)
            os.rename(out, old)
        try:
            os.rename(self.path, out)
        except OSError:
            if old is not None:
                os.rename(old, out)
            self._discard()
            raise
        os.chmod(out, 0o777 & ~_umask())
        if old is not None:
            shutil.rmtree(old, ignore_errors=True)


def _seed(out: Path, staging: Path) -> None:
    """Copy what ``out`` holds into ``staging`` to continue the run there: files that are only
    ever replaced whole (a study's Parquet and npz chunks) hard-linked, every other file
    copied (it may be rewritten in place), links and special files left out."""
    for root, dirs, files in os.walk(out):
        rel = Path(root).relative_to(out)
        for d in dirs:
            if not os.path.islink(Path(root) / d):
                (staging / rel / d).mkdir(exist_ok=True)
        for f in files:
            src, dst = Path(root) / f, staging / rel / f
            if not stat.S_ISREG(os.lstat(src).st_mode):
                continue
            if src.suffix in (".parquet", ".npz"):
                try:
                    os.link(src, dst)
                    continue
                except OSError:
                    pass
            shutil.copy2(src, dst)


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


class OutputFile:
    """Atomic single output file (``schema --out``, ``report --out``, ``init``).

    ``with OutputFile(path, what="--out", force=...) as tmp:`` write ``tmp`` (a fresh file
    beside ``path``); on leaving without an exception or a signal it replaces ``path`` in one
    rename (with the signals held back), else it is deleted and ``path`` is untouched. Two
    files of one command (``plantmech report``'s page and its record) are nested blocks: the
    inner one is put in place first, and the outer one follows it even if a signal came in
    between (the command then ends with its result). The
    rules of :class:`OutputRun` for one file: an existing ``path`` only with ``force`` (and
    without ``force`` a file appearing during the run is not replaced either), never a
    directory, a device, FIFO or socket, never a link (nothing is written through one, and
    the link is not replaced either), never one of ``inputs``."""

    def __init__(self, path: str | Path, what: str = "--out", force: bool = False,
                 inputs: tuple = (), hint: str = "add --force to replace it"):
        if str(path).strip() == "":
            raise OutputError(f"{what} is empty: give a file name")
        self.path = Path(path)
        self.what = what
        self.force = force
        st = refuse_link(self.path, what)
        if st is not None:
            if stat.S_ISDIR(st.st_mode):
                raise OutputError(f"{what} {path} is a directory: give a file name")
            if not stat.S_ISREG(st.st_mode):
                raise OutputError(f"{what} {path} is a device, FIFO or socket: it is never "
                                  "replaced")
            if any(_identity(Path(p)) == _identity(self.path) for p in inputs):
                raise OutputError(f"{what} {path} is an input of this command")
            if not force:
                raise OutputError(f"{what} {path} exists; {hint}")
        parent = _probe(self.path.parent, what)
        if parent is None or not os.path.isdir(self.path.parent):
            raise OutputError(f"{what} {path}: {self.path.parent} is not a directory")
        self.tmp: Path | None = None

    def __enter__(self) -> Path:
        from plantmech.outputs import signals

        with signals.blocked():
            try:
                fd, name = tempfile.mkstemp(prefix=".plantmech-", dir=self.path.parent)
            except OSError as exc:
                raise OutputError(f"{self.what} {self.path}: cannot be written there "
                                  f"({exc.strerror})") from None
            os.close(fd)
            self.tmp = Path(name)
        if signals.received() is not None and not signals.finished():
            self.tmp.unlink(missing_ok=True)
            signals.check()
        return self.tmp

    def __exit__(self, exc_type, exc, tb) -> bool:
        from plantmech.outputs import signals

        with signals.blocked():
            # a signal after another output of the command was put in place (signals.finish:
            # the command ends with its result) does not keep this one from joining it
            if exc_type is not None or (signals.received() is not None
                                        and not signals.finished()):
                self.tmp.unlink(missing_ok=True)
            else:
                os.chmod(self.tmp, 0o666 & ~_umask())
                try:
                    if self.force:
                        os.replace(self.tmp, self.path)  # replaces a link itself, never its target
                    else:
                        os.link(self.tmp, self.path)  # never replaces what appeared meanwhile
                        self.tmp.unlink()
                except OSError as exc:
                    self.tmp.unlink(missing_ok=True)
                    if exc.errno == errno.EEXIST:
                        raise OutputError(f"{self.what} {self.path} was created by something "
                                          "else during the run; nothing written") from None
                    raise
                signals.finish()
        if exc_type is None:
            signals.check()
        return False


def prepare_out_dir(out: str | Path, inputs: list[Path], force: bool = True) -> Path:
    """Create ``out`` in place (non-atomic; for library use): refuse an ``out`` that is an
    input, holds one or a link to one. Commands use :class:`OutputRun` instead."""
    out, _ = _check_out(Path(out), [Path(p) for p in inputs], force)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OutputError(f"--out {out}: cannot be created ({exc.strerror})") from None
    return out


NOT_COMPUTABLE = ("not computable for this design (the geometry or motion it measures does "
                  "not exist, e.g. the inverse design is infeasible: see the diagnostics)")


def _objective_without_value(obj: dict) -> bool:
    """An objective/check dict (name, value, limit) whose value is missing or not finite."""
    if not ("name" in obj and "value" in obj and "limit" in obj):
        return False
    v = obj["value"]
    return v is None or (isinstance(v, float | np.floating) and not math.isfinite(v))


def _clean(obj, where: str = ""):
    if isinstance(obj, dict) and _objective_without_value(obj):
        # reported as not computable, with the reason, and never ok
        obj = {**obj, "value": None, "ok": False,
               "not_computable": obj.get("not_computable") or NOT_COMPUTABLE}
    if isinstance(obj, dict):
        return {k: _clean(v, f"{where}.{k}" if where else str(k)) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_clean(v, f"{where}[{i}]") for i, v in enumerate(obj)]
    if isinstance(obj, np.ndarray):
        return _clean(obj.tolist(), where)
    if isinstance(obj, np.generic):
        obj = obj.item()
    if isinstance(obj, float) and not math.isfinite(obj):
        raise NonFiniteOutput(f"{where} = {obj}: not computable (a non-finite value is never "
                              "written)")
    return obj


#: a job's summary.json (read by people) holds every number to this many significant
#: digits, and says so in its ``precision`` key; the other JSON records keep full precision
SUMMARY_DIGITS = 12
SUMMARY_PRECISION = f"every number to {SUMMARY_DIGITS} significant digits"


def _rounded(obj, digits: int):
    if isinstance(obj, dict):
        return {k: _rounded(v, digits) for k, v in obj.items()}
    if isinstance(obj, list):
        return [_rounded(v, digits) for v in obj]
    if isinstance(obj, float):
        return float(f"{obj:.{digits}g}")
    return obj


def write_json(path: Path, data: dict) -> None:
    """JSON with every float finite; raises NonFiniteOutput naming the field otherwise.
    An objective or check (a dict with name, value, limit) whose value is missing or not
    finite is written with value null, ok false and a ``not_computable`` reason. A file
    named summary.json has its numbers rounded to ``SUMMARY_DIGITS`` significant digits
    and a ``precision`` key saying so."""
    clean = _clean(data)
    if Path(path).name == "summary.json" and isinstance(clean, dict):
        clean = dict(_rounded(clean, SUMMARY_DIGITS), precision=SUMMARY_PRECISION)
    write_text_atomic(path, json.dumps(clean, indent=2, allow_nan=False) + "\n")


def write_text_atomic(path: Path, text: str) -> None:
    """``path`` holds ``text`` whole or is as it was: written to a fresh file beside it and
    renamed over it (a link at ``path`` is replaced, never written through)."""
    path = Path(path)
    fd, name = tempfile.mkstemp(prefix=f".{path.name}.", dir=path.parent)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            fh.write(text)
        os.chmod(name, 0o666 & ~_umask())
        os.replace(name, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(name)
        raise


def write_csv(path: Path, columns: dict[str, np.ndarray], fmt: str = "%.6f",
              gaps: tuple[str, ...] = ()) -> None:
    """Columns of equal length, every value finite; raises NonFiniteOutput naming the
    column and row otherwise. In the columns named in ``gaps`` a NaN marks a documented
    gap (e.g. the sun's toothless sector) and is written as an empty cell."""
    names = list(columns)
    data = [np.asarray(columns[k], dtype=float) for k in names]
    for name, col in zip(names, data, strict=True):
        bad = np.flatnonzero(np.isinf(col) if name in gaps else ~np.isfinite(col))
        if bad.size:
            raise NonFiniteOutput(f"{path.name}: column {name} row {bad[0] + 1} is "
                                  f"{col[bad[0]]}: not computable ({bad.size} such rows)")
    with path.open("w", newline="", encoding="utf-8") as fh:
        w = csv.writer(fh)
        w.writerow(names)
        for row in zip(*data, strict=True):
            w.writerow(["" if np.isnan(v) else fmt % v for v in row])


def check_line(c: dict, name_width: int = 26, digits: int = 2, value_width: int = 14) -> str:
    """One objective/check dict as a console line: status (ok, FAIL, or info for a check
    reported but not required), name, value with unit, limit."""
    val = "n/a" if c["value"] is None else f"{c['value']:.{digits}f} {c['unit']}"
    status = "info" if c.get("required", True) is False else ("ok  " if c["ok"] else "FAIL")
    return (f"  {status} {c['name']:<{name_width}} "
            f"{val:>{value_width}}   limit {c['limit']}")
