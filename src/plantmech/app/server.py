"""HTTP API of the plantmech app (FastAPI), bound to 127.0.0.1 by ``plantmech app``.

Every design travels as JSON (the design file's tables) and is validated by
``plantmech.design.load_design`` exactly as the CLI validates a file, so the page shows
the CLI's field-named errors. No file-system path ever comes from the client: examples
are chosen by name from the packaged ``plantmech/examples/*.toml``, the file given on the command
line is read once at start, generated files live in server-side temporary
directories and are served by name from the task's own list.

Edits (``/api/evaluate`` over HTTP, or a stream of them over the WebSocket ``/api/ws``)
are computed in worker processes, one per core (``plantmech.app.compute``): the whole
computation, from the request's JSON to the answer's, runs there
(``evaluate_request``). On the WebSocket only the newest waiting edit of a connection is
computed: an edit that a newer one replaced before its turn is answered ``superseded``.

Limits: request bodies and messages over ``MAX_BODY_BYTES`` get 413; a computation
(waiting included) over ``COMPUTE_TIMEOUT_S`` answers 503 with a JSON error and its
worker process is killed and replaced; background tasks (optimization, gear cutting) run
in child processes that are killed at their time limit.
"""

from __future__ import annotations

import asyncio
import re
import time
from pathlib import Path
from typing import Any

import numpy as np
from fastapi import FastAPI, Request, WebSocket
from fastapi.responses import FileResponse, JSONResponse, PlainTextResponse, Response
from fastapi.staticfiles import StaticFiles
from starlette.websockets import WebSocketDisconnect

from plantmech.app import scene

STATIC = Path(__file__).parent / "static"
MAX_BODY_BYTES = 512 * 1024
COMPUTE_TIMEOUT_S = 20.0
DRAG_SAMPLES = 360  # the app's working resolution during a drag (samples per carrier turn)
FRAMES = 360  # animation frames per carrier turn
DRAG_FRAMES, DRAG_DETAIL = 180, 360  # during a drag: frames, points per curve and plot


class AppError(Exception):
    """An error answered as JSON: status, message, and the fields it concerns."""

    def __init__(self, status: int, message: str, fields: list[dict] | None = None):
        super().__init__(message)
        self.status, self.message, self.fields = status, message, fields or []


def examples_dir() -> Path:
    """The examples shipped in the package (``plantmech.starters``; the repository's
    ``examples/`` is a link to them), so a wheel install has them too."""
    from plantmech.starters import example_path

    return example_path("sugarcane_seeder").parent


def example_names() -> list[str]:
    """The packaged examples (the seeders, the transplanters, the general planetary
    trains at the top of the examples folder)."""
    d = examples_dir()
    if not d.is_dir():
        return []
    return sorted(p.stem for p in d.glob("*.toml"))


_FIELD = re.compile(r"field '([^']+)': (.*)")


def field_errors(message: str) -> list[dict]:
    """[{field, message}] from a DesignError text (one line per field)."""
    out = []
    for line in message.splitlines():
        m = _FIELD.search(line)
        if m:
            out.append({"field": m.group(1), "message": m.group(2)})
    return out


def validate_design(raw: Any, label: str = "design", may_hold_null: bool = True):
    """Validate a design given as JSON tables, exactly as a design file is validated
    (``load_design``): returns the design model or raises AppError(422) whose
    message and fields name what is wrong. ``may_hold_null=False``: the caller knows the
    tables hold no JSON null (``evaluate_request``: no ``null`` in the request's bytes),
    so the walk looking for one is skipped."""
    from plantmech.design import DesignError, load_design

    if not isinstance(raw, dict):
        raise AppError(422, f"{label}: a design must be a table of fields")
    null = _null_field(raw) if may_hold_null else None
    if null is not None:  # the one JSON value a design file (TOML) cannot hold
        msg = (f"{label}: field '{null}': cannot be written as TOML: null has no TOML form "
               "(leave the field out)")
        raise AppError(422, msg, field_errors(msg))
    try:  # the parsed tables themselves: the same validation as a file, without its I/O
        design = load_design(raw, name=label)
    except DesignError as exc:
        msg = str(exc)
        raise AppError(422, msg, field_errors(msg)) from None
    return design


def _null_field(value, path: str = "") -> str | None:
    """Dotted path of the first null (None) inside JSON tables and arrays, else None: the
    only JSON value without a TOML form (strings, numbers, booleans, tables and arrays
    all have one), so a design without nulls can be written as a design file."""
    if value is None:
        return path or "(top)"
    if isinstance(value, dict):
        for key, item in value.items():
            if item is None or isinstance(item, (dict, list)):
                found = _null_field(item, f"{path}.{key}" if path else str(key))
                if found is not None:
                    return found
    elif isinstance(value, list):
        for k, item in enumerate(value):
            if item is None or isinstance(item, (dict, list)):
                found = _null_field(item, f"{path}.{k}")
                if found is not None:
                    return found
    return None


def design_json(design) -> dict:
    return design.model_dump(mode="json", exclude_none=True)


def fast_json(content) -> Response:
    """A JSON response serialized by orjson (NumPy arrays directly, NaN as null): the
    drawing data of one evaluation is ~10^5 numbers."""
    import orjson

    return Response(orjson.dumps(content, option=orjson.OPT_SERIALIZE_NUMPY),
                    media_type="application/json")


def _finite(x):
    if x is None:
        return None
    x = float(x)
    return x if np.isfinite(x) else None


# --- evaluation ---------------------------------------------------------------------------


def evaluate(design, quality: str = "full") -> dict:
    """Everything the page shows for ``design``: drawing data, checks, diagnostics.

    quality "drag": the app's working resolution (``DRAG_SAMPLES``) and only what a drag
    must see live (seeder trajectory: the inverse design with its feasibility verdict,
    Table 1 and the attitude objectives); "full": the design's own resolution and every
    check (seeder: the forward simulation of the designed train with every section-4.1
    objective and the gear checks)."""
    from plantmech.kinds import kind_of

    return kind_of(design).hook("app_scene")(design, quality == "drag")


def _seeder(design, drag: bool) -> dict:
    """A seeder from its trajectory (inverse design) or from its [train] (forward)."""
    if design.train is None:
        return _seeder_trajectory(design, drag)
    return _seeder_train(design, drag)


def _resolution(drag: bool) -> tuple[int, int]:
    """(animation frames, points per curve and plot) sent to the page."""
    return (DRAG_FRAMES, DRAG_DETAIL) if drag else (FRAMES, 720)


def _seeder_trajectory(design, drag: bool) -> dict:
    from plantmech.geometry.trajectory import TrajectoryError
    from plantmech.workflows import run_seeder_inverse

    d = design.model_copy()  # a copy of the one table changed (a deep copy costs ~2 ms)
    d.trajectory = design.trajectory.model_copy(
        update={"samples": DRAG_SAMPLES} if drag else {})
    try:  # during a drag the pitch curves' manufacturability waits for the release
        job = run_seeder_inverse(d, manufacturability=not drag)
    except TrajectoryError as exc:
        raise AppError(422, f"design: field 'trajectory.points': {exc}",
                       [{"field": "trajectory.points", "message": str(exc)}]) from None
    out = scene.seeder_inverse_scene(job, *_resolution(drag))
    checks = list(job.summary["trajectory_checks"]) + list(job.summary.get("objectives", []))
    out["quality"] = "drag" if drag else "full"
    if not job.result.feasible:
        out["checks"] = scene.checks_list(checks)
        return out
    if drag:  # live: the inverse design, Table 1, the attitude and the speed objectives
        from plantmech.workflows import inverse_speed_objectives

        sp = inverse_speed_objectives(job)
        speeds = scene.speed_plots(job.result.carrier_angle, sp, DRAG_DETAIL)
        del speeds["speed_carrier_angle_deg"]  # the other plots' grid: sent once
        out["plots"].update(speeds)
        out["checks"] = scene.checks_list(checks + sp["checks"])
        out["pending"] = ("speeds of the inverse design's train; the forward simulation of "
                          "the resampled train and the gear checks follow on release")
        return out
    from plantmech.workflows import InfeasibleDesign, run_seeder_forward

    try:
        fwd = run_seeder_forward(d)
    except InfeasibleDesign:  # cannot happen for a feasible inverse, kept for safety
        out["checks"] = scene.checks_list(checks)
        return out
    fs = scene.seeder_forward_scene(fwd, FRAMES)
    out["plots"].update({k: fs["plots"][k] for k in ("speed_static_m_s", "speed_dynamic_m_s",
                                                     "travel_m_s")})
    out["plots"]["speed_carrier_angle_deg"] = fs["plots"]["carrier_angle_deg"]
    out["checks"] = scene.checks_list(list(job.summary["trajectory_checks"]) + fwd.checks)
    dev = fwd.metrics.get("deviation_from_trajectory_mm")
    if dev:
        out["deviation_mm"] = dev
    return out


def _seeder_train(design, drag: bool) -> dict:
    from plantmech.gears.closure import ClosureError
    from plantmech.geometry.periodic import PitchCurveError
    from plantmech.workflows import run_seeder_forward

    d = design.model_copy(deep=True)
    if drag:
        d.train.samples = DRAG_SAMPLES
    try:
        job = run_seeder_forward(d)
    except (ClosureError, PitchCurveError, ValueError) as exc:
        text = str(exc)
        field = "train.gear3.radii_mm" if "gear 3" in text or "planet" in text else (
            "train.gear2.radii_mm" if "gear 2" in text or "sun" in text else "train")
        return {"mechanism": "sugarcane_seeder", "feasible": False, "quality":
                "drag" if drag else "full", "checks": [], "train_error": text,
                "diagnostics": [{"kind": "train", "severity": "error", "message": text,
                                 "field": field, "between_points": None,
                                 "carrier_angle_deg": None}],
                **({"train_points": _train_points(d)})}
    out = scene.seeder_forward_scene(job, *_resolution(drag))
    if job.trajectory is not None:
        out.update({k: v for k, v in scene.trajectory_part(d, job.trajectory, spans=False).items()
                    if k in ("plan", "points", "sections_points")})
    out.update({"feasible": True, "diagnostics": [], "quality": "drag" if drag else "full",
                "checks": scene.checks_list(job.checks)})
    return out  # the speeds share the other plots' grid (carrier_angle_deg): sent once


def _train_points(d) -> dict:
    t = d.train
    return {name: {"angles_deg": list(g.angles()), "radii_mm": list(g.radii_mm),
                   "a_mm": a}
            for name, g, a in (("gear2", t.gear2, t.a1_mm), ("gear3", t.gear3, t.a2_mm))}


def _transplanter(design, drag: bool) -> dict:
    from plantmech.gears.internal import InternalPairError
    from plantmech.workflows import run_transplanter

    d = design.model_copy(deep=True)
    if drag:
        d.samples = DRAG_SAMPLES
    from plantmech.kinds import kind_of

    gear = kind_of(d).fixed_gear
    try:
        job = run_transplanter(d)
    except (InternalPairError, ValueError) as exc:
        raise AppError(422, f"design: [{gear}]: {exc}",
                       [{"field": f"{gear}.radii_mm", "message": str(exc)}]) from None
    out = scene.transplanter_scene(job, *_resolution(drag))
    out["checks"] = scene.checks_list(job.summary["objectives"])
    out["quality"] = "drag" if drag else "full"
    out["centre_distance_mm"] = job.summary["centre_distance_mm"]
    return out


def _planetary(design, drag: bool) -> dict:
    """A general planetary train: its forward motion (``trains``), the [limits] checks
    and, at full quality, every pair's pitch-curve manufacturability rules
    (``objectives.planetary.judged``, the rows ``plantmech optimize --problem planetary``
    judges it by)."""
    from plantmech.objectives.planetary import checks, judged, motion_objectives
    from plantmech.trains.model import simulate
    from plantmech.trains.spec import TrainSpecError, build_from_design

    d = design.model_copy(deep=True)
    if drag:
        d.samples = DRAG_SAMPLES
    try:
        built = build_from_design(d)
    except TrainSpecError as exc:
        field = str(exc).split("'")[0] or "train.pairs"
        msg = f"design: field '{exc}"
        raise AppError(422, msg, field_errors(msg) or [{"field": field, "message": str(exc)}]
                       ) from None
    motion = simulate(built, d.samples)
    out = scene.planetary_scene(d, motion, *_resolution(drag))
    if drag:
        values = motion_objectives(motion, d.carrier.speed_deg_s)
        found = [c.as_dict() for c in checks(values, d.limits)]
        out["pending"] = "the pitch curves' manufacturability follows on release"
    else:
        found = judged([d], built, motion)[0]  # the motion drawn: built and run once
    out["checks"] = scene.checks_list(found)
    out["quality"] = "drag" if drag else "full"
    out["centre_distance_mm"] = [float(a) for a in built.centre_distances[0]]
    return out


def _planetary_parameters(design) -> list[dict]:
    """The numeric fields a planetary file frees in ``[optimize.variables]`` (with their
    bounds), else every number of its arm, carrier and pairs' curves with a box of
    +-25 % (angles +-45 deg) around the current value."""
    from plantmech.design_planetary import get_path
    from plantmech.units import unit_of

    opt = getattr(design, "optimize", None)
    variables = dict(getattr(opt, "variables", None) or {})
    out = []
    if variables:
        for path, (lo, hi) in variables.items():
            value = float(get_path(design, path))
            unit = unit_of(path)
            out.append({"field": path, "label": path, "unit": unit, "value": value,
                        "min": float(lo), "max": float(hi)})
        return out
    data = design_json(design)
    candidates = [("arm", "arm", data.get("arm", {})),
                  ("carrier", "carrier", data.get("carrier", {}))]
    for k, pair in enumerate(data.get("train", {}).get("pairs", [])):
        for part in ("driver", "follower"):
            if isinstance(pair.get(part), dict):
                candidates.append((f"train.pairs.{k}.{part}", f"pair {k + 1} {part}",
                                   pair[part]))
        law = pair.get("law")
        if isinstance(law, dict) and isinstance(law.get("constants"), dict):
            candidates.append((f"train.pairs.{k}.law.constants", f"pair {k + 1} law",
                               law["constants"]))
    return _general_parameters(candidates)


def _general_parameters(tables) -> list[dict]:
    """Every number of the given tables ``(dotted prefix, label, table dict)``, a list of
    lengths (``radii_mm``) item by item, with a box of +-25 % (angles +-45 deg, an
    eccentricity within 0..0.95) around the current value; counts and speeds (arms,
    lobes, teeth, speed) are not edited."""
    from plantmech.units import unit_of

    out = []
    for prefix, label, table in tables:
        for key, value in table.items():
            if isinstance(value, list) and unit_of(key) == "mm" and all(
                    isinstance(v, int | float) and not isinstance(v, bool) for v in value):
                items = [(f"{key}.{i}", f"{key} {i}", v) for i, v in enumerate(value)]
            elif isinstance(value, bool) or not isinstance(value, int | float):
                continue
            else:
                items = [(key, key, value)]
            if key in ("arms", "lobes", "teeth", "speed_deg_s"):
                continue
            unit = unit_of(key)
            for sub, name, v in items:
                if unit == "deg":
                    lo, hi = v - 45.0, v + 45.0
                else:
                    span = 0.25 * abs(v) or 1.0
                    lo, hi = v - span, v + span
                if key == "eccentricity":
                    lo, hi = max(lo, 0.0), min(hi, 0.95)
                out.append({"field": f"{prefix}.{sub}", "label": f"{label} {name}",
                            "unit": unit, "value": float(v), "min": float(lo),
                            "max": float(hi)})
    return out


def editable_parameters(design) -> list[dict]:
    """The transplanter's published parameters the page edits: design field, unit and
    the optimizer's bounds around the current value (``optimize.problems.Transplanter``)
    as the input's limits."""
    from plantmech.kinds import kind_of

    return kind_of(design).hook("app_parameters")(design)


def _no_parameters(design) -> list[dict]:
    """The seeder is edited on the drawing (its points or its pitch-curve radii)."""
    return []


def _khv_parameters(design) -> list[dict]:
    """The K-H-V train: every number of its tables, with the general bounds
    (``_general_parameters``: +-25 %, angles +-45 deg)."""
    data = design_json(design)
    return _general_parameters([(t, t.replace("_", " "), data[t]) for t in (
        "sun_gear", "carrier", "arm", "seedling_box") if isinstance(data.get(t), dict)])


def _transplanter_parameters(design) -> list[dict]:
    """The differential transplanter: its published parameters with the optimizer's bounds
    around the current value (``optimize.problems.Transplanter``) as the input's limits."""
    from plantmech.kinds import kind_of
    from plantmech.optimize.problems import Transplanter

    gear = kind_of(design).fixed_gear
    field = {"initial_angle_deg": "carrier.initial_angle_deg",
             "initial_phase_deg": "internal_gear.initial_phase_deg",
             "S_mm": "arm.S_mm", "H1_mm": "arm.H1_mm", "beta_deg": "arm.beta_deg",
             "box_x_mm": "seedling_box.x_mm", "box_y_mm": "seedling_box.y_mm",
             "box_inclination_deg": "seedling_box.inclination_deg"}
    try:
        variables = Transplanter(design).variables
    except Exception:  # noqa: BLE001 - a design the optimizer cannot take: no bounds
        variables = []
    out = []
    for v in variables:
        if re.fullmatch(r"r\d+", v.name):
            path, label = f"{gear}.radii_mm.{v.name[1:]}", f"radius r{v.name[1:]}"
        elif v.name in field:
            path, label = field[v.name], v.name
        else:
            continue
        out.append({"field": path, "label": label, "unit": v.unit, "value": v.x0,
                    "min": v.lower, "max": v.upper})
    return out


def evaluate_request(raw: bytes) -> tuple[int, bytes]:
    """(HTTP status, JSON bytes) of one edit request body ``{"design": {...}, "quality":
    "drag" | "full"}``: the answer of ``evaluate`` with the design as validated and, at
    full quality, the page's editable parameters; or ``{"error", "fields"}``. Runs in a
    compute worker (``plantmech.app.compute``); other keys of the body (the WebSocket's
    message id) are ignored."""
    import orjson

    try:
        try:
            data = orjson.loads(raw)
        except orjson.JSONDecodeError:
            raise AppError(400, "request body is not valid JSON") from None
        if not isinstance(data, dict):
            raise AppError(400, "request body must be a JSON object")
        quality = data.get("quality", "full")
        if quality not in ("drag", "full"):
            raise AppError(400, "field 'quality': expected 'drag' or 'full'")
        # a JSON null is written "null": without those four bytes (anywhere, strings
        # included) the tables hold none and the walk looking for one is skipped
        design = validate_design(data.get("design"), may_hold_null=b"null" in raw)
        result = evaluate(design, quality)
        result["design"] = design_json(design)
        result["parameters"] = editable_parameters(design) if quality == "full" else None
        return 200, orjson.dumps(result, option=orjson.OPT_SERIALIZE_NUMPY)
    except AppError as exc:
        return exc.status, orjson.dumps({"error": exc.message, "fields": exc.fields})
    except Exception as exc:  # noqa: BLE001 - an engine failure is an answer, not a dead worker
        return 500, orjson.dumps({"error": f"internal error while evaluating the design: "
                                           f"{type(exc).__name__}: {exc}", "fields": []})


def warm_up() -> None:
    """One drag evaluation of the seeder example: a compute worker's imports and first
    calls happen before it takes the first edit."""
    import orjson

    from plantmech.design import load_design

    design = design_json(load_design(examples_dir() / "sugarcane_seeder.toml"))
    evaluate_request(orjson.dumps({"design": design, "quality": "drag"}))


def same_origin(headers) -> bool:
    """A WebSocket handshake or a POST comes from the app's own page: no Origin (not a
    browser) or an Origin whose host and port are the Host header's (WebSockets are not
    bound by the browser's same-origin rule, and a "simple" cross-origin POST is sent
    before any CORS check, so a page elsewhere could start a task); a browser's
    ``Sec-Fetch-Site`` other than same-origin (or none: typed by the user) is refused too."""
    site = headers.get("sec-fetch-site")
    if site is not None and site not in ("same-origin", "none"):
        return False
    origin = headers.get("origin")
    if origin is None:
        return True
    return origin.split("://", 1)[-1].rstrip("/") == headers.get("host", "")


def _json_content_type(headers) -> bool:
    """The request body is declared ``application/json`` (parameters such as charset
    allowed): a form or text/plain body, which a page elsewhere may send without a CORS
    preflight, is never read."""
    kind = headers.get("content-type", "").split(";", 1)[0].strip().lower()
    return kind == "application/json"


LOOPBACK_HOSTS = ("127.0.0.1", "localhost", "[::1]", "testserver")


def _loopback_host(headers) -> bool:
    """The Host header names a loopback host (the rule of the app's TrustedHostMiddleware:
    a page elsewhere cannot reach the API by rebinding its name)."""
    host = dict(headers).get(b"host", b"").decode("latin-1")
    return host.split(":")[0] in LOOPBACK_HOSTS  # as starlette's TrustedHostMiddleware


class BodyLimit:
    """ASGI middleware: a POST, PUT or PATCH needs a Content-Length of at most
    ``MAX_BODY_BYTES`` (411 / 413 with a JSON error otherwise), and, from a loopback Host,
    the app's own origin (403: :func:`same_origin`) and an ``application/json`` body (415).
    Plain ASGI rather than ``@app.middleware("http")``: that wrapper costs every edit
    request a task and a stream.

    ``compute``: with it, ``POST /api/evaluate`` from a loopback Host is answered here —
    body read, handed to ``compute`` (``pool.run``), its bytes sent — without FastAPI's
    routing, request and response objects (the edit request is the hot path of the drag
    and of the load test; every other request, and an edit with another Host, goes
    through the whole stack). The answer and its headers are those of the route."""

    def __init__(self, app, compute=None):
        self.app = app
        self.compute = compute

    async def __call__(self, scope, receive, send):
        if scope["type"] == "http" and scope["method"] in ("POST", "PUT", "PATCH"):
            length = dict(scope["headers"]).get(b"content-length")
            error = None
            if length is None:
                error = (411, "a request body needs a Content-Length")
            elif not length.isdigit() or int(length) > MAX_BODY_BYTES:
                error = (413, f"request body over the {MAX_BODY_BYTES} byte limit")
            elif _loopback_host(scope["headers"]):  # another Host: 400 from TrustedHost
                headers = {k.decode("latin-1").lower(): v.decode("latin-1")
                           for k, v in scope["headers"]}
                if not same_origin(headers):
                    error = (403, "a request from another origin (a page elsewhere) is "
                             "refused: the app's API answers its own page only")
                elif not _json_content_type(headers):
                    error = (415, "a request body must be JSON (Content-Type: "
                             "application/json)")
            if error is not None:
                await JSONResponse({"error": error[1]}, status_code=error[0])(
                    scope, receive, send)
                return
        if scope["type"] != "http" or scope["path"] != "/api/evaluate":
            await self.app(scope, receive, send)
            return
        t0 = time.perf_counter()
        if (self.compute is not None and scope["method"] == "POST"
                and _loopback_host(scope["headers"])):
            await self._evaluate(receive, send, t0)
            return

        async def timed_send(message):
            # the whole request inside the server (body, validation, queue, compute,
            # JSON) as a second Server-Timing entry beside the computation's own
            if message["type"] == "http.response.start":
                dur = (time.perf_counter() - t0) * 1e3
                message = {**message, "headers": [*message.get("headers", []), (
                    b"server-timing", f"server;dur={dur:.2f}".encode())]}
            await send(message)

        await self.app(scope, receive, timed_send)

    async def _evaluate(self, receive, send, t0: float) -> None:
        chunks = []
        while True:
            message = await receive()
            if message["type"] == "http.disconnect":
                return
            chunks.append(message.get("body", b""))
            if not message.get("more_body", False):
                break
        status, answer, ms = await self.compute(b"".join(chunks))
        dur = (time.perf_counter() - t0) * 1e3
        await send({"type": "http.response.start", "status": status, "headers": [
            (b"content-length", str(len(answer)).encode()),
            (b"content-type", b"application/json"),
            (b"server-timing", f"compute;dur={ms:.2f}".encode()),
            (b"server-timing", f"server;dur={dur:.2f}".encode())]})
        await send({"type": "http.response.body", "body": answer})


# --- the application ----------------------------------------------------------------------


def create_app(initial: Path | None = None, workers: int | None = None,
               prewarm: bool = False) -> FastAPI:
    """The app; ``initial``: a design file named on the command line (read once, never
    written); ``workers``: compute worker processes (default one per core,
    ``compute.worker_count``; 0: in the server's own threads, ``compute.ThreadCompute``);
    ``prewarm``: start them with the server rather than at the first edit."""
    from contextlib import asynccontextmanager

    from plantmech.app.compute import ComputeError, ComputePool, ThreadCompute
    from plantmech.app.tasks import TaskManager

    tasks = TaskManager()
    pool = ThreadCompute() if workers == 0 else ComputePool(workers)

    @asynccontextmanager
    async def lifespan(_app):
        if prewarm:
            pool.start()
        yield
        pool.shutdown()
        tasks.shutdown()

    app = FastAPI(title="plantmech app", docs_url=None, redoc_url=None, lifespan=lifespan)
    from starlette.middleware.trustedhost import TrustedHostMiddleware

    # loopback names only: a page elsewhere cannot reach the API by rebinding its name
    app.add_middleware(TrustedHostMiddleware,
                       allowed_hosts=list(LOOPBACK_HOSTS))
    app.state.tasks = tasks
    app.state.compute = pool
    initial_payload: dict | None = None
    if initial is not None:
        from plantmech.design import load_design

        design = load_design(initial)  # DesignError goes to the CLI, before the server
        initial_payload = {"name": initial.name, "design": design_json(design)}


    @app.exception_handler(AppError)
    async def _app_error(request: Request, exc: AppError):
        return JSONResponse({"error": exc.message, "fields": exc.fields},
                            status_code=exc.status)

    async def compute(raw: bytes) -> tuple[int, bytes, float]:
        """(status, answer JSON, compute ms) of an edit request body, computed by a worker
        process under the compute time limit (waiting included)."""
        try:
            return await pool.run(raw, COMPUTE_TIMEOUT_S)
        except ComputeError as exc:
            import orjson

            return exc.status, orjson.dumps({"error": exc.message, "fields": []}), 0.0

    app.add_middleware(BodyLimit, compute=compute)

    async def body(request: Request) -> dict:
        import orjson

        try:  # orjson: nesting bounded (1024), no recursion to exhaust (json's raised
            data = orjson.loads(await request.body())  # RecursionError: a 500)
        except orjson.JSONDecodeError:
            raise AppError(400, "request body is not valid JSON") from None
        if not isinstance(data, dict):
            raise AppError(400, "request body must be a JSON object")
        return data

    @app.get("/", include_in_schema=False)
    async def index():
        return FileResponse(STATIC / "index.html", headers={"Cache-Control": "no-store"})

    app.mount("/static", StaticFiles(directory=STATIC), name="static")

    @app.get("/api/examples")
    async def examples():
        return {"examples": example_names()}

    @app.get("/api/examples/{name}")
    async def example(name: str):
        if name not in example_names():  # whitelist: never a path from the client
            raise AppError(404, f"no bundled example named {name!r}")
        from plantmech.design import DesignError, load_design

        try:
            design = load_design(examples_dir() / f"{name}.toml")
        except DesignError as exc:
            raise AppError(422, str(exc)) from None
        return {"name": name, "design": design_json(design)}

    @app.get("/api/compute")
    async def compute_status():
        """The compute workers: how many the server runs and how many are ready."""
        pool.start()
        return {"workers": pool.size, "ready": pool.ready}

    @app.get("/api/initial")
    async def initial_design():
        return {"initial": initial_payload}

    @app.post("/api/parse")
    async def parse(request: Request):
        """A TOML text the user opened in the page (the browser reads the file)."""
        from plantmech.design import MAX_NESTING, DesignError
        from plantmech.inputs import parse_toml

        data = await body(request)
        text, label = data.get("text"), str(data.get("name") or "design")[:80]
        if not isinstance(text, str):
            raise AppError(400, "field 'text': the design file's text is missing")
        try:  # as a design file is parsed: nesting bounded before the parser recurses
            raw = parse_toml(text, label, MAX_NESTING, DesignError,
                             "a design file needs at most 3")
        except DesignError as exc:
            raise AppError(422, str(exc)) from None
        design = validate_design(raw, label)
        return {"name": label, "design": design_json(design)}

    @app.post("/api/evaluate")
    async def evaluate_endpoint(request: Request):
        status, answer, ms = await compute(await request.body())
        # the page splits its drag latency into the worker's computation and the rest
        return Response(answer, status_code=status, media_type="application/json",
                        headers={"Server-Timing": f"compute;dur={ms:.2f}"})

    @app.websocket("/api/ws")
    async def edit_stream(ws: WebSocket):
        """A stream of edits from the page: each message is ``/api/evaluate``'s body with an
        ``id``; each answer is ``{"id", "status", "compute", "server", "result"}`` (ms: the
        worker's computation, the message's whole stay in the server). Only the newest
        waiting edit is computed; one replaced before its turn gets ``{"id",
        "superseded": true}``."""
        import orjson

        if not same_origin(ws.headers):
            await ws.close(code=1008, reason="the app's own page only")
            return
        await ws.accept()
        waiting: list = []  # at most one (id, raw message, arrival time)
        arrived = asyncio.Event()
        closed = False

        async def receive():
            nonlocal closed
            try:
                while True:
                    msg = await ws.receive()
                    if msg["type"] == "websocket.disconnect":
                        break
                    raw = msg.get("bytes") or (msg.get("text") or "").encode()
                    t = time.perf_counter()
                    if waiting:
                        await ws.send_text(orjson.dumps({"id": waiting[0][0],
                                                         "superseded": True}).decode())
                        waiting.clear()
                    if len(raw) > MAX_BODY_BYTES:
                        await ws.send_text(orjson.dumps({
                            "id": None, "status": 413, "result": {
                                "error": f"message over the {MAX_BODY_BYTES} byte limit",
                                "fields": []}}).decode())
                        continue
                    try:  # the id only (the worker reads the rest, and says what is wrong)
                        ident = orjson.loads(raw).get("id")
                    except (orjson.JSONDecodeError, AttributeError):
                        ident = None
                    waiting.append((ident, raw, t))
                    arrived.set()
            except (WebSocketDisconnect, RuntimeError):
                pass
            closed = True
            arrived.set()

        reader = asyncio.create_task(receive())
        try:
            while True:
                await arrived.wait()
                arrived.clear()
                if closed:
                    break
                if not waiting:
                    continue
                ident, raw, t = waiting.pop()
                status, answer, ms = await compute(raw)
                server_ms = (time.perf_counter() - t) * 1e3
                head = (f'{{"id":{orjson.dumps(ident).decode()},"status":{status},'
                        f'"compute":{ms:.2f},"server":{server_ms:.2f},"result":')
                await ws.send_text(head + answer.decode() + "}")
        except (WebSocketDisconnect, RuntimeError):
            pass
        finally:
            reader.cancel()

    @app.post("/api/toml")
    async def toml(request: Request):
        """The design as a TOML file to download (save = download)."""
        from plantmech.outputs.optimization_report import design_toml

        data = await body(request)
        design = validate_design(data.get("design"))
        text = design_toml(design, "Saved from the plantmech app")
        name = re.sub(r"[^A-Za-z0-9_.-]+", "_", design.name).strip("_") or "design"
        return PlainTextResponse(text, media_type="application/toml", headers={
            "Content-Disposition": f'attachment; filename="{name}.toml"'})

    @app.get("/api/problems")
    async def problems(mechanism: str = "sugarcane_seeder"):
        from plantmech.kinds import KINDS
        from plantmech.optimize.jobs import job_defaults

        kind = KINDS.get(mechanism)
        names = kind.problems if kind is not None else ()  # the problems that take its file
        out = []
        for p in names:  # the app requires manufacturability (the job's defaults with it)
            algo, gen, pop, stages = job_defaults(p)
            out.append({"name": p, "algorithm": algo, "generations": gen, "pop": pop,
                        "stages": stages})
        return {"problems": out}

    @app.post("/api/optimize")
    async def start_optimize(request: Request):
        from plantmech.optimize.jobs import PROBLEMS

        data = await body(request)
        design = validate_design(data.get("design"))
        problem = data.get("problem")
        if problem not in PROBLEMS:
            raise AppError(422, f"field 'problem': expected one of {', '.join(PROBLEMS)}",
                           [{"field": "problem", "message": "unknown problem"}])
        opts = {}
        for key, lo, hi in (("generations", 1, 500), ("pop", 4, 400), ("seed", 0, 2**31)):
            v = data.get(key)
            if v is None:
                continue
            if not isinstance(v, int) or isinstance(v, bool) or not lo <= v <= hi:
                raise AppError(422, f"field '{key}': a whole number from {lo} to {hi}",
                               [{"field": key, "message": f"a whole number from {lo} to {hi}"}])
            opts[key] = v
        task = tasks.start_optimize(design_json(design), problem, **opts)
        return {"task": task}

    @app.post("/api/gears")
    async def start_gears(request: Request):
        data = await body(request)
        design = validate_design(data.get("design"))
        opts = {}
        for key, lo, hi in (("module", 0.05, 50.0), ("face_width", 0.1, 1000.0),
                            ("backlash", 0.0, 5.0)):
            v = data.get(key)
            if v is None or v == "":
                continue
            if isinstance(v, bool) or not isinstance(v, int | float) or not lo <= v <= hi:
                raise AppError(422, f"field '{key}': a number from {lo:g} to {hi:g}",
                               [{"field": key, "message": f"a number from {lo:g} to {hi:g}"}])
            opts[key] = float(v)
        return {"task": tasks.start_gears(design_json(design), **opts)}

    @app.get("/api/tasks/{task_id}")
    async def task_status(task_id: str):
        st = tasks.status(task_id)
        if st is None:
            raise AppError(404, f"no task {task_id!r}")
        return st

    @app.post("/api/tasks/{task_id}/cancel")
    async def task_cancel(task_id: str):
        if not tasks.cancel(task_id):
            raise AppError(404, f"no running task {task_id!r}")
        return {"cancelled": task_id}

    @app.get("/api/tasks/{task_id}/files/{name}")
    async def task_file(task_id: str, name: str):
        path = tasks.file(task_id, name)  # only names the task itself listed
        if path is None:
            raise AppError(404, f"task {task_id!r} has no file {name!r}")
        return FileResponse(path, filename=name)

    @app.get("/favicon.ico", include_in_schema=False)
    async def favicon():
        return Response(status_code=204)

    return app
