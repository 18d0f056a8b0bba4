"""Seeded fuzzer of the inputs other than design files (issue 29): study files
(``study --spec``), a study directory's ``summary.json``/``study.json`` and Parquet chunks
(``report``), a gears directory's DXF files (``verify --gears``), the numeric options of
every command, and ``init --name``.

Each case lays out its files in its own directory and runs one command in this process
through ``tests.fuzzing.run_case``, whose oracle judges it: no traceback, no hang, an
invalid input refused with exit 2 and an ``error:`` line and nothing left behind, a
valid one run to a result (exit 0/3/4) with no non-finite value written; and (``init``)
no file written outside DIR. The same seed always gives the same cases.

``python -m tests.fuzz_inputs --cases N --seed S --out DIR`` runs N cases and writes
``DIR/tally.json``; ``tests/test_fuzz_inputs.py`` runs a fixed corpus of the invalid and
cheap cases of seed 0 in CI.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import random
import shutil
import sys
import tomllib
from pathlib import Path

from tests.fuzzing import Case, run_case

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"
KINDS = ("spec", "summary", "chunks", "gears", "option", "init_name")
SPECS = {"seeder_tolerance": "sugarcane_seeder_optimized.toml",
         "seeder_sweep": "sugarcane_seeder_optimized.toml",
         "seeder_multistart": "sugarcane_seeder_optimized.toml",
         "transplanter_tolerance": "rice_transplanter.toml",
         "transplanter_sweep": "rice_transplanter.toml",
         "planetary_tolerance": "rotary_transplanter_elliptic.toml"}


def _case_dir(work: Path, index: int) -> Path:
    d = work / f"in{index}"
    if d.exists() or d.is_symlink():
        shutil.rmtree(d, ignore_errors=True)
    d.mkdir(parents=True)
    return d


def _special(path: Path, what: str) -> None:
    """Put an odd thing where a file is expected."""
    if what == "fifo":
        os.mkfifo(path)
    elif what == "directory":
        path.mkdir()
    elif what == "dev_zero":
        path.symlink_to("/dev/zero")
    elif what == "binary":
        path.write_bytes(bytes(random.Random(str(path)).randrange(256) for _ in range(4096)))
    elif what == "empty":
        path.write_bytes(b"")
    elif what == "huge":
        with open(path, "wb") as fh:  # sparse: larger than any input of its kind
            fh.truncate(600_000_000)
    elif what == "deep":
        path.write_text('kind = "sweep"\nx = ' + "[" * 3000 + "]" * 3000 + "\n")
    elif what == "missing":
        pass
    else:  # pragma: no cover
        raise ValueError(what)


SPECIAL = ("fifo", "directory", "dev_zero", "binary", "empty", "huge", "deep", "missing")


# --- study files ---------------------------------------------------------------------------


def _small(spec: dict) -> None:
    """A study that runs in seconds: few designs, coarse cycles."""
    spec["cycle_samples"] = 90
    if "dense" in spec or spec.get("kind") != "multi-start":
        spec.pop("dense", None)
    if spec["kind"] == "tolerance":
        spec.update(samples=4, chunk=4)
    elif spec["kind"] == "sweep":
        spec["chunk"] = 8
        if spec.get("method") == "lhs":
            spec["samples"] = 4
        for p in spec["parameters"].values():
            p["levels"] = 2
        spec["parameters"] = dict(list(spec["parameters"].items())[:2])
    else:
        spec.pop("cycle_samples")
        spec.update(starts=1, generations=1, pop=4)


def _spec_mutations(spec: dict, rng) -> tuple[str, bool]:
    """Mutate a (small) spec; (what, invalid)."""
    kind = spec["kind"]
    params = spec.get("parameters", {})
    name = rng.choice(list(params)) if params else None
    options = ["samples_huge", "grid_huge", "value_huge", "value_nan", "seed_negative",
               "seed_wide", "kind_wrong", "unknown_field", "no_parameters", "chunk_zero",
               "low_above_high", "unknown_distribution", "unknown_parameter", "too_many_chunks",
               "valid", "valid", "valid", "valid"]  # a quarter of them run a study
    if kind == "multi-start":
        options = ["problem_bogus", "algorithm_bogus", "problem_other_mechanism",
                   "seed_wide", "seed_negative", "kind_wrong", "unknown_field", "starts_zero",
                   "valid", "valid"]
    what = rng.choice(options)
    if what == "valid":
        return "valid", False
    if what == "samples_huge":
        spec["samples"] = rng.choice([10**8, 10**9, 2**63 - 1])
        if kind == "sweep":
            spec["method"] = "lhs"
    elif what == "grid_huge":
        spec.update(kind="sweep", method="grid")
        spec["parameters"] = {n: {"low": 0.0, "high": 1.0, "levels": 1000}
                              for n in ("L2_mm", "a1_mm", "S_mm")}
        spec.pop("samples", None)
    elif what in ("value_huge", "value_nan"):
        p = params[name]
        key = rng.choice([k for k in p if isinstance(p[k], float | int)
                          and k != "levels"] or ["low"])
        p[key] = 1e308 if what == "value_huge" else math.nan
    elif what == "seed_negative":
        spec["seed"] = -1
    elif what == "seed_wide":
        spec["seed"] = 2**32 + rng.randrange(10**6)
    elif what == "kind_wrong":
        spec["kind"] = rng.choice([["tolerance"], 3, "montecarlo", True])
    elif what == "unknown_field":
        spec[rng.choice(["sample", "chunks", "workers"])] = 1
    elif what == "no_parameters":
        spec["parameters"] = {}
    elif what == "chunk_zero":
        spec["chunk"] = 0
    elif what == "low_above_high":
        if kind == "sweep":
            params[name].update(low=2.0, high=1.0)
        else:
            params[name] = {"distribution": "uniform", "low": 2.0, "high": 1.0}
    elif what == "unknown_distribution":
        params[name] = {"distribution": "cauchy", "sigma": 1.0}
        spec["kind"] = "tolerance"
        spec.pop("method", None)
        spec.setdefault("samples", 4)
        for n in params:
            params[n] = {"distribution": "cauchy", "sigma": 1.0}
    elif what == "unknown_parameter":
        params["no_such_parameter_mm"] = dict(params[name])
    elif what == "too_many_chunks":
        spec.update(kind="tolerance", samples=1_000_000, chunk=1)
        spec.pop("method", None)
        spec["parameters"] = {n: {"distribution": "normal", "sigma": 0.01} for n in params}
    elif what == "problem_bogus":
        spec["problem"] = "bogus"
    elif what == "algorithm_bogus":
        spec["algorithm"] = "simplex"
    elif what == "problem_other_mechanism":
        spec["problem"] = "transplanter"
    elif what == "starts_zero":
        spec["starts"] = 0
    return what, True


def _toml(doc: dict) -> str:
    import tomli_w

    return tomli_w.dumps(doc)


def spec_case(index: int, rng) -> Case:
    name = rng.choice(sorted(SPECS))
    case = Case(index, name, "study")
    spec = tomllib.loads((EXAMPLES / "studies" / f"{name}.toml").read_text(encoding="utf-8"))
    _small(spec)
    special = rng.choice(SPECIAL) if rng.random() < 0.3 else None
    if special:
        case.mutations, case.invalid = [f"spec: {special}"], True
    else:
        what, case.invalid = _spec_mutations(spec, rng)
        case.mutations = [f"spec: {what}"]
    text = "" if special else _toml(spec)
    case.text = text

    def prepare(work: Path):
        d = _case_dir(work, index)
        path = d / "study.toml"
        if special:
            _special(path, special)
        else:
            path.write_text(text, encoding="utf-8")
        out = d / "out"
        return (["study", str(EXAMPLES / SPECS[name]), "--spec", str(path), "--out",
                 str(out), "--workers", "1", "--quiet", "--no-plots"], out)

    case.prepare = prepare
    return case


# --- a study directory for report ------------------------------------------------------------


def sweep_study_dir(out: Path) -> Path:
    """A small sweep study directory laid out as 'plantmech study' writes one (numbers
    made here: the report only reads them)."""
    import numpy as np
    import pyarrow as pa
    import pyarrow.parquet as pq

    (out / "chunks").mkdir(parents=True)
    (out / "study.json").write_text(json.dumps({"fingerprint": "x", "kind": "sweep",
                                                "design": "d", "mechanism":
                                                "sugarcane_seeder"}), encoding="utf-8")
    L2 = np.array([480.0, 490.0, 500.0, 510.0])
    obj = (L2 - 480.0) / 20.0
    cols = {"sample": np.arange(4), "L2_mm": L2, "obj": obj, "obj__ok": obj < 1.0,
            "all_ok": obj < 1.0, "path_deviation_mm": np.zeros(4)}
    pq.write_table(pa.table(cols), out / "chunks" / "chunk_00000.parquet")
    summary = {"kind": "sweep", "method": "grid", "samples": 4, "limits": {"obj": "< 1"},
               "parameters": [{"name": "L2_mm", "low": 480.0, "high": 510.0, "levels": 4,
                               "nominal": 498.0}],
               "objectives": [{"name": "obj", "fraction_ok": 0.75, "min": 0.0, "max": 1.5}],
               "fraction_all_ok": 0.75, "variants_not_moved": 0, "complete": True,
               "run": {"total_chunks": 1, "computed_chunks": 1, "skipped_chunks": 0,
                       "evaluations": 4, "failed_chunks": [], "wall_s": 1.0, "workers": 1}}
    (out / "summary.json").write_text(json.dumps(summary), encoding="utf-8")
    return out


def _summary_mutation(study: Path, rng) -> tuple[str, bool]:
    s = json.loads((study / "summary.json").read_text(encoding="utf-8"))
    what = rng.choice(["drop", "retype", "nan", "kind", "list", "state_garbage",
                       "state_missing", "special", "valid"])
    if what == "valid":
        return what, False
    if what == "drop":
        key = rng.choice(["kind", "samples", "fraction_all_ok", "objectives", "parameters"])
        s.pop(key)
        what += f" {key}"
    elif what == "retype":
        key = rng.choice(["samples", "fraction_all_ok", "objectives", "parameters", "run"])
        s[key] = rng.choice(["x", [1], {"a": 1}, -5, True])
        what += f" {key}"
    elif what == "nan":
        text = json.dumps(s).replace('"fraction_all_ok": 0.75', '"fraction_all_ok": NaN')
        (study / "summary.json").write_text(text, encoding="utf-8")
        return what, True
    elif what == "kind":
        s["kind"] = rng.choice(["montecarlo", ["sweep"], None, 7])
    elif what == "list":
        s = [s]
    elif what == "state_garbage":
        (study / "study.json").write_bytes(b"\x00{not json")
    elif what == "state_missing":
        (study / "study.json").unlink()
    elif what == "special":
        target = rng.choice(["summary.json", "study.json"])
        (study / target).unlink()
        kind = rng.choice(SPECIAL)
        _special(study / target, kind)
        return f"{target}: {kind}", True
    (study / "summary.json").write_text(json.dumps(s), encoding="utf-8")
    return what, True


def _chunk_mutation(study: Path, rng) -> tuple[str, bool]:
    import pyarrow as pa
    import pyarrow.parquet as pq

    chunk = study / "chunks" / "chunk_00000.parquet"
    what = rng.choice(["garbage", "truncated", "strings", "missing_column", "other_schema",
                       "special", "valid"])
    if what == "valid":
        (study / "sweep.png").unlink(missing_ok=True)  # drawn from the chunk
        return what, False
    if what == "garbage":
        chunk.write_bytes(b"PAR1" + bytes(rng.randrange(256) for _ in range(512)) + b"PAR1")
    elif what == "truncated":
        data = chunk.read_bytes()
        chunk.write_bytes(data[: len(data) // 2])
    elif what == "strings":
        pq.write_table(pa.table({"sample": [0], "L2_mm": ["long"], "obj": ["x"]}), chunk)
    elif what == "missing_column":
        pq.write_table(pa.table({"sample": [0, 1], "other": [1.0, 2.0]}), chunk)
    elif what == "other_schema":
        pq.write_table(pa.table({"sample": [7]}), study / "chunks" / "chunk_00001.parquet")
    elif what == "special":
        kind = rng.choice([k for k in SPECIAL if k not in ("missing", "deep")])
        chunk.unlink()
        _special(chunk, kind)
        what = f"chunk: {kind}"
    return what, True


def report_case(index: int, rng, kind: str) -> Case:
    seed = rng.randrange(2**31)
    case = Case(index, kind, "report", [kind], invalid=_report_invalid(seed, kind))

    def prepare(work: Path):
        d = _case_dir(work, index)
        study = sweep_study_dir(d / "study")
        what, _ = (_summary_mutation if kind == "summary" else _chunk_mutation)(
            study, random.Random(seed))
        case.mutations = [f"{kind}: {what}"]
        out = d / "report.html"
        return ["report", str(study), "--out", str(out)], out

    case.prepare = prepare
    return case


def _report_invalid(seed: int, kind: str) -> bool:
    """Whether the mutation drawn from ``seed`` makes the study directory invalid (the
    same draw as prepare's, on a scratch copy)."""
    import tempfile

    with tempfile.TemporaryDirectory() as tmp:
        study = sweep_study_dir(Path(tmp) / "study")
        _, invalid = (_summary_mutation if kind == "summary" else _chunk_mutation)(
            study, random.Random(seed))
    return invalid


# --- gears directories for verify -----------------------------------------------------------


def _gear_points(teeth: int, radius: float, depth: float, inward: bool = False):
    import numpy as np

    t = np.linspace(0, 2 * np.pi, 16 * teeth, endpoint=False)
    r = radius + (-depth if inward else depth) * np.cos(teeth * t)
    return np.c_[r * np.cos(t), r * np.sin(t)]


def write_gear_dxf(path: Path, layer: str, rings) -> None:
    import ezdxf

    doc = ezdxf.new()
    for ring in rings:
        doc.modelspace().add_lwpolyline([tuple(map(float, p)) for p in ring], close=True,
                                        dxfattribs={"layer": layer})
    doc.saveas(path)


def _gears_dir(d: Path) -> Path:
    """A rice transplanter's gears directory: the internal gear (a toothed hole in a
    rim) and the planet, toothed circles standing in for what 'plantmech gears' writes."""
    import numpy as np

    g = d / "gears"
    g.mkdir()
    rim = 90.0 * np.c_[np.cos(np.linspace(0, 2 * np.pi, 64, endpoint=False)),
                       np.sin(np.linspace(0, 2 * np.pi, 64, endpoint=False))]
    write_gear_dxf(g / "internal.dxf", "internal", [rim, _gear_points(60, 60.0, 2.0, True)])
    write_gear_dxf(g / "planet.dxf", "planet", [_gear_points(30, 30.0, 2.0)])
    return g


def gears_case(index: int, rng) -> Case:
    import numpy as np

    case = Case(index, "rice_transplanter", "verify")
    which = rng.choice(["internal", "planet"])
    what = rng.choice(["damaged", "binary", "collinear", "far", "unclosed", "nan",
                       "few_points", *SPECIAL[:4], "missing", "empty"])
    case.mutations, case.invalid = [f"{which}.dxf: {what}"], True

    def prepare(work: Path):
        d = _case_dir(work, index)
        g = _gears_dir(d)
        f = g / f"{which}.dxf"
        if what == "damaged":
            text = f.read_text(encoding="utf-8")
            f.write_text(text[: len(text) // 3] + "\n10\nnot-a-number\n", encoding="utf-8")
        elif what == "collinear":
            write_gear_dxf(f, which, [np.c_[np.linspace(0, 80, 12), np.zeros(12)]])
        elif what == "far":
            write_gear_dxf(f, which, [_gear_points(30, 30.0, 2.0) + 20_000.0])
        elif what == "unclosed":
            import ezdxf

            doc = ezdxf.new()
            doc.modelspace().add_lwpolyline([tuple(p) for p in _gear_points(30, 30.0, 2.0)],
                                            close=False, dxfattribs={"layer": which})
            doc.saveas(f)
        elif what == "nan":
            text = f.read_text(encoding="utf-8").splitlines()
            poly = next(i for i, ln in enumerate(text) if ln.strip() == "LWPOLYLINE")
            k = next(i for i in range(poly, len(text)) if text[i].strip() == "10")
            text[k + 1] = "nan"  # the outline's first x
            f.write_text("\n".join(text) + "\n", encoding="utf-8")
        elif what == "few_points":
            write_gear_dxf(f, which, [np.array([[0.0, 0.0], [10.0, 0.0], [0.0, 10.0]])])
        else:
            f.unlink()
            _special(f, what)
        out = d / "out"
        return (["verify", str(EXAMPLES / "rice_transplanter.toml"), "--gears", str(g),
                 "--out", str(out), "--steps", "90", "--no-loads", "--no-plots"], out)

    case.prepare = prepare
    return case


# --- numeric options ------------------------------------------------------------------------

#: (command argv before the option, options with their kind) - every option has a range
_DESIGN = str(EXAMPLES / "sugarcane_seeder_optimized.toml")
OPTIONS = {
    "gears": (["gears", _DESIGN], {"--module": float, "--face-width": float,
                                   "--backlash": float, "--pressure-angle": float,
                                   "--addendum": float, "--dedendum": float}),
    "optimize": (["optimize", _DESIGN, "--problem", "seeder-layer2"],
                 {"--seed": int, "--generations": int, "--pop": int, "--points": int,
                  "--seeding-shifts": int}),
    "design": (["design", _DESIGN], {"--seed": int, "--generations": int, "--module": float,
                                     "--time-limit": float}),
    "verify": (["verify", _DESIGN, "--gears", str(EXAMPLES)],
               {"--steps": int, "--max-te": float, "--max-attitude-error": float,
                "--max-tip-band": float, "--density": float, "--face-width": float,
                "--arm-mass": float, "--payload": float, "--carrier-speed": float}),
    "study": (["study", _DESIGN, "--spec", str(EXAMPLES / "studies" / "seeder_sweep.toml")],
              {"--workers": int, "--max-chunks": int}),
}
BAD_VALUES = ("-1e20", "1e20", "nan", "inf", "-inf", "abc", "", "1e400", "0x10", "--")
BAD_INT_VALUES = ("1.5", "1e3", "4294967296000", "-1")


def option_case(index: int, rng) -> Case:
    command = rng.choice(sorted(OPTIONS))
    head, opts = OPTIONS[command]
    option = rng.choice(sorted(opts))
    bad = list(BAD_VALUES) + (list(BAD_INT_VALUES) if opts[option] is int else [])
    value = rng.choice(bad)
    case = Case(index, command, command, [f"{option} {value!r}"], invalid=True)

    def prepare(work: Path):
        d = _case_dir(work, index)
        out = d / "out"
        argv = [*head, "--out", str(out), f"{option}={value}"]
        if command == "study" or command == "app":
            argv.append("--quiet")
        return argv, out

    case.prepare = prepare
    return case


# --- init --name -----------------------------------------------------------------------------

GOOD_NAMES = ("a.toml", "my design.toml", "ünï-côde.toml", "x" * 250 + ".toml", "-x.toml",
              ".hidden.toml", "a..b.toml", " x.toml", "x.toml ", "a\nb.toml")
BAD_NAMES = ("../x.toml", "../../x.toml", "sub/x.toml", "a\\b.toml", "..", ".",
             "a\x00b.toml", "x" * 300, "ABS")


def init_case(index: int, rng) -> Case:
    good = rng.random() < 0.35
    name = rng.choice(GOOD_NAMES if good else BAD_NAMES)
    kind = rng.choice(["seeder", "seeder-train", "transplanter", "planetary"])
    case = Case(index, kind, "init", [f"--name {name[:40]!r}"], invalid=not good)

    def prepare(work: Path):
        d = _case_dir(work, index)
        target = str(d / "elsewhere.toml") if name == "ABS" else name
        out = d / "dir"
        return ["init", kind, str(out), "--name", target], out

    def check(work: Path, rc: int) -> str | None:
        d = work / f"in{index}"
        outside = sorted(p.name for p in d.iterdir() if p.name != "dir")
        if outside:
            return f"wrote outside DIR: {outside}"
        if rc == 0 and [p.name for p in (d / "dir").iterdir()] != [name]:
            return f"DIR holds {[p.name for p in (d / 'dir').iterdir()]}, not {name!r}"
        return None

    case.prepare, case.check = prepare, check
    return case


# --- cases, runs --------------------------------------------------------------------------------


def make_input_case(index: int, seed: int) -> Case:
    """The index-th input case of a seed (deterministic)."""
    rng = random.Random(f"inputs:{seed}:{index}")
    kind = rng.choices(KINDS, weights=(30, 15, 15, 15, 15, 10))[0]
    if kind == "spec":
        return spec_case(index, rng)
    if kind in ("summary", "chunks"):
        return report_case(index, rng, kind)
    if kind == "gears":
        return gears_case(index, rng)
    if kind == "option":
        return option_case(index, rng)
    return init_case(index, rng)


def cheap(case: Case) -> bool:
    """Runs in about a second: every refusal, a report, an init (a valid study starts a
    cluster and computes; those run in the seeded runs, not in CI's corpus)."""
    return case.invalid or case.command in ("report", "init")


def input_corpus(seed: int = 0, size: int = 60) -> list[Case]:
    out, i = [], 0
    while len(out) < size:
        c = make_input_case(i, seed)
        i += 1
        if cheap(c):
            out.append(c)
    return out


def run_inputs(cases: list[Case], work: Path, timeout: float = 60.0, log=None) -> dict:
    import matplotlib

    matplotlib.use("Agg")
    tally = {"cases": 0, "by_command": {}, "failures": [], "exit_codes": {},
             "max_wall_s": 0.0}
    for case in cases:
        v = run_case(case, work, timeout)
        shutil.rmtree(work / f"in{case.index}", ignore_errors=True)
        tally["cases"] += 1
        c = tally["by_command"].setdefault(case.command, {
            "cases": 0, "invalid": 0, "traceback": 0, "hang": 0, "non_finite": 0,
            "silently_accepted": 0, "bad_exit": 0, "left_behind": 0})
        c["cases"] += 1
        c["invalid"] += case.invalid
        tally["exit_codes"][str(v["exit"])] = tally["exit_codes"].get(str(v["exit"]), 0) + 1
        tally["max_wall_s"] = max(tally["max_wall_s"], v["wall_s"])
        if v["kind"]:
            c[v["kind"]] += 1
            tally["failures"].append(v)
        if log is not None:
            log(f"{case.index} {case.command} {case.mutations} exit {v['exit']} "
                f"{v['wall_s']:.2f}s {v['kind'] or 'ok'} {v['detail'][:160]}")
    return tally


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", type=int, default=200)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--timeout", type=float, default=60.0)
    ap.add_argument("--out", default="out/fuzz-inputs")
    args = ap.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    with (out / "cases.log").open("w", encoding="utf-8") as logf:
        def log(line):
            logf.write(line + "\n")
            logf.flush()

        import time

        t0 = time.perf_counter()
        tally = run_inputs([make_input_case(i, args.seed) for i in range(args.cases)],
                           out / "work", args.timeout, log)
        tally["seed"], tally["wall_s"] = args.seed, round(time.perf_counter() - t0, 1)
        tally["load_avg"] = [round(x, 2) for x in os.getloadavg()]
    (out / "tally.json").write_text(json.dumps(tally, indent=2, default=str) + "\n",
                                    encoding="utf-8")
    print(json.dumps({k: tally[k] for k in ("seed", "cases", "by_command", "exit_codes",
                                            "max_wall_s", "wall_s", "load_avg")}, indent=2))
    print(f"{len(tally['failures'])} failing cases (details in {out / 'tally.json'})")
    return 1 if tally["failures"] else 0


if __name__ == "__main__":
    sys.exit(main())
