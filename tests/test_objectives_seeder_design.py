"""objectives/seeder_design.py: the seeder's section angles and population evaluation of a
design file, in the objectives layer (moved from the jobs layer's workflows.py, which
re-exports them)."""

import numpy as np
import pytest

from plantmech.design import load_design
from plantmech.objectives import seeder_design

from .conftest import EXAMPLES


def test_the_jobs_layer_re_exports_the_same_functions():
    from plantmech import workflows

    for name in ("evaluate_seeder_population", "section_reference_psi", "SeederPopulation",
                 "SEEDER_PARAMS", "InfeasibleDesign"):
        assert getattr(workflows, name) is getattr(seeder_design, name)


@pytest.mark.parametrize("name", ["sugarcane_table4.toml", "sugarcane_seeder.toml"])
def test_reference_angles_are_the_forward_jobs_section_angles(name):
    """``section_reference_psi`` is the forward job's ``section_psi`` (a [train] design: its
    own simulation, sections located on its tip path or given; a trajectory design with no
    [train]: its inverse design's carrier angles at the section points)."""
    from plantmech.workflows import run_seeder_forward

    design = load_design(EXAMPLES / name)
    seeder_design._REFERENCE_PSI.clear()
    ref = seeder_design.section_reference_psi(design)
    job = run_seeder_forward(design)
    assert np.array_equal(ref, [job.section_psi[k] for k in "abcdef"])
    assert not ref.flags.writeable
    assert seeder_design.section_reference_psi(design) is ref  # kept per design content


def test_an_infeasible_trajectory_design_has_no_reference_angles():
    from plantmech.objectives.inverse_evaluation import InfeasibleDesign

    design = load_design(EXAMPLES / "sugarcane_table2_as_printed.toml")
    assert design.train is None
    with pytest.raises(InfeasibleDesign):
        seeder_design.section_reference_psi(design)
