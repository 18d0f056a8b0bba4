"""The app in a real browser: Playwright driving Debian's chromium (never a downloaded
browser). Loads both mechanisms, drags a type-value point and sees the objectives
change, makes the design infeasible and sees the red span with its reason, runs a
short optimization and loads a point of its front, cuts the teeth of a general train."""

from __future__ import annotations

import pytest

from tests.app_page import HAVE_CHROMIUM, browser_page, drag, load, point_px, served_app

pytestmark = pytest.mark.skipif(not HAVE_CHROMIUM,
                                reason="Debian's chromium is not installed (.ci/run installs it)")
sync_api = pytest.importorskip("playwright.sync_api")


@pytest.fixture(scope="module")
def base_url():
    with served_app() as url:
        yield url


@pytest.fixture(scope="module")
def page(base_url):
    with browser_page(base_url) as pg:
        yield pg


def check_value(page, name):
    return page.locator(f'#checks tr[data-check="{name}"] td.num').inner_text()


def test_both_mechanisms_load_and_animate(page):
    load(page, "sugarcane_seeder")
    assert page.locator("#checks tbody tr").count() >= 13
    assert "mm" in check_value(page, "small_ring_height")
    a0 = page.locator("#angle").inner_text()
    # the carrier turns
    page.wait_for_function("a => document.getElementById('angle').innerText !== a", arg=a0,
                           timeout=5000)
    load(page, "rice_transplanter")
    assert "deg" in check_value(page, "picking_angle")
    assert page.locator("#edit input[data-field='arm.S_mm']").count() == 1
    # text in a number field: the design model's message beside that field
    inp = page.locator("#edit input[data-field='arm.S_mm']")
    inp.fill("abc")
    inp.press("Enter")
    err = page.locator("[data-error-for='arm.S_mm']")
    err.wait_for(timeout=20000)
    assert "number" in err.inner_text()
    assert "INVALID INPUT" in page.locator("#verdict").inner_text()  # nothing shown as valid
    page.click("#undo")
    page.wait_for_function("!window.__plantmech.inflight && window.__plantmech.result"
                           " && window.__plantmech.design.arm.S_mm === 150", timeout=20000)


def test_stage_labels_do_not_overlap(page):
    """The transplanter's stages lie close together ("planting" beside "return", "picking"
    beside "carry"): their labels are placed in rows, every label drawn, no two boxes
    overlapping, all inside the plot."""
    load(page, "rice_transplanter")
    # the previous test may end on this example: wait for this load's own answer
    page.wait_for_function("window.__plantmech.result && window.__plantmech.result.stages_deg"
                           " && !window.__plantmech.inflight", timeout=30000)
    stages = page.evaluate("Object.entries(window.__plantmech.result.stages_deg.arm_I)"
                           ".filter(([k, v]) => v).map(([k]) => k)")
    assert len(stages) >= 4
    for plot in ("plot1", "plot2", "plot3"):
        boxes = page.evaluate(f"document.getElementById('{plot}').spanLabels")
        assert sorted(b["text"] for b in boxes) == sorted(stages)
        width = page.evaluate(f"document.getElementById('{plot}').width")
        legend = page.evaluate(f"document.getElementById('{plot}').legendBox")
        for i, a in enumerate(boxes):
            assert 0 <= a["x"] and a["x"] + a["w"] <= width + 1, a
            for b in boxes[i + 1:] + ([legend] if legend else []):
                apart = (a["x"] + a["w"] <= b["x"] or b["x"] + b["w"] <= a["x"]
                         or a["y"] + a["h"] <= b["y"] or b["y"] + b["h"] <= a["y"])
                assert apart, (plot, a, b)


def test_drag_changes_objectives_and_undo(page):
    load(page, "sugarcane_seeder")
    before = check_value(page, "large_ring_width")
    x, y = page.evaluate("window.__plantmech.design.trajectory.points[10]")
    page.evaluate("window.__dragTimes.length = 0")
    drag(page, 10, [x + 6.0, y + 4.0])
    after = check_value(page, "large_ring_width")
    assert after != before
    assert page.evaluate("window.__dragTimes.length") >= 1  # drag answers were drawn live
    # they came over the page's edit stream (the WebSocket), not one HTTP request per move
    assert set(page.evaluate("window.__dragBreakdown.map(b => b.transport)")) == {"websocket"}
    assert page.evaluate("window.__plantmech.undo.length") == 1  # one entry per gesture
    page.click("#undo")
    page.wait_for_function("!window.__plantmech.inflight && window.__plantmech.undo.length"
                           " === 0 && window.__plantmech.result.quality === 'full'")
    assert check_value(page, "large_ring_width") == before


def test_drag_sends_the_next_edit_before_drawing_and_keeps_the_check_rows(page):
    """While a point is dragged faster than the answers come, the waiting edit goes out
    the moment an answer arrives, before that answer is drawn (the server computes while
    the page draws), and the checks table keeps its rows: only their cells change, and
    they show the drawn answer's values."""
    load(page, "sugarcane_seeder")
    x0, y0 = point_px(page, 10)
    page.evaluate("window.__dragBreakdown.length = 0")
    page.mouse.move(x0, y0)
    page.mouse.down()
    for k in range(1, 4):  # a few mm at most: the design stays feasible
        page.mouse.move(x0 + k, y0)
    page.wait_for_function("window.__dragBreakdown.length >= 1", timeout=60000)
    n0 = page.evaluate("""() => { document.querySelector(
        '#checks tr[data-check="large_ring_width"]').__marked = true;
        return window.__dragBreakdown.length; }""")
    for k in range(1, 41):  # no pause: moves come faster than answers
        page.mouse.move(x0 + 3 + k * 0.05, y0 + k * 0.05)
    page.wait_for_function(f"window.__dragBreakdown.length >= {n0 + 2}", timeout=60000)
    page.wait_for_function("!window.__plantmech.inflight && !window.__plantmech.pending",
                           timeout=60000)
    row = page.evaluate("""(n0) => { const tr = document.querySelector(
        '#checks tr[data-check="large_ring_width"]'); const s = window.__plantmech;
        const c = s.result.checks.find((c) => c.name === 'large_ring_width');
        return [tr.__marked === true, tr.cells[1].textContent,
                `${+c.value.toPrecision(5)} ${c.unit}`, s.result.quality,
                window.__dragBreakdown.length - n0]; }""", n0)
    page.mouse.up()
    page.wait_for_function("!window.__plantmech.inflight && !window.__plantmech.pending"
                           " && window.__plantmech.result.quality === 'full'", timeout=60000)
    marked, shown, expected, quality, drawn = row
    assert quality == "drag" and drawn >= 2
    assert marked, "the checks table's rows were rebuilt during the drag"
    assert shown == expected  # the cell shows the drawn answer's value
    parts = page.evaluate("window.__dragBreakdown")
    ahead = [b for b in parts if b["next_sent"] is not None]
    assert ahead, "no answer arrived with an edit waiting: the drag was not fast enough"
    for b in ahead:  # sent after the answer came and before its drawing began (ms)
        assert 0.0 <= b["next_sent"] <= b["send_next"]


def test_infeasible_span_drawn_red_with_reason(page):
    load(page, "sugarcane_seeder")
    x, _ = page.evaluate("window.__plantmech.design.trajectory.points[3]")
    drag(page, 3, [x, -219.36])  # Table 2's printed misprint
    assert "INFEASIBLE" in page.locator("#verdict").inner_text()
    reasons = page.locator("#diagnostics li").all_inner_texts()
    assert any("between q3 and q4" in r for r in reasons), reasons
    # the span q3-q4 is drawn red on the canvas
    rgb = page.evaluate("""() => { const s = window.__plantmech;
        const c = document.getElementById('mech');
        const p = s.result.spans[3][12]; const [x, y] = s.view.toPx(p[0], p[1]);
        const px = c.getContext('2d').getImageData(Math.round(x), Math.round(y), 1, 1);
        return Array.from(px.data); }""")
    assert rgb[0] > 180 and rgb[1] < 90 and rgb[2] < 90, rgb


def test_optimize_and_load_a_point_of_its_front(page):
    """A short optimization (1 generation of 4: the report's content is
    test_app_designer's); a click on its front loads that design, the user's kept for
    undo. Cutting teeth is tested on the seeder in tests/test_app_designer.py."""
    load(page, "sugarcane_table4")
    page.select_option("#opt-problem", "seeder-layer2")
    page.fill("#opt-gen", "1")
    page.fill("#opt-pop", "4")
    page.click("#opt-start")
    page.wait_for_function("document.getElementById('opt-status').innerText.includes("
                           "'evaluations')", timeout=55000)
    n = page.evaluate("document.getElementById('opt-pareto')._pts.length")
    assert n >= 1
    page.locator("#opt-pareto").scroll_into_view_if_needed()
    cx, cy, width = page.evaluate("(() => { const c = document.getElementById('opt-pareto');"
                                  " return [...c._pts[0].slice(0, 2), c.width]; })()")
    box = page.locator("#opt-pareto").bounding_box()
    scale = box["width"] / width  # the canvas may be drawn scaled by CSS
    page.mouse.click(box["x"] + cx * scale, box["y"] + cy * scale)
    page.wait_for_function("window.__plantmech.name.includes('optimized')"
                           " && !window.__plantmech.inflight")
    assert page.evaluate("window.__plantmech.undo.length") == 1  # the user's design is kept


def test_a_general_planetary_train(page):
    """The three-ellipse train: drawn and checked, a number edited, its teeth cut and
    drawn on the animated gears (each gear file by its name: sun, idler, planet)."""
    load(page, "rotary_transplanter_elliptic")
    assert page.locator("#checks tbody tr").count() == 6
    assert "centre distances 50.00, 50.00 mm" in page.locator("#mech-info").inner_text()
    inp = page.locator("#edit input[data-field='arm.length_mm']")
    inp.fill("190")
    inp.press("Enter")
    page.wait_for_function("!window.__plantmech.inflight && window.__plantmech.result"
                           " && window.__plantmech.design.arm.length_mm === 190"
                           " && window.__plantmech.result.quality === 'full'", timeout=20000)
    assert float(check_value(page, "path_height_mm").split()[0]) > 239.1  # a longer arm
    # the file frees no field for the optimizer: the page says so, nothing to start
    page.wait_for_function("document.getElementById('opt-start').disabled", timeout=10000)
    assert "[optimize.variables]" in page.locator("#opt-status").inner_text()
    page.click("#g-start")
    page.wait_for_function("window.__plantmech.teeth && window.__plantmech.teeth.gears"
                           " && 'idler1' in window.__plantmech.teeth.gears", timeout=120000)
    drawn = page.evaluate("Object.entries(window.__plantmech.teeth.gears)"
                          ".filter(([, e]) => e.drawn).map(([k]) => k).sort()")
    assert drawn == ["idler1", "planet", "sun"], page.locator("#teeth-note").inner_text()
