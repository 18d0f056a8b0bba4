"""The app as a designer uses it (issue 31), in Debian's chromium driven by Playwright: the
Make panel's verdict against the verification.json it offers, the gesture machine (a
radius drag, zoom and pan, hover), errors cleared when corrected, undo/redo across loads,
results tied to their design, the layout at 1024 and 1280 px (screenshots written under
pytest's temporary directory, their paths printed), the infeasible design's ghost and
ratio plot, the K-H-V edit panel and the optimizer's report.

One server and one page for the module (tests/test_app_browser.py's fixtures); the
expensive tasks are small: teeth cut at module 8 (about 8 s for the seeder), the
optimizer at 1 generation of 4."""

from __future__ import annotations

import json
import math
import tomllib
from pathlib import Path

import pytest

from tests.app_page import HAVE_CHROMIUM, browser_page, drag, load, point_px, served_app

pytestmark = pytest.mark.skipif(not HAVE_CHROMIUM,
                                reason="Debian's chromium is not installed (.ci/run installs it)")
pytest.importorskip("playwright.sync_api")


@pytest.fixture(scope="module")
def page():
    with served_app() as url, browser_page(url) as pg:
        yield pg


SETTLED = ("!window.__plantmech.inflight && !window.__plantmech.pending"
           " && !window.__plantmech.drag && window.__plantmech.result"
           " && window.__plantmech.result.quality === 'full'")


def settle(page):
    page.wait_for_function(SETTLED, timeout=60000)


def view(page) -> dict:
    """The mechanism view's scale (px/mm) and the pixel of the origin."""
    return page.evaluate("() => { const v = window.__plantmech.view;"
                         " return {s: v.s, ox: v.ox, oy: v.oy}; }")


def download(page, selector) -> Path:
    with page.expect_download() as dl:
        page.locator(selector).first.click()
    return Path(dl.value.path())


def canvas_px(page, canvas_id, x, y):
    """Page coordinates of canvas pixel (x, y) of a canvas drawn scaled by CSS."""
    page.locator(f"#{canvas_id}").scroll_into_view_if_needed()
    box = page.locator(f"#{canvas_id}").bounding_box()
    width = page.evaluate(f"document.getElementById('{canvas_id}').width")
    k = box["width"] / width
    return box["x"] + x * k, box["y"] + y * k


def test_seeder_make_panel_carries_the_verdict_of_verification_json(page):
    """The bundled seeder's gears cannot be cut: the panel says so with every finding of
    the verification.json it offers, each failing pair marked FAIL (not "meshes"), every
    download marked; an edit labels it stale, another example clears it."""
    load(page, "sugarcane_seeder")
    page.fill("#g-module", "8")
    page.click("#g-start")
    page.locator("#g-headline").wait_for(timeout=55000)
    rec = json.loads(download(page, "#g-files a:text-is('verification.json')").read_text())
    assert rec["verdict"]["label"] == "not manufacturable" and rec["findings"]
    head = page.locator("#g-headline").inner_text()
    assert "not manufacturable" in head and f"{len(rec['findings'])} findings" in head
    assert "not manufacturable" in page.locator("#make-headline").inner_text()
    items = page.locator("ol.findings li").all_inner_texts()
    assert len(items) == len(rec["findings"])
    for text, f in zip(items, rec["findings"], strict=True):  # gear, place and why
        assert text.startswith(f"{f['gear']}: {f['check']}") and f["why"] in text
    failed = {f["gear"] for f in rec["findings"]}
    for m in rec["mesh"]:
        cell = page.locator(f"#g-status tr[data-pair='{m['pair']}'] td").last.inner_text()
        assert cell == ("FAIL" if m["pair"] in failed or not m["ok"] else "meshes")
    assert "NOT MANUFACTURABLE" in page.locator("#g-files").inner_text()
    links = page.locator("#g-files a")
    assert links.count() == len([f for f in rec["files"] if not f.endswith(".png")]) + 1
    assert all("not-ok" in (links.nth(k).get_attribute("class") or "")
               for k in range(links.count()))
    dxf = download(page, "#g-files a:text-is('gear2.dxf')").read_text(errors="replace")
    assert "SECTION" in dxf and "ENTITIES" in dxf
    drawn = page.evaluate("Object.entries(window.__plantmech.teeth.gears)"
                          ".filter(([, e]) => e.drawn).map(([k]) => k).sort()")
    assert drawn == ["gear2", "gear3", "planet", "sun"]
    assert "Teeth as cut" in page.locator("#teeth-note").inner_text()
    # an edit of the design: the cut belongs to an earlier version (its teeth hidden)
    inp = page.locator("#edit input[data-field='trajectory.points.12.0']")
    inp.fill(str(float(inp.input_value()) + 1.0))
    inp.press("Enter")
    settle(page)
    assert "STALE" in page.locator("#g-stale").inner_text()
    assert "earlier version" in page.locator("#make-headline").inner_text()
    assert "design changed" in page.locator("#teeth-note").inner_text()
    page.click("#undo")  # the cut design is back: so are its teeth, and no stale label
    settle(page)
    assert "Teeth as cut" in page.locator("#teeth-note").inner_text()
    assert page.locator("#g-stale").inner_text() == ""
    # another example: nothing of the seeder's cut stays on offer
    load(page, "rice_transplanter")
    for sel in ("#g-verdict", "#g-files", "#g-status", "#make-headline", "#g-stale"):
        assert page.locator(sel).inner_text().strip() == "", sel


def test_radius_drag_of_ten_moves(page):
    """Ten pointer moves on a radius handle of gear 2: ten radii applied (each the
    pointer's distance from the centre along the handle's ray), the panel kept, one
    full-resolution answer after the release, one undo entry; undo restores it."""
    load(page, "sugarcane_table4")
    r0 = page.evaluate("window.__plantmech.design.train.gear2.radii_mm[0]")
    handles = page.evaluate("window.__radiusHandles().filter(h => h.g === 'gear2')")
    design = page.evaluate("window.__plantmech.design.train.gear2")
    angles = design.get("angles_deg") or [360 * i / len(design["radii_mm"])
                                          for i in range(len(design["radii_mm"]))]
    h = handles[0]
    assert angles[0] == 0 and abs(h["a"]) < 1e-9  # the first handle: the +x ray of gear 2
    j = angles.index(180)  # the handle opposite: their distance is s (r0 + r_j) pixels
    s = (h["x"] - handles[j]["x"]) / (r0 + design["radii_mm"][j])
    marker = page.evaluate("() => { const c = document.getElementById('radii');"
                           " c.__kept = true; return window.__answers.length; }")
    x0, y0 = canvas_px(page, "radii", h["x"], h["y"])
    box = page.locator("#radii").bounding_box()
    k = box["width"] / page.evaluate("document.getElementById('radii').width")
    page.mouse.move(x0, y0)
    page.mouse.down()
    seen = []
    for step in range(1, 11):
        page.mouse.move(x0 + 1.5 * step, y0)
        seen.append(page.evaluate("window.__plantmech.design.train.gear2.radii_mm[0]"))
    page.mouse.up()
    settle(page)
    expected = [round(r0 + 1.5 * step / k / s, 2) for step in range(1, 11)]
    assert seen == pytest.approx(expected, abs=0.011)
    assert len(set(seen)) == 10
    assert page.evaluate("document.getElementById('radii').__kept") is True  # not rebuilt
    answers = page.evaluate(f"window.__answers.slice({marker})")
    assert answers[-1] == "full" and answers.count("full") == 1, answers
    assert page.evaluate("window.__plantmech.undo.length") == 1
    assert page.evaluate("window.__plantmech.result.design.train.gear2.radii_mm[0]") == seen[-1]
    assert page.locator("#edit input[data-field='train.gear2.radii_mm.0']").input_value() \
        == str(seen[-1])
    page.click("#undo")
    page.wait_for_function(f"window.__plantmech.design.train.gear2.radii_mm[0] === {r0}")
    settle(page)


def test_an_invalid_value_then_a_valid_one_clears_the_error(page):
    load(page, "sugarcane_seeder")
    field = "trajectory.points.5.0"
    inp = page.locator(f"#edit input[data-field='{field}']")
    good = inp.input_value()
    inp.fill("abc")
    inp.press("Enter")
    page.locator(f"[data-error-for='{field}']").wait_for(timeout=30000)
    assert "invalid" in inp.get_attribute("class")
    inp.fill(good)  # the field keeps the focus: the panel is updated in place
    inp.press("Enter")
    page.wait_for_function(f"!document.querySelector(\"[data-error-for='{field}']\")",
                           timeout=30000)
    settle(page)
    assert "invalid" not in (inp.get_attribute("class") or "")
    assert page.evaluate("document.activeElement.dataset.field") == field
    assert "INVALID" not in page.locator("#verdict").inner_text()


def test_zoom_and_pan_then_a_drag_lands_on_the_point_under_the_pointer(page):
    load(page, "sugarcane_seeder")
    page.click("#fit")
    v0 = view(page)
    cx, cy = (round(c) for c in canvas_px(page, "mech", 360, 280))  # events: whole pixels
    box = page.locator("#mech").bounding_box()
    k = box["width"] / 720
    at = [(cx - box["x"]) / k, (cy - box["y"]) / k]  # the canvas pixel under the pointer
    page.mouse.move(cx, cy)
    under = page.evaluate("([x, y]) => window.__plantmech.view.toMM(x, y)", at)
    page.mouse.wheel(0, -300)
    page.wait_for_function(f"window.__plantmech.view.s > {v0['s']} * 1.2")
    v1 = view(page)
    assert v1["s"] / v0["s"] == pytest.approx(math.exp(300 * 0.0015), rel=1e-6)
    assert page.evaluate("([x, y]) => window.__plantmech.view.toMM(x, y)", at) == \
        pytest.approx(under, abs=0.6 / v1["s"])  # what is under the wheel stays (0.6 px)
    # pan: a press away from every point drags the view
    spot = page.evaluate("""() => { const s = window.__plantmech, pts = s.design.trajectory
        .points.map(p => s.view.toPx(p[0], p[1]));
        for (let y = 60; y < 540; y += 20) for (let x = 60; x < 660; x += 20)
          if (pts.every(([px, py]) => Math.hypot(px - x, py - y) > 40)) return [x, y];
        return null; }""")
    assert spot is not None
    px, py = canvas_px(page, "mech", *spot)
    page.mouse.move(px, py)
    page.mouse.down()
    page.mouse.move(px + 20, py + 10, steps=4)
    page.mouse.up()
    v2 = view(page)
    assert v2["ox"] - v1["ox"] == pytest.approx(20 / k, abs=0.5)
    assert v2["oy"] - v1["oy"] == pytest.approx(10 / k, abs=0.5)
    assert page.evaluate("window.__plantmech.undo.length") == 0  # a pan edits nothing
    x, y = page.evaluate("window.__plantmech.design.trajectory.points[10]")
    drag(page, 10, [x + 3.0, y + 2.0])
    q = page.evaluate("window.__plantmech.design.trajectory.points[10]")
    assert q == pytest.approx([x + 3.0, y + 2.0], abs=1.0 / (k * v2["s"]) + 0.011)
    page.click("#undo")
    settle(page)


def test_hover_and_grab_cursors_and_the_read_out(page):
    load(page, "sugarcane_seeder")
    page.click("#fit")
    x, y = point_px(page, 10)
    page.mouse.move(x, y)
    assert page.evaluate("document.getElementById('mech').style.cursor") == "grab"
    q = page.evaluate("window.__plantmech.design.trajectory.points[10]")
    assert page.locator("#readout").inner_text().startswith(
        f"q10: x {q[0]:.2f} mm, y {q[1]:.2f} mm")
    page.mouse.down()
    page.mouse.move(x + 2, y)
    assert page.evaluate("document.getElementById('mech').style.cursor") == "grabbing"
    page.mouse.up()
    settle(page)
    page.click("#undo")
    settle(page)


def test_labels_do_not_collide_and_a_legend_names_the_colours(page):
    load(page, "sugarcane_seeder")
    page.click("#fit")
    boxes = page.evaluate("document.getElementById('mech').pointLabels")
    n = page.evaluate("window.__plantmech.design.trajectory.points.length")
    assert len(boxes) == n  # every point labelled
    legend = page.evaluate("document.getElementById('mech').legendBox")
    entries = page.evaluate("document.getElementById('mech').legendEntries")
    assert {"sun (fixed)", "gear 2", "gear 3", "planet", "tip path"} <= set(entries)
    for i, a in enumerate(boxes):
        assert 0 <= a["x"] and a["x"] + a["w"] <= 720 and 0 <= a["y"] <= 560 - a["h"], a
        for b in boxes[i + 1:] + [legend]:
            assert (a["x"] + a["w"] <= b["x"] or b["x"] + b["w"] <= a["x"]
                    or a["y"] + a["h"] <= b["y"] or b["y"] + b["h"] <= a["y"]), (a, b)


@pytest.mark.parametrize("size", [(1024, 768), (1280, 800)])
def test_layout_shows_every_verdict_from_1024_px(page, size, tmp_path_factory):
    w, h = size
    page.set_viewport_size({"width": w, "height": h})
    try:
        load(page, "sugarcane_seeder")
        shot = tmp_path_factory.mktemp("screens") / f"seeder_{w}x{h}.png"
        page.screenshot(path=str(shot), full_page=True)
        print(f"screenshot: {shot}")
        rows = page.locator("#checks tbody tr")
        assert rows.count() >= 13
        for k in range(rows.count()):
            cell = rows.nth(k).locator("td").last
            cell.scroll_into_view_if_needed()
            box = cell.bounding_box()
            assert box["x"] >= 0 and box["x"] + box["width"] <= w, (k, box)
            assert cell.inner_text() in ("pass", "FAIL")
        for sel in ("#mech", "#plot1", "#plot3", "#opt-pareto", "#g-start"):
            box = page.locator(sel).bounding_box()
            assert box["x"] >= 0 and box["x"] + box["width"] <= w, (sel, box)
    finally:
        page.set_viewport_size({"width": 1400, "height": 1100})


def test_infeasible_design_keeps_a_ghost_and_draws_the_bad_ratio(page):
    """Table 2's misprinted q3: no train, so the last feasible one is ghosted; the ratio
    the trajectory asks for is drawn, negative in the red span the diagnostics name."""
    load(page, "sugarcane_seeder")
    x, _ = page.evaluate("window.__plantmech.design.trajectory.points[3]")
    drag(page, 3, [x, -219.36])
    assert "INFEASIBLE" in page.locator("#verdict").inner_text()
    assert "last feasible design (ghost)" in page.evaluate(
        "document.getElementById('mech').legendEntries")
    ratio = page.evaluate("document.getElementById('plot3').seriesY[0]")
    angles = page.evaluate("window.__plantmech.result.plots.carrier_angle_deg")
    lo, hi = page.evaluate("window.__plantmech.result.diagnostics.find(d => d.severity"
                           " === 'error').carrier_angle_deg")
    neg = [a for a, r in zip(angles, ratio, strict=True) if r is not None and r < 0]
    assert neg and lo - 1 <= min(neg) and max(neg) <= hi + 1  # negative inside the span
    labels = [b["text"] for b in page.evaluate("document.getElementById('plot3').spanLabels")]
    assert "infeasible" in labels
    page.click("#undo")
    settle(page)


def test_only_the_coincident_points_turn_red(page):
    load(page, "sugarcane_seeder")
    page.click("#fit")
    x5, y5 = page.evaluate("window.__plantmech.design.trajectory.points[5]")
    for c, v in ((0, x5), (1, y5)):
        inp = page.locator(f"#edit input[data-field='trajectory.points.6.{c}']")
        inp.fill(str(v))
        inp.press("Enter")
    page.wait_for_function("window.__plantmech.fieldErrors.length > 0"
                           " && !window.__plantmech.inflight", timeout=30000)
    msg = page.evaluate("window.__plantmech.fieldErrors.map(e => e.message).join(' ')")
    assert "q5" in msg and "q6" in msg
    colours = page.evaluate("""() => { const s = window.__plantmech;
        const ctx = document.getElementById('mech').getContext('2d');
        return s.design.trajectory.points.map(p => { const [x, y] = s.view.toPx(p[0], p[1]);
          return Array.from(ctx.getImageData(Math.round(x), Math.round(y), 1, 1).data); }); }""")
    red = [i for i, (r, g, b, _) in enumerate(colours) if r > 200 and g < 80 and b < 80]
    assert red == [5, 6], red
    page.click("#undo")
    page.click("#undo")
    settle(page)


def test_needle_angle_is_drawn_without_jumps(page):
    load(page, "rice_transplanter")
    raw = page.evaluate("window.__plantmech.result.plots.needle_angle_deg")
    drawn = page.evaluate("document.getElementById('plot1').seriesY")
    for r, d in zip(raw, drawn, strict=True):
        steps = [abs(b - a) for a, b in zip(d, d[1:], strict=False)
                 if a is not None and b is not None]
        assert max(steps) < 30  # continuous through 0/360
        for a, b in zip(r, d, strict=True):  # the same angle, whole turns added
            if a is not None:
                assert (b - a) / 360 == pytest.approx(round((b - a) / 360), abs=1e-9)


def test_khv_edit_panel_offers_every_number_of_its_train(page):
    load(page, "rice_transplanter_khv")
    design = page.evaluate("window.__plantmech.design")
    fields = set(page.evaluate(
        "Array.from(document.querySelectorAll('#edit input[data-field]'))"
        ".map(e => e.dataset.field)"))
    expected = {f"sun_gear.radii_mm.{i}" for i in range(len(design["sun_gear"]["radii_mm"]))}
    expected |= {f"arm.{k}" for k in design["arm"]} | {"carrier.initial_angle_deg"}
    assert expected <= fields, expected - fields
    inp = page.locator("#edit input[data-field='sun_gear.radii_mm.0']")
    inp.fill("37")
    inp.press("Enter")
    page.wait_for_function("window.__plantmech.result.design.sun_gear.radii_mm[0] === 37"
                           " && !window.__plantmech.inflight", timeout=30000)
    assert page.evaluate("window.__plantmech.undo.length") == 1
    page.click("#undo")
    settle(page)
    # the transplanter problem takes it (issue 28: the K-H-V train is optimized as the
    # papers' machines are), so it is offered and can be started
    problems = page.evaluate("Array.from(document.querySelectorAll('#opt-problem option'))"
                             ".map(o => o.value)")
    assert "transplanter" in problems, problems
    assert not page.locator("#opt-start").is_disabled()
    assert "no optimizer problem" not in page.locator("#opt-status").inner_text()


def test_optimize_reports_stages_counts_changes_tradeoff_and_cancel(page):
    """A small layer-1 run of the seeder: progress by stage, the start's and the result's
    counts of checks met (from run.json), what it changed (against best.toml), the
    trade-off archive drawn (tradeoff.csv's rows); a click loads the best design, undo
    brings the user's back under its name, Ctrl+Shift+Z redoes; a cancel says cancelled."""
    load(page, "sugarcane_seeder")
    name = page.evaluate("window.__plantmech.name")
    start = page.evaluate("window.__plantmech.design")
    start_checks = {c["name"]: c["ok"] for c in page.evaluate("window.__plantmech.fullResult"
                                                             ".checks")}
    page.evaluate("""() => { window.__optTexts = []; new MutationObserver(() =>
        window.__optTexts.push(document.getElementById('opt-status').innerText))
        .observe(document.getElementById('opt-status'), {childList: true, subtree: true,
                                                          characterData: true}); }""")
    page.select_option("#opt-problem", "seeder-layer1")
    page.fill("#opt-gen", "1")
    page.fill("#opt-pop", "4")
    page.click("#opt-start")
    page.locator("#opt-counts").wait_for(timeout=55000)
    texts = page.evaluate("window.__optTexts")
    stages = [int(t.split("stage ")[1].split()[0]) for t in texts if " stage " in t]
    assert stages == sorted(stages)  # never counts backwards across stages
    run = json.loads(download(page, "#opt-status a:text-is('run.json')").read_text())
    rows = (run.get("verified_full_resolution") or {}).get("objectives") or run["objectives"]
    # counted on the same checks: the run's required rows the start's answer has too
    req = [o for o in rows if o.get("required", True) and o["name"] in start_checks]
    counts = page.locator("#opt-counts").inner_text()
    met0 = sum(start_checks[o["name"]] for o in req)
    met1 = sum(o["ok"] for o in req)
    assert f"start {met0}/{len(req)} → result {met1}/{len(req)}" in counts
    assert ("WORSE" in counts) == (met1 < met0)
    best = tomllib.loads(download(page, "#opt-status a:text-is('best.toml')").read_text())
    changed = page.locator("#opt-changes li")
    assert changed.count() >= 1
    for k in range(min(changed.count(), 10)):
        path = changed.nth(k).get_attribute("data-field").split(".")
        a, b = start, best
        for key in path:
            a, b = a[int(key) if isinstance(a, list) else key], \
                b[int(key) if isinstance(b, list) else key]
        text = changed.nth(k).inner_text()
        if isinstance(b, int | float):
            assert a != pytest.approx(b) and f"→ {float(b):.6g}" in text
        else:  # a choice
            assert a != b and json.dumps(b) in text
    assert "name" not in changed.evaluate_all("els => els.map(e => e.dataset.field)")
    if not run["feasible"]:  # nothing meets everything: the trade-off archive is drawn
        csv = download(page, "#opt-status a:text-is('tradeoff.csv')").read_text()
        assert page.evaluate("document.getElementById('opt-pareto').dataset.kind") \
            == "tradeoff"
        assert page.evaluate("document.getElementById('opt-pareto')._pts.length") \
            == len(csv.strip().splitlines()) - 1
    # load the best design, undo, redo
    page.locator("#opt-pareto").scroll_into_view_if_needed()
    pts = page.evaluate("document.getElementById('opt-pareto')._pts[0]")
    x, y = canvas_px(page, "opt-pareto", pts[0], pts[1])
    page.mouse.click(x, y)
    page.wait_for_function("window.__plantmech.name.includes('optimized')")
    settle(page)
    assert page.locator("#opt-stale").inner_text() == ""  # the run's own design
    page.click("#undo")
    page.wait_for_function(f"window.__plantmech.name === {json.dumps(name)}")
    settle(page)
    page.locator("#mech").click(position={"x": 2, "y": 2})  # focus off the inputs
    page.keyboard.press("Control+Shift+Z")
    page.wait_for_function("window.__plantmech.name.includes('optimized')")
    settle(page)
    # a run cancelled says so (not "failed")
    page.fill("#opt-gen", "200")
    page.click("#opt-start")
    page.wait_for_function("document.getElementById('opt-status').innerText"
                           ".startsWith('running') || document.getElementById('opt-status')"
                           ".innerText.startsWith('starting')", timeout=30000)
    page.click("#opt-cancel")
    page.wait_for_function("document.getElementById('opt-status').innerText"
                           ".includes('cancelled')", timeout=30000)
    assert "failed" not in page.locator("#opt-status").inner_text()
