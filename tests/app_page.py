"""The browser tests' shared pieces (tests/test_app_browser.py, tests/test_app_designer.py):
the app served on a free loopback port and a page of Debian's chromium (driven by
Playwright, never a downloaded browser) that fails on any console error."""

from __future__ import annotations

import socket
import threading
import time
from contextlib import contextmanager
from pathlib import Path

CHROMIUM = "/usr/bin/chromium"
HAVE_CHROMIUM = Path(CHROMIUM).exists()


@contextmanager
def served_app():
    """The app (compute workers warmed: numba's kernels compiled here once, the workers
    load them from disk) on a free loopback port: yields its URL."""
    import uvicorn

    from plantmech.app.server import create_app, warm_up

    warm_up()
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    srv = uvicorn.Server(uvicorn.Config(create_app(), host="127.0.0.1", port=port,
                                        log_level="warning"))
    th = threading.Thread(target=srv.run, daemon=True)
    th.start()
    t0 = time.time()
    while not srv.started and time.time() - t0 < 20:
        time.sleep(0.05)
    try:
        yield f"http://127.0.0.1:{port}"
    finally:
        srv.should_exit = True
        th.join(10)


@contextmanager
def browser_page(url: str, width: int = 1400, height: int = 1100):
    """A chromium page on the app, its first design evaluated; afterwards no console
    error may have been logged."""
    from playwright.sync_api import sync_playwright

    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM)
        ctx = browser.new_context(viewport={"width": width, "height": height},
                                  accept_downloads=True)
        pg = ctx.new_page()
        errors: list[str] = []
        pg.on("pageerror", lambda e: errors.append(str(e)))
        pg.on("console", lambda m: errors.append(m.text) if m.type == "error"
              and not m.text.startswith("Failed to load resource") else None)
        pg.goto(url)
        # the first answer of a fresh checkout compiles the kernels (numba's cache is cold)
        pg.wait_for_function("window.__plantmech && window.__plantmech.result", timeout=90000)
        pg.errors = errors
        yield pg
        browser.close()
    assert not errors, errors


def load(page, name):
    """Choose a bundled example and wait for its own first full answer (not the answer
    of the design shown before, which may have the same name)."""
    n0 = page.evaluate("window.__answers.length")
    page.select_option("#example", "")  # so that choosing the same example reloads it
    page.select_option("#example", name)
    page.wait_for_function(
        "([n, n0]) => window.__answers.length > n0 && window.__plantmech.name === n"
        " && window.__plantmech.result && window.__plantmech.result.quality === 'full'"
        " && !window.__plantmech.inflight && !window.__plantmech.pending",
        arg=[name, n0], timeout=90000)  # a first load may compile kernels (cold cache)


def point_px(page, i, xy=None):
    """Page coordinates of type-value point q_i (or of a given mm position)."""
    page.locator("#mech").scroll_into_view_if_needed()
    page.wait_for_function("window.__plantmech.view")
    box = page.locator("#mech").bounding_box()
    px, py = page.evaluate(
        """([i, xy]) => { const s = window.__plantmech;
            const p = xy || s.design.trajectory.points[i];
            const c = document.getElementById('mech'); const [x, y] = s.view.toPx(p[0], p[1]);
            const r = c.getBoundingClientRect();
            return [x * r.width / c.width, y * r.height / c.height]; }""",
        [i, xy])
    return box["x"] + px, box["y"] + py


def drag(page, i, to_mm, steps=8):
    x0, y0 = point_px(page, i)
    x1, y1 = point_px(page, i, to_mm)
    page.mouse.move(x0, y0)
    page.mouse.down()
    for k in range(1, steps + 1):
        page.mouse.move(x0 + (x1 - x0) * k / steps, y0 + (y1 - y0) * k / steps)
        page.wait_for_timeout(30)
    page.mouse.up()
    page.wait_for_function("!window.__plantmech.inflight && !window.__plantmech.pending"
                           " && window.__plantmech.result.quality === 'full'", timeout=30000)
