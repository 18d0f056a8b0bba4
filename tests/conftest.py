from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"


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
