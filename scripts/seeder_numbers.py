"""Dump the numbers every bundled seeder example gives (issue 16's acceptance: the same to
1e-6 in their units before and after the engine's speed work) to JSON, and compare two
dumps.

    python scripts/seeder_numbers.py dump OUT.json
    python scripts/seeder_numbers.py compare OLD.json NEW.json [--tol 1e-6]

Dumped per example: the inverse job (summary, L1/L2, centre distances, sampled pitch
radii, tip and arm angles, point carrier angles), the forward job (summary, objective
values, metrics, sampled tip/arm/ratio), and for the examples with a [train] a seeded
population of 40 variants (every objective value, centre distances, located sections,
closure errors, sampled tips); the layer-1 population checks of the inverse examples.
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import numpy as np

from plantmech.design import SectionAngles, load_design

ROOT = Path(__file__).resolve().parents[1]
EX = ROOT / "examples"
SEEDERS = ("sugarcane_seeder.toml", "sugarcane_seeder_dwell.toml", "sugarcane_seeder_g.toml",
           "sugarcane_seeder_optimized.toml", "sugarcane_table2_as_printed.toml",
           "sugarcane_table4.toml")


def _plain(x):
    """JSON-ready copy (arrays -> lists, numpy scalars -> floats, NaN -> 'nan')."""
    if isinstance(x, dict):
        return {str(k): _plain(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_plain(v) for v in x]
    if isinstance(x, np.ndarray):
        return _plain(x.tolist())
    if isinstance(x, (bool, np.bool_)):
        return bool(x)
    if isinstance(x, (int, np.integer)):
        return int(x)
    if isinstance(x, (float, np.floating)):
        x = float(x)
        return x if math.isfinite(x) else repr(x)
    if hasattr(x, "as_dict"):
        return _plain(x.as_dict())
    return x if x is None or isinstance(x, str) else repr(x)


def _every(a, k=9):
    return None if a is None else np.asarray(a)[::k]


def inverse_numbers(design) -> dict:
    from plantmech.workflows import run_seeder_inverse

    job = run_seeder_inverse(design)
    r = job.result
    return {"summary": job.summary, "feasible": r.feasible, "L1": r.L1, "L2": r.L2,
            "a1": r.a1, "a2": r.a2, "u_start": r.u_start, "shaft_offset": r.shaft_offset,
            "point_carrier_angle": r.point_carrier_angle,
            "r1": _every(r.r1), "r2": _every(r.r2), "r3": _every(r.r3), "r4": _every(r.r4),
            "tip": _every(r.tip), "tip_realized": _every(r.tip_realized),
            "arm_realized": _every(r.arm_angle_realized), "total_ratio": _every(r.total_ratio),
            "closure_error": r.closure_error, "dwell": r.dwell}


def forward_numbers(design) -> dict:
    from plantmech.workflows import run_seeder_forward

    job = run_seeder_forward(design)
    res = job.result
    return {"summary": job.summary, "metrics": job.metrics,
            "checks": [(c.name, c.value) for c in job.checks],
            "section_psi": job.section_psi, "travel": job.travel_m_s,
            "a": [job.train.a1, job.train.a2], "closure": res.closure_error,
            "tip": _every(res.tip), "arm": _every(res.arm_angle),
            "ratio": _every(res.total_ratio), "gear2": _every(res.gear2_angle)}


def population_numbers(design, P: int = 40, samples: int = 720, dense: int = 2048) -> dict:
    from plantmech.workflows import evaluate_seeder_population

    rng = np.random.default_rng(7)
    t = design.train
    R2 = np.asarray(t.gear2.radii_mm) + rng.uniform(-2, 2, (P, len(t.gear2.radii_mm)))
    R3 = np.asarray(t.gear3.radii_mm) + rng.uniform(-2, 2, (P, len(t.gear3.radii_mm)))
    out = {}
    for label, params in (("radii", None), ("params", {
            "L1_mm": t.L1_mm + rng.uniform(-1, 1, P),
            "initial_arm_angle_deg": t.initial_arm_angle_deg + rng.uniform(-1, 1, P),
            "gear2_contact_angle_deg": t.gear2.contact_angle_deg + rng.uniform(-2, 2, P),
            "gear3_contact_angle_deg": t.gear3.contact_angle_deg + rng.uniform(-2, 2, P),
            "backlash_deg": rng.uniform(0, 0.5, P)})):
        pop = evaluate_seeder_population(design, R2, R3, samples=samples, dense=dense,
                                         params=params)
        m, ev = pop.motion, pop.evaluation
        out[label] = {"names": ev.names, "values": ev.values, "violation": ev.violation,
                      "a1": m.a1, "a2": m.a2, "closure": m.closure_error,
                      "section_psi": pop.section_psi, "tip": m.tip[:, ::37],
                      "arm": m.arm_angle[:, ::37], "ratio": m.total_ratio[:, ::37],
                      "gear2": m.gear2_angle[:, ::37],
                      "metrics": {k: v for k, v in ev.metrics.items()}}
    return out


def layer1_numbers(design, P: int = 12) -> dict:
    from plantmech.workflows import seeder_inverse_checks_population

    rng = np.random.default_rng(3)
    pts = np.asarray(design.trajectory.points)
    X = pts[None] + rng.uniform(-3, 3, (P,) + pts.shape)
    return seeder_inverse_checks_population(design, X, 360)


def dump(path: Path) -> None:
    out = {}
    for name in SEEDERS:
        d = load_design(EX / name)
        entry = {}
        if d.trajectory is not None and d.gear_train is not None:
            entry["inverse"] = inverse_numbers(d)
            for samples in (360, 3600):
                dd = d.model_copy(deep=True)
                dd.trajectory.samples = samples
                entry[f"inverse_{samples}"] = inverse_numbers(dd)
            if d.gear_train.dwell is None or not d.gear_train.dwell.enabled:
                entry["layer1"] = layer1_numbers(d)
        try:
            entry["forward"] = forward_numbers(d)
        except Exception as exc:  # an infeasible inverse behind the forward job
            entry["forward"] = f"{type(exc).__name__}: {exc}"
        if d.train is not None:
            entry["population"] = population_numbers(d)
            # the other interpolation, centre distances as given and given sections
            v = d.model_copy(deep=True)
            v.train.interpolation = "spline"
            v.train.closure = "check"
            v.train.closure_tolerance_deg = 10.0
            base = forward_numbers(d)
            v.train.a1_mm, v.train.a2_mm = base["a"]
            psi = base["section_psi"]
            v.train.sections_deg = SectionAngles(**{k: float(np.degrees(psi[k]))
                                                    for k in "abcdef"})
            entry["population_spline_check"] = population_numbers(v)
        out[name] = _plain(entry)
        print(name, "done", file=sys.stderr)
    path.write_text(json.dumps(out))


_LARGEST = [0.0]


def _compare(a, b, where, tol, bad):
    if isinstance(a, dict) and isinstance(b, dict):
        for k in sorted(set(a) | set(b)):
            if k not in a or k not in b:
                bad.append((f"{where}/{k}", "missing on one side", None))
                continue
            _compare(a[k], b[k], f"{where}/{k}", tol, bad)
    elif isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            bad.append((where, f"length {len(a)} != {len(b)}", None))
            return
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            _compare(x, y, f"{where}[{i}]", tol, bad)
    elif isinstance(a, (int, float)) and isinstance(b, (int, float)) \
            and not isinstance(a, bool) and not isinstance(b, bool):
        # 1e-6 in the value's units, relative for values above 1000 (printed digits)
        _LARGEST[0] = max(_LARGEST[0], abs(a - b) / max(1.0, abs(a) / 1000.0))
        if abs(a - b) > tol * max(1.0, abs(a) / 1000.0):
            bad.append((where, f"{a!r} != {b!r}", abs(a - b)))
    elif a != b:
        bad.append((where, f"{a!r} != {b!r}", None))


def compare(old: Path, new: Path, tol: float = 1e-6) -> int:
    a, b = json.loads(old.read_text()), json.loads(new.read_text())
    bad: list = []
    _compare(a, b, "", tol, bad)
    worst = max((x[2] for x in bad if x[2] is not None), default=0.0)
    for w, msg, _ in bad[:40]:
        print(f"{w}: {msg}")
    print(f"{len(bad)} differences beyond {tol:g} (largest numeric {worst:.3g}; largest "
          f"difference of all numbers {_LARGEST[0]:.3g})")
    return 1 if bad else 0


if __name__ == "__main__":
    if sys.argv[1] == "dump":
        dump(Path(sys.argv[2]))
    else:
        tol = float(sys.argv[sys.argv.index("--tol") + 1]) if "--tol" in sys.argv else 1e-6
        sys.exit(compare(Path(sys.argv[2]), Path(sys.argv[3]), tol))
