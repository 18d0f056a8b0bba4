"""``plantmech optimize --problem planetary``: a general planetary train's free variables
against its [limits] and the pitch-curve manufacturability rules.

The variables are the numeric fields the design file names in ``[optimize.variables]``
(dotted paths, each with [lower, upper]; ``design_planetary.PlanetaryOptimize``); a file
without that table frees its shape by default (:func:`default_variables`: every non-zero
length and shape number of its given pitch curves, then the arm length, each +-10 %, at
most ``MAX_VARIABLES``; recorded in run.json's ``design_choices``). Every
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

#: the default variables' box: +- this fraction of the file's value
DEFAULT_SPAN = 0.10
#: the numeric fields of a pitch curve freed by default (lengths and shape numbers; the
#: angles place a curve rather than shape it, the structure is not a number to search)
_SHAPE_FIELDS = ("semi_major_mm", "eccentricity", "radius_mm", "offset_mm", "radii_mm",
                 "mean_radius_mm", "cos_mm", "sin_mm")


def default_variables(design, span: float = DEFAULT_SPAN) -> dict[str, list[float]]:
    """{dotted path: [lower, upper]} freed when a planetary file names none: every non-zero
    length and shape number of each given pitch curve (pairs in order, a list field item
    by item), then the arm length, each within +-``span`` of its value, in that order up
    to ``MAX_VARIABLES``. A bound that makes the file invalid on its own (an eccentricity
    above its limit, an offset reaching its radius) is drawn halfway to the value until the
    file takes it (five tries; else the field stays fixed)."""
    from pydantic import ValidationError

    from plantmech.design_planetary import MAX_VARIABLES, get_path, set_path

    paths = []
    for k, pair in enumerate(design.train.pairs):
        for role in ("driver", "follower"):
            curve = getattr(pair, role)
            if curve is None:
                continue
            for name in _SHAPE_FIELDS:
                value = getattr(curve, name, None)
                base = f"train.pairs.{k}.{role}.{name}"
                if isinstance(value, list):
                    paths += [f"{base}.{i}" for i in range(len(value))]
                elif value is not None:
                    paths.append(base)
        if pair.law is not None and pair.law.constants:  # a law's named numbers
            paths += [f"train.pairs.{k}.law.constants.{n}" for n in pair.law.constants]
    if design.arm.length_mm is not None:
        paths.append("arm.length_mm")
    data = design.model_dump(exclude={"optimize"})
    out = {}
    for path in paths:
        if len(out) == MAX_VARIABLES:
            break
        value = float(get_path(design, path))
        if value == 0.0:
            continue
        bounds = []
        for sign in (-1.0, 1.0):
            delta = span * abs(value)
            for _ in range(5):
                set_path(data, path, value + sign * delta)
                try:
                    design.__class__.model_validate(data)
                    break
                except ValidationError:
                    delta /= 2
            else:
                delta = 0.0
            set_path(data, path, value)
            bounds.append(value + sign * delta)
        if bounds[0] < bounds[1]:
            out[path] = bounds
    return out


class PlanetaryProblem(DesignProblem):
    """The free variables of a planetary design file -> its checks as constraints."""

    name = "planetary"
    objective_names = ["max_working_pressure_angle_deg"]

    def __init__(self, design, manufacturability: bool = True):
        from plantmech.kinds import kind_of

        if self.name not in kind_of(design).problems:
            raise ValueError("problem 'planetary' optimizes a mechanism = \"planetary\" design "
                             "(this file is a " + design.mechanism + ")")
        from plantmech.design_planetary import PlanetaryOptimize, get_path, set_path
        from plantmech.units import unit_of

        self.defaulted = design.optimize is None
        opt = design.optimize
        if opt is None:
            free = default_variables(design)
            if not free:
                raise ValueError("field 'optimize': the file gives no [optimize.variables] "
                                 "and has no non-zero pitch-curve length or arm length to "
                                 "free by default; name the free fields, e.g. "
                                 "\"train.pairs.0.driver.eccentricity\" = [0.1, 0.4] "
                                 "(docs/design-file.md)")
            opt = PlanetaryOptimize(variables=free)
        self.manufacturability = manufacturability
        self.samples = opt.samples
        variables = []
        for path, (lo, hi) in opt.variables.items():
            def apply(d, val, path=path):
                set_path(d, path, float(val))
            variables.append(Variable(path, float(get_path(design, path)), float(lo),
                                      float(hi), unit_of(path), apply))
        self.row_names = [r["name"] for r in self._rows(design)]
        super().__init__(design, variables, n_constr=len(self.row_names))

    def design_choices(self) -> dict:
        """run.json's ``design_choices`` entry of the variables when they were defaulted."""
        if not self.defaulted:
            return {}
        return {"variables": {
            "value": f"{len(self.variables)} fields +-{DEFAULT_SPAN:.0%} of the file's values "
                     "(" + ", ".join(v.name for v in self.variables) + ")",
            "set_by": "default: the file has no [optimize.variables]"}}

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
