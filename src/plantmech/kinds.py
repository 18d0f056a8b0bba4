"""The mechanism kinds: one registry of what each design file's ``mechanism`` is and how every
command handles it.

A design file names its kind (``mechanism = "sugarcane_seeder"``, ``"rice_transplanter"``,
``"rice_transplanter_khv"``, ``"planetary"``); ``design.load_design`` reads it into that
kind's model (``design.MECHANISMS``). Everything a command does differently per kind is
looked up here, never decided by comparing the kind's name:

- ``problems`` / ``default_problem``: the optimization problems that take the file, and the
  one ``plantmech design`` (and ``plantmech optimize`` without ``--problem``) runs;
- ``fixed_gear``: the design field of a transplanter's fixed non-circular gear (errors and
  the app's radius fields point there; the standard-module scaling scales it);
- ``hooks``: for each capability (the app's scene and edit panel, the forward and inverse
  commands, the single-design forward job, the report's parts and animation, the study
  model, the toothed gear pairs, the contact geometry the strength table rates, ``verify``)
  the function that does it, named ``"module:attribute"`` and imported on first use, so this
  module (layer "design", ``tests/test_layers.py``) imports nothing above it.

To add a kind: its design model registers itself in ``design.MECHANISMS`` (as
``design_planetary.py`` does), and one ``Kind`` here names its problems and hooks;
``tests/test_kinds.py`` checks that every hook resolves, and that no module outside the
design loader, this registry and the objective sets branches on a kind's name.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from plantmech.design import MECHANISMS

#: the capabilities a kind names a hook for (a kind without one does not offer it)
CAPABILITIES = (
    "app_scene",        # (design, drag) -> the app's drawing data and checks
    "app_parameters",   # (design) -> the app's edit panel: [{field, label, unit, value, ...}]
    "forward_cli",      # (args, design, run) -> exit code of ``plantmech forward``
    "inverse_cli",      # (args, design, run) -> exit code of ``plantmech inverse``
    "forward_job",      # (design) -> the full-resolution forward job (summary, figures)
    "report_parts",     # (design) -> (summary, figures, animation) of ``plantmech design``
    "study_model",      # class: .check(design, names), (design, names, cycle_samples)
    "pitch_findings",   # (design) -> the pitch curves' manufacturability findings
    "verify_gears",     # (design) -> the gear files ``plantmech verify`` reads, by name
    "verify_run",       # (args, design, gears, out) -> verification record (with _loads)
    "require_train",    # (design) -> None, or ValueError: the file gives no train to run
    "optimizer_check",  # (design, tooth_fit) -> {all_met, objectives} at full resolution
    "gear_pairs",       # (design, module, backlash, samples, min_teeth, tooth, method)
                        #   -> [(GearPair, ToothSpec)] of ``plantmech gears``
    "strength_contacts",  # (design, psi, gears) -> the contact geometry per mesh that
                          #   ``contact.strength.strength_record`` rates
    "animation",        # (design) -> the mechanism animated over one cycle (--report)
)


@dataclass(frozen=True)
class Kind:
    """One mechanism kind (see the module docstring)."""

    name: str
    label: str
    problems: tuple[str, ...]
    hooks: Mapping[str, str]
    fixed_gear: str | None = None
    #: the design with a tooth count on its fixed gear is scaled to a standard module by
    #: ``plantmech design`` (the transplanters)
    standard_module_scaling: bool = False
    #: (design) -> the problem ``plantmech design`` runs (None: nothing it may move)
    choose_problem: Callable[[Any], str | None] = field(default=lambda design: None)
    #: (the job record's "skipped", the line printed) when ``choose_problem`` gives None
    unoptimized_reason: tuple[str, str] = ("", "")
    #: (design) -> True when the file gives a trajectory only (inverse design's input):
    #: no train to check before the optimizer designs one
    trajectory_only: Callable[[Any], bool] = field(default=lambda design: False)
    #: ``plantmech inverse`` refuses a file of this kind without a [trajectory] before it
    #: starts (the general train's inverse names its own missing fields)
    inverse_needs_trajectory: bool = False
    #: the commands that take a file of this kind (None: every one), and those of them
    #: whose --report takes it (``interfaces.cli.refuse_planetary``)
    commands: tuple[str, ...] | None = None
    #: the design file's table an error of its train is reported in (None: the error
    #: names its field)
    section: str | None = None
    report_commands: tuple[str, ...] = ()

    @property
    def model(self):
        """The design file's pydantic model (``design.MECHANISMS``)."""
        return MECHANISMS[self.name]

    def default_problem(self, design) -> str | None:
        return self.choose_problem(design)

    def has(self, capability: str) -> bool:
        return capability in self.hooks

    def hook(self, capability: str) -> Callable:
        """The function (or class) that does ``capability`` for this kind, imported now;
        KeyError naming the kind when it has none."""
        if capability not in CAPABILITIES:
            raise KeyError(f"unknown capability {capability!r}")
        try:
            target = self.hooks[capability]
        except KeyError:
            raise KeyError(f"a {self.label} has no {capability!r}") from None
        module, _, attr = target.partition(":")
        return getattr(importlib.import_module(module), attr)


def _seeder_problem(design) -> str:
    # a trajectory alone is no train yet: the layered search designs one
    return "seeder-layered" if design.train is None else "seeder-layer2"


_TRANSPLANTER_HOOKS = {
    "app_scene": "plantmech.app.server:_transplanter",
    "animation": "plantmech.pipeline:_animation_transplanter",
    "forward_cli": "plantmech.interfaces.cli:_forward_transplanter",
    "forward_job": "plantmech.workflows:run_transplanter",
    "report_parts": "plantmech.pipeline:_job_parts_transplanter",
    "study_model": "plantmech.studies.parameters:TransplanterModel",
    "pitch_findings": "plantmech.workflows:objective_findings",
    "verify_run": "plantmech.interfaces.verify_cli:_run_transplanter",
    "optimizer_check": "plantmech.optimize.jobs:_check_transplanter",
}

KINDS: dict[str, Kind] = {k.name: k for k in (
    Kind("sugarcane_seeder", "sugarcane seeder",
         problems=("seeder-layer1", "seeder-layer2", "seeder-layered", "seeder-joint"),
         choose_problem=_seeder_problem, section="train",
         trajectory_only=lambda design: design.train is None, inverse_needs_trajectory=True,
         hooks={
             "app_scene": "plantmech.app.server:_seeder",
             "app_parameters": "plantmech.app.server:_no_parameters",
             "forward_cli": "plantmech.interfaces.cli:_forward_seeder",
             "inverse_cli": "plantmech.interfaces.cli:_inverse_seeder",
             "forward_job": "plantmech.workflows:run_seeder_forward",
             "report_parts": "plantmech.pipeline:_job_parts_seeder",
             "study_model": "plantmech.studies.parameters:SeederModel",
             "pitch_findings": "plantmech.workflows:objective_findings",
             "verify_gears": "plantmech.interfaces.verify_cli:seeder_gear_names",
             "verify_run": "plantmech.interfaces.verify_cli:_run_seeder",
             "optimizer_check": "plantmech.optimize.jobs:_check_seeder",
             "gear_pairs": "plantmech.mechanisms.gear_pairs:seeder_pairs",
             "strength_contacts": "plantmech.contact.strength:seeder_contacts",
             "animation": "plantmech.pipeline:_animation_seeder",
         }),
    Kind("rice_transplanter", "differential rice transplanter",
         problems=("transplanter",), fixed_gear="internal_gear", section="internal_gear",
         standard_module_scaling=True, choose_problem=lambda design: "transplanter",
         hooks={**_TRANSPLANTER_HOOKS,
                "app_parameters": "plantmech.app.server:_transplanter_parameters",
                "verify_gears": "plantmech.interfaces.verify_cli:transplanter_gear_names",
                "gear_pairs": "plantmech.mechanisms.gear_pairs:differential_pairs",
                "strength_contacts": "plantmech.contact.strength:differential_contacts"}),
    Kind("rice_transplanter_khv", "K-H-V rice transplanter",
         # the sun's radii, the carrier's start, the arm and the box, as the differential's
         problems=("transplanter",), fixed_gear="sun_gear", section="sun_gear",
         standard_module_scaling=True, choose_problem=lambda design: "transplanter",
         hooks={**_TRANSPLANTER_HOOKS,
                "app_parameters": "plantmech.app.server:_khv_parameters",
                "verify_gears": "plantmech.interfaces.verify_cli:khv_gear_names",
                "verify_run": "plantmech.interfaces.verify_cli:_run_khv",
                "gear_pairs": "plantmech.mechanisms.gear_pairs:khv_pairs",
                "strength_contacts": "plantmech.contact.strength:khv_contacts"}),
    Kind("planetary", "general planetary train",
         problems=("planetary",),
         commands=("forward", "gears", "optimize", "inverse", "study", "design", "verify"),
         report_commands=("forward", "gears", "optimize", "study", "design"),
         # the fields its [optimize.variables] frees, or the design stands
         choose_problem=lambda design: None if design.optimize is None else "planetary",
         unoptimized_reason=(
             "the file has no [optimize.variables]",
             "the file frees no field ([optimize.variables]: the dotted paths the optimizer "
             "may move: plantmech docs design-file)"),
         hooks={
             "app_scene": "plantmech.app.server:_planetary",
             "app_parameters": "plantmech.app.server:_planetary_parameters",
             "forward_cli": "plantmech.interfaces.planetary_cli:forward_planetary",
             "inverse_cli": "plantmech.interfaces.planetary_inverse_cli:inverse_planetary",
             "report_parts": "plantmech.pipeline:_planetary_parts",
             "study_model": "plantmech.studies.parameters:PlanetaryModel",
             "pitch_findings": "plantmech.trains.gearing:pitch_curve_findings",
             "verify_gears": "plantmech.contact.planetary:gear_file_names",
             "verify_run": "plantmech.interfaces.verify_cli:_run_planetary",
             "require_train": "plantmech.pipeline:_require_planetary_curves",
             "optimizer_check": "plantmech.optimize.planetary_problem:verify",
             "gear_pairs": "plantmech.trains.gearing:gear_pairs",
             "strength_contacts": "plantmech.contact.strength:planetary_contacts",
             "animation": "plantmech.pipeline:_animation_planetary",
         }),
)}

assert set(KINDS) == set(MECHANISMS), "every design model has its kind"


def kind_of(design_or_name) -> Kind:
    """The ``Kind`` of a loaded design (its ``mechanism`` field) or of a kind's name;
    KeyError naming the known kinds for any other name."""
    name = getattr(design_or_name, "mechanism", design_or_name)
    try:
        return KINDS[name]
    except KeyError:
        raise KeyError(f"unknown mechanism {name!r} (expected one of "
                       f"{', '.join(KINDS)})") from None
