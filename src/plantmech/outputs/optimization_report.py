"""Files of an optimization run: best.toml, pareto.csv, history.csv, run.json, plots."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from plantmech.outputs.files import write_csv, write_json

# axis labels of the problems' objectives (what is minimized, with its unit)
OBJECTIVE_LABELS = {
    "picking_swing": "picking swing (attitude over ab) / deg",
    "seeding_swing": "seeding swing (attitude over de) / deg",
    "sowing_angle": "sowing angle |at e| / deg",
    "seeding_peak_speed": "seeding peak speed (over de) / (m/s)",
    "neg_return_min_speed_dynamic": "- return minimum dynamic speed (over ef) / (m/s)",
    "seedling_block_skew": "seedling-block skew (vi) / mm",
    "hole_width": "widest hole (ix) / mm",
    "angle_difference_offcentre": "|angle difference (v) - mid-range| / deg",
}


# the pairs and gear-shape checks named in words (the trade-off plot's annotations)
PAIR_WORDS = {"sun_gear2": "sun-gear 2 pair", "gear3_planet": "gear 3-planet pair"}
CHECK_WORDS = (("pitch_tangent_angle_", "pitch tangent angle (working pressure angle less "
                "the tool's), "),
               ("working_pressure_angle_", "working pressure angle, "),
               ("cuttable_module_", "cuttable module, "),
               ("convex_", "convex pitch curve, "))


def check_label(name: str) -> str:
    """A check's name in words (its pair spelled out)."""
    for prefix, words in CHECK_WORDS:
        if name.startswith(prefix):
            rest = name[len(prefix):]
            return words + PAIR_WORDS.get(rest, rest.replace("_", " "))
    return name.replace("_", " ")


def objective_label(name: str) -> str:
    """Axis label (with unit) of an objective by its name."""
    return OBJECTIVE_LABELS.get(name, name.replace("_", " "))


def variable_column(name: str, unit: str) -> str:
    """CSV column of a variable: its name with the unit appended once (``S_mm`` stays)."""
    return name if not unit or name.endswith(f"_{unit}") else f"{name}_{unit}"


def _toml_item(value):
    """A tomlkit item written as a person would: a point (a list of numbers) on one line,
    a list of points one point per line, a long list of numbers wrapped one per line."""
    import tomlkit

    if isinstance(value, dict):
        table = tomlkit.table()
        for k, v in value.items():
            table[k] = _toml_item(v)
        return table
    if isinstance(value, list) and value and all(isinstance(v, dict) for v in value):
        aot = tomlkit.aot()
        for v in value:
            aot.append(_toml_item(v))
        return aot
    if isinstance(value, list):
        arr = tomlkit.array()
        for v in value:
            arr.append(_toml_item(v) if isinstance(v, list) else v)
        nested = any(isinstance(v, list) for v in value)
        arr.multiline(nested or len(arr.as_string()) > 72)
        return arr
    return tomlkit.item(value)


def _merge_toml(doc, new: dict, old: dict) -> None:
    """Edit the parsed input ``doc`` (tomlkit, comments and layout kept) into ``new``: only
    the values that differ from ``old`` (the input as loaded) are rewritten, keys the
    design no longer has are removed, new ones appended."""
    for k in [k for k in doc if k not in new]:
        del doc[k]
    for k, v in new.items():
        if k in old and old[k] == v:  # unchanged: as written, or a default left out
            continue
        if (k in doc and isinstance(v, dict) and isinstance(old.get(k), dict)
                and hasattr(doc[k], "keys")):
            _merge_toml(doc[k], v, old[k])
        else:
            doc[k] = _toml_item(v)


def design_toml(design, header: str = "", source: str | Path | None = None) -> str:
    """A design as TOML that ``load_design`` reads back exactly, written as a person would (a
    point per line; numbers in full, as they are the design that was checked: rounding can
    break an exact fit such as a carrier holding its shafts in line). With ``source`` (the
    input design file it was made from), the input is edited: its comments and layout kept,
    only the values the design changed rewritten. ``header`` is written as comment lines on
    top."""
    import tomlkit

    data = design.model_dump(exclude_none=True, mode="json")
    doc = None
    if source is not None:
        from plantmech.design import DesignError, load_design

        try:
            text = Path(source).read_text(encoding="utf-8")
            old = load_design(Path(source)).model_dump(exclude_none=True, mode="json")
            doc = tomlkit.parse(text)
            _merge_toml(doc, data, old)
        except (OSError, DesignError, ValueError, tomlkit.exceptions.TOMLKitError):
            doc = None  # the input is gone or changed: the design written afresh
    if doc is None:
        doc = tomlkit.document()
        for k, v in data.items():
            doc[k] = _toml_item(v)
    text = tomlkit.dumps(doc)
    lines = [f"# {line}" if line else "#" for line in header.splitlines()]
    return ("\n".join(lines) + "\n\n" if lines else "") + text


def write_run(out: Path, result, problem, design_input: str, recheck=None,
              extra: dict | None = None, source: Path | None = None) -> tuple[list[Path], dict]:
    """Write every file of one run into ``out`` (created by the caller); returns (files,
    run record). ``recheck(path) -> {all_met, objectives}`` re-checks a written design file
    at full resolution: the best design and, if it fails, the next candidates of the final
    Pareto set, in order, until one passes (at most 5); ``best.toml`` is written after it,
    its header stating the re-checked verdict, and the record's ``feasible`` is the
    re-checked one. The design files are the input file (``source``, default the path
    ``design_input``) edited: its comments kept (``design_toml``)."""
    rec = dict(result.record(), **(extra or {}))
    best_x, verified, tried = result.best_x, None, 0
    source = Path(design_input) if source is None else source
    if recheck is not None:
        partial = out / "best.toml.partial"
        for x in _candidates(result):
            tried += 1
            partial.write_text(design_toml(problem.decode(x), source=source),
                               encoding="utf-8")
            v = recheck(partial)
            if verified is None or v["all_met"]:
                best_x, verified = x, v
            if v["all_met"]:
                break
        partial.unlink()
        rec["verified_full_resolution"] = dict(verified, candidates_rechecked=tried)
        rec["feasible"] = bool(result.feasible and verified["all_met"])
    rec["best_x"] = [float(v) for v in best_x]
    status = ("every objective met, re-checked at full resolution" if rec["feasible"]
              else "NOT every objective met" + (
                  ": the full-resolution re-check fails " + ", ".join(
                      o["name"] for o in verified["objectives"]
                      if not o["ok"] and o.get("required", True))
                  if verified is not None and not verified["all_met"] else
                  " (the closest design found)"))
    header = (f"Best design of `plantmech optimize --problem {result.problem}` "
              f"(algorithm {result.algorithm}, random seed {result.seed}, {result.evaluations} "
              f"evaluations, {result.wall_s:.1f} s)\nfrom {design_input}\nverdict: {status}; "
              "see run.json" + "".join(f"\n{line}" for line in choice_lines(rec)))
    (out / "best.toml").write_text(design_toml(problem.decode(best_x), header, source),
                                   encoding="utf-8")
    hist = result.history
    cols = {k: np.array([h[k] for h in hist], dtype=float)
            for k in ("generation", "evaluations", "best_violation",
                      "feasible_in_population", "wall_s")}
    cols["best_so_far"] = best_so_far(hist)
    cols["stage"] = np.array([h.get("stage", 1) for h in hist], dtype=float)
    write_csv(out / "history.csv", cols)
    cols = {}
    for i, v in enumerate(problem.variables):
        cols[variable_column(v.name, v.unit)] = result.pareto_x[:, i]
    for i, n in enumerate(problem.objective_names):
        cols[n] = result.pareto_f[:, i]
    write_csv(out / "pareto.csv", cols)
    written = [out / "best.toml", out / "run.json", out / "history.csv", out / "pareto.csv"]
    if result.tradeoff is not None:
        rec["tradeoff"] = tradeoff_record(result.tradeoff, problem)
        written += write_tradeoff(out, result.tradeoff, problem, rec["tradeoff"])
    rec["verdict"] = run_verdict(rec)
    write_json(out / "run.json", rec)
    written += plot_run(out, result, problem)
    return written, rec


def choice_lines(rec: dict) -> list[str]:
    """One line per choice the job made or took from the design file (run.json's
    ``design_choices``: interpolation, tooth system)."""
    return [f"{name.replace('_', ' ')}: {c['value']} (set by {c['set_by']})"
            for name, c in rec.get("design_choices", {}).items()]


def run_verdict(rec: dict) -> dict:
    """The run's verdict from its full-resolution re-check (else the optimizer's own rows):
    the required checks that fail."""
    from plantmech.outputs.verdict import verdict

    v = rec.get("verified_full_resolution")
    rows = v["objectives"] if v is not None else rec["objectives"]
    failed = [o["name"] for o in rows if not o["ok"] and o.get("required", True)]
    if not rec["feasible"] and not failed:
        failed = ["optimizer: no design met every objective"]
    return verdict(problems=failed)


def _candidates(result, most: int = 5):
    """The best design, then the final Pareto set's other members (nearest first)."""
    out = [result.best_x]
    px = np.atleast_2d(result.pareto_x)
    order = np.argsort(np.linalg.norm(px - result.best_x, axis=1))
    for k in order:
        if len(out) >= most:
            break
        if not np.allclose(px[k], result.best_x):
            out.append(px[k])
    return out


def tradeoff_record(t: dict, problem) -> dict:
    """What conflicts: the front of (agronomic, manufacturability) violation and, at its two
    ends, which checks fail (the design closest to the agronomic objectives: its failing
    manufacturability checks; the most manufacturable design: its failing objectives)."""
    from plantmech.optimize.problems import is_gear_shape_check

    rec = {"front": [{"agronomic_violation": round(float(a), 6),
                      "manufacturing_violation": round(float(m), 6)}
                     for a, m in zip(t["agronomic"], t["manufacturing"], strict=True)]}
    ends = {"best_agronomic": int(np.argmin(t["agronomic"])),
            "best_manufacturing": int(np.argmin(t["manufacturing"]))}
    b = problem.evaluate_batch(t["X"][list(ends.values())])
    for row, (key, _) in enumerate(ends.items()):
        rec[key] = {
            "agronomic_violation": float(t["agronomic"][ends[key]]),
            "manufacturing_violation": float(t["manufacturing"][ends[key]]),
            "fails": [n for n, ok in zip(b.names, b.ok[row], strict=True) if not ok]}
    both = [n for n in rec["best_agronomic"]["fails"] if is_gear_shape_check(n)]
    rec["conflict"] = (
        "none: one design meets both" if t["agronomic"].min() == 0 and
        t["manufacturing"][np.argmin(t["agronomic"])] == 0 else
        f"the designs closest to every objective fail {', '.join(both) or 'no gear check'}; "
        "the most manufacturable fail " + (", ".join(
            n for n in rec["best_manufacturing"]["fails"] if not is_gear_shape_check(n))
            or "no objective"))
    return rec


def write_tradeoff(out: Path, t: dict, problem, rec: dict | None = None) -> list[Path]:
    """tradeoff.csv (the front) and tradeoff.png: the non-dominated designs, both axes from
    0 (0 = met), each end labelled with the checks it fails (``tradeoff_record``)."""
    import matplotlib.pyplot as plt

    write_csv(out / "tradeoff.csv", {"agronomic_violation": t["agronomic"],
                                     "manufacturing_violation": t["manufacturing"]})
    fig, ax = plt.subplots(figsize=(7.5, 5.2))
    ax.plot(t["agronomic"], t["manufacturing"], "o", ms=5, color="tab:red",
            label=f"non-dominated designs ({len(t['agronomic'])})")
    found = bool(np.any((t["agronomic"] <= 0) & (t["manufacturing"] <= 0)))
    ax.plot([0], [0], "*", ms=12, color="tab:green" if found else "none",
            markeredgecolor="tab:green",
            label="every objective and check met" + ("" if found else
                                                    " (the goal: no design found)"))
    for key, label, align in (("best_agronomic", "closest to every objective", "left"),
                              ("best_manufacturing", "most manufacturable", "right")):
        end = (rec or {}).get(key)
        if end is None:
            continue
        fails = "\n  ".join([check_label(n) for n in end["fails"][:4]]
                            + (["..."] if len(end["fails"]) > 4 else []))
        ax.annotate(f"{label}\nfails: {fails or 'nothing'}",
                    (end["agronomic_violation"], end["manufacturing_violation"]),
                    xytext=(0.02 if align == "left" else 0.98, 0.55 if align == "left" else 0.3),
                    textcoords="axes fraction", ha=align, fontsize=7.5,
                    arrowprops={"arrowstyle": "->", "color": "0.4"})
    xr = max(0.05, 1.15 * float(np.max(t["agronomic"])))
    yr = max(0.05, 1.15 * float(np.max(t["manufacturing"])))
    ax.set_xlim(-0.03 * xr, xr)  # the origin (everything met) stays in view
    ax.set_ylim(-0.03 * yr, yr)
    ax.set_xlabel("agronomic objectives: summed relative violation / - (0: all met)")
    ax.set_ylabel("manufacturability: summed relative violation / - (0: cuttable)")
    ax.set_title(f"Objectives against manufacturability, every evaluated design: "
                 f"{problem.name}", fontsize=10)
    ax.legend(fontsize=8, loc="upper right")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(out / "tradeoff.png", dpi=120)
    plt.close(fig)
    return [out / "tradeoff.csv", out / "tradeoff.png"]


def plot_run(out: Path, result, problem) -> list[Path]:
    """Write convergence.png (and pareto.png for two or more objectives); their paths."""
    written = [out / "convergence.png"]
    convergence_figure(result).savefig(written[0], dpi=120)
    fig = pareto_figure(result, problem)
    if fig is not None:
        fig.savefig(out / "pareto.png", dpi=120)
        written.append(out / "pareto.png")
    return written


# the violation axis is logarithmic: a run reaching 0 is drawn at this floor
VIOLATION_FLOOR = 1e-6


def best_so_far(history: list[dict]) -> np.ndarray:
    """The least total violation found so far at each row of a run's history, restarted
    at each stage (a stage's limits are its own: its violations are not comparable with
    the previous stage's); never rises within a stage."""
    out, best, stage = np.empty(len(history)), np.inf, None
    for i, h in enumerate(history):
        if h.get("stage", 1) != stage:
            best, stage = np.inf, h.get("stage", 1)
        best = min(best, h["best_violation"])
        out[i] = best
    return out


def convergence_figure(result):
    """The best design so far (least total relative violation) against evaluations, over
    the whole job: every stage, each shaded and named (a relaxed stage's violation is
    against its own limits). The floor line that marks 'every objective met' is drawn only
    when a design met them all."""
    from matplotlib.figure import Figure

    hist = result.history
    fig = Figure(figsize=(10, 4.5), layout="constrained")
    ax = fig.subplots()
    ev = np.array([h["evaluations"] for h in hist], dtype=float)
    stage = np.array([h.get("stage", 1) for h in hist])
    best = np.maximum(best_so_far(hist), VIOLATION_FLOOR)
    n, labels = (int(stage.max()) if len(stage) else 1), set()
    for k in range(1, n + 1):
        rows = np.flatnonzero(stage == k)
        if not len(rows):
            continue
        judged = all(hist[i].get("judged", True) for i in rows)
        label = ("best design so far" if judged
                 else "best so far, against the stage's relaxed limits")
        ax.semilogy(ev[rows], best[rows], ".-", color="k" if judged else "0.55",
                    label=None if label in labels else label)
        labels.add(label)
        if n > 1:
            lo = ev[rows[0]] - (ev[rows[0]] - ev[rows[0] - 1]) / 2 if rows[0] else 0.0
            hi = ev[rows[-1]]
            if k % 2:
                ax.axvspan(lo, hi, color="tab:blue", alpha=0.06, lw=0)
            ax.text((lo + hi) / 2, 1.0, f"stage {k}/{n}", transform=ax.get_xaxis_transform(),
                    ha="center", va="bottom", fontsize=7)
    ax.set_xlabel("evaluations (from the start of the job)")
    ax.set_ylabel("least total relative violation so far / -")
    met = bool(result.feasible)
    verdict = ("every objective met" if met
               else "NOT met: the best design misses an objective")
    ax.set_title(f"Convergence of {result.problem} ({result.algorithm}, random seed "
                 f"{result.seed}): {verdict}", pad=14 if n > 1 else 6)
    if met:
        ax.axhline(VIOLATION_FLOOR, color="tab:green", lw=1, ls=":",
                   label=f"{VIOLATION_FLOOR:g}: violation 0, every objective met")
    if result.first_feasible_evaluations:
        ax.axvline(result.first_feasible_evaluations, color="tab:green", ls="--",
                   label=f"first design meeting every objective ({result.first_feasible_s:.1f} s)")
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0)
    ax.grid(alpha=0.3, which="both")
    return fig


def pareto_figure(result, problem):
    """Final non-dominated objectives, axes with units (Figure), or None for fewer than
    two objectives or points."""
    from matplotlib.figure import Figure

    F = result.pareto_f
    names = problem.objective_names
    if F.ndim != 2 or F.shape[1] < 2 or len(F) < 2:
        return None
    fig = Figure(figsize=(7.5, 5.5), layout="constrained")
    ax = fig.subplots()
    sc = ax.scatter(F[:, 0], F[:, 1], c=F[:, 2] if F.shape[1] > 2 else "tab:blue",
                    cmap="viridis")
    if F.shape[1] > 2:
        fig.colorbar(sc, ax=ax, label=objective_label(names[2]))
    ax.set_xlabel(objective_label(names[0]))
    ax.set_ylabel(objective_label(names[1]))
    ax.set_title("Pareto front (final population, non-dominated; all minimized)")
    ax.grid(alpha=0.3)
    return fig
