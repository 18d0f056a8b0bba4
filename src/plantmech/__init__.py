"""plantmech: design of planting mechanisms driven by non-circular planetary gear trains.

Sugarcane seeders (Liu et al. 2023, Int J Agric & Biol Eng 16(6)) and rice transplanters
(Zhou et al. 2022, J Agric Eng LIII:1412): inverse design from a planned tip trajectory,
forward simulation with every objective of the papers, optimization, gear teeth.

Quick start (the same jobs as the command line, without files)::

    import plantmech as pm

    pm.list_examples()                                  # designs shipped in the package
    design = pm.load_design(pm.example_path("sugarcane_seeder"))   # a path (TOML)
    job = pm.run_seeder_inverse(design)         # trajectory -> gear train
    job.summary["feasible"], job.summary["objectives"]  # verdict, objectives
    fwd = pm.run_seeder_forward(design)         # gear train -> motion, objectives
    figs = pm.job_figures(fwd)                  # [(name, matplotlib Figure), ...]
    pm.job_report(fwd, "report.html")           # self-contained HTML + mechanism.gif
    rice = pm.run_transplanter(pm.load_design(pm.example_path("rice_transplanter")))
    pm.run_gears(rice.design, "gears_out")      # teeth, checks, DXF/SVG/STL files
    pm.run_optimization(design, "seeder-layered", out_dir, "my design")  # best.toml
    pm.run_design(design, out_dir, "my design")   # check, optimize, teeth, one verdict

Every ``summary`` is a dict of plain numbers (what ``summary.json`` holds); objectives are
``{"name", "value", "unit", "limit", "ok"}``. Units: mm and degrees in design files and
summaries, m/s for speeds; radians inside. Layers (data flows downwards only; the order
is held by tests/test_layers.py): design -> geometry -> gears -> trains -> mechanisms ->
objectives -> verification -> contact -> optimize -> studies -> outputs -> jobs -> app ->
interfaces. See docs/api.md and examples/api.ipynb. The names below are imported on first use, so
``import plantmech`` stays fast.
"""

__version__ = "0.1.0"

# public name -> (module, attribute); imported lazily by __getattr__
_EXPORTS = {
    "load_design": ("plantmech.design", "load_design"),
    "DesignError": ("plantmech.design", "DesignError"),
    "run_seeder_inverse": ("plantmech.workflows", "run_seeder_inverse"),
    "run_seeder_forward": ("plantmech.workflows", "run_seeder_forward"),
    "run_transplanter": ("plantmech.workflows", "run_transplanter"),
    "run_gears": ("plantmech.workflows", "run_gears"),
    "InfeasibleDesign": ("plantmech.objectives.inverse_evaluation", "InfeasibleDesign"),
    "evaluate_seeder_population": ("plantmech.objectives.seeder_design",
                                   "evaluate_seeder_population"),
    "evaluate_transplanter_population": ("plantmech.objectives.transplanter_design",
                                         "evaluate_transplanter_population"),
    # not "optimize": that is the subpackage plantmech.optimize, whose import would shadow it
    "run_optimization": ("plantmech.optimize.jobs", "optimize"),
    "run_design": ("plantmech.pipeline", "run_design"),
    "job_figures": ("plantmech.outputs.report", "job_figures"),
    "job_animation": ("plantmech.outputs.report", "job_animation"),
    "job_report": ("plantmech.outputs.report", "job_report"),
    "write_report": ("plantmech.outputs.report", "write_report"),
    "write_gif": ("plantmech.outputs.report", "write_gif"),
    "example_path": ("plantmech.starters", "example_path"),
    "list_examples": ("plantmech.starters", "list_examples"),
    "write_starter": ("plantmech.starters", "write_starter"),
}

__all__ = ["__version__", *_EXPORTS]


def __getattr__(name: str):
    try:
        module, attr = _EXPORTS[name]
    except KeyError:
        raise AttributeError(f"module 'plantmech' has no attribute {name!r}") from None
    import importlib

    value = getattr(importlib.import_module(module), attr)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_EXPORTS))
