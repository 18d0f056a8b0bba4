"""Reading a user's input file, the one way every command does it (design files, study
files, a study directory's summary and chunks, a gears directory's files).

A file is opened non-blocking and checked with ``fstat`` before a byte is read: only a
regular file is read (a FIFO, socket or device never hangs or fills the memory), at most
``max_bytes`` (the size is told in the error), as UTF-8 where text is expected. TOML and
JSON are checked for nesting before the parser recurses. Every error is raised as the
caller's exception class, naming the file and what it should have been.
"""

from __future__ import annotations

import json
import os
import stat
import tomllib
from pathlib import Path


class InputFileError(ValueError):
    """An input file that cannot be read as what it should be (names the file)."""


def read_input_bytes(path: str | Path, what: str, max_bytes: int,
                     error: type[Exception] = InputFileError) -> bytes:
    """The bytes of ``path``, a regular file of at most ``max_bytes``; ``error(message)``
    naming ``path`` and ``what`` it should be (e.g. "design file") otherwise."""
    path = Path(path)
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
    except FileNotFoundError:
        raise error(f"{path}: no such {what}") from None
    except IsADirectoryError:
        raise error(f"{path}: is a directory, not a {what}") from None
    except OSError as exc:
        raise error(f"{path}: cannot be opened ({exc.strerror})") from None
    try:
        st = os.fstat(fd)
        if stat.S_ISDIR(st.st_mode):
            raise error(f"{path}: is a directory, not a {what}")
        if not stat.S_ISREG(st.st_mode):
            raise error(f"{path}: not a regular file (a pipe, socket or device); give a {what}")
        if st.st_size > max_bytes:
            raise error(f"{path}: {st.st_size} bytes; a {what} is at most {max_bytes} bytes")
        data = os.read(fd, max_bytes + 1)
    except OSError as exc:
        raise error(f"{path}: cannot be read ({exc.strerror})") from None
    finally:
        os.close(fd)
    if len(data) > max_bytes:  # grew since fstat
        raise error(f"{path}: larger than {max_bytes} bytes; a {what} is at most that")
    return data


def read_input_text(path: str | Path, what: str, max_bytes: int,
                    error: type[Exception] = InputFileError) -> str:
    """:func:`read_input_bytes` decoded as UTF-8."""
    data = read_input_bytes(path, what, max_bytes, error)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        raise error(f"{path}: not a UTF-8 text file") from None


def nesting_depth(text: str) -> int:
    """Deepest bracket nesting outside strings and comments (a cheap guard before a
    parser that recurses once per level: TOML's, JSON's)."""
    depth = best = 0
    quote = None
    i, n = 0, len(text)
    while i < n:
        ch = text[i]
        if quote:
            if ch == "\\" and quote[0] == '"':
                i += 2
                continue
            if text.startswith(quote, i):
                i += len(quote)
                quote = None
                continue
        elif ch == "#":
            j = text.find("\n", i)
            i = n if j < 0 else j
            continue
        elif ch in "\"'":
            quote = ch * 3 if text.startswith(ch * 3, i) else ch
            i += len(quote)
            continue
        elif ch in "[{":
            depth += 1
            best = max(best, depth)
        elif ch in "]}":
            depth = max(depth - 1, 0)
        i += 1
    return best


def parse_toml(text: str, source: str, max_nesting: int, error: type[Exception] = InputFileError,
               needs: str = "") -> dict:
    """TOML text nested at most ``max_nesting`` levels -> dict; ``error`` naming
    ``source`` otherwise (``needs``: how deep the file kind needs, for the message)."""
    if nesting_depth(text) > max_nesting:
        raise error(f"{source}: arrays or tables nested deeper than {max_nesting} levels"
                    + (f"; {needs}" if needs else ""))
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise error(f"{source}: not valid TOML: {exc}") from None
    except RecursionError:
        raise error(f"{source}: arrays or tables nested too deeply") from None


def _no_constant(name: str):
    raise ValueError(f"{name} is not a number JSON allows")


def read_input_json(path: str | Path, what: str, max_bytes: int, max_nesting: int,
                    error: type[Exception] = InputFileError):
    """A JSON file (bounded as :func:`read_input_text`, nested at most ``max_nesting``
    levels, no NaN or Infinity) -> its value."""
    text = read_input_text(path, what, max_bytes, error)
    if nesting_depth(text.replace("#", " ")) > max_nesting:  # JSON has no comments
        raise error(f"{path}: arrays or objects nested deeper than {max_nesting} levels; "
                    f"not a {what}")
    try:
        return json.loads(text, parse_constant=_no_constant)
    except (ValueError, RecursionError) as exc:
        raise error(f"{path}: not a valid {what} (JSON: {exc})") from None
