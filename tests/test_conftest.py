"""The suite's own helpers (tests/conftest.py): the fast discrete Hausdorff distance
equals shapely's (GEOS's) on the kinds of geometry the tests compare; the shared
artefact cache builds a key once and hands every later caller the same value."""

import numpy as np
import pytest
import shapely

from tests.conftest import Shared, hausdorff_distance


def _wavy(n, amp, phase, radius=40.0, hole=False):
    t = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    r = radius + amp * np.sin(9 * t + phase)
    shell = np.c_[r * np.cos(t), r * np.sin(t)]
    holes = [0.3 * shell[::-1]] if hole else []
    return shapely.Polygon(shell, holes)


@pytest.mark.parametrize("densify", [None, 0.5, 0.05, 0.02])
def test_hausdorff_distance_is_shapelys(densify):
    a, b = _wavy(300, 1.5, 0.0, hole=True), _wavy(200, 1.2, 0.3, hole=True)
    cases = [(a.exterior, b.exterior), (a.boundary, b.boundary), (a, b),
             (a.exterior, shapely.LineString(shapely.get_coordinates(b.exterior)[:200]))]
    for x, y in cases:
        want = shapely.hausdorff_distance(x, y, densify=densify)
        assert want > 0.1
        assert hausdorff_distance(x, y, densify) == pytest.approx(want, rel=1e-12, abs=0)


def test_hausdorff_distance_refuses_points():
    with pytest.raises(ValueError, match="Point"):
        hausdorff_distance(shapely.Point(0, 0), shapely.Point(1, 0))


def test_shared_builds_once(tmp_path):
    calls = []
    first, second = Shared(tmp_path), Shared(tmp_path)  # two workers' caches
    assert first.get("k", lambda: calls.append(1) or {"v": 1}) == {"v": 1}
    assert second.get("k", lambda: calls.append(2) or {"v": 2}) == {"v": 1}
    assert calls == [1]
    path, value = second.dir("d", lambda p: (p / "f").write_text("x"))
    assert (path / "f").read_text() == "x" and value == 1
    assert first.dir("d", lambda p: 1 / 0) == (path, 1)


def test_every_slow_entry_names_a_test():
    """A renamed or removed test leaves tests/slow.txt naming nothing: caught here."""
    from tests.conftest import ROOT, _slow_list

    for entry in _slow_list():
        path, name = entry.split("[", 1)[0].split("::")
        assert f"def {name}(" in (ROOT / path).read_text(), entry
