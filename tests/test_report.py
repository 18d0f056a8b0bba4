"""The HTML report and the mechanism GIF (outputs/report.py): contents from the job's own
numbers, no external resource, and in Debian's Chromium (Playwright, every request
blocked): no console error and an animation that advances."""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import numpy as np
import pytest

from plantmech.design import load_design
from plantmech.outputs import report as rp
from tests.conftest import EXAMPLES

CHROMIUM = "/usr/bin/chromium"


@pytest.fixture(scope="module")
def table4_job():
    from plantmech.workflows import run_seeder_forward

    return run_seeder_forward(load_design(EXAMPLES / "sugarcane_table4.toml"))


@pytest.fixture(scope="module")
def rice_job():
    from plantmech.workflows import run_transplanter

    return run_transplanter(load_design(EXAMPLES / "rice_transplanter.toml"))


def test_check_rows_and_verdict_from_a_summary():
    s = {"name": "x", "objectives": [
        {"name": "a", "value": 1.0, "unit": "mm", "limit": "< 2 mm", "ok": True},
        {"name": "b", "value": 3.0, "unit": "mm", "limit": "< 2 mm", "ok": False},
        {"name": "c", "value": 9.0, "unit": "deg", "limit": "reported", "ok": False,
         "required": False}],
         "mesh": [{"pair": "sun_gear2", "ok": True, "max_interference_mm": 0.0}],
         "other": {"nested": [{"name": "d", "ok": True}]}}
    rows = rp.check_rows(s)
    assert [r.get("name") or r["pair"] for r in rows] == ["a", "b", "c", "sun_gear2", "d"]
    assert rows[-1]["group"] == "other.nested"
    ok, text = rp.summary_verdict(s)
    # c is reported, not required: 4 required checks, one (b) fails
    assert not ok and "1 of 4" in text and "b" in text
    s["objectives"][1]["ok"] = True
    assert rp.summary_verdict(s) == (True, "every objective and check met (4 of 4)")
    assert rp.summary_verdict({"feasible": False})[0] is False
    # nothing checked (a gear pair's forward run): neither met nor failed, said so
    ok, text = rp.summary_verdict({"name": "pair", "tip": {"x_mm": [0.0]}})
    assert ok is None and text.startswith("nothing checked beyond the train closing")
    page = rp.build_report({"name": "pair"})
    assert 'class="verdict none"' in page and "&#10003;" not in page


def test_seeder_animation_links_have_the_train_lengths(table4_job):
    """Every frame: |OB| = L1 and |BA| = L2 (the simulated tip, independent of the
    animation's carrier line)."""
    a = rp.seeder_forward_animation(table4_job)
    carrier, arm = (np.asarray(lk["points"]) for lk in a.links)
    assert a.frames == rp.FRAMES == carrier.shape[0]
    tr = table4_job.train
    np.testing.assert_allclose(np.linalg.norm(carrier[:, 1] - carrier[:, 0], axis=1), tr.L1,
                               rtol=1e-9)
    np.testing.assert_allclose(np.linalg.norm(arm[:, 1] - arm[:, 0], axis=1), tr.L2,
                               rtol=1e-6)
    assert a.frame_labels[0].endswith(" 0.0 deg") and a.frame_labels[18].endswith("90.0 deg")


def test_transplanter_animation_arms_have_the_arm_lengths(rice_job):
    a = rp.transplanter_animation(rice_job)
    arm = rice_job.design.arm
    for lk in a.links:
        p = np.asarray(lk["points"])  # O, planet axis, break point A, tip B
        np.testing.assert_allclose(np.linalg.norm(p[:, 3] - p[:, 1], axis=1), arm.S_mm,
                                   rtol=1e-9)
        np.testing.assert_allclose(np.linalg.norm(p[:, 2] - p[:, 1], axis=1), arm.H1_mm,
                                   rtol=1e-9)
    assert len(a.links) == rice_job.design.carrier.arms


def test_gif_has_every_other_frame(table4_job, tmp_path):
    from PIL import Image

    a = rp.seeder_forward_animation(table4_job)
    path = rp.write_gif(a, tmp_path / "m.gif")
    im = Image.open(path)
    assert im.n_frames == rp.FRAMES // 2
    # GIF delays are in 10 ms steps
    assert im.info["loop"] == 0 and abs(im.info["duration"] - 1000 * 2 / a.fps) <= 10
    # the arm moves: consecutive frames differ
    im.seek(0)
    f0 = np.asarray(im.convert("RGB"), float)
    im.seek(5)
    assert np.abs(np.asarray(im.convert("RGB"), float) - f0).sum() > 0


def _report(job, tmp_path, anim):
    from plantmech.outputs import seeder_plots as sp

    figs = [("speed.png", sp.plot_forward_speed(job))]
    return rp.write_report(tmp_path / "report.html", job.summary, figs, anim,
                           command="plantmech forward (test)")


def test_report_is_self_contained_and_reports_every_objective(table4_job, tmp_path):
    paths = _report(table4_job, tmp_path, rp.seeder_forward_animation(table4_job))
    assert [p.name for p in paths] == ["report.html", "mechanism.gif"]
    text = paths[0].read_text()
    # no resource from elsewhere: every src is a data URI, no link/script src at all
    assert not re.search(r'(src|href)\s*=\s*"(?!data:)', text)
    assert "<link" not in text
    n_obj = len(table4_job.summary["objectives"])
    assert text.count("<tr><td class=") == n_obj
    failing = [o for o in table4_job.summary["objectives"] if not o["ok"]]
    assert text.count('<td class="fail">FAIL</td>') == len(failing)
    assert f"{len(failing)} of {n_obj} checks fail" in text
    data = json.loads(re.search(r'id="animation-data">(.*?)</script>', text, re.S).group(1))
    assert data["n"] == rp.FRAMES and len(data["links"][0]) == rp.FRAMES


@pytest.mark.skipif(not Path(CHROMIUM).exists() or shutil.which("true") is None,
                    reason="Debian's chromium is not installed (.ci/run installs it)")
def test_report_in_chromium_offline(rice_job, tmp_path):
    """Opened in Chromium with every network request blocked: no console error, no page
    error, no request at all, and the animation advances by itself and with the slider."""
    sync_api = pytest.importorskip("playwright.sync_api")
    from plantmech.outputs import transplanter_plots as tp

    html_path = rp.write_report(tmp_path / "report.html", rice_job.summary,
                                [("trajectories.png", tp.plot_trajectories(rice_job))],
                                rp.transplanter_animation(rice_job), gif=False)[0]
    errors, requests = [], []
    with sync_api.sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=CHROMIUM,
                                     args=["--no-sandbox", "--disable-gpu"])
        try:
            context = browser.new_context(offline=True)
            context.route("**/*", lambda route: (requests.append(route.request.url),
                                                 route.abort()))
            page = context.new_page()
            page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
            page.on("pageerror", lambda e: errors.append(str(e)))
            page.set_content(html_path.read_text(), wait_until="load")
            first = page.get_attribute("#link-0", "points")
            page.wait_for_function(
                "document.getElementById('mechanism').getAttribute('data-frame') > 5",
                timeout=15000)
            assert page.get_attribute("#link-0", "points") != first
            assert page.inner_text("#frame-label").startswith("carrier angle")
            page.click("#play")  # pause
            frame = page.get_attribute("#mechanism", "data-frame")
            page.wait_for_timeout(400)
            assert page.get_attribute("#mechanism", "data-frame") == frame
            page.fill("#frame-slider", "36")
            page.dispatch_event("#frame-slider", "input")
            assert page.get_attribute("#mechanism", "data-frame") == "36"
            assert page.inner_text("#frame-label").endswith("180.0 deg")
            assert page.is_visible("#verdict") and page.is_visible("#checks-table")
            # every arm is drawn in its colour (tab:blue of matplotlib = #1f77b4)
            strokes = page.evaluate("[...document.querySelectorAll('.link')].map("
                                    "e => getComputedStyle(e).stroke)")
            assert strokes[0] == "rgb(31, 119, 180)" and len(set(strokes)) == 3
            # the embedded plot decoded
            assert page.evaluate("document.querySelector('figure img').naturalWidth") > 100
        finally:
            browser.close()
    assert errors == []
    assert requests == []


def test_cli_report_of_an_infeasible_inverse_design(tmp_path):
    """No gear train, so no animation and no GIF; the verdict and the diagnostics say why."""
    from plantmech.interfaces.cli import main

    out = tmp_path / "inf"
    main(["inverse", str(EXAMPLES / "sugarcane_table2_as_printed.toml"), "--out", str(out),
          "--report"])
    text = (out / "report.html").read_text()
    assert 'class="verdict fail"' in text and "INFEASIBLE" in text
    assert "[ratio_not_positive] between q3 and q4" in text
    assert "animation-data" not in text and not (out / "mechanism.gif").exists()


def test_cli_report_of_an_optimization(tmp_path):
    """optimize --report: the run's verdict, its plots and best.toml animated."""
    from plantmech.interfaces.cli import main

    out = tmp_path / "opt"
    rc = main(["optimize", str(EXAMPLES / "rice_transplanter.toml"), "--problem",
               "transplanter", "--generations", "1", "--pop", "4", "--quiet", "--out",
               str(out), "--report"])
    run = json.loads((out / "run.json").read_text())
    text = (out / "report.html").read_text()
    assert rc in (0, 4) and (rc == 0) == bool(run["feasible"])
    assert ('class="verdict ok"' in text) == bool(run["feasible"])
    assert text.count("data:image/png;base64,") >= 1  # convergence.png at least
    # one objective table: the full-resolution re-check's values, each objective once
    table = re.search(r'<table id="checks-table">(.*?)</table>', text, re.S).group(1)
    checked = run["verified_full_resolution"]["objectives"]
    for o in checked:
        assert table.count(f"<td>{o['name']}</td>") == 1, o["name"]
    assert "<td>objectives at full resolution</td>" in table and "<td>objectives</td>" not in table
    data = json.loads(re.search(r'id="animation-data">(.*?)</script>', text, re.S).group(1))
    assert len(data["links"]) == 3  # the best design's three arms
    assert (out / "mechanism.gif").stat().st_size > 1000


def test_planetary_animation_and_report(tmp_path):
    """A general planetary train's report (``forward --report``): the arm from the planet
    axis to the tip is the arm's length in every frame, the planet axis stays at the
    chain's distance from O, every gear's pitch curve drawn with no legend entry; the
    page holds every [limits] check."""
    from plantmech.interfaces.cli import main

    ex = EXAMPLES / "rotary_transplanter_elliptic.toml"
    out = tmp_path / "o"
    assert main(["forward", str(ex), "--out", str(out), "--report"]) == 0
    html_text = (out / "report.html").read_text()
    assert "path_height_mm" in html_text and "loops" in html_text
    assert (out / "mechanism.gif").stat().st_size > 10_000
    from plantmech.design import load_design
    from plantmech.trains.model import simulate
    from plantmech.trains.spec import build_from_design

    design = load_design(ex)
    built = build_from_design(design)
    a = rp.planetary_animation(design, simulate(built, 720))
    arms = [lk for lk in a.links if lk["label"].startswith("carrier and arm")]
    gears = [lk for lk in a.links if not lk["label"]]
    assert len(arms) == design.carrier.arms and len(gears) == 5  # sun, 2 x (idler, planet)
    for lk in arms:
        p = np.asarray(lk["points"])  # O, idler axis, planet axis, tip
        np.testing.assert_allclose(np.linalg.norm(p[:, 3] - p[:, 2], axis=1),
                                   design.arm.length_mm, rtol=1e-9)
        np.testing.assert_allclose(np.linalg.norm(p[:, 2], axis=1),
                                   abs(built.shafts[0, -1]), rtol=1e-9)
    assert "<i style" in rp._legend(a) and rp._legend(a).count("<span>") == 4
