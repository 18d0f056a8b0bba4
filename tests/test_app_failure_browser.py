"""An optimization started from the app's page that fails inside its task (issue 29): the page
says why in words, with no traceback, and the server's log (the program `plantmech app`, its
task processes writing to the same stderr) holds no traceback either. Playwright driving
Debian's chromium, as tests/test_app_browser.py.

The failure is a real one a user meets: the printed Table 2 path of Liu et al. (2023)
(``sugarcane_table2_as_printed``, no [train]) has an infeasible inverse design, and layer 2
optimizes the train derived from it: the task stops with "the trajectory's inverse design is
infeasible: run layer 1 first" (``mechanisms.seeder_trains.with_train``)."""

from __future__ import annotations

import signal
import socket
import subprocess
import sys
import time
import urllib.request

import pytest

from tests.app_page import HAVE_CHROMIUM, browser_page, load

pytestmark = pytest.mark.skipif(not HAVE_CHROMIUM,
                                reason="Debian's chromium is not installed (.ci/run installs it)")
sync_api = pytest.importorskip("playwright.sync_api")


def _port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture(scope="module")
def app_program(tmp_path_factory):
    """`plantmech app` as a user starts it, its stdout and stderr (the server's log, its
    task processes' included) in a file: (URL, the process, the log's path)."""
    log = tmp_path_factory.mktemp("app") / "server.log"
    port = _port()
    with log.open("w") as fh:
        p = subprocess.Popen([sys.executable, "-m", "plantmech.interfaces.cli", "app",
                              "--port", str(port), "--no-browser", "--workers", "1"],
                             stdout=fh, stderr=subprocess.STDOUT, text=True)
    url = f"http://127.0.0.1:{port}"
    t0 = time.time()
    while time.time() - t0 < 90:
        try:
            urllib.request.urlopen(url + "/api/examples", timeout=2).read()
            break
        except OSError:
            assert p.poll() is None, log.read_text()
            time.sleep(0.2)
    try:
        yield url, p, log
    finally:
        if p.poll() is None:
            p.kill()
            p.wait(10)


MARKUP = '<img src=x onerror="window.__xss = (window.__xss || 0) + 1">'


@pytest.mark.parametrize("start,status", [("#opt-start", "#opt-status"),
                                          ("#g-start", "#g-status")])
def test_a_refusal_holding_markup_shows_as_text(app_program, start, status):
    """The server's words are text, never markup: a design holding a field named like an
    HTML image with an onerror script is refused by the server, whose message names the
    field (``design: field '<img ...>': unknown field``); the optimizer's and the gear
    cutter's status show that message as the characters it is. Before, startOptimize and
    startGears put it into innerHTML: the image was made and its script ran."""
    url, p, log = app_program
    with browser_page(url) as page:
        load(page, "rice_transplanter")
        page.evaluate("(k) => { window.__plantmech.design[k] = 1; }", MARKUP)
        page.click(start)
        page.wait_for_function("(s) => document.querySelector(s).innerText.includes("
                               "'unknown field')", arg=status, timeout=30000)
        text = page.locator(status).inner_text()
        assert f"field '{MARKUP}': unknown field" in text, text
        assert page.locator(f"{status} img").count() == 0
        assert page.evaluate("document.querySelectorAll('img[src=\"x\"]').length") == 0
        page.wait_for_timeout(300)  # an image's onerror would have run by now
        assert page.evaluate("window.__xss") is None


def test_a_failing_optimization_says_why_without_a_traceback(app_program):
    url, p, log = app_program
    with browser_page(url) as page:
        load(page, "sugarcane_table2_as_printed")
        page.select_option("#opt-problem", "seeder-layer2")
        page.fill("#opt-gen", "1")
        page.fill("#opt-pop", "4")
        page.click("#opt-start")
        page.wait_for_function("document.getElementById('opt-status').innerText"
                               ".includes('optimization failed')", timeout=90000)
        status = page.locator("#opt-status").inner_text()
        body = page.evaluate("document.body.innerText")
        assert status == ("optimization failed: the trajectory's inverse design is "
                          "infeasible: run layer 1 first"), status
        for words in ("Traceback", 'File "', "ValueError", "Error:"):
            assert words not in body, words
        assert page.evaluate("document.getElementById('opt-start').disabled") is False
        assert page.evaluate("document.getElementById('opt-cancel').disabled") is True
    p.send_signal(signal.SIGINT)  # Ctrl-C: the server stops cleanly
    assert p.wait(60) == 0
    text = log.read_text()
    assert "Traceback" not in text and "Error" not in text, text
    assert f"plantmech app on {url}/" in text
