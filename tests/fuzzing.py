"""Seeded fuzzer of the design files and the commands (issue 19).

Each case takes one bundled example (``examples/*.toml``), applies one to three seeded
mutations and runs one command in this process (``inverse``, ``forward``, ``gears`` or
``optimize --generations 2``) through ``plantmech.interfaces.cli.main``. The same seed
always gives the same cases.

The oracle: a case FAILS, and is tallied under its kind, when

- ``traceback``: an exception escapes ``main`` (anything but argparse's SystemExit 2);
- ``hang``: the command runs longer than ``--timeout`` seconds (60 s by default; a
  timer interrupts it; an exception escaping after the time limit counts as a hang).
  ``--clock wall`` (the default) counts wall seconds; ``--clock cpu`` counts the CPU
  seconds the case uses (this process and the children it waited for), for a machine
  shared with other work, where wall time measures the neighbours; a case blocked
  without using CPU is still stopped after 10 x ``--timeout`` wall seconds. The tally
  records both clocks for every case;
- ``non_finite``: a written file holds a non-finite value: ``NaN``/``Infinity`` in a
  JSON file, an objective/check dict whose ``value`` is null without a
  ``not_computable`` reason, or a CSV cell that is empty, ``nan`` or ``inf``;
- ``silently_accepted``: the mutation made the design invalid (the mutators below say
  which ones do: a wrong type such as ``true``, ``"254"`` or ``3.0`` for a number or an
  index, an unknown or missing field, a coordinate or size out of range, a non-positive
  length, section indices equal or out of order, duplicate or collinear type-value
  points, a zero-length dwell, a mechanism that is not a known name, nesting too deep,
  too many points) and the command did not exit 2;
  a value refused at writing (exit 3, "not computable") counts here too, as a value
  the engine should have computed or refused earlier;
- ``bad_exit``: exit 2 without an ``error:`` line on stderr, or an exit status other
  than 0, 2, 3, 4;
- ``left_behind``: exit 2 with the output directory (or a temporary directory beside
  it) left on disk, or exit 0/3/4 without it.

Mutations that keep the design valid (small perturbations of numbers and points) may
end in any of 0, 2, 3, 4; they drive the engine into odd corners.

``python -m tests.fuzzing --cases N --seed S --out DIR`` runs N cases and writes
``DIR/tally.json`` (counts by command and kind, and every failing case with its design
and output) and prints the tally; ``tests/test_fuzz_corpus.py`` runs a fixed-seed corpus
in CI. Cases run with samples reduced to 360 per turn (``--full`` keeps the files'
samples) so that thousands of cases fit in a few hours.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import math
import random
import shutil
import signal
import sys
import time
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
# the examples the cases mutate, fixed so that a new example does not change the seeded
# corpus (the cases' numbers in the regression tests stay the same designs)
CORPUS_EXAMPLES = ("rice_transplanter", "rice_transplanter_khv", "rice_transplanter_toothed",
                   "sugarcane_seeder", "sugarcane_seeder_dwell", "sugarcane_seeder_g",
                   "sugarcane_seeder_optimized", "sugarcane_table2_as_printed",
                   "sugarcane_table4")
COMMANDS = ("inverse", "forward", "gears", "optimize")


@dataclass
class Case:
    """One fuzz case: the example, the mutations, the design text and the command."""

    index: int
    example: str
    command: str
    mutations: list[str] = field(default_factory=list)
    invalid: bool = False
    text: str = ""
    extra_args: list[str] = field(default_factory=list)
    # a case of another input kind (``tests.fuzz_inputs``): ``prepare(work)`` lays out its
    # files and returns (argv, out: the directory or file it may write); ``check(work, rc)``
    # says what it left wrong (a file written outside --out / DIR), or None
    prepare: object = None
    check: object = None


# --- mutations ------------------------------------------------------------------------


def _leaves(obj, path=()):
    """Every (path, value) of scalars and lists in a parsed TOML document."""
    if isinstance(obj, dict):
        for k, v in obj.items():
            yield from _leaves(v, (*path, k))
    elif isinstance(obj, list):
        yield path, obj
        for i, v in enumerate(obj):
            if not isinstance(v, dict):
                yield from _leaves(v, (*path, i))
    else:
        yield path, obj


def _get(doc, path):
    for p in path:
        doc = doc[p]
    return doc


def _set(doc, path, value):
    _get(doc, path[:-1])[path[-1]] = value


def _numbers(doc):
    return [(p, v) for p, v in _leaves(doc)
            if isinstance(v, int | float) and not isinstance(v, bool)
            and p and p[0] not in ("name", "description")]


def _points_path(doc):
    if "trajectory" in doc and "points" in doc["trajectory"]:
        return ("trajectory", "points")
    return None


def m_bool_for_number(doc, rng):
    p, _ = rng.choice(_numbers(doc))
    _set(doc, p, rng.choice([True, False]))
    return f"{_name(p)} = bool", True


def m_string_for_number(doc, rng):
    p, v = rng.choice(_numbers(doc))
    _set(doc, p, str(v))
    return f"{_name(p)} = string {str(v)!r}", True


def m_float_for_int(doc, rng):
    ints = [(p, v) for p, v in _numbers(doc) if isinstance(v, int)]
    if not ints:
        return m_bool_for_number(doc, rng)
    p, v = rng.choice(ints)
    _set(doc, p, float(v))
    # a float where a float is allowed stays valid: only indices and counts are ints
    is_int = (p[-1] in ("samples", "lobes", "teeth", "arms")
              or (len(p) > 1 and p[-2] == "sections" and p[-1] in "abcdef"))
    return f"{_name(p)} = {float(v)}", is_int


def m_huge(doc, rng):
    p, _ = rng.choice(_numbers(doc))
    v = rng.choice([1e300, -1e300, 1e150, 1e20])
    _set(doc, p, v)
    return f"{_name(p)} = {v:g}", True


def m_nan(doc, rng):
    p, _ = rng.choice(_numbers(doc))
    v = rng.choice([math.nan, math.inf, -math.inf])
    _set(doc, p, v)
    return f"{_name(p)} = {v}", True


def m_zero_or_negative(doc, rng):
    p, v = rng.choice(_numbers(doc))
    new = rng.choice([0, -abs(v) - 1])
    _set(doc, p, new)
    # only fields that must be positive make this invalid; the oracle does not guess
    return f"{_name(p)} = {new} (may be valid)", False


def m_perturb(doc, rng):
    p, v = rng.choice(_numbers(doc))
    new = v * (1 + rng.gauss(0, 0.05)) if isinstance(v, float) else v + rng.choice([-1, 1])
    _set(doc, p, new)
    return f"{_name(p)} perturbed to {new:g} (may be valid)", False


def m_perturb_points(doc, rng):
    pp = _points_path(doc)
    if pp is None:
        return m_perturb(doc, rng)
    pts = _get(doc, pp)
    s = rng.choice([1.0, 5.0, 20.0])
    for q in pts:
        q[0] += rng.gauss(0, s)
        q[1] += rng.gauss(0, s)
    return f"points moved by ~{s} mm (may be valid)", False


def m_sections_equal(doc, rng):
    sec = doc.get("trajectory", {}).get("sections")
    if not sec:
        return m_unknown_field(doc, rng)
    letters = rng.choice([list("abcdef"), ["b", "f"], ["c", "a"], ["d", "e"]])
    for x in letters[1:]:
        sec[x] = sec[letters[0]]
    return f"sections {'='.join(letters)} equal", True


def m_sections_swap(doc, rng):
    sec = doc.get("trajectory", {}).get("sections")
    if not sec:
        return m_unknown_field(doc, rng)
    x, y = rng.sample("abcdef", 2)
    sec[x], sec[y] = sec[y], sec[x]
    return f"sections {x} and {y} swapped", True


def m_collinear(doc, rng):
    pp = _points_path(doc)
    if pp is None:
        return m_huge(doc, rng)
    pts = _get(doc, pp)
    for i, q in enumerate(pts):
        q[0], q[1] = 200.0 + 10.0 * i, 50.0 + 5.0 * i
    return "points collinear", True


def m_duplicate_point(doc, rng):
    pp = _points_path(doc)
    if pp is None:
        return m_huge(doc, rng)
    pts = _get(doc, pp)
    i = rng.randrange(len(pts))
    j = (i + rng.choice([1, 3, 7])) % len(pts)
    pts[j] = list(pts[i])
    return f"point q{j} = q{i}", True


def m_densify(doc, rng):
    pp = _points_path(doc)
    if pp is None:
        return m_huge(doc, rng)
    pts = _get(doc, pp)
    k = rng.choice([40, 400])
    dense = []
    for i in range(len(pts)):
        a, b = pts[i], pts[(i + 1) % len(pts)]
        dense += [[a[0] + (b[0] - a[0]) * t / k, a[1] + (b[1] - a[1]) * t / k]
                  for t in range(k)]
    _set(doc, pp, dense)
    return f"points densified x{k} ({len(dense)} points)", True


def m_scale_points(doc, rng):
    pp = _points_path(doc)
    if pp is None:
        return m_huge(doc, rng)
    f = rng.choice([1e150, 1e6, 1e-12])
    for q in _get(doc, pp):
        q[0] *= f
        q[1] *= f
    return f"points scaled x{f:g}", True


def m_dwell_zero(doc, rng):
    if "trajectory" not in doc:
        return m_huge(doc, rng)
    gt = doc.setdefault("gear_train", {})
    x = rng.choice("abcdef")
    gt["dwell"] = {"enabled": True, "start": x, "end": x, "anchor": "e"}
    return f"dwell {x}-{x}", True


def m_dwell_off_turn(doc, rng):
    if "train" not in doc:
        return m_dwell_zero(doc, rng)
    doc["train"]["dwell"] = {"start_deg": rng.choice([300.0, 359.0]), "sector_deg": 90.0}
    return "train.dwell past the end of the turn", True


def m_unknown_field(doc, rng):
    tables = [p for p, v in _leaves(doc) if isinstance(v, dict)] or [()]
    t = _get(doc, rng.choice(tables)) if tables else doc
    t["colour"] = "blue"
    return "unknown field 'colour'", True


def m_delete_field(doc, rng):
    keys = [k for k in doc if k not in ("name", "description")]
    k = rng.choice(keys)
    del doc[k]
    required = {"mechanism", "carrier", "arm", "seedling_box", "internal_gear", "sun_gear"}
    has_both = "trajectory" in doc or "train" in doc
    invalid = k in required or (doc.get("mechanism") == "sugarcane_seeder" and not has_both)
    return f"deleted [{k}]", invalid


def m_mechanism(doc, rng):
    v = rng.choice([["sugarcane_seeder"], 3, "rice_transplanter", "rice_transplanter_khv",
                    "sugarcane_seeder", "windmill", {"a": 1}])
    same = v == doc.get("mechanism")
    doc["mechanism"] = v
    return f"mechanism = {v!r}", not same


def m_list_for_scalar(doc, rng):
    p, v = rng.choice(_numbers(doc))
    _set(doc, p, [v, v])
    return f"{_name(p)} = [v, v]", True


def m_string_for_list(doc, rng):
    lists = [(p, v) for p, v in _leaves(doc) if isinstance(v, list) and p]
    if not lists:
        return m_unknown_field(doc, rng)
    p, _ = rng.choice(lists)
    _set(doc, p, "1, 2, 3")
    return f"{_name(p)} = string", True


def m_empty_list(doc, rng):
    lists = [(p, v) for p, v in _leaves(doc) if isinstance(v, list) and p
             and len(v) > 0 and not isinstance(p[-1], int)]
    if not lists:
        return m_unknown_field(doc, rng)
    p, _ = rng.choice(lists)
    _set(doc, p, [])
    return f"{_name(p)} = []", True


def m_truncate_list(doc, rng):
    lists = [(p, v) for p, v in _leaves(doc) if isinstance(v, list) and len(v) > 4
             and not isinstance(p[-1], int)]
    if not lists:
        return m_perturb(doc, rng)
    p, v = rng.choice(lists)
    n = rng.choice([1, 3, len(v) - 1])
    _set(doc, p, v[:n])
    # shorter lists can be valid (radii); fewer than 4 radii or 6 points never are
    return f"{_name(p)} cut to {n}", n < 4


def m_extreme_box(doc, rng):
    if "seedling_box" not in doc:
        return m_perturb(doc, rng)
    key = rng.choice(["x_mm", "y_mm", "sample_mm", "length_mm", "mat_thickness_mm"])
    v = rng.choice([1e6, 1e-6, 5000.0, 0.01])
    doc["seedling_box"][key] = v
    depth = None
    if rng.random() < 0.5:
        depth = rng.choice([1e6, 1e-6, 900.0])
        doc.setdefault("field", {})["planting_depth_mm"] = depth
    return (f"seedling_box.{key} = {v:g}, planting depth {depth} (may be valid)",
            v == 1e6 or depth == 1e6)


MUTATORS = [
    (m_bool_for_number, 2), (m_string_for_number, 2), (m_float_for_int, 2), (m_huge, 2),
    (m_nan, 1), (m_zero_or_negative, 2), (m_perturb, 4), (m_perturb_points, 3),
    (m_sections_equal, 1), (m_sections_swap, 1), (m_collinear, 1), (m_duplicate_point, 1),
    (m_densify, 1), (m_scale_points, 1), (m_dwell_zero, 1), (m_dwell_off_turn, 1),
    (m_unknown_field, 1), (m_delete_field, 1), (m_mechanism, 1), (m_list_for_scalar, 1),
    (m_string_for_list, 1), (m_empty_list, 1), (m_truncate_list, 1), (m_extreme_box, 2),
]


BENIGN = {m_perturb, m_perturb_points, m_zero_or_negative, m_extreme_box}


def _name(path) -> str:
    return ".".join(str(p) for p in path)


def _deep_nesting(rng) -> str:
    depth = rng.choice([50, 2000])
    return 'mechanism = "sugarcane_seeder"\nx = ' + "[" * depth + "]" * depth + "\n"


def make_case(index: int, seed: int, full: bool = False) -> Case:
    """The index-th case of a seed: an example, mutations, a command (deterministic)."""
    import tomli_w

    rng = random.Random(f"{seed}:{index}")
    examples = [EXAMPLES / f"{n}.toml" for n in CORPUS_EXAMPLES]
    ex = rng.choice(examples)
    doc = tomllib.loads(ex.read_text(encoding="utf-8"))
    command = rng.choices(COMMANDS, weights=(40, 40, 6, 14))[0]
    case = Case(index, ex.name, command)
    if rng.random() < 0.01:
        case.text, case.invalid = _deep_nesting(rng), True
        case.mutations.append("deep nesting")
        return case
    if not full:
        _fast(doc)
    if rng.random() > 0.03:  # a few cases run the example unmodified
        fns, weights = zip(*MUTATORS, strict=True)
        picked = rng.choices(fns, weights=weights, k=rng.choice([1, 1, 1, 2, 3]))
        # perturbations first, then at most one other mutation: a later mutation must not
        # undo an earlier one (moving a point that was set to `true` makes it a number)
        benign = [f for f in picked if f in BENIGN]
        others = [f for f in picked if f not in BENIGN][:1]
        for fn in benign + others:
            try:
                what, invalid = fn(doc, rng)
            except (KeyError, IndexError, TypeError, ValueError):
                continue
            case.mutations.append(what)
            case.invalid |= invalid
    try:
        case.text = tomli_w.dumps(doc)
    except (TypeError, ValueError):  # e.g. a list mixing types: write it by hand
        case.text = _toml_by_hand(doc)
    if command == "optimize":
        problem = ("transplanter" if doc.get("mechanism") in
                   ("rice_transplanter", "rice_transplanter_khv")
                   else rng.choice(["seeder-layer1", "seeder-layer2"]))
        case.extra_args = ["--problem", problem, "--generations", "2", "--pop", "8",
                           "--quiet"]
    elif command in ("inverse", "forward"):
        case.extra_args = ["--no-plots"]
    elif command == "gears":
        case.extra_args = ["--module", rng.choice(["4", "6", "10"])]
    return case


def _fast(doc) -> None:
    """Fewer samples per turn (360) so a case takes about a second."""
    for table in (doc.get("trajectory"), doc.get("train"), doc):
        if isinstance(table, dict) and "samples" in table:
            table["samples"] = 360
    if doc.get("mechanism") in ("rice_transplanter", "rice_transplanter_khv"):
        doc["samples"] = 360


def _toml_by_hand(doc) -> str:
    return json.dumps(doc).replace('": ', '" = ')  # not TOML: exercises the parser error


# --- oracle ---------------------------------------------------------------------------


class Hang(BaseException):
    """Raised by the alarm when a case runs past its time limit."""


def _non_finite_in(path: Path) -> str | None:
    """Where a written file holds a non-finite value, or None."""
    if path.suffix == ".json":
        text = path.read_text(encoding="utf-8")
        bad: list[str] = []

        def walk(o, where):
            if isinstance(o, float) and not math.isfinite(o):
                bad.append(where)
            elif isinstance(o, dict):
                if ("name" in o and "value" in o and o["value"] is None
                        and "not_computable" not in o):
                    bad.append(f"{where}.value (null objective)")
                for k, v in o.items():
                    walk(v, f"{where}.{k}")
            elif isinstance(o, list):
                for i, v in enumerate(o):
                    walk(v, f"{where}[{i}]")

        walk(json.loads(text), path.name)
        return bad[0] if bad else None
    if path.suffix == ".csv":
        lines = path.read_text(encoding="utf-8").splitlines()
        allowed = _empty_allowed(path, lines[0].split(",") if lines else [])
        for r, line in enumerate(lines[1:], start=1):
            for c, cell in enumerate(line.split(",")):
                if c in allowed and cell == "":
                    continue
                if cell == "" or cell.strip().lower().lstrip("+-") in ("nan", "inf",
                                                                         "infinity"):
                    return f"{path.name} row {r} column {c} = {cell!r}"
    return None


def _empty_allowed(path: Path, header: list[str]) -> set[int]:
    """Columns where an empty cell is documented: the sun's toothless sector in
    pitch_curves.csv, the speed ratios while the gears stand still in motion.csv."""
    names = {"pitch_curves.csv": ("r1_mm",),
             "motion.csv": ("ratio", "stage1_ratio", "stage2_ratio")}.get(path.name, ())
    return {i for i, h in enumerate(header) if h in names}


def _cpu_seconds() -> float:
    """CPU seconds used so far by this process and the children it waited for."""
    import os

    t = os.times()
    return t.user + t.system + t.children_user + t.children_system


def run_case(case: Case, work: Path, timeout: float, clock: str = "wall") -> dict:
    """Run one case; the verdict dict has ``kind`` None (passed) or the failure kind.
    ``clock``: "wall" or "cpu", what ``timeout`` (s) counts (module docstring)."""
    from plantmech.interfaces.cli import main

    work.mkdir(parents=True, exist_ok=True)
    design = work / f"case{case.index}.toml"
    if case.prepare is not None:
        argv, out = case.prepare(work)
    else:
        design.write_text(case.text, encoding="utf-8")
        out = work / f"out{case.index}"
        argv = [case.command, str(design), "--out", str(out), *case.extra_args]
    stdout, stderr = io.StringIO(), io.StringIO()
    kind, detail, rc = None, "", None

    def on_alarm(signum, frame):
        raise Hang()

    old = signal.signal(signal.SIGALRM, on_alarm)
    old_prof = signal.signal(signal.SIGPROF, on_alarm)
    if clock == "cpu":
        signal.setitimer(signal.ITIMER_PROF, timeout)
        signal.setitimer(signal.ITIMER_REAL, 10 * timeout)
    else:
        signal.setitimer(signal.ITIMER_REAL, timeout)
    t0 = time.perf_counter()
    c0 = _cpu_seconds()
    try:
        with contextlib.redirect_stdout(stdout), contextlib.redirect_stderr(stderr):
            rc = main(argv)
    except Hang:
        kind, detail = "hang", f"over {timeout:g} s"
    except SystemExit as exc:
        rc = exc.code
    except BaseException as exc:  # noqa: BLE001 - the oracle records every escape
        import traceback

        tb = traceback.extract_tb(exc.__traceback__)
        where = next((f"{Path(f.filename).name}:{f.lineno}" for f in reversed(tb)
                      if "plantmech" in f.filename), "?")
        kind, detail = "traceback", f"{type(exc).__name__} at {where}: {str(exc)[:200]}"
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.setitimer(signal.ITIMER_PROF, 0)
        signal.signal(signal.SIGALRM, old)
        signal.signal(signal.SIGPROF, old_prof)
    wall = time.perf_counter() - t0
    cpu = _cpu_seconds() - c0
    if kind == "hang" and clock == "cpu":
        detail = (f"blocked: over {10 * timeout:g} wall s" if wall >= 9.9 * timeout
                  else f"over {timeout:g} CPU s")
    if kind == "traceback" and (cpu >= 0.8 * timeout or wall >= 9.9 * timeout
                                if clock == "cpu" else wall >= timeout):
        # the alarm's Hang raised inside a library that turns what it catches into its
        # own error (trimesh reports a failed optional import as "no graph engines
        # available"): the case ran out of time
        kind, detail = "hang", f"over {timeout:g} s (surfaced as {detail[:120]})"
    err = stderr.getvalue()
    leftovers = [p.name for p in out.parent.glob(".plantmech-*")]
    if kind is None:
        if rc not in (0, 2, 3, 4):
            kind, detail = "bad_exit", f"exit {rc}"
        elif rc == 2 and "error" not in err:
            kind, detail = "bad_exit", "exit 2 without an error message"
        elif case.invalid and rc != 2:
            kind, detail = "silently_accepted", f"exit {rc} for {case.mutations}"
        elif rc == 2 and (out.exists() or leftovers):
            kind, detail = "left_behind", f"exit 2 left {out.name} {leftovers}"
        elif rc == 3 and "not computable" in err:
            kind, detail = "non_finite", "refused at writing: " + err.strip()[-300:]
        elif rc in (0, 3, 4) and not out.exists():
            kind, detail = "left_behind", f"exit {rc} but no {out.name}"
        elif leftovers:
            kind, detail = "left_behind", f"temporary directories {leftovers}"
        elif case.check is not None and (wrong := case.check(work, rc)):
            kind, detail = "left_behind", wrong
    if kind is None and out.is_dir():
        for f in sorted(out.rglob("*")):
            if f.is_file() and f.suffix in (".json", ".csv"):
                where = _non_finite_in(f)
                if where:
                    kind, detail = "non_finite", where
                    break
    verdict = {"case": case.index, "example": case.example, "command": case.command,
               "mutations": case.mutations, "invalid": case.invalid, "exit": rc,
               "wall_s": round(wall, 3), "cpu_s": round(cpu, 3), "kind": kind,
               "detail": detail}
    if kind is not None:
        verdict["design"] = case.text[:20000]
        verdict["stderr"] = err[-2000:]
    if out.is_dir() and not out.is_symlink():
        shutil.rmtree(out, ignore_errors=True)
    elif out.exists() or out.is_symlink():
        out.unlink()
    for p in out.parent.glob(".plantmech-*"):
        shutil.rmtree(p, ignore_errors=True)
    design.unlink(missing_ok=True)
    return verdict


def run_fuzz(cases: int, seed: int, work: Path, timeout: float = 60.0, full: bool = False,
             start: int = 0, log=None, checkpoint=None, commands=COMMANDS,
             clock: str = "wall") -> dict:
    """Run ``cases`` cases; return the tally (counts by command and kind, failures).
    ``checkpoint(tally)`` is called every 25 cases (the tally so far). ``commands``: run
    only the cases of these commands (the others are counted under ``skipped``; the
    cases keep their numbers, so runs of disjoint command sets add up to the whole)."""
    import matplotlib

    matplotlib.use("Agg")
    work.mkdir(parents=True, exist_ok=True)
    tally = {"seed": seed, "cases": 0, "timeout_s": timeout, "clock": clock,
             "by_command": {}, "failures": [], "exit_codes": {}, "max_wall_s": 0.0,
             "max_cpu_s": 0.0, "over_timeout_wall": 0, "skipped": 0, "slowest": {}}
    t0 = time.perf_counter()
    for i in range(start, start + cases):
        case = make_case(i, seed, full)
        if case.command not in commands:
            tally["skipped"] += 1
            continue
        v = run_case(case, work, timeout, clock)
        tally["cases"] += 1
        tally["max_cpu_s"] = max(tally["max_cpu_s"], v["cpu_s"])
        tally["over_timeout_wall"] += v["wall_s"] > timeout
        c = tally["by_command"].setdefault(v["command"], {
            "cases": 0, "traceback": 0, "hang": 0, "non_finite": 0, "silently_accepted": 0,
            "bad_exit": 0, "left_behind": 0})
        c["cases"] += 1
        tally["exit_codes"][str(v["exit"])] = tally["exit_codes"].get(str(v["exit"]), 0) + 1
        tally["max_wall_s"] = max(tally["max_wall_s"], v["wall_s"])
        slow = tally["slowest"].get(v["command"])
        if slow is None or v["wall_s"] > slow["wall_s"]:
            tally["slowest"][v["command"]] = {k: v[k] for k in ("case", "example", "mutations",
                                                                "exit", "wall_s", "cpu_s")}
        if v["kind"]:
            c[v["kind"]] += 1
            tally["failures"].append(v)
        if checkpoint is not None and tally["cases"] % 25 == 0:
            tally["load_avg"] = _load()
            tally["wall_s"] = round(time.perf_counter() - t0, 1)
            checkpoint(tally)
        if log is not None:
            log(f"{i} {v['command']} {v['example']} exit {v['exit']} {v['wall_s']:.2f}s "
                f"cpu {v['cpu_s']:.2f}s "
                f"{v['kind'] or 'ok'} {v['detail'][:160]}")
    tally["wall_s"] = round(time.perf_counter() - t0, 1)
    tally["load_avg"] = _load()
    return tally


def _load() -> list[float] | None:
    """The machine's load average (1, 5, 15 min), where the system tells it."""
    try:
        import os

        return [round(x, 2) for x in os.getloadavg()]
    except (AttributeError, OSError):
        return None


def corpus(seed: int = 0, size: int = 120) -> list[Case]:
    """The CI corpus: the first cases of ``seed`` that are cheap to run (every invalid
    design, valid inverse/forward cases, at most 3 valid optimize cases and no valid
    gears case: cutting teeth takes a minute a design on a loaded machine)."""
    out, optimize, i = [], 0, 0
    while len(out) < size:
        c = make_case(i, seed)
        i += 1
        if not c.invalid and c.command == "gears":
            continue
        if not c.invalid and c.command == "optimize":
            if optimize >= 3:
                continue
            optimize += 1
        out.append(c)
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", type=int, default=10_000)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--start", type=int, default=0, help="first case index")
    ap.add_argument("--timeout", type=float, default=60.0, help="seconds per case")
    ap.add_argument("--out", default="out/fuzz", help="directory for tally.json")
    ap.add_argument("--full", action="store_true", help="keep the files' sample counts")
    ap.add_argument("--clock", choices=("wall", "cpu"), default="wall",
                    help="what --timeout counts: wall seconds, or the case's CPU seconds "
                         "(a shared machine; blocked cases still stop at 10 x --timeout wall)")
    ap.add_argument("--commands", default=",".join(COMMANDS),
                    help="comma-separated commands whose cases run (default: all)")
    args = ap.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    logf = (out / "cases.log").open("a", encoding="utf-8")

    def log(line):
        logf.write(line + "\n")
        logf.flush()

    def save(tally):
        tmp = out / "tally.json.tmp"
        tmp.write_text(json.dumps(tally, indent=2) + "\n", encoding="utf-8")
        tmp.replace(out / "tally.json")

    commands = tuple(c for c in args.commands.split(",") if c)
    unknown = sorted(set(commands) - set(COMMANDS))
    if unknown:
        ap.error(f"--commands: unknown {unknown} (known: {', '.join(COMMANDS)})")
    tally = run_fuzz(args.cases, args.seed, out / "work", args.timeout, args.full,
                     args.start, log, checkpoint=save, commands=commands,
                     clock=args.clock)
    tally["finished"] = True
    save(tally)
    failed = len(tally["failures"])
    print(json.dumps({k: tally[k] for k in ("cases", "skipped", "clock", "by_command",
                                            "exit_codes", "max_wall_s", "max_cpu_s",
                                            "over_timeout_wall", "slowest", "wall_s",
                                            "load_avg")},
                     indent=2))
    print(f"{failed} failing cases (details in {out / 'tally.json'})")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
