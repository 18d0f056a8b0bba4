"""Tolerance and sweep studies: chunks of designs on Dask, then the summary.

Tolerance: chunk c draws its deviations from its own random stream (seed, c), so the
samples do not depend on which worker ran which chunk, nor on a restart. Sweep: the grid
or Latin hypercube is laid out once and cut into chunks.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from plantmech.studies import distributions as dist
from plantmech.studies.engine import RunStats, claim_out_dir, read_extras, read_results, run_chunks
from plantmech.studies.parameters import (
    OUTPUT_UNITS,
    StudyInputError,
    chunk_outputs,
    make_model,
    path_normal,
)
from plantmech.studies.spec import SweepSpec, ToleranceSpec


@dataclass
class StudyOutcome:
    stats: RunStats
    summary: dict
    written: list[Path] = field(default_factory=list)


def tolerance_chunk(model, payload):
    """Worker task: ``n`` Monte Carlo variants of chunk ``index`` -> (columns, band)."""
    index, start, n, seed, dists = payload
    u = dist.chunk_rng(seed, index).random((n, len(dists)))
    u = np.clip(u, 1e-15, 1 - 1e-15)
    deltas = np.stack([dist.sample(d, u[:, k]) for k, d in enumerate(dists)], axis=1)
    cols, band = chunk_outputs(model, deltas)
    head = {"sample": np.arange(start, start + n)}
    head.update({f"d_{name}": deltas[:, k] for k, name in enumerate(model.names)})
    return {**head, **cols}, band


def sweep_chunk(model, payload):
    """Worker task: the sweep designs ``values`` (n, K) absolute -> (columns, None)."""
    start, values = payload
    nominal = np.array([model.nominal(nm) for nm in model.names])
    cols, _ = chunk_outputs(model, values - nominal)
    head = {"sample": np.arange(start, start + len(values))}
    head.update({name: values[:, k] for k, name in enumerate(model.names)})
    return {**head, **cols}, None


def sweep_values(spec: SweepSpec) -> np.ndarray:
    """(n, K) absolute parameter values of the sweep, in the spec's parameter order."""
    ranges = list(spec.parameters.values())
    if spec.method == "grid":
        return dist.grid([np.linspace(r.low, r.high, r.levels) for r in ranges])
    u = dist.latin_hypercube(spec.samples, len(ranges), np.random.default_rng(spec.seed))
    lo = np.array([r.low for r in ranges])
    hi = np.array([r.high for r in ranges])
    return lo + (hi - lo) * u


def run_study(design, spec, out: Path, fingerprint: str, scheduler: str | None = None,
              workers: int = 2, progress: bool = True,
              max_chunks: int | None = None) -> StudyOutcome:
    names = list(spec.parameters)
    model = make_model(design, names, spec.cycle_samples, spec.dense)
    claim_out_dir(out, fingerprint, {"kind": spec.kind, "design": design.name,
                                     "mechanism": design.mechanism, "parameters": names})
    if isinstance(spec, ToleranceSpec):
        dists = list(spec.parameters.values())
        chunks = []
        for c, start in enumerate(range(0, spec.samples, spec.chunk)):
            n = min(spec.chunk, spec.samples - start)
            chunks.append((c, (c, start, n, spec.seed, dists), n))
        stats = run_chunks(out, tolerance_chunk, model, chunks, scheduler, workers, progress,
                           max_chunks)
        summary = tolerance_summary(model, spec, out) if _rows(out) else {}
    else:
        values = sweep_values(spec)
        chunks = [(c, (start, values[start:start + spec.chunk]),
                   len(values[start:start + spec.chunk]))
                  for c, start in enumerate(range(0, len(values), spec.chunk))]
        stats = run_chunks(out, sweep_chunk, model, chunks, scheduler, workers, progress,
                           max_chunks)
        summary = sweep_summary(model, spec, out) if _rows(out) else {}
    if summary:  # a stopped study still summarises the chunks it finished
        summary["complete"] = stats.complete
    summary["run"] = stats.as_dict()
    return StudyOutcome(stats, summary)


def _rows(out: Path) -> int:
    from plantmech.studies.engine import done_chunks

    return len(done_chunks(out))


# --- summaries ---------------------------------------------------------------------------

QUANTILES = (0.001, 0.01, 0.05, 0.5, 0.95, 0.99, 0.999)


def wilson(k: int, n: int, z: float = 1.96) -> tuple[float, float]:
    """95 % Wilson score interval of a probability from k successes in n trials."""
    if n == 0:
        return (float("nan"), float("nan"))
    p = k / n
    den = 1 + z * z / n
    mid = (p + z * z / (2 * n)) / den
    half = z * np.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / den
    return (float(max(mid - half, 0.0)), float(min(mid + half, 1.0)))


def describe(x: np.ndarray) -> dict:
    x = np.asarray(x, dtype=float)
    f = x[np.isfinite(x)]
    if not len(f):
        return {"not_computed": int(len(x))}
    q = np.quantile(f, QUANTILES)
    return {"mean": float(f.mean()), "std": float(f.std(ddof=1)) if len(f) > 1 else 0.0,
            "min": float(f.min()), "max": float(f.max()),
            "quantiles": {f"{p:g}": float(v) for p, v in zip(QUANTILES, q, strict=True)},
            "not_computed": int(len(x) - len(f))}


def standardized_regression(X: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, float]:
    """Standardized regression coefficients (K,) of y on the columns of X over the
    finite rows, and the fit's R^2 (how linear the response is)."""
    ok = np.isfinite(y) & np.isfinite(X).all(axis=1)
    X, y = X[ok], y[ok]
    sx, sy = X.std(axis=0), y.std()
    if len(y) < X.shape[1] + 2 or sy <= 1e-9 * max(1.0, abs(float(y.mean()))):
        return np.zeros(X.shape[1]), float("nan")  # constant up to round-off
    A = np.c_[np.ones(len(y)), X]
    coef, *_ = np.linalg.lstsq(A, y, rcond=None)
    resid = y - A @ coef
    return coef[1:] * sx / sy, float(1.0 - resid.var() / y.var())


def first_order(model, stds: np.ndarray, rel_step: float = 0.01) -> dict:
    """Central finite differences of the same model at the nominal design, step
    ``rel_step`` x std per parameter: gradients of every objective and of the tip's
    deviation along the nominal path's normal at every cycle sample."""
    K = len(stds)
    h = rel_step * np.where(stds > 0, stds, 1.0)
    deltas = np.vstack([np.zeros(K), np.diag(h), -np.diag(h)])
    ev = model.evaluate(deltas)
    normal = path_normal(ev.tip_rate[0])
    en = ((ev.tip - ev.tip[:1]) * normal[None]).sum(axis=-1)  # (2K+1, S)
    grad_obj = (ev.values[1:K + 1] - ev.values[K + 1:]) / (2 * h[:, None])  # (K, M)
    grad_en = (en[1:K + 1] - en[K + 1:]) / (2 * h[:, None])  # (K, S)
    return {"names": ev.names, "units": ev.units, "limits": ev.limits, "step": h,
            "grad_objectives": grad_obj, "grad_normal": grad_en, "nominal": ev}


def variants_not_moved(data: dict) -> int:
    """How many variants of the results table could not be built or moved (no motion: no
    path deviation; ``chunk_outputs`` leaves them out of the band)."""
    return int((~np.isfinite(data["path_deviation_mm"])).sum())


def band_statistics(out: Path) -> dict:
    bands = read_extras(out)
    n = sum(int(b["count"][0]) for b in bands)
    total = sum(int(b.get("variants", b["count"])[0]) for b in bands)
    if n == 0:
        raise StudyInputError(f"none of the {total} variants could be built and moved: the "
                              "deviations take every variant outside what the design "
                              "file accepts (smaller deviations, or another nominal)")
    s = sum(b["sum"] for b in bands)
    s2 = sum(b["sumsq"] for b in bands)
    mean = s / n
    var = np.maximum(s2 / n - mean**2, 0.0) * n / max(n - 1, 1)
    return {"count": n, "variants": total, "mean": mean, "std": np.sqrt(var),
            "min": np.min([b["min"] for b in bands], axis=0),
            "max": np.max([b["max"] for b in bands], axis=0)}


def tolerance_summary(model, spec: ToleranceSpec, out: Path) -> dict:
    data = read_results(out)
    N = len(data["sample"])
    names = list(spec.parameters)
    dists = list(spec.parameters.values())
    stds = np.array([dist.std(d) for d in dists])
    fo = first_order(model, stds)
    stuck = [n for n, g in zip(names, fo["grad_normal"], strict=True)
             if not np.isfinite(g).all()]
    if stuck:
        raise StudyInputError(
            f"parameter {stuck[0]!r}: a step of 1 % of its standard deviation from the "
            "nominal cannot be built or moved, so its first-order sensitivity is not "
            "computable: the nominal design lies on the edge of what the file accepts")
    nominal = fo["nominal"]
    X = np.stack([data[f"d_{n}"] for n in names], axis=1)
    objectives = []
    met_nominal = [k for k in range(len(fo["names"])) if nominal.ok[0, k]]
    for k, name in enumerate(fo["names"]):
        ok = data[f"{name}__ok"].astype(bool)
        src, r2 = standardized_regression(X, data[name])
        contrib = np.abs(fo["grad_objectives"][:, k]) * stds
        # an objective the nominal design cannot compute (a K-H-V tip that never passes
        # through the seedling mat: no picking angle) has no nominal value and no first
        # order: None in the summary (JSON has no NaN), its variants counted as not met
        computable = bool(np.isfinite(nominal.values[0, k]))
        objectives.append({
            "name": name, "unit": fo["units"][k], "limit": fo["limits"][k],
            "nominal": _finite(nominal.values[0, k]), "nominal_ok": bool(nominal.ok[0, k]),
            "probability_ok": float(ok.mean()), "probability_ok_95": wilson(int(ok.sum()), N),
            **describe(data[name]),
            "first_order_std": _finite(np.sqrt(np.sum(contrib**2))),
            "first_order_mean": _finite(nominal.values[0, k]
                                        + fo["grad_objectives"][:, k] @ np.array(
                                            [dist.mean(d) for d in dists])),
            "sensitivity": _ranked(names, src, contrib if computable else None, r2),
        })
    all_ok = data["all_ok"].astype(bool)
    kept = np.ones(N, bool)
    for k in met_nominal:
        kept &= data[f"{fo['names'][k]}__ok"].astype(bool)
    outputs = {}
    for name in ("tip_deviation_mm", "path_deviation_mm", "attitude_error_deg"):
        src, r2 = standardized_regression(X, data[name])
        outputs[name] = {"unit": OUTPUT_UNITS[name], **describe(data[name]),
                         "sensitivity": _ranked(names, src, None, r2)}
    band = band_statistics(out)
    means = np.array([dist.mean(d) for d in dists])
    fo_band = np.sqrt(((fo["grad_normal"] * stds[:, None]) ** 2).sum(axis=0))
    fo_mean = (fo["grad_normal"] * means[:, None]).sum(axis=0)
    contrib_band = np.sqrt(((fo["grad_normal"] * stds[:, None]) ** 2).mean(axis=1))
    outputs["path_deviation_mm"]["first_order_rms_contribution_mm"] = {
        n: float(c) for n, c in sorted(zip(names, contrib_band, strict=True),
                                       key=lambda t: -t[1])}
    return {
        "kind": "tolerance", "samples": N, "seed": spec.seed, "chunk": spec.chunk,
        "cycle_samples": spec.cycle_samples,
        "parameters": [{"name": n, **d.model_dump(exclude_none=True), "std": float(s),
                        "nominal": float(model.nominal(n))}
                       for n, d, s in zip(names, dists, stds, strict=True)],
        "variants_not_moved": variants_not_moved(data),
        "probability_all_ok": float(all_ok.mean()),
        "probability_all_ok_95": wilson(int(all_ok.sum()), N),
        "nominal_met": [fo["names"][k] for k in met_nominal],
        "probability_nominal_met_kept": float(kept.mean()),
        "probability_nominal_met_kept_95": wilson(int(kept.sum()), N),
        "objectives": objectives, "outputs": outputs,
        "band": {"carrier_angle_deg": np.degrees(nominal.carrier_angle),
                 "nominal_tip_mm": nominal.tip[0], "normal": path_normal(nominal.tip_rate[0]),
                 "mc_mean_mm": band["mean"], "mc_std_mm": band["std"],
                 "mc_min_mm": band["min"], "mc_max_mm": band["max"],
                 "first_order_mean_mm": fo_mean, "first_order_std_mm": fo_band},
        "sensitivity_method": (
            "src: standardized regression coefficients of the Monte Carlo samples (with the "
            "fit's R^2: near 1 the response is linear and the ranking complete); "
            "first_order_sigma: |d output / d parameter| x std, central differences of the "
            "same model at the nominal design (step 0.01 std)"),
    }


def _finite(x) -> float | None:
    """``x`` as a float, or None where it is not finite (JSON has no NaN)."""
    x = float(x)
    return x if np.isfinite(x) else None


def _ranked(names, src, contrib, r2) -> dict:
    rows = []
    for k, n in enumerate(names):
        row = {"parameter": n, "src": float(src[k])}
        if contrib is not None:
            row["first_order_sigma"] = float(contrib[k])
        rows.append(row)
    key = (lambda r: -r["first_order_sigma"]) if contrib is not None else (lambda r: -abs(r["src"]))
    # an output no varied parameter moves has no fit: None (JSON has no NaN)
    return {"r2": float(r2) if np.isfinite(r2) else None, "ranking": sorted(rows, key=key)}


def sweep_summary(model, spec: SweepSpec, out: Path) -> dict:
    data = read_results(out)
    N = len(data["sample"])
    names = list(spec.parameters)
    obj = [c[:-4] for c in data if c.endswith("__ok")]
    all_ok = data["all_ok"].astype(bool)
    best = None
    if all_ok.any():
        k = int(np.flatnonzero(all_ok)[0])
        best = {n: float(data[n][k]) for n in names}
    nominal = model.evaluate(np.zeros((1, len(names))))
    return {
        "kind": "sweep", "method": spec.method, "samples": N,
        "limits": dict(zip(nominal.names, nominal.limits, strict=True)),
        "parameters": [{"name": n, **r.model_dump(), "nominal": float(model.nominal(n))}
                       for n, r in spec.parameters.items()],
        "objectives": [{"name": o, "fraction_ok": float(data[f"{o}__ok"].mean()),
                        **describe(data[o])} for o in obj],
        "fraction_all_ok": float(all_ok.mean()),
        "variants_not_moved": variants_not_moved(data),
        "first_design_meeting_all": best,
    }
