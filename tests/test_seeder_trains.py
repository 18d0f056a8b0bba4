"""mechanisms/seeder_trains.py: the seeder's train from a design file's [train] or from the
inverse design of its trajectory, and a [train] table resampled from an inverse design."""

import numpy as np

from plantmech.design import load_design
from plantmech.mechanisms.seeder_forward import simulate
from plantmech.mechanisms.seeder_trains import (
    inverse_design_of,
    train_from_design,
    train_from_inverse,
    train_from_inverse_job,
    train_table_from_inverse,
    with_train,
)
from plantmech.workflows import run_seeder_inverse

from .conftest import EXAMPLES


def test_inverse_design_of_is_the_inverse_job_result():
    d = load_design(EXAMPLES / "sugarcane_seeder.toml")
    traj, res = inverse_design_of(d)
    job = run_seeder_inverse(d, manufacturability=False)
    assert np.array_equal(res.tip_realized, job.result.tip_realized)
    assert np.array_equal(traj(np.linspace(0, traj.period, 50)),
                          job.trajectory(np.linspace(0, traj.period, 50)))
    assert train_from_inverse_job(job) == train_table_from_inverse(res, d.trajectory.samples)


def test_resampled_train_table():
    """with_train: a design that has a [train] is returned as it is; one that has only a
    trajectory gets the inverse design's L1, L2, a1, a2 and 16 radii per gear read off its
    pitch curves at uniform body angles (closure by scale)."""
    own = load_design(EXAMPLES / "sugarcane_table4.toml")
    assert with_train(own) is own
    d = load_design(EXAMPLES / "sugarcane_seeder.toml")
    _, res = inverse_design_of(d)
    table = with_train(d).train
    assert (table.L1_mm, table.L2_mm, table.a1_mm, table.a2_mm) == (res.L1, res.L2, res.a1,
                                                                    res.a2)
    assert table.closure == "scale" and table.gear2.angles_deg == [22.5 * k for k in range(16)]
    tr = train_from_inverse(res)
    assert np.allclose(table.gear2.radii_mm, tr.gear2(np.radians(table.gear2.angles_deg)),
                       rtol=0, atol=1e-12)
    # the resampled train runs (closure by scale) and its motion is finite
    fwd = simulate(train_from_design(d.model_copy(update={"train": table}))[0], samples=360)
    assert np.isfinite(fwd.tip).all()
