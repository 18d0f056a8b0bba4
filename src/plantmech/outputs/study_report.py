"""The HTML report of a design study directory (``plantmech study --out DIR``).

Reads what the study wrote (``study.json``, ``summary.json``, ``band.csv``, the Parquet
chunks, ``plan.csv`` for the planned trajectory) and shows, for a tolerance study: the
verdict (P(every objective met) with its 95 % interval, against the required
probability when the study file gives one), the probability that each objective holds,
the tolerances, the tip-path band over the planned trajectory, the sensitivity ranking
and the histograms with their limits. Sweeps and multi-start studies get their table
and plot. Plots a study skipped (``--no-plots``) are drawn here from its files. No
physics here: every number comes from the study's files.
"""

from __future__ import annotations

import datetime as _dt
import html
import json
from pathlib import Path

import numpy as np

from plantmech.inputs import InputFileError

REPORT_NAME = "report.html"

_EXTRA_STYLE = """
.verdict.info { background: #eef3fa; color: #17375e; border: 1px solid #7fa6d6; }
.risk { color: #a15c00; font-weight: 700; }
.pbar { display: inline-block; width: 6em; height: 0.7em; background: #f2d7d5;
        vertical-align: middle; margin-right: 0.4em; border-radius: 2px; }
.pbar i { display: block; height: 100%; background: #4a7ab0; border-radius: 2px; }
.small { font-size: 0.85em; color: #555; }
#probability-table { font-size: 0.85em; }
#probability-table td.num { white-space: normal; }
#probability-table .lim { display: block; color: #555; font-size: 0.9em; }
"""


# The directory holds no study, or its files cannot be read (names the file): an input
# file error, as every one (``plantmech.inputs``; ``studies.engine.StudyStateError`` from
# the readers of the chunks and the summary is one too, so ``except StudyReportError``
# catches them all).
StudyReportError = InputFileError


def load_study(out: str | Path) -> tuple[dict, dict]:
    """(study.json, summary.json) of a study directory, read bounded and checked against
    what the report reads (``studies.summary``; StudyReportError naming file and field)."""
    from plantmech.studies.summary import read_state, read_summary

    out = Path(out)
    if not out.is_dir():
        raise StudyReportError(f"{out}: not a directory")
    return read_state(out), read_summary(out)


def study_verdict(summary: dict) -> tuple[str, str]:
    """(style, sentence): style 'ok', 'fail' or 'info' (a result with no requirement to
    meet). The same rule as the exit status of ``plantmech study``."""
    n = summary.get("samples", summary.get("starts", 0))
    run = summary.get("run", {})
    if summary.get("complete") is False:
        return "fail", (f"INCOMPLETE: this covers the {n} finished "
                        f"{'starts' if summary['kind'] == 'multi-start' else 'samples'} only "
                        f"({run.get('total_chunks', '?')} chunks planned); rerun the same "
                        "'plantmech study' command to resume")
    kind = summary["kind"]
    if kind == "tolerance":
        p, (lo, hi) = summary["probability_all_ok"], summary["probability_all_ok_95"]
        text = (f"P(every objective met) = {p:.4f} (95 %: {lo:.4f}-{hi:.4f}) over {n} "
                f"samples; P(the {len(summary['nominal_met'])} objectives the nominal "
                f"design meets all still met) = {summary['probability_nominal_met_kept']:.4f}")
        req = summary.get("required_probability")
        if req is None:
            return "info", text + " (no required_probability in the study file)"
        if summary.get("requirement_met"):
            return "ok", text + f"; required {req:g}: met"
        return "fail", f"NOT MET: required P(every objective met) >= {req:g}; " + text
    if kind == "sweep":
        return "info", (f"{100 * summary['fraction_all_ok']:.1f} % of the {n} designs meet "
                        "every objective")
    ok = summary.get("successes", 0) > 0
    return ("ok" if ok else "fail"), (
        f"{summary.get('successes', 0)} of {summary.get('starts', n)} starts met every "
        "objective" + ("" if ok else ": NOT MET"))


def study_verdict_record(summary: dict) -> dict:
    """The study's verdict as every command's (``outputs.verdict``): built once by
    ``plantmech study``, recorded as summary.json's ``verdict`` with its sentence
    (``text``) and style, read back by the report and by ``plantmech report``."""
    from plantmech.outputs.verdict import verdict

    if "kind" not in summary:  # no chunk finished
        style, text = "fail", ("INCOMPLETE: no chunk of this study has finished; rerun the "
                               "same 'plantmech study' command to resume")
    else:
        style, text = study_verdict(summary)
    return {**verdict(problems=[text] if style == "fail" else []), "style": style,
            "text": text}


def study_verdict_line(v: dict) -> str:
    """The line ``plantmech study`` and ``plantmech report`` print last."""
    return "verdict: " + (f"ok - {v['text']}" if v["ok"] else v["text"])


def recorded_verdict(summary: dict) -> dict:
    """summary.json's recorded verdict, or (a directory written before it was recorded, or
    edited since) the one its numbers give now."""
    fresh = study_verdict_record(summary)
    v = summary.get("verdict")
    if isinstance(v, dict) and v.get("text") == fresh["text"] and v.get("ok") == fresh["ok"]:
        return v
    return fresh


def _f(v, digits: int = 4) -> str:
    if v is None or (isinstance(v, float) and not np.isfinite(v)):
        return "n/a"
    if isinstance(v, float | int | np.floating):
        return f"{float(v):.{digits}g}"
    return html.escape(str(v))


def _pbar(p: float) -> str:
    return f'<span class="pbar"><i style="width:{100 * p:.1f}%"></i></span>'


def _probability_cell(o: dict, n: int) -> str:
    p = o["probability_ok"]
    lo, hi = o["probability_ok_95"]
    if p >= 1.0:
        text = f"1: met in all {n} samples (95 %: &ge; {lo:.4f})"
    elif p <= 0.0:
        text = f"0: met in none of {n} samples (95 %: &le; {hi:.4f})"
    else:
        text = f"{p:.4f} (95 %: {lo:.4f}-{hi:.4f})"
    return _pbar(p) + "<br>" + text


def _status(p: float) -> tuple[str, str]:
    if p >= 1.0:
        return "ok", "holds"
    if p <= 0.0:
        return "fail", "fails"
    return "risk", "at risk"


def _objectives_table(summary: dict) -> str:
    n = summary["samples"]
    rows = ['<table id="probability-table"><thead><tr><th>status</th><th>objective '
            "(limit)</th><th>nominal design</th><th>P(ok) (95 % interval)</th>"
            "<th>mean &plusmn; std (first order)</th><th>0.1 % .. 99.9 %</th>"
            "<th>most influential (first order; Monte Carlo SRC)</th></tr></thead><tbody>"]
    for o in summary["objectives"]:
        cls, word = _status(o["probability_ok"])
        unit = html.escape(o.get("unit") or "")
        q = o.get("quantiles", {})
        rank = o["sensitivity"]["ranking"]
        top = rank[0] if rank else None
        best_src = max(rank, key=lambda r: abs(r["src"])) if rank else None
        infl = ""
        if top is not None and top.get("first_order_sigma", 0) > 1e-12:
            infl = f"{html.escape(top['parameter'])} ({_f(top['first_order_sigma'], 3)} {unit})"
        else:
            infl = "none at first order"
        if best_src is not None:
            r2 = o["sensitivity"].get("r2")
            infl += (f"; SRC {html.escape(best_src['parameter'])} {best_src['src']:+.2f}"
                     + (f" (R&sup2; {r2:.2f})" if r2 is not None and r2 == r2 else ""))
        nom_cls = "ok" if o["nominal_ok"] else "fail"
        rows.append(
            f'<tr><td class="{cls}">{word}</td><td>{html.escape(o["name"])}'
            f'<span class="lim">{html.escape(o["limit"])}</span></td>'
            f'<td class="num"><span class="{nom_cls}">{_f(o["nominal"], 6)}</span> {unit}</td>'
            f'<td class="num">{_probability_cell(o, n)}</td>'
            f'<td class="num">{_f(o.get("mean"), 6)} &plusmn; {_f(o.get("std"), 3)} {unit}'
            f'<br>({_f(o.get("first_order_std"), 3)})</td>'
            f'<td class="num">{_f(q.get("0.001"), 4)} ..<br>{_f(q.get("0.999"), 4)}</td>'
            f"<td>{infl}</td></tr>")
    rows.append("</tbody></table>")
    return "\n".join(rows)


def _distribution_text(p: dict) -> str:
    d = p["distribution"]
    mean = p.get("mean", 0.0)
    shift = f" about {mean:+g}" if mean else ""
    if d == "normal":
        return f"normal, sigma {p['sigma']:g}{shift}"
    if d == "truncated_normal":
        return f"normal, sigma {p['sigma']:g}, cut at &plusmn; {p['limit']:g}{shift}"
    if p.get("plus_minus") is not None:
        return f"uniform &plusmn; {p['plus_minus']:g}{shift}"
    return f"uniform {p['low']:g} .. {p['high']:g}"


def study_mechanism(state: dict, summary: dict) -> str:
    """The mechanism a study varied: study.json's, or (older studies) told by the
    parameters' names."""
    from plantmech.studies.parameters import SEEDER_PARAMETERS

    if state.get("mechanism"):
        return state["mechanism"]
    names = [p["name"] for p in summary.get("parameters", [])]
    return ("sugarcane_seeder" if names and all(n in SEEDER_PARAMETERS for n in names)
            else "rice_transplanter")


def _parameters_table(summary: dict, mechanism: str) -> str:
    from plantmech.kinds import KINDS

    kind = KINDS.get(mechanism)
    known = kind.hook("study_model").PARAMETERS if kind is not None else {}
    rows = ['<table id="tolerance-table"><thead><tr><th>parameter</th><th>what</th>'
            "<th>deviation</th><th>std</th><th>nominal</th></tr></thead><tbody>"]
    for p in summary["parameters"]:
        unit, what = known.get(p["name"], ("", ""))
        rows.append(f'<tr><td>{html.escape(p["name"])}</td><td>{html.escape(what)}</td>'
                    f"<td>{_distribution_text(p)} {html.escape(unit)}</td>"
                    f'<td class="num">{_f(p["std"])} {html.escape(unit)}</td>'
                    f'<td class="num">{_f(p["nominal"], 7)} {html.escape(unit)}</td></tr>')
    rows.append("</tbody></table>")
    return "\n".join(rows)


def _band_table(summary: dict) -> str:
    b = summary.get("band_summary", {})
    outs = summary.get("outputs", {})
    rows = ['<table id="band-table"><tbody>']
    if b:
        rows.append(f"<tr><td>largest std of the deviation along the path normal over the "
                    f'cycle</td><td class="num">{_f(b["largest_mc_std_mm"])} mm (first order '
                    f'{_f(b["largest_first_order_std_mm"])} mm)</td></tr>')
        rows.append(f"<tr><td>widest Monte Carlo envelope (min .. max)</td>"
                    f'<td class="num">{_f(b["largest_envelope_width_mm"])} mm</td></tr>')
    labels = {"path_deviation_mm": "largest deviation along the path normal, per sample",
              "tip_deviation_mm": "largest distance from the nominal tip, per sample",
              "attitude_error_deg": "largest arm / needle angle error, per sample"}
    for name, text in labels.items():
        o = outs.get(name)
        if o and "quantiles" in o:
            q = o["quantiles"]
            rows.append(f"<tr><td>{text}</td><td class=\"num\">median {_f(q['0.5'])}, "
                        f"99 % {_f(q['0.99'])}, 99.9 % {_f(q['0.999'])} {o['unit']}</td></tr>")
    share = outs.get("path_deviation_mm", {}).get("first_order_rms_contribution_mm", {})
    if share:
        top = ", ".join(f"{html.escape(k)} {v:.3g} mm" for k, v in list(share.items())[:4])
        rows.append(f"<tr><td>largest shares of the band (first order, rms over the cycle)"
                    f"</td><td>{top}</td></tr>")
    rows.append("</tbody></table>")
    return "\n".join(rows)


def _sensitivity_table(summary: dict) -> str:
    rows = ['<table id="sensitivity-table"><thead><tr><th>objective</th>'
            "<th>P(ok)</th><th>R&sup2; of the linear fit</th>"
            "<th>ranking (first order |d/dx| x std; Monte Carlo SRC)</th></tr></thead><tbody>"]
    for o in summary["objectives"]:
        s = o["sensitivity"]
        largest = max([r.get("first_order_sigma", 0.0) for r in s["ranking"]] + [0.0])
        # round-off (a share below 1e-6 of the largest) is no contribution
        rank = [r for r in s["ranking"] if r.get("first_order_sigma", 0) > 1e-6 * largest
                and r.get("first_order_sigma", 0) > 0 or abs(r["src"]) >= 0.05][:4]
        unit = html.escape(o.get("unit") or "")
        items = "; ".join(f"{html.escape(r['parameter'])} {_f(r.get('first_order_sigma'), 3)}"
                          f" {unit} (SRC {r['src']:+.2f})" for r in rank) or "none"
        r2 = s.get("r2")
        rows.append(f"<tr><td>{html.escape(o['name'])}</td>"
                    f'<td class="num">{o["probability_ok"]:.4f}</td>'
                    f'<td class="num">{_f(r2, 2) if r2 is not None else "n/a"}</td>'
                    f"<td>{items}</td></tr>")
    rows.append("</tbody></table>")
    return "\n".join(rows)


BAND_COLUMNS = ("carrier_angle_deg", "nominal_x_mm", "nominal_y_mm", "normal_x", "normal_y",
                "mc_mean_mm", "mc_std_mm", "mc_min_mm", "mc_max_mm", "first_order_mean_mm",
                "first_order_std_mm")


def _band_from_csv(out: Path) -> dict | None:
    from plantmech.studies.summary import read_csv

    path = out / "band.csv"
    if not path.exists():
        return None
    col = read_csv(path, BAND_COLUMNS)
    return {"carrier_angle_deg": col["carrier_angle_deg"],
            "nominal_tip_mm": np.c_[col["nominal_x_mm"], col["nominal_y_mm"]],
            "normal": np.c_[col["normal_x"], col["normal_y"]],
            "mc_mean_mm": col["mc_mean_mm"], "mc_std_mm": col["mc_std_mm"],
            "mc_min_mm": col["mc_min_mm"], "mc_max_mm": col["mc_max_mm"],
            "first_order_mean_mm": col["first_order_mean_mm"],
            "first_order_std_mm": col["first_order_std_mm"]}


def _plan_from_csv(out: Path) -> np.ndarray | None:
    from plantmech.studies.summary import read_csv

    path = out / "plan.csv"
    if not path.exists():
        return None
    arr = read_csv(path, ("x_mm", "y_mm"))
    return np.c_[arr["x_mm"], arr["y_mm"]]


def ensure_plots(out: Path, summary: dict, into: Path | None = None) -> list[Path]:
    """The study's PNG plots, drawn from its files where the study skipped them (into
    ``into``, default the study directory itself)."""
    from plantmech.outputs import study_plots as sp
    from plantmech.studies.engine import read_results

    into = out if into is None else Path(into)
    kind = summary["kind"]
    names = {"tolerance": ["histograms.png", "sensitivity.png", "band.png"],
             "sweep": ["sweep.png"], "multi-start": ["multistart.png"]}[kind]
    missing = [n for n in names if not (out / n).exists()]
    if missing:
        from plantmech.studies.summary import check_columns

        data = read_results(out)
        check_columns(data, summary, out)
        for n in missing:
            if n == "histograms.png":
                sp.plot_histograms(into / n, data, summary)
            elif n == "sensitivity.png":
                sp.plot_sensitivity(into / n, summary)
            elif n == "band.png":
                band = _band_from_csv(out)
                if band is not None:
                    sp.plot_band(into / n, {**summary, "band": band}, _plan_from_csv(out))
            elif n == "sweep.png":
                sp.plot_sweep(into / n, data, summary)
            else:
                sp.plot_multistart(into / n, data)
    return [d / n for n in names for d in (out, into) if (d / n).exists()]


def _figure(path: Path, caption: str) -> str:
    from plantmech.outputs.report import _img_tag

    return (f'<figure id="fig-{path.stem}">{_img_tag(path, caption)}<figcaption>'
            f"{html.escape(caption)}</figcaption></figure>")


BAND_CAPTION = (
    "Tip-path band. Left: the planned trajectory (grey, where the design has one), the "
    "nominal tip path (black) and the Monte Carlo envelope of the deviation along the "
    "path's normal (red, magnified by the factor in the legend so that it can be seen). "
    "Right: that deviation over the cycle: Monte Carlo min .. max (shaded), mean +- 3 std, "
    "and the first-order (finite-difference) mean +- 3 std. Steps are flank changes of "
    "the backlash.")
HIST_CAPTION = (
    "Histograms of every objective (blue: samples meeting it, red: not), the limits in "
    "red (a limit far from every sample is named at the edge with its distance), the "
    "nominal design dashed; P(ok) with its 95 % Wilson interval.")
SENS_CAPTION = (
    "Sensitivity ranking: bars, the first-order contribution |d objective / d parameter| "
    "x std (central differences of the same model at the nominal design); text, the "
    "standardized regression coefficient (SRC) of the Monte Carlo samples. An R² far "
    "below 1 means the response is not linear (outputs over a set of cycle samples move "
    "in steps): read the SRC there.")


GENERATOR = '<meta name="generator" content="plantmech report">'


def build_study_report(out: str | Path, command: str = "", plots_into: Path | None = None
                       ) -> str:
    """The study's report as one self-contained HTML string (plots the study skipped are
    drawn into ``plots_into``, default the study directory)."""
    from plantmech import __version__
    from plantmech.outputs.files import _clean
    from plantmech.outputs.report import _STYLE

    out = Path(out)
    state, summary = load_study(out)
    kind = summary["kind"]
    v = recorded_verdict(summary)
    style, verdict = v["style"], v["text"]
    title = f"plantmech {kind} study: {state.get('design', '')}"
    when = _dt.datetime.now(_dt.UTC).strftime("%Y-%m-%d %H:%M UTC")
    mark = {"ok": "&#10003;", "fail": "&#10007;", "info": "Result:"}[style]
    parts = ["<!doctype html>", '<html lang="en"><head><meta charset="utf-8">', GENERATOR,
             '<meta name="viewport" content="width=device-width, initial-scale=1">',
             f"<title>{html.escape(title)}</title><style>{_STYLE}{_EXTRA_STYLE}</style>"
             "</head><body>", f"<h1>{html.escape(title)}</h1>",
             f'<p class="meta">{html.escape(command or str(out))} &middot; plantmech '
             f"{__version__} &middot; {when}</p>",
             f'<div id="verdict" class="verdict {style}">{mark} {html.escape(verdict)}</div>']
    plots = {p.name: p for p in ensure_plots(out, summary, plots_into)}
    if kind == "tolerance":
        n = summary["samples"]
        parts += ['<h2 id="probability">Probability that each objective holds</h2>',
                  f'<p class="small">{n} Monte Carlo samples; the nominal design\'s value in '
                  "green where it meets the objective, red where it does not. "
                  "<b>holds</b>: met in every sample (the interval bounds how rarely it may "
                  "fail), <b>at risk</b>: met in some, <b>fails</b>: in none.</p>",
                  _objectives_table(summary),
                  '<h2 id="tolerances">Tolerances</h2>',
                  '<p class="small">Every value is a deviation from the design, drawn '
                  "independently per sample (docs/studies.md: the model behind each).</p>",
                  _parameters_table(summary, study_mechanism(state, summary)),
                  '<h2 id="band">Tip-path band over the planned trajectory</h2>'
                  if (out / "plan.csv").exists() else
                  '<h2 id="band">Tip-path band around the nominal path</h2><p class="small">'
                  "This design has no planned trajectory: the band is drawn around its "
                  "nominal tip path.</p>",
                  _band_table(summary)]
        if "band.png" in plots:
            parts.append(_figure(plots["band.png"], BAND_CAPTION))
        parts += ['<h2 id="sensitivity">Sensitivity ranking</h2>', _sensitivity_table(summary)]
        if "sensitivity.png" in plots:
            parts.append(_figure(plots["sensitivity.png"], SENS_CAPTION))
        if "histograms.png" in plots:
            parts += ['<h2 id="histograms">Histograms with the limits</h2>',
                      _figure(plots["histograms.png"], HIST_CAPTION)]
    elif kind == "sweep":
        rows = ['<table id="sweep-table"><thead><tr><th>objective</th><th>limit</th>'
                "<th>fraction of the designs meeting it</th><th>min .. max</th></tr></thead>"
                "<tbody>"]
        for o in summary["objectives"]:
            rows.append(f"<tr><td>{html.escape(o['name'])}</td>"
                        f"<td>{html.escape(summary.get('limits', {}).get(o['name'], ''))}</td>"
                        f'<td class="num">{_pbar(o["fraction_ok"])}{o["fraction_ok"]:.4f}</td>'
                        f'<td class="num">{_f(o.get("min"))} .. {_f(o.get("max"))}</td></tr>')
        rows.append("</tbody></table>")
        parts += ['<h2 id="sweep">Objectives over the sweep</h2>', "\n".join(rows)]
        if "sweep.png" in plots:
            parts.append(_figure(plots["sweep.png"], "Every objective against every swept "
                                 "parameter (blue: met, grey: not met, red: limits)."))
    else:
        rows = ['<table id="best-table"><thead><tr><th>rank</th><th>seed</th>'
                "<th>met every objective</th><th>total violation</th><th>file</th></tr>"
                "</thead><tbody>"]
        for b in summary.get("best", []):
            rows.append(f"<tr><td>{b['rank']}</td><td>{b['seed']}</td>"
                        f"<td>{'yes' if b.get('feasible') else 'no'}</td>"
                        f'<td class="num">{_f(b["total_violation"])}</td>'
                        f"<td>{html.escape(b['file'])}</td></tr>")
        rows.append("</tbody></table>")
        parts += ['<h2 id="starts">Best designs</h2>', "\n".join(rows)]
        if "multistart.png" in plots:
            parts.append(_figure(plots["multistart.png"], "Total violation of each start's "
                                 "best design (0: every objective met)."))
    run = summary.get("run", {})
    parts += ['<h2 id="run">Run</h2>',
              f"<p>{summary.get('samples', summary.get('starts', 0))} "
              f"{'starts' if kind == 'multi-start' else 'designs'}"
              f" in this directory. The last run: {run.get('computed_chunks', 0)} chunks "
              f"computed, {run.get('skipped_chunks', 0)} already done, "
              f"{len(run.get('failed_chunks', []))} failed, of {run.get('total_chunks', 0)}; "
              f"{run.get('evaluations', 0)} evaluations in {_f(run.get('wall_s'))} s on "
              f"{run.get('workers', 0)} workers"
              + (f" ({_f(run.get('designs_per_s'))} designs/s)" if run.get("designs_per_s")
                 else "") + ".</p>"]
    js = json.dumps(_clean(summary), indent=1, default=str)
    parts += ['<h2 id="summary">Everything computed</h2>',
              f"<details><summary>summary.json ({len(js)} characters)</summary>"
              f"<pre>{html.escape(js)}</pre></details>", "</body></html>"]
    return "\n".join(parts)


def write_study_report(out: str | Path, path: str | Path | None = None,
                       command: str = "", plots_into: Path | None = None) -> Path:
    """Write the report of study directory ``out`` (default ``out/report.html``; the file
    replaced in one rename, never written through a link)."""
    from plantmech.outputs.files import write_text_atomic

    out = Path(out)
    target = Path(path) if path is not None else out / REPORT_NAME
    write_text_atomic(target, build_study_report(out, command, plots_into))
    return target


def is_previous_report(path: Path) -> bool:
    """``path`` is a regular file written by ``plantmech report`` / ``study --report``
    (replaced without --force); anything else is never replaced without it."""
    import os
    import stat

    try:
        if not stat.S_ISREG(os.lstat(path).st_mode):
            return False
        with open(path, "rb") as fh:
            head = fh.read(4096).decode("utf-8", "replace")
    except OSError:
        return False
    return head.lower().startswith("<!doctype html>") and GENERATOR in head


#: ``plantmech report``'s JSON record (beside the page, :func:`record_path`) says so here
RECORD_OF = "plantmech report"


def record_path(page: Path) -> Path:
    """Where ``plantmech report`` records its run: the page's name with ``.json``
    (``report.html`` -> ``report.json``)."""
    return Path(page).with_suffix(".json")


def report_record(study: Path, page: Path, command: str, verdict: dict,
                  plots: list[str]) -> dict:
    """``plantmech report``'s JSON record: what it read and wrote, and the study's one verdict
    (:func:`recorded_verdict`, the dict ``plantmech study`` recorded in summary.json and
    both commands print last)."""
    from plantmech import __version__

    return {"record_of": RECORD_OF, "plantmech_version": __version__, "command": command,
            "study": str(study), "report": str(page), "plots_added_to_study": plots,
            "verdict": verdict}


def is_previous_record(path: Path) -> bool:
    """``path`` is a regular file holding a record :func:`report_record` wrote (replaced
    without --force); anything else is never replaced without it. Read bounded."""
    from plantmech.inputs import read_input_bytes

    try:
        data = json.loads(read_input_bytes(path, "report record", 1 << 20))
    except (InputFileError, ValueError):
        return False
    return isinstance(data, dict) and data.get("record_of") == RECORD_OF
