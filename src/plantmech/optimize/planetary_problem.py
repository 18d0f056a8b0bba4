"""``plantmech optimize --problem planetary``: a general planetary train's free variables
against its [limits] and the pitch-curve manufacturability rules.

The variables are the numeric fields the design file names in ``[optimize.variables]``
(dotted paths, each with [lower, upper]; ``design_planetary.PlanetaryOptimize``). Every
check of ``objectives.planetary.design_evaluation`` is a constraint (its relative
violation must reach 0): the [limits] checks of the motion and, per pair, the module
window and the working pressure angle (reported only, with ``--no-manufacturability``).
The one objective minimized among designs meeting them is the largest working pressure
angle of the chain (deg): the smoother the teeth push, the better.

A generation is evaluated as ONE population (``objectives.planetary.population_evaluation``):
the candidates' numbers become (P,) arrays of one ``trains.model.Train`` (the structure,
which no numeric variable changes, is shared), built, simulated and judged at once. A
candidate that breaks a rule of the design file (e.g. an eccentric circle's offset beyond
its radius once two bounds combine) is refused: graded (every row violated, the rule as
its note), not evaluated.
"""

from __future__ import annotations

import numpy as np

from plantmech.optimize.problems import Batch, DesignProblem, Variable, is_gear_shape_check


class PlanetaryProblem(DesignProblem):
    """The free variables of a planetary design file -> its checks as constraints."""

    name = "planetary"
    objective_names = ["max_working_pressure_angle_deg"]

    def __init__(self, design, manufacturability: bool = True):
        if design.mechanism != "planetary":
            raise ValueError("problem 'planetary' optimizes a mechanism = \"planetary\" design "
                             "(this file is a " + design.mechanism + ")")
        if design.optimize is None:
            raise ValueError("field 'optimize': problem 'planetary' needs an "
                             "[optimize.variables] table naming the free fields, e.g. "
                             "\"train.pairs.0.driver.eccentricity\" = [0.1, 0.4] "
                             "(docs/design-file.md)")
        from plantmech.design_planetary import get_path, set_path
        from plantmech.units import unit_of

        self.manufacturability = manufacturability
        self.samples = design.optimize.samples
        variables = []
        for path, (lo, hi) in design.optimize.variables.items():
            def apply(d, val, path=path):
                set_path(d, path, float(val))
            variables.append(Variable(path, float(get_path(design, path)), float(lo),
                                      float(hi), unit_of(path), apply))
        self.row_names = [r["name"] for r in self._rows(design)]
        super().__init__(design, variables, n_constr=len(self.row_names))

    def _rows(self, design) -> list[dict]:
        from plantmech.objectives.planetary import design_evaluation

        return design_evaluation(design, self.samples)

    def candidates(self, X) -> tuple[list, list]:
        """(designs, refusals): the design of each row of X, or None and the reason when it
        breaks a rule of the design file."""
        from pydantic import ValidationError

        designs, refusals = [], []
        for x in np.atleast_2d(X):
            d = self.decode(x)
            try:
                d = d.__class__.model_validate(d.model_dump())
                designs.append(d)
                refusals.append(None)
            except ValidationError as exc:
                e = exc.errors()[0]
                loc = ".".join(str(p) for p in e["loc"])
                designs.append(None)
                refusals.append(f"the candidate breaks a rule of the design file ({loc}: "
                                f"{e['msg']})")
        return designs, refusals

    def evaluate_batch(self, X):
        from plantmech.objectives.planetary import population_evaluation

        designs, refusals = self.candidates(X)
        accepted = [d for d in designs if d is not None]
        evaluated = iter(population_evaluation(accepted, self.samples) if accepted else [])
        rows = [next(evaluated) if d is not None else
                [{"name": n, "value": None, "unit": "", "limit": "", "ok": False,
                  "violation": np.inf, "note": why} for n in self.row_names]
                for d, why in zip(designs, refusals, strict=True)]
        # units and limits from a candidate the file's checks accepted (a refused one
        # carries none)
        first = next((row for row in rows if any(r["limit"] for r in row)), rows[0])
        names = [r["name"] for r in first]
        if any([r["name"] for r in row] != names for row in rows):
            raise RuntimeError("planetary problem: candidates gave different checks")
        value = np.array([[np.nan if r["value"] is None else r["value"] for r in row]
                          for row in rows], dtype=float)
        G = np.array([[r["violation"] for r in row] for row in rows], dtype=float)
        ok = np.array([[r["ok"] for r in row] for row in rows], dtype=bool)
        gear = np.array([is_gear_shape_check(n) for n in names])
        wpa = np.where(np.char.startswith(np.array(names), "working_pressure_angle")[None, :],
                       value, -np.inf).max(axis=1)
        F = np.where(np.isfinite(wpa), wpa, 1e6)[:, None]
        required = np.ones(len(names), bool)
        extra = {}
        if not self.manufacturability:  # reported, not required
            required = ~gear
            extra["graded_violation"] = G.copy()
            G = np.where(gear[None, :], 0.0, G)
        return Batch(F, G, names, [r["unit"] for r in first], [r["limit"] for r in first],
                     value, ok, required=required, extra=extra)


def verify(design, manufacturability: bool = True) -> dict:
    """Full-resolution re-check of a planetary design (the file's own ``samples``):
    {all_met, objectives} as ``optimize.jobs.verify``."""
    from plantmech.objectives.planetary import design_evaluation

    objs = []
    for r in design_evaluation(design):
        o = {k: v for k, v in r.items() if k != "violation"}
        if not manufacturability and is_gear_shape_check(o["name"]):
            o["required"] = False
        objs.append(o)
    return {"all_met": all(o["ok"] for o in objs if o.get("required", True)),
            "objectives": objs}
