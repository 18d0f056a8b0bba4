"""One honest verdict per command: printed last, stored in the JSON record, and the exit status.

Exit status of every command: 0 everything asked of the design is met, 2 invalid input, 3 the
design is infeasible (no mechanism to build), 4 it ran but something is not met (the record says
what), 5 no space left on the device (nothing written), 130 / 143 / 129 stopped by SIGINT
(Ctrl-C) / SIGTERM / SIGHUP (nothing written). Nothing counts as met unless every check says so.
"""

from __future__ import annotations

EXIT_OK, EXIT_INPUT, EXIT_INFEASIBLE, EXIT_NOT_MET, EXIT_NO_SPACE = 0, 2, 3, 4, 5


def verdict(*check_lists, infeasible: bool = False, problems: list[str] | None = None) -> dict:
    """{status, ok, exit_code, failed}: ``check_lists`` are lists of check dicts (name, ok);
    ``problems`` further reasons for "not met" (a file that is not what it claims, a failed
    re-check, a check not run), listed first: the verdict line shows the first eight."""
    failed = list(problems or [])
    failed += [c["name"] for checks in check_lists for c in checks if not c.get("ok")]
    if infeasible:
        return {"status": "infeasible", "ok": False, "exit_code": EXIT_INFEASIBLE,
                "failed": failed}
    ok = not failed
    return {"status": "ok" if ok else "not met", "ok": ok,
            "exit_code": EXIT_OK if ok else EXIT_NOT_MET, "failed": failed}


def verdict_line(v: dict, what: str, caveats=()) -> str:
    """The line every command prints last, after its ``caveats`` (``outputs.caveats``: dicts
    or texts), one "caveat:" line each."""
    from plantmech.outputs.caveats import lines

    head_lines = "".join(f"{line}\n" for line in lines(caveats))
    if v["status"] == "ok":
        return f"{head_lines}verdict: ok - {what}"
    head = "INFEASIBLE" if v["status"] == "infeasible" else "NOT MET"
    n = len(v["failed"])
    listed = ", ".join(v["failed"][:8]) + (f" and {n - 8} more" if n > 8 else "")
    return f"{head_lines}verdict: {head}" + (f" - {n} not met: {listed}" if n else "")
