"""The app's API against a page on another origin, in a real browser (Debian's chromium
through Playwright): a page served from another port sends the "simple" cross-origin
POSTs a browser allows without a CORS preflight (text/plain fetch, a form) and none
starts a task (before: a gear-cutting task started); the app's own page still does.
And no process of a task outlives it: after an optimization from the app, and after a
cancelled one, neither the task process nor any process of its group remains (before: the
task process and its pool worker stayed, about 500 MB, until the server stopped)."""

from __future__ import annotations

import http.server
import json
import os
import socket
import threading
import time
from pathlib import Path

import pytest

CHROMIUM = "/usr/bin/chromium"
pytestmark = pytest.mark.skipif(not Path(CHROMIUM).exists(),
                                reason="Debian's chromium is not installed (.ci/run installs it)")
sync_api = pytest.importorskip("playwright.sync_api")
psutil = pytest.importorskip("psutil")


def _port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.fixture(scope="module")
def app_server():
    import uvicorn

    from plantmech.app.server import create_app

    app = create_app(workers=0)
    port = _port()
    srv = uvicorn.Server(uvicorn.Config(app, host="127.0.0.1", port=port, log_level="warning"))
    th = threading.Thread(target=srv.run, daemon=True)
    th.start()
    t0 = time.time()
    while not srv.started and time.time() - t0 < 20:
        time.sleep(0.05)
    yield app, f"http://127.0.0.1:{port}"
    srv.should_exit = True
    th.join(10)


@pytest.fixture(scope="module")
def elsewhere(tmp_path_factory):
    """Another origin: a static server on another port (http://127.0.0.1:OTHER)."""
    root = tmp_path_factory.mktemp("elsewhere")
    (root / "index.html").write_text("<!doctype html><title>elsewhere</title>"
                                     '<form id="f" method="POST" enctype="text/plain">'
                                     '<input name=\'{"design": {"a": "\' value=\'"}}\'>'
                                     "</form>", encoding="utf-8")

    class Quiet(http.server.SimpleHTTPRequestHandler):
        def __init__(self, *a, **kw):
            super().__init__(*a, directory=str(root), **kw)

        def log_message(self, *a):
            pass

    httpd = http.server.ThreadingHTTPServer(("127.0.0.1", _port()), Quiet)
    th = threading.Thread(target=httpd.serve_forever, daemon=True)
    th.start()
    yield f"http://127.0.0.1:{httpd.server_address[1]}"
    httpd.shutdown()


@pytest.fixture(scope="module")
def browser():
    with sync_api.sync_playwright() as p:
        b = p.chromium.launch(executable_path=CHROMIUM)
        yield b
        b.close()


def _example(page, base: str) -> dict:
    return page.evaluate("async u => (await (await fetch(u)).json()).design",
                         f"{base}/api/examples/sugarcane_seeder")


def test_a_page_on_another_origin_cannot_start_a_task(app_server, elsewhere, browser):
    app, base = app_server
    own = browser.new_page()
    own.goto(base)
    design = _example(own, base)
    page = browser.new_page()
    page.goto(elsewhere)
    seen: list[tuple[str, int]] = []
    page.on("response", lambda r: seen.append((r.url, r.status)) if r.url.startswith(base)
            else None)
    # "simple" requests: no preflight, the browser sends them and only hides the answer
    body = json.dumps({"design": design, "problem": "seeder-layer2"})
    for path in ("/api/gears", "/api/optimize"):
        page.evaluate("""async ([url, body]) => {
            try { await fetch(url, {method: "POST", mode: "no-cors",
                                    headers: {"Content-Type": "text/plain"}, body}); }
            catch (e) {} }""", [base + path, body])
    # a JSON fetch needs a preflight the app never grants
    page.evaluate("""async ([url, body]) => {
        try { await fetch(url, {method: "POST", headers: {"Content-Type": "application/json"},
                                body}); } catch (e) {} }""",
                  [base + "/api/gears", '{"design": {}}'])
    # a form posted to the app (a navigation)
    page.evaluate("([u]) => { const f = document.getElementById('f'); f.action = u; "
                  "f.submit(); }", [base + "/api/gears"])
    page.wait_for_load_state()
    time.sleep(0.5)
    assert app.state.tasks.tasks == {}, "a page elsewhere started a task"
    assert "another origin" in page.content()  # the form's answer: 403 with the reason
    # the app's own page still starts one (the check is not a closed door)
    r = own.evaluate("""async ([url, design]) => { const r = await fetch(url, {method: "POST",
        headers: {"Content-Type": "application/json"}, body: JSON.stringify({design,
        problem: "seeder-layer2", generations: 1, pop: 4})}); return [r.status, await r.json()]
        }""", [base + "/api/optimize", design])
    assert r[0] == 200 and r[1]["task"] in app.state.tasks.tasks
    own.evaluate("u => fetch(u, {method: 'POST', headers: {'Content-Type': "
                 "'application/json'}, body: '{}'})", f"{base}/api/tasks/{r[1]['task']}/cancel")
    own.close()
    page.close()


def _group(pgid: int) -> list[int]:
    """Live (not zombie) processes of a process group."""
    out = []
    for p in psutil.process_iter(["pid", "status"]):
        try:
            if os.getpgid(p.info["pid"]) == pgid and p.info["status"] != psutil.STATUS_ZOMBIE:
                out.append(p.info["pid"])
        except (ProcessLookupError, psutil.NoSuchProcess):
            pass
    return out


def _run(page, base: str, design: dict, generations: int, cancel_when_pool: bool = False):
    """Start a layer-1 optimization (its population runs in a process pool) from the app's
    page; (task, largest process group seen, final state)."""
    r = page.evaluate("""async ([url, design, g]) => { const r = await fetch(url, {method:
        "POST", headers: {"Content-Type": "application/json"}, body: JSON.stringify({design,
        problem: "seeder-layer1", generations: g, pop: 4})}); return await r.json(); }""",
                      [base + "/api/optimize", design, generations])
    task_id = r["task"]
    largest, state, t0 = 0, "running", time.time()
    while state == "running" and time.time() - t0 < 50:
        st = page.evaluate("async u => (await (await fetch(u)).json())",
                           f"{base}/api/tasks/{task_id}")
        state = st["state"]
        time.sleep(0.2)
        if state == "running":
            largest = max(largest, len(_group(_TASKS[task_id])))
            if cancel_when_pool and largest >= 2:
                page.evaluate("u => fetch(u, {method: 'POST', headers: {'Content-Type': "
                              "'application/json'}, body: '{}'})",
                              f"{base}/api/tasks/{task_id}/cancel")
    return task_id, largest, state


_TASKS: dict = {}


@pytest.mark.parametrize("generations, cancel", [(1, False), (500, True)],
                         ids=["finished", "cancelled"])
def test_no_process_of_a_task_remains(app_server, browser, monkeypatch, generations, cancel):
    app, base = app_server
    tasks = app.state.tasks
    start = tasks._start

    def remember(*a, **kw):  # the task process's pid is its process group's id
        task_id = start(*a, **kw)
        _TASKS[task_id] = tasks.tasks[task_id].process.pid
        return task_id

    monkeypatch.setattr(tasks, "_start", remember)
    page = browser.new_page()
    page.goto(base)
    design = _example(page, base)
    task_id, largest, state = _run(page, base, design, generations, cancel)
    assert state == ("failed" if cancel else "done"), tasks.status(task_id)
    assert largest >= 2, "the task never ran a pool: nothing was tested"
    pgid = _TASKS[task_id]
    t0 = time.time()
    while _group(pgid) and time.time() - t0 < 10:
        time.sleep(0.1)
    assert _group(pgid) == [], f"processes of task {task_id} remain"
    task = tasks.tasks[task_id]
    assert task.reaped and task.process.exitcode is not None
    page.close()
