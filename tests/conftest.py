import fcntl
import os
import pickle
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"


class Shared:
    """Expensive artefacts (cut gear sets, their simulated-cut references, a verified gear
    directory, an installed wheel) built once per test run and read by every test that
    needs them, across the pytest-xdist workers: the first caller of a key builds it under
    a file lock, the others wait for it and read it (a pickle, or a directory). The
    directory is the run's own (the workers' common base temp), never a previous run's.
    What a builder returns is read-only to the tests that share it."""

    def __init__(self, root: Path):
        self.root = root
        self._memo: dict = {}

    def _locked(self, key: str):
        f = open(self.root / f"{key}.lock", "w")
        fcntl.flock(f, fcntl.LOCK_EX)
        return f

    def get(self, key: str, build):
        """``build()`` once per run for ``key`` (any picklable value)."""
        if key in self._memo:
            return self._memo[key]
        path = self.root / f"{key}.pickle"
        with self._locked(key):
            if path.exists():
                value = pickle.loads(path.read_bytes())
            else:
                value = build()
                tmp = path.with_suffix(".part")
                tmp.write_bytes(pickle.dumps(value, protocol=pickle.HIGHEST_PROTOCOL))
                os.replace(tmp, path)
        self._memo[key] = value
        return value

    def dir(self, key: str, build) -> Path:
        """A directory written once per run by ``build(path)`` (which may return a value,
        kept with it: ``(path, value)`` is returned)."""
        def made():
            path = self.root / key
            if path.exists():  # a builder that failed part way: start again
                import shutil

                shutil.rmtree(path)
            path.mkdir()
            return path, build(path)

        return self.get(key, made)


@pytest.fixture(scope="session")
def shared(tmp_path_factory, request) -> Shared:
    """The run's artefact cache (Shared); under xdist its directory is the workers' common
    base temp (the parent of each worker's own), else this session's base temp."""
    base = tmp_path_factory.getbasetemp()
    if hasattr(request.config, "workerinput"):
        base = base.parent
    root = base / "shared"
    root.mkdir(exist_ok=True)
    return Shared(root)


def design_one_generation(tmp_path, example: str):
    """``plantmech design`` on a copy of a bundled example with one generation per
    optimizer stage, quiet: (exit status, output folder). The copy must be left as it was
    (nothing the user gave is overwritten)."""
    from plantmech.interfaces.cli import main

    src = tmp_path / example
    text = (EXAMPLES / example).read_text()
    src.write_text(text)
    out = tmp_path / "o"
    rc = main(["design", str(src), "--out", str(out), "--generations", "1", "--quiet"])
    assert src.read_text() == text
    return rc, out


class AnalyticCurve:
    """Exact closed curve with the ClosedTrajectory interface (parameter u in rad)."""

    def __init__(self, fn, n_points=36):
        self.fn = fn
        self.knots = np.linspace(0.0, 2 * np.pi, n_points + 1)
        self.points = fn(self.knots[:-1])

    @property
    def period(self):
        return 2 * np.pi

    def __call__(self, u, nu=0):
        assert nu == 0
        u = np.asarray(u, dtype=float)
        return self.fn(np.mod(u, 2 * np.pi))

    def point_index_of(self, u):
        return np.interp(np.mod(u, 2 * np.pi), self.knots, np.arange(len(self.knots)))

    def point_parameter(self, i):
        return float(self.knots[i % len(self.points)])


def known_motion(L1=100.0, L2=250.0, phi0=0.3, arm_offset=0.0, A=0.35, B=0.1):
    """Tip of a three-bar driven by a clockwise carrier and a monotonic planet law.

    carrier_abs = phi0 - u, planet_rel = u + A sin u + B sin 2u (A + 2B < 1 keeps it
    monotonic), arm = carrier_abs + planet_rel + arm_offset.
    """

    def angles(u):
        carrier = phi0 - u
        rel = u + A * np.sin(u) + B * np.sin(2 * u)
        return carrier, carrier + rel + arm_offset

    def fn(u):
        c, a = angles(u)
        x = L1 * np.cos(c) + L2 * np.cos(a)
        y = L1 * np.sin(c) + L2 * np.sin(a)
        return np.stack([x, y], axis=-1)

    return fn, angles


@pytest.fixture
def table2_points():
    from plantmech.design import load_design

    d = load_design(EXAMPLES / "sugarcane_table2_as_printed.toml")
    return np.asarray(d.trajectory.points)


def write_toml(tmp_path, doc: dict, name: str = "d.toml") -> str:
    """Write ``doc`` (a design file's table) as TOML into ``tmp_path / name``; its path."""
    import tomli_w

    p = tmp_path / name
    p.write_text(tomli_w.dumps(doc), encoding="utf-8")
    return str(p)


def assert_file_refused(doc: dict, field: str, tmp_path, capsys) -> None:
    """A design file's table ``doc`` is refused naming ``field`` (a regex): by load_design
    (DesignError) and by ``plantmech forward`` (exit 2, the field in stderr, no output)."""
    import re

    from plantmech.design import DesignError, load_design
    from plantmech.interfaces.cli import main

    with pytest.raises(DesignError) as exc:
        load_design(doc, name="t.toml")
    assert re.search(field, str(exc.value)), str(exc.value)
    out = tmp_path / "o"
    assert main(["forward", write_toml(tmp_path, doc), "--out", str(out)]) == 2
    assert not out.exists()
    assert re.search(field, capsys.readouterr().err)


def gears_cut(shared: Shared, key: str, design, *options, printed: bool = False):
    """``plantmech gears design --out <folder> *options`` once per test run (its folder is
    read, never written, by the tests that share it; a test that alters gear files copies
    them first): (the output folder, the exit status), and with ``printed`` what the
    command printed (its standard output, kept with the folder: the test that reads it
    need not be the one that ran the command)."""
    import contextlib
    import io

    from plantmech.interfaces.cli import main

    def cut(p):
        text = io.StringIO()
        with contextlib.redirect_stdout(text):
            code = main(["gears", str(design), "--out", str(p / "gears"), *options])
        return code, text.getvalue()

    path, (code, text) = shared.dir(f"gears-{key}", cut)
    return (path / "gears", code, text) if printed else (path / "gears", code)


def _lines(g) -> list:
    """The coordinate sequences of a linear or polygonal geometry, as GEOS walks them."""
    kind = g.geom_type
    if kind in ("LineString", "LinearRing"):
        return [g]
    if kind == "Polygon":
        return [g.exterior, *g.interiors]
    if kind in ("MultiLineString", "MultiPolygon", "GeometryCollection"):
        return [line for part in g.geoms for line in _lines(part)]
    raise ValueError(f"hausdorff_distance: {kind} not supported")


def hausdorff_distance(a, b, densify: float | None = None) -> float:
    """``shapely.hausdorff_distance(a, b, densify)`` (GEOS's discrete Hausdorff distance:
    every vertex, and with ``densify`` every segment cut into round(1 / densify) equal
    parts, p0 + i (p1 - p0) / n for i < n, measured to the nearest segment of the other
    geometry's boundary, both ways) with the same points and the same point-to-segment
    distances, the nearest segment found through an STRtree instead of GEOS's scan of
    every segment for every point (that scan is O(points x segments): minutes on the
    fine outlines the envelope tests compare). tests/test_conftest.py checks it against
    shapely's."""
    import shapely

    def points(g):
        out = [shapely.get_coordinates(g)]
        if densify:
            n = int(np.floor(1.0 / densify + 0.5))
            i = np.arange(n, dtype=float)[None, :]
            for line in _lines(g):
                c = shapely.get_coordinates(line)
                p0, p1 = c[:-1], c[1:]
                dx, dy = (p1[:, 0] - p0[:, 0]) / n, (p1[:, 1] - p0[:, 1]) / n
                x = p0[:, :1] + i * dx[:, None]
                y = p0[:, 1:] + i * dy[:, None]
                out.append(np.c_[x.ravel(), y.ravel()])
        return np.vstack(out)

    def segments(g):
        segs = []
        for line in _lines(g):
            c = shapely.get_coordinates(line)
            segs.append(np.stack([c[:-1], c[1:]], axis=1))
        return shapely.STRtree(shapely.linestrings(np.concatenate(segs)))

    worst = 0.0
    for x, y in ((a, b), (b, a)):
        _, d = segments(y).query_nearest(shapely.points(points(x)), return_distance=True,
                                         all_matches=False)
        worst = max(worst, float(d.max()))
    return worst


CPU_LOG = os.environ.get("PLANTMECH_TEST_CPU")


@pytest.hookimpl(wrapper=True)
def pytest_runtest_protocol(item, nextitem):
    """With PLANTMECH_TEST_CPU=file: each test's CPU seconds (setup, call and teardown,
    with the processes it waited for) appended to ``file`` as "seconds<TAB>id", the
    measure of a test's cost that a loaded machine does not inflate as it does wall time."""
    if not CPU_LOG:
        return (yield)
    import resource

    def cpu():
        me, kids = (resource.getrusage(w) for w in
                    (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN))
        return me.ru_utime + me.ru_stime + kids.ru_utime + kids.ru_stime

    start = cpu()
    try:
        return (yield)
    finally:
        with open(CPU_LOG, "a") as f:
            f.write(f"{cpu() - start:.2f}\t{item.nodeid}\n")


SLOW = Path(__file__).with_name("slow.txt")


def _slow_list() -> list[str]:
    """tests/slow.txt: the slow tests' ids (a whole function: every parametrization), the
    slowest first; ``#`` starts a comment (the measured time)."""
    lines = (line.split("#", 1)[0].strip() for line in SLOW.read_text().splitlines())
    return [line for line in lines if line]


def pytest_collection_modifyitems(config, items):
    """Mark the tests of tests/slow.txt ``slow`` and run them first, slowest first (the two
    xdist workers then end together on the short ones); the others keep their order."""
    rank = {name: i for i, name in enumerate(_slow_list())}
    slow = []
    for item in items:
        name = item.nodeid.split("[", 1)[0]
        if item.nodeid in rank or name in rank:
            item.add_marker(pytest.mark.slow)
            slow.append((rank.get(item.nodeid, rank.get(name)), len(slow), item))
    if slow:
        first = [item for *_, item in sorted(slow, key=lambda s: s[:2])]
        chosen = set(map(id, first))
        items[:] = first + [item for item in items if id(item) not in chosen]
