"""The error estimate of an inverse design (objectives/inverse_estimate.py, issue 34).

Independent expectations: known first-order trains (an elliptic sun about its focus, fixed,
its twin planet, a carrier arm and an arm) run forward; the inverse design of points of
their tip path is compared with the analytic ellipse (r = A (1 - e^2) / (1 - e cos(phi -
phi_0)) in the absolute frame): the estimate must cover that true error, flag it above the
limit, name the span at the fold, and fall below 0.2 mm at 288 points.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from plantmech.geometry.trajectory import ClosedTrajectory
from plantmech.interfaces.cli import main
from plantmech.objectives.inverse_estimate import (
    estimate_rows,
    first_order_estimate,
    first_order_solution,
)
from plantmech.objectives.planetary_inverse import first_order_inverse
from plantmech.trains.curves import ellipse
from plantmech.trains.model import PairSpec, Train, forward
from tests.conftest import EXAMPLES
from tests.conftest import write_toml as _write

SUN_PHASE = 90.0


def _known_path(A, e, L, arm0_deg, samples):
    tr = Train([PairSpec("external", ellipse(A, e, 8192), phase=np.radians(SUN_PHASE),
                         follower_turns=1.0)],
               carrier0=np.radians(90.0), carrier_sense=-1, arm_length=L,
               arm_angle=np.radians(arm0_deg))
    return forward(tr, samples).tip[0, 0]


def _true_sun_error(res, A, e) -> float:
    """Largest distance (mm) of the inverse design's sun from the analytic ellipse at equal
    absolute direction."""
    n = len(res.sun_radii)
    phi = 2 * np.pi * np.arange(n) / n
    expected = A * (1 - e**2) / (1 - e * np.cos(phi - np.radians(SUN_PHASE)))
    theta = np.mod(phi - np.radians(res.sun_phase_deg), 2 * np.pi)
    found = np.interp(theta, phi, res.sun_radii, period=2 * np.pi)
    return float(np.abs(found - expected).max())


@pytest.fixture(scope="module")
def elliptic_path():
    """Seed-000-like proportions (issue 34): A = 30 mm, e = 0.35, carrier arm 2 A = 60 mm,
    arm 150 mm; 14400 samples of its tip path."""
    return _known_path(30.0, 0.35, 150.0, -90.0, 14400)


def _design(tip, n):
    pts = tip[:: len(tip) // n]
    pts = np.c_[pts.real, pts.imag]
    res = first_order_inverse(ClosedTrajectory.through(pts), "long", "external", -1, 3600)
    assert res.feasible, res.reasons
    return pts, res


def test_36_points_the_estimate_covers_the_true_sun_error_and_names_the_fold(elliptic_path):
    pts, res = _design(elliptic_path, 36)
    true = _true_sun_error(res, 30.0, 0.35)
    assert true > 2.0  # the method's error the round trip cannot see (issue 34: 3.4 mm)
    est = first_order_estimate(pts, res, "long", "external", -1, 3600)
    assert est["computed"]
    assert est["pitch_radius_mm"]["sun"] >= true
    rows = {r["name"]: r for r in estimate_rows(est)}
    assert not rows["error_estimate_pitch_radius_mm"]["ok"]
    assert "sun" in rows["error_estimate_pitch_radius_mm"]["note"]
    # the fold: the chain folds at the nearest point of the path (rho = L - a = 90 mm)
    k_fold = int(np.argmin(np.hypot(*pts.T)))
    psi_fold = float(res.point_carrier_angle_deg[k_fold])
    assert abs(est["worst_carrier_angle_deg"] - psi_fold) < 20.0
    i, j = est["worst_points"]
    # the named points are those next to the fold's (q0 here; the largest is 10 deg after)
    assert min(abs((k - k_fold + 18) % 36 - 18) for k in (i, j)) <= 1
    lo, hi = est["spans"][0]["carrier_angle_deg"]  # the worst run, named in the advice
    assert (psi_fold - lo) % 360 <= (hi - lo) % 360
    assert "add type-value points at" in rows["error_estimate_pitch_radius_mm"]["note"]


def test_288_points_the_estimate_is_below_0_2_mm_and_met(elliptic_path):
    pts, res = _design(elliptic_path, 288)
    est = first_order_estimate(pts, res, "long", "external", -1, 3600)
    assert est["pitch_radius_mm"]["sun"] < 0.2
    assert est["pitch_radius_mm"]["sun"] >= _true_sun_error(res, 30.0, 0.35)
    assert all(r["ok"] for r in estimate_rows(est))


def test_the_example_exits_4_its_sun_truly_off_and_the_limit_is_the_files(tmp_path, capsys):
    """examples/planetary/first_order_inverse.toml: 24 points of a known train (A = 25 mm,
    e = 0.2, arm 20 mm); the sun is 2.4 mm off, which its estimate (7.2 mm) covers; a file that
    accepts 10 mm exits 0."""
    import tomllib

    src = EXAMPLES / "planetary" / "first_order_inverse.toml"
    out = tmp_path / "o"
    assert main(["inverse", str(src), "--out", str(out), "--no-plots"]) == 4
    text = capsys.readouterr().out
    assert "error estimate (every other point)" in text
    s = json.loads((out / "summary.json").read_text())
    doc = tomllib.loads(src.read_text())
    pts = np.array(doc["trajectory"]["points"])
    res = first_order_inverse(ClosedTrajectory.through(pts), "short", "external", -1, 3600)
    true = _true_sun_error(res, 25.0, 0.2)
    assert 0.5 < true < s["error_estimate"]["pitch_radius_mm"]["sun"]
    doc["trajectory"]["error_estimate_limit_mm"] = 10.0
    assert main(["inverse", _write(tmp_path, doc), "--out", str(tmp_path / "p"),
                 "--no-plots"]) == 0
    capsys.readouterr()


def test_the_solution_compares_equal_designs_as_zero(elliptic_path):
    """The comparison itself: a design against itself, and against itself with its start
    moved by whole samples (the carrier angle is absolute), is 0."""
    from plantmech.objectives.inverse_estimate import compare

    pts, res = _design(elliptic_path, 72)
    full = first_order_solution(res, -1)
    assert max(v.max() for v in compare(full, full).values()) < 1e-9
    shifted = first_order_solution(res, -1)
    k = 7
    shifted.carrier = np.r_[full.carrier[k:], full.carrier[:k] - 2 * np.pi]
    shifted.tip = np.roll(full.tip, -k)
    shifted.radii = {g: np.roll(r, -k) for g, r in full.radii.items()}
    assert max(v.max() for v in compare(full, shifted).values()) < 1e-9


def test_seeder_estimate_not_computed_says_why(tmp_path, capsys):
    """Table 2's odd points alone need a planet that turns back: the estimate is not
    computed, said on the terminal, in summary.json and in the verdict (no row counts)."""
    out = tmp_path / "s"
    code = main(["inverse", str(EXAMPLES / "planetary" / "sugarcane_seeder_inverse.toml"),
                 "--out", str(out), "--no-plots"])
    text = capsys.readouterr().out
    s = json.loads((out / "summary.json").read_text())
    assert code == 0, text
    assert not s["error_estimate"]["computed"]
    assert "odd type-value points" in s["error_estimate"]["reason"]
    assert "error estimate not computed" in text
    assert "its error estimate was not computed" in text.splitlines()[-1]
