"""A toothless dwell must lock (mechanisms/seeder_inverse.py, issue 34): gear 2 stands still
through the dwell, so the same point of it faces the sun where meshing stops and where it
resumes; a locking arc needs one pitch radius there, and Eq. 5 applies to that radius.

Independent expectations: a mirror-symmetric known-motion trajectory (carrier C = -psi, arm
beta = A sin psi: tip(-psi) = conj(tip(psi))) has a ratio law symmetric about psi = pi, so a
dwell symmetric about the fold locks (one radius) and Eq. 5's theta_2 follows in closed form
from theta_1 and that radius; moved off the symmetry by one point it does not. The bundled
dwell example: r2 = a1 - r1 (external pair), so the step of gear 2 equals that of the sun's
edge radii, 49.19 - 30.31 = 18.89 mm.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from plantmech.design import load_design
from plantmech.geometry.trajectory import ClosedTrajectory
from plantmech.interfaces.cli import main
from plantmech.mechanisms.seeder_inverse import (
    DWELL_LOCK_TOLERANCE_MM,
    DwellSpec,
    InverseSettings,
    dwell_lock_check,
    inverse_design,
)
from plantmech.mechanisms.seeder_trains import inverse_design_of
from tests.conftest import EXAMPLES

L1, L2, A, N = 254.0, 498.0, 0.3, 36


def _symmetric(dwell: DwellSpec):
    psi = 2 * np.pi * np.arange(N) / N
    tip = L1 * np.exp(-1j * psi) + L2 * np.exp(1j * A * np.sin(psi))
    traj = ClosedTrajectory.through(np.c_[tip.real, tip.imag])
    return inverse_design(traj, InverseSettings(samples=3600, dwell=dwell))


def test_a_dwell_symmetric_about_the_fold_locks_and_eq5_uses_its_radius():
    res = _symmetric(DwellSpec(start=16, end=20, anchor=4))
    assert res.feasible
    d = res.dwell
    assert d["lock_radius_jump"] < 1e-6
    r_end, r_start = d["sun_radius_at_ends"]
    assert r_end == pytest.approx(r_start, abs=1e-6)
    assert d["edge_radius"] == pytest.approx(r_start, abs=1e-6)
    a1, half = L1 / 2, 0.5 * d["theta1"]  # a1 = L1 / 2 (the default)
    expected = 2 * np.arctan(r_start * np.sin(half) / (a1 - r_start * np.cos(half)))
    assert d["theta2"] == pytest.approx(expected, abs=1e-12)
    assert dwell_lock_check(d)["ok"]
    assert "dwell_cannot_lock" not in {x.kind for x in res.diagnostics}


def test_moved_off_the_symmetry_the_dwell_cannot_lock_and_says_why():
    res = _symmetric(DwellSpec(start=15, end=20, anchor=4))
    assert res.feasible  # written and simulated, but the check fails
    d = res.dwell
    assert d["lock_radius_jump"] > 10 * DWELL_LOCK_TOLERANCE_MM
    assert d["theta2"] is None and d["edge_radius"] is None
    row = dwell_lock_check(d)
    assert not row["ok"] and row["value"] == pytest.approx(d["lock_radius_jump"], abs=1e-6)
    assert "no locking arc" in row["note"]
    warn = [x for x in res.diagnostics if x.kind == "dwell_cannot_lock"]
    assert warn and warn[0].severity == "warning" and warn[0].between_points == [15, 20]


def test_the_dwell_example_exits_4_naming_the_18_9_mm_step(tmp_path, capsys):
    _, res = inverse_design_of(load_design(EXAMPLES / "sugarcane_seeder_dwell.toml"))
    e = res.dwell["edge_pitch_radii"]
    a1 = res.a1
    for side in ("meshing_start", "meshing_end"):  # external pair: r1 + r2 = a1
        assert e[side]["r1"] + e[side]["r2"] == pytest.approx(a1, abs=1e-9)
    step = abs(e["meshing_start"]["r1"] - e["meshing_end"]["r1"])
    assert step == pytest.approx(18.89, abs=0.01)
    out = tmp_path / "o"
    doc = (EXAMPLES / "sugarcane_seeder_dwell.toml").read_text().replace(
        "samples = 3600          # samples per carrier turn", "samples = 720")
    src = tmp_path / "d.toml"
    src.write_text(doc)
    assert main(["inverse", str(src), "--out", str(out), "--no-plots"]) == 4
    text = capsys.readouterr().out
    assert "WARNING [dwell_cannot_lock]" in text
    s = json.loads((out / "summary.json").read_text())
    assert "dwell_lock_radius_jump_mm" in s["verdict"]["failed"]
    assert s["dwell"]["theta2_deg"] is None and s["dwell"]["edge_radius"] is None
    row = s["dwell_checks"][0]
    assert row["value"] == pytest.approx(18.89, abs=0.02)  # at 720 samples
