"""Study parameters of each mechanism and the population model that evaluates a chunk of
variants at once.

A study varies named parameters; every variant is the design with the parameters moved
by ``deltas`` (P, K) (deviations from the nominal, in the parameter's unit) and is
evaluated through the population APIs (``objectives.seeder_design.evaluate_seeder_population``,
``objectives.transplanter_design.evaluate_transplanter_population``): one chunk, one call,
no loop per design.

Seeder (seed 000) tolerance model (docs/studies.md):

* ``gear2_radius_mm``, ``gear3_radius_mm``: radial offset of the pitch curve of gear 2 (3)
  (cutting error). The teeth fix each pair's turn, so the mate rolls on the complement at
  the centre distance that closes the pair (solved per variant); a radial error of the
  sun (planet) is then absorbed the same way, which is why gears 2 and 3 carry it.
* ``a1_mm``, ``a2_mm``: centre distances sun - gears 2/3 and gears 2/3 - planet. With the
  pair closed by its teeth a centre-distance error leaves the ratio unchanged to first
  order (the operating pitch curves scale with the distance; the turn depends on r / a
  only); on a collinear carrier (a1 + a2 = L1) it moves the planet axis: L1 += da1 + da2.
* ``L1_mm`` (carrier length, only for a non-collinear carrier), ``L2_mm`` (arm length).
* ``sun_phase_deg``: the fixed sun mounted turned (the whole train turns with it: initial
  carrier and arm angles move together); ``arm_phase_deg``: the arm mounted turned on the
  planet shaft; ``gear2_phase_deg``, ``gear3_phase_deg``: gear 2 (3) meets its mate at a
  body angle off by the error (keyed turned on the shared shaft).
* ``backlash_deg``: angular play of the arm against the carrier
  (``mechanisms.backlash.backlash_offset``); give it a distribution on >= 0.
* ``travel_speed_m_s``: the machine's travel speed (nominal: the design's, or the nominal
  design's zero-speed travel of Eq. 18).

Transplanter (seed 001): ``gear_radius_mm`` (radial offset of the internal gear's, or the
K-H-V sun's, control radii), ``S_mm``, ``H1_mm``, ``beta_deg`` (arm), ``carrier_phase_deg``
(initial carrier angle), ``ring_phase_deg`` (the lobe phase sigma; differential train),
``box_x_mm``, ``box_y_mm``, ``box_inclination_deg`` (seedling box placement), and:

* ``carrier_length_mm``: the planet axis bored that much farther from O than the pair's
  centre distance (differential: a; K-H-V: 2 a, the sum of both bores' errors). The
  teeth keep the ratio, which depends on r / a only: the planet turns as in the pair
  and only its axis moves (the motion of the pair scaled by (L + dL) / L, tested);
  the gears, their module and the gearbox are unchanged.
* ``backlash_deg``: angular play of the planet (the arm) against its drive, as the
  seeder's (``mechanisms.backlash.backlash_offset`` on d gamma_2 / d psi).
* ``travel_speed_m_s``: the machine's travel speed. Nominal: the speed that plants at
  the design's spacing (``workflows.transplanter_travel_speed``); at a fixed carrier
  speed the spacing follows it, s = s0 v / v0, which moves (viii) the forward
  inclination; (ix) the hole width is the widest over the whole spacing range.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

SEEDER_PARAMETERS = {  # name -> (unit, what)
    "gear2_radius_mm": ("mm", "radial offset of gear 2's pitch curve"),
    "gear3_radius_mm": ("mm", "radial offset of gear 3's pitch curve"),
    "a1_mm": ("mm", "centre distance sun - gears 2/3"),
    "a2_mm": ("mm", "centre distance gears 2/3 - planet"),
    "L1_mm": ("mm", "carrier length O - planet axis (non-collinear carrier only)"),
    "L2_mm": ("mm", "arm length planet axis - tip"),
    "sun_phase_deg": ("deg", "sun (frame) mounting angle"),
    "arm_phase_deg": ("deg", "arm mounting angle on the planet shaft"),
    "gear2_phase_deg": ("deg", "gear 2 phase at its mesh with the sun"),
    "gear3_phase_deg": ("deg", "gear 3 phase at its mesh with the planet"),
    "backlash_deg": ("deg", "angular play of the arm against the carrier"),
    "travel_speed_m_s": ("m/s", "machine travel speed"),
}
TRANSPLANTER_PARAMETERS = {
    "gear_radius_mm": ("mm", "radial offset of the internal gear's (K-H-V: sun's) radii"),
    "S_mm": ("mm", "arm: planet axis - needle tip"),
    "H1_mm": ("mm", "arm: planet axis - break point"),
    "beta_deg": ("deg", "arm angle on the planet"),
    "carrier_phase_deg": ("deg", "initial carrier angle"),
    "ring_phase_deg": ("deg", "lobe phase sigma of the internal gear"),
    "box_x_mm": ("mm", "seedling box door x"),
    "box_y_mm": ("mm", "seedling box door y"),
    "box_inclination_deg": ("deg", "seedling box inclination"),
    "carrier_length_mm": ("mm", "carrier: O - planet axis, beyond the pair's centre distance"),
    "backlash_deg": ("deg", "angular play of the planet (arm) against its drive"),
    "travel_speed_m_s": ("m/s", "machine travel speed (sets the plant spacing)"),
}


class StudyInputError(ValueError):
    """A study cannot be set up for this design (names the parameter and why)."""


@dataclass
class Evaluated:
    """P variants: objective names, values (P, M) and ok (P, M); tip (P, S, 2) mm, its rate
    d tip / d psi (P, S, 2) mm/rad, the attitude (arm or needle angle, P x S, deg) over the
    cycle samples ``carrier_angle`` (S,) rad, and extra scalar outputs (name -> (P,))."""

    names: list[str]
    units: list[str]
    limits: list[str]
    values: np.ndarray
    ok: np.ndarray
    carrier_angle: np.ndarray
    tip: np.ndarray
    tip_rate: np.ndarray
    attitude_deg: np.ndarray
    extra: dict


def model_class(design):
    """The study model of the design's kind (``kinds.Kind``, hook "study_model")."""
    from plantmech.kinds import kind_of

    return kind_of(design).hook("study_model")


def parameters_of(design) -> dict:
    """The named study parameters of the design's kind ({}: any numeric field, by its
    dotted path, as the general train's)."""
    return model_class(design).PARAMETERS


def make_model(design, names: list[str], cycle_samples: int = 720, dense: int = 2048):
    return model_class(design).build(design, names, cycle_samples, dense)


def _check_names(names, known, mechanism):
    bad = [n for n in names if n not in known]
    if bad:
        raise StudyInputError(f"parameter {bad[0]!r} is not a study parameter of a {mechanism} "
                              f"(known: {', '.join(known)})")


def _collinear(t) -> bool:
    return abs(t.a1_mm + t.a2_mm - t.L1_mm) <= 1e-6 * t.L1_mm


def check_parameters(design, names: list[str]) -> None:
    """StudyInputError naming the first of ``names`` this design cannot vary: the checks
    of the model's construction, without its evaluation (a study checks them before its
    --out is made)."""
    model_class(design).check(design, names)


class SeederModel:
    """Variants of a seeder's [train] (see the module docstring for the model)."""

    mechanism = "sugarcane_seeder"
    PARAMETERS = SEEDER_PARAMETERS

    @classmethod
    def build(cls, design, names, cycle_samples: int = 720, dense: int = 2048):
        return cls(design, names, cycle_samples, dense)

    @staticmethod
    def check(design, names: list[str]) -> None:
        _check_names(names, SEEDER_PARAMETERS, "sugarcane_seeder")
        t = design.train
        if t is None:
            raise StudyInputError("a seeder study needs a design with a [train] (pitch curves); "
                                  "run 'plantmech optimize --problem seeder-layered' or give one")
        if "L1_mm" in names and _collinear(t):
            raise StudyInputError(
                f"parameter 'L1_mm': the carrier is collinear (a1 + a2 = L1 = {t.L1_mm:.3f} mm),"
                " so L1 follows from the centre distances: give tolerances on 'a1_mm' and "
                "'a2_mm' instead")

    def __init__(self, design, names: list[str], cycle_samples: int = 720, dense: int = 2048):
        from plantmech.objectives.seeder_design import (
            evaluate_seeder_population,
            section_reference_psi,
        )

        self.check(design, names)
        t = design.train
        if t.closure not in ("centre_distance", "scale"):
            # toothed pairs close by their teeth: the variants' pairs are closed by solving
            # the centre distance (the nominal design is unchanged when it closes)
            design = design.model_copy(deep=True)
            design.train.closure = "centre_distance"
        self.collinear = _collinear(t)
        self.design, self.names = design, list(names)
        self.cycle_samples, self.dense = cycle_samples, dense
        self.reference_psi = section_reference_psi(design)
        self.travel0 = design.operation.travel_speed_m_s
        if self.travel0 is None:  # the nominal design's zero-speed travel (Eq. 18)
            pop = evaluate_seeder_population(design, samples=cycle_samples, dense=dense,
                                             reference_psi=self.reference_psi)
            self.travel0 = float(pop.evaluation.metrics["zero_speed_travel_m_s"][0])

    def nominal(self, name: str) -> float:
        t = self.design.train
        return {"a1_mm": t.a1_mm, "a2_mm": t.a2_mm, "L1_mm": t.L1_mm, "L2_mm": t.L2_mm,
                "travel_speed_m_s": self.travel0}.get(name, 0.0)

    def evaluate(self, deltas: np.ndarray) -> Evaluated:
        from plantmech.objectives.seeder_design import evaluate_seeder_population

        t = self.design.train
        deltas = np.atleast_2d(np.asarray(deltas, dtype=float))
        P = deltas.shape[0]
        d = {n: deltas[:, k] for k, n in enumerate(self.names)}
        z = np.zeros(P)
        g = d.get
        R2 = np.asarray(t.gear2.radii_mm, float)[None, :] + g("gear2_radius_mm", z)[:, None]
        R3 = np.asarray(t.gear3.radii_mm, float)[None, :] + g("gear3_radius_mm", z)[:, None]
        params = {}
        if {"L1_mm", "a1_mm", "a2_mm"} & set(d):
            extra = g("a1_mm", z) + g("a2_mm", z) if self.collinear else 0.0
            params["L1_mm"] = t.L1_mm + g("L1_mm", z) + extra
        if "L2_mm" in d:
            params["L2_mm"] = t.L2_mm + d["L2_mm"]
        if "sun_phase_deg" in d:
            params["initial_carrier_angle_deg"] = t.initial_carrier_angle_deg + d["sun_phase_deg"]
        if {"sun_phase_deg", "arm_phase_deg"} & set(d):
            params["initial_arm_angle_deg"] = (t.initial_arm_angle_deg + g("sun_phase_deg", z)
                                               + g("arm_phase_deg", z))
        if "gear2_phase_deg" in d:
            params["gear2_contact_angle_deg"] = t.gear2.contact_angle_deg + d["gear2_phase_deg"]
        if "gear3_phase_deg" in d:
            params["gear3_contact_angle_deg"] = t.gear3.contact_angle_deg + d["gear3_phase_deg"]
        if "backlash_deg" in d:
            params["backlash_deg"] = d["backlash_deg"]
        if "travel_speed_m_s" in d or self.design.operation.travel_speed_m_s is None:
            # a fixed travel (the nominal zero-speed one when the design leaves it open):
            # the machine does not re-tune its speed to each manufactured train
            params["travel_speed_m_s"] = self.travel0 + g("travel_speed_m_s", z)
        pop = evaluate_seeder_population(self.design, R2, R3, samples=self.cycle_samples,
                                         dense=self.dense, reference_psi=self.reference_psi,
                                         params=params)
        m, ev = pop.motion, pop.evaluation
        return Evaluated(list(ev.names), list(ev.units), list(ev.limits), ev.values, ev.ok,
                         m.carrier_angle, m.tip, m.tip_rate, np.degrees(m.arm_angle), {})


class TransplanterModel:
    """Variants of a transplanter (seed 001): see the module docstring."""

    PARAMETERS = TRANSPLANTER_PARAMETERS

    @classmethod
    def build(cls, design, names, cycle_samples: int = 720, dense: int = 2048):
        return cls(design, names, cycle_samples)

    @staticmethod
    def _fixed_gear(design):
        """The fixed non-circular gear: the internal gear (differential) or the sun (K-H-V)."""
        from plantmech.kinds import kind_of

        return getattr(design, kind_of(design).fixed_gear)

    @classmethod
    def check(cls, design, names: list[str]) -> None:
        _check_names(names, TRANSPLANTER_PARAMETERS, design.mechanism)
        if not hasattr(cls._fixed_gear(design), "initial_phase_deg") \
                and "ring_phase_deg" in names:
            raise StudyInputError("parameter 'ring_phase_deg': a K-H-V train has no lobe phase")

    def __init__(self, design, names: list[str], cycle_samples: int = 720):
        from plantmech.mechanisms.transplanter_design import transplanter_travel_speed

        self.check(design, names)
        self.mechanism = design.mechanism
        if getattr(self._fixed_gear(design), "centre_distance_mm", None):
            # the variants' pairs close by their teeth: solve the centre distance
            design = design.model_copy(deep=True)
            design.internal_gear.centre_distance_mm = None
        self.design, self.names, self.cycle_samples = design, list(names), cycle_samples
        self.travel0 = transplanter_travel_speed(design)
        self._carrier0 = None

    def _gear(self):
        return self._fixed_gear(self.design)

    def carrier_length(self) -> float:
        """O - planet axis (mm) of the nominal design: a (differential) or 2 a (K-H-V)."""
        if self._carrier0 is None:
            from plantmech.mechanisms.transplanter_design import simulate_transplanter

            _, motion, _, _ = simulate_transplanter(self.design, samples=8, dense=1024)
            self._carrier0 = float(np.abs(motion.centre[0, 0, 0]))
        return self._carrier0

    def nominal(self, name: str) -> float:
        d = self.design
        if name == "carrier_length_mm":
            return self.carrier_length()
        return {"S_mm": d.arm.S_mm, "H1_mm": d.arm.H1_mm, "beta_deg": d.arm.beta_deg,
                "box_x_mm": d.seedling_box.x_mm, "box_y_mm": d.seedling_box.y_mm,
                "box_inclination_deg": d.seedling_box.inclination_deg,
                "travel_speed_m_s": self.travel0}.get(name, 0.0)

    def evaluate(self, deltas: np.ndarray) -> Evaluated:
        from plantmech.objectives.transplanter_design import evaluate_transplanter_population

        deltas = np.atleast_2d(np.asarray(deltas, dtype=float))
        P = deltas.shape[0]
        d = {n: deltas[:, k] for k, n in enumerate(self.names)}
        z = np.zeros(P)
        dz = self.design
        radii = np.asarray(self._gear().radii_mm, float)[None, :] + d.get(
            "gear_radius_mm", z)[:, None]
        params = {}
        for name, field in (("S_mm", "S_mm"), ("H1_mm", "H1_mm"), ("beta_deg", "beta_deg"),
                            ("box_x_mm", "box_x_mm"), ("box_y_mm", "box_y_mm"),
                            ("box_inclination_deg", "box_inclination_deg")):
            if name in d:
                params[field] = self.nominal(name) + d[name]
        if "carrier_phase_deg" in d:
            params["initial_angle_deg"] = dz.carrier.initial_angle_deg + d["carrier_phase_deg"]
        if "ring_phase_deg" in d:
            params["initial_phase_deg"] = dz.internal_gear.initial_phase_deg + d["ring_phase_deg"]
        if "carrier_length_mm" in d:
            params["carrier_offset_mm"] = d["carrier_length_mm"]
        if "backlash_deg" in d:
            params["backlash_deg"] = d["backlash_deg"]
        if "travel_speed_m_s" in d:
            # a fixed carrier speed: one plant per arm per turn, the spacing follows the speed
            v = self.travel0 + d["travel_speed_m_s"]
            if np.any(v <= 0):
                k = int(np.flatnonzero(v <= 0)[0])
                raise StudyInputError(
                    f"parameter 'travel_speed_m_s': a deviation of {d['travel_speed_m_s'][k]:g}"
                    f" m/s stops the machine (nominal {self.travel0:g} m/s)")
            params["plant_spacing_mm"] = dz.field.plant_spacing_mm * v / self.travel0
        motion, ev = evaluate_transplanter_population(dz, radii, samples=self.cycle_samples,
                                                      params=params or None)
        B = motion.B[:, 0, :]
        rate = motion.tip_rate[:, 0, :]
        tip = np.stack([B.real, B.imag], axis=-1)
        tip_rate = np.stack([rate.real, rate.imag], axis=-1)
        keep = [k for k, n in enumerate(ev.names) if n not in NOT_IN_POPULATION]
        return Evaluated([ev.names[k] for k in keep], [ev.units[k] for k in keep],
                         [ev.limits[k] for k in keep], ev.values[:, keep], ev.ok[:, keep],
                         motion.carrier_angle, tip, tip_rate, motion.needle_angle[:, 0, :], {})


class PlanetaryModel:
    """Variants of a general planetary train (``mechanism = "planetary"``): a study
    parameter is any numeric field of the file by its dotted path ("arm.length_mm",
    "train.pairs.0.driver.eccentricity", "train.pairs.1.centre_distance_mm", ...; the
    deviation in the field's unit). Each variant is the file with the fields moved,
    validated again as a file (a variant breaking a file rule, or whose train does not
    roll or close, is counted as failing every check), and the variants are built,
    simulated and judged as ONE population (``objectives.planetary.structure_population``:
    the [limits] checks and the pitch curves' manufacturability rules)."""

    mechanism = "planetary"
    PARAMETERS: dict = {}  # any numeric field, by its dotted path

    @classmethod
    def build(cls, design, names, cycle_samples: int = 720, dense: int = 2048):
        return cls(design, names, cycle_samples)

    @classmethod
    def check(cls, design, names: list[str]) -> None:
        cls(design, names)  # reads the fields' values only

    def __init__(self, design, names: list[str], cycle_samples: int = 720):
        from plantmech.design_planetary import get_path

        self.design, self.names, self.cycle_samples = design, list(names), cycle_samples
        self._nominal = {}
        for n in names:
            try:
                value = get_path(design, n)
            except (ValueError, AttributeError, TypeError) as exc:
                raise StudyInputError(f"parameter {n!r}: not a field of this planetary design "
                                      f"({exc}); give a dotted path such as 'arm.length_mm' "
                                      "or 'train.pairs.0.driver.eccentricity'") from None
            if isinstance(value, bool) or not isinstance(value, int | float):
                raise StudyInputError(f"parameter {n!r}: not a number in this design (a study "
                                      "moves numeric fields)")
            if n.split(".")[-1] in ("arms", "lobes", "grid", "samples", "teeth"):
                raise StudyInputError(f"parameter {n!r}: a count (a whole number) cannot "
                                      "deviate by a tolerance")
            self._nominal[n] = float(value)

    def nominal(self, name: str) -> float:
        return self._nominal[name]

    def _variant(self, row):
        from pydantic import ValidationError

        from plantmech.design_planetary import set_path

        data = self.design.model_dump()
        for n, dv in zip(self.names, row, strict=True):
            set_path(data, n, self._nominal[n] + float(dv))
        try:
            return self.design.__class__.model_validate(data)
        except ValidationError as exc:
            return str(exc).splitlines()[0]

    def evaluate(self, deltas: np.ndarray) -> Evaluated:
        from plantmech.objectives.planetary import structure_population

        deltas = np.atleast_2d(np.asarray(deltas, dtype=float))
        P = deltas.shape[0]
        variants = [self._variant(row) for row in deltas]
        valid = [i for i, v in enumerate(variants) if not isinstance(v, str)]
        if 0 not in valid and P:
            raise StudyInputError(f"the nominal design is refused: {variants[0]}")
        rows, motions = structure_population([variants[i] for i in valid],
                                             self.cycle_samples)
        template = next(r for r, m in zip(rows, motions, strict=True) if m is not None) \
            if any(m is not None for m in motions) else rows[0]
        names = [r["name"] for r in template]
        values = np.full((P, len(names)), np.nan)
        ok = np.zeros((P, len(names)), dtype=bool)
        S = self.cycle_samples
        tip = np.full((P, S), np.nan + 0j)
        rate = np.full((P, S), np.nan + 0j)
        arm = np.full((P, S), np.nan)
        for i, r, m in zip(valid, rows, motions, strict=True):
            values[i] = [np.nan if x["value"] is None else x["value"] for x in r]
            ok[i] = [x["ok"] for x in r]
            if m is not None:
                tip[i], rate[i], arm[i] = m
        return Evaluated(names, [r["unit"] for r in template], [r["limit"] for r in template],
                         values, ok, 2.0 * np.pi * np.arange(S) / S,
                         np.stack([tip.real, tip.imag], axis=-1),
                         np.stack([rate.real, rate.imag], axis=-1), np.degrees(arm), {})


# objectives (i) and (ii): the shapely interference checks are left out of population
# evaluations (they dominate the cost); `plantmech forward` reports them per design
NOT_IN_POPULATION = ("arms_clearance", "arm_box_clearance")


def path_normal(tip_rate: np.ndarray) -> np.ndarray:
    """Unit normals (S, 2) of a path from its tangent d tip / d psi (S, 2): the tangent
    turned by +90 deg."""
    n = np.c_[-tip_rate[:, 1], tip_rate[:, 0]]
    return n / np.maximum(np.hypot(n[:, 0], n[:, 1]), 1e-300)[:, None]


def chunk_outputs(model, deltas: np.ndarray) -> tuple[dict, dict]:
    """Evaluate the nominal design and the variants ``deltas`` (P, K) in one population;
    returns (columns: name -> (P,) for the results table, band statistics over the cycle
    samples of the tip's deviation along the nominal path's normal: sums, sums of
    squares, minima, maxima (S,), count).

    Columns: each objective's value and ``<name>__ok``, ``all_ok``, ``tip_deviation_mm``
    (largest distance between the variant's and the nominal tip at equal carrier angle),
    ``path_deviation_mm`` (largest deviation along the nominal path's normal: the band),
    ``attitude_error_deg`` (largest arm/needle angle difference from the nominal).
    """
    deltas = np.atleast_2d(np.asarray(deltas, dtype=float))
    P = deltas.shape[0]
    ev = model.evaluate(np.vstack([np.zeros((1, deltas.shape[1])), deltas]))
    cols = {}
    for k, n in enumerate(ev.names):
        cols[n] = ev.values[1:, k]
        cols[f"{n}__ok"] = ev.ok[1:, k]
    cols["all_ok"] = ev.ok[1:].all(axis=1)
    dev = ev.tip[1:] - ev.tip[:1]
    normal = path_normal(ev.tip_rate[0])
    en = dev[..., 0] * normal[None, :, 0] + dev[..., 1] * normal[None, :, 1]  # (P, S) mm
    cols["tip_deviation_mm"] = np.hypot(dev[..., 0], dev[..., 1]).max(axis=1)
    cols["path_deviation_mm"] = np.abs(en).max(axis=1)
    dang = np.mod(ev.attitude_deg[1:] - ev.attitude_deg[:1] + 180.0, 360.0) - 180.0
    cols["attitude_error_deg"] = np.abs(dang).max(axis=1)
    for k, v in ev.extra.items():
        cols[k] = v[1:]
    # a variant the model could not build or move (a refused field, a pair that does not
    # close) has no motion: the band is over the variants that moved, and says how many
    moved = np.isfinite(en).all(axis=1)
    em = en[moved]
    S = en.shape[1]
    band = {"sum": em.sum(axis=0), "sumsq": (em * em).sum(axis=0),
            "min": em.min(axis=0) if len(em) else np.full(S, np.inf),
            "max": em.max(axis=0) if len(em) else np.full(S, -np.inf),
            "count": np.array([int(moved.sum())]), "variants": np.array([P])}
    return cols, band


OUTPUT_UNITS = {"tip_deviation_mm": "mm", "path_deviation_mm": "mm",
                "attitude_error_deg": "deg"}
