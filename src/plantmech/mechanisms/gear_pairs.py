"""Toothed gear pairs of a design file (``gear_pairs``): the seeder's sun-gear 2 and gear
3-planet pairs, the transplanter's internal gear-planet pair, the K-H-V train's sun-middle
and middle-planet pairs, a planetary train's pairs (``trains.gearing``); checked tooth
proportions and the limits the cut gears must meet. Units: mm, deg in the proportions."""

from __future__ import annotations

import numpy as np

from plantmech.kinds import kind_of
from plantmech.mechanisms.seeder_trains import (
    inverse_design_of,
    train_from_design,
    train_from_inverse,
)
from plantmech.mechanisms.transplanter_design import simulate_transplanter


def tooth_proportions(pressure_angle_deg: float = 20.0, addendum: float = 1.0,
                      dedendum: float = 1.25) -> dict:
    """Checked tooth proportions (ToothSpec fields): pressure angle (deg), addendum and
    dedendum (x module); the dedendum must exceed the addendum (root clearance)."""
    if not 0.0 < pressure_angle_deg < 45.0:
        raise ValueError(f"pressure angle {pressure_angle_deg:g} deg: must lie between 0 and "
                         "45 deg (standard: 20)")
    if not addendum > 0.0:
        raise ValueError(f"addendum {addendum:g} x module: must be positive (standard: 1.0)")
    if not dedendum > addendum:
        raise ValueError(f"dedendum {dedendum:g} x module must exceed the addendum "
                         f"{addendum:g} (root clearance; standard: 1.25)")
    return {"pressure_angle_deg": float(pressure_angle_deg), "addendum": float(addendum),
            "dedendum": float(dedendum)}


def gear_pairs(design, module: float | None = None, backlash: float = 0.1,
               samples: int = 3000, min_teeth: int = 20, tooth: dict | None = None,
               method: str = "envelope"):
    """Toothed gear pairs of a design, by the ``"gear_pairs"`` hook of its kind
    (``plantmech.kinds``): the seeder's sun-gear 2 and gear 3-planet pairs
    (``seeder_pairs``), the differential transplanter's internal gear-planet pair
    (``differential_pairs``), the K-H-V train's two pairs (``khv_pairs``), any chain of pairs
    of a planetary train (``trains.gearing.gear_pairs``); ``tooth``: tooth proportions
    (``tooth_proportions``); ``method``: "envelope" (rack-cut teeth from the meshing
    equation's envelope) or "simulated" (every gear by the Boolean cut of its cutter's
    positions).
    Returns [(GearPair, ToothSpec)]."""
    if method not in ("envelope", "simulated"):
        raise ValueError(f"teeth method {method!r}: choose 'envelope' or 'simulated'")
    tooth = tooth_proportions(**(tooth or {}))
    return kind_of(design).hook("gear_pairs")(design, module, backlash, samples, min_teeth,
                                              tooth, method)


def seeder_pairs(design, module, backlash: float, samples: int, min_teeth: int,
                 tooth: dict, method: str) -> list:
    """The seeder's sun-gear 2 and gear 3-planet pairs (``gear_pairs``'s arguments,
    ``tooth`` checked): from its [train], or from the inverse design of its trajectory."""
    from plantmech.gears.teeth import (
        PitchPolyline,
        ToothSpec,
        check_tooth_counts,
        make_pair,
        teeth_count,
    )

    out = []
    if design.train is not None:
        tr, _ = train_from_design(design)
    else:
        _, res = inverse_design_of(design)
        if not res.feasible:
            raise ValueError("the trajectory's inverse design is infeasible: no gears")
        tr = train_from_inverse(res)
    from plantmech.mechanisms.seeder_forward import sun_rolling_start

    # the sun's rolling arc starts where gear 2 is held through the toothless dwell,
    # so the arc it never rolls on (its toothless, locking arc) faces gear 2 there
    for name, curve, a, start in (("gear2_sun", tr.gear2, tr.a1, sun_rolling_start(tr)),
                                  ("gear3_planet", tr.gear3, tr.a2, tr.gear3.theta0)):
        th = start + np.linspace(0.0, 2 * np.pi, samples)
        r = curve(th)
        if not curve.periodic and start == curve.theta0:
            # a turn from the lock point (gear 2 of a dwell design steps there): the
            # turn's last radius is the one before the step
            r[-1] = float(curve.spline(curve.theta0 + 2 * np.pi))
        P = PitchPolyline.from_polar(th[:-1], r[:-1], samples).perimeter
        names = name.split("_")
        mate_p = _mate_perimeter(th, r, a, False, samples)
        choice = None
        if module is None:  # the workshop's choice (gears.modules.choose_teeth)
            choice = _choice(design, tooth, P, {names[1]: mate_p}, names[0], 1,
                             _window_external(curve, start, a, names, tooth, design))
            m = choice["module_mm"]
        else:
            check_tooth_counts(module, {names[0]: P})
            z, m = teeth_count(P, module)
        check_tooth_counts(m, {names[1]: mate_p})
        spec = ToothSpec(module=m, backlash_mm=backlash, method=method, **tooth)
        bore = _bore(r.min(), spec)
        gp = make_pair(name, th, r, a, spec, samples=samples, bore_a=bore,
                       bore_b=_bore((a - r).min(), spec))
        gp.module_choice = choice
        out.append((gp, spec))
    return out


def differential_pairs(design, module, backlash: float, samples: int, min_teeth: int,
                       tooth: dict, method: str) -> list:
    """The differential transplanter's internal gear-planet pair (``gear_pairs``'s
    arguments, ``tooth`` checked)."""
    from plantmech.gears.teeth import (
        PitchPolyline,
        ToothSpec,
        check_tooth_counts,
        make_pair,
        teeth_count,
    )

    out = []
    pair, *_ = simulate_transplanter(design, samples=360)
    g = design.internal_gear
    ang, R = pair.internal_polar(0)
    order = np.argsort(np.mod(ang, 2 * np.pi))
    th = np.r_[np.mod(ang, 2 * np.pi)[order], 2 * np.pi + np.mod(ang, 2 * np.pi)[order][0]]
    r = np.r_[R[order], R[order][0]]
    P = PitchPolyline.from_polar(th[:-1], r[:-1], samples).perimeter
    a = float(pair.a[0])
    choice = None
    if g.teeth and module is None:
        z, m = g.teeth, P / (np.pi * g.teeth)
        check_tooth_counts(m, {"internal": P}, "internal_gear.teeth")
    elif module is None:  # the workshop's choice (gears.modules.choose_teeth)
        from plantmech.gears.internal import tooth_fit
        from plantmech.gears.manufacturability import binding, rules_for

        fit = tooth_fit(pair, 1.0, rules_for(design, tooth))["verdict"]
        choice = _choice(design, tooth, P, {
            "planet": _mate_perimeter(th, r, a, True, samples)}, "internal", g.lobes,
            (float(fit.module_high[0]), binding(fit)[0]))
        m = choice["module_mm"]
    else:
        check_tooth_counts(module, {"internal": P})
        z, m = teeth_count(P, module, g.lobes)
    check_tooth_counts(m, {"planet": _mate_perimeter(th, r, a, True, samples)},
                       "internal_gear.teeth" if g.teeth and module is None else "--module")
    spec = ToothSpec(module=m, backlash_mm=backlash, method=method, **tooth)
    gp = make_pair("internal_planet", th, r, a, spec, internal=True, samples=samples,
                   rim=g.rim_mm + 3.0, bore_b=_bore((r - a).min(), spec))
    gp.module_choice = choice
    out.append((gp, spec))
    return out


def khv_pairs(design, module, backlash: float, samples: int, min_teeth: int,
              tooth: dict, method: str) -> list:
    """The K-H-V train's sun-middle and middle-planet pairs, the middle cut once
    (``gear_pairs``'s arguments, ``tooth`` checked)."""
    from plantmech.gears.teeth import (
        PitchPolyline,
        ToothSpec,
        check_tooth_counts,
        make_pair,
        teeth_count,
    )

    out = []
    from plantmech.geometry.periodic import RadiusCurve

    kp, *_ = simulate_transplanter(design, samples=360)
    sig = kp.sigma[:-1]
    th_s = np.radians(design.carrier.initial_angle_deg) - sig
    order = np.argsort(np.mod(th_s, 2 * np.pi))
    th = np.mod(th_s, 2 * np.pi)[order]
    r = kp.r_sun[0, :-1][order]
    th, r = np.r_[th, th[0] + 2 * np.pi], np.r_[r, r[0]]
    a = float(kp.a[0])
    P = PitchPolyline.from_polar(th[:-1], r[:-1], samples).perimeter
    source = "sun_gear.teeth" if design.sun_gear.teeth and module is None else "--module"
    choice = None
    if design.sun_gear.teeth and module is None:
        m = P / (np.pi * design.sun_gear.teeth)
    elif module is None:  # the workshop's choice (gears.modules.choose_teeth)
        sun = RadiusCurve.from_samples(th[:-1], r[:-1], kind="spline")
        choice = _choice(design, tooth, P, {
            "middle": _mate_perimeter(th, r, a, False, samples)}, "sun", 1,
            _window_external(sun, th[0], a, ("sun", "middle"), tooth, design))
        m = choice["module_mm"]
    else:
        check_tooth_counts(module, {"sun": P})
        z, m = teeth_count(P, module)
    check_tooth_counts(m, {"sun": P, "middle": _mate_perimeter(th, r, a, False, samples)},
                       source)
    spec = ToothSpec(module=m, backlash_mm=backlash, method=method, **tooth)
    p1 = make_pair("sun_middle", th, r, a, spec, samples=samples,
                   bore_a=_bore(r.min(), spec), bore_b=_bore((a - r).min(), spec))
    # the middle meets the planet half a middle turn from the sun contact
    middle = RadiusCurve.from_samples(p1.phi_b[:-1], (a - r)[:-1], kind="spline")
    th2 = p1.phi_b[0] + np.pi + np.linspace(0.0, 2 * np.pi, len(th))
    check_tooth_counts(m, {"planet": _mate_perimeter(th2, middle(th2), a, False, samples)},
                       source)
    p2 = make_pair("middle_planet", th2, middle(th2), a, p1.spec, samples=samples,
                   gear_a=p1.gear_b, pitch_a=p1.pitch_b, tooth_at_a=p1.tooth_at_b,
                   bore_b=_bore((a - middle(th2)).min(), spec))
    p1.module_choice = choice
    out += [(p1, spec), (p2, spec)]
    return out


def _window_external(curve, start: float, a: float, names, tooth: dict, design,
                     n: int = 3600) -> tuple[float, str]:
    """(largest module the pitch curves of an external pair allow, the rule that binds it):
    ``gears.manufacturability`` of the gear's curve from ``start`` over one turn and its
    mate at centre distance ``a`` (mm), as the seeder's gear checks judge it."""
    from plantmech.gears.manufacturability import (
        PairShape,
        assess_pair,
        binding,
        rules_for,
        shape_pair,
    )

    t = start + np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    r, r1, r2 = curve.derivatives(t)
    shapes, mu = shape_pair(t, r[None], r1[None], r2[None], a, tuple(names))
    v = assess_pair(PairShape("_".join(names), shapes, mu), rules_for(design, tooth))
    return float(v.module_high[0]), binding(v)[0]


def _choice(design, tooth: dict, perimeter: float, mates: dict, gear: str, multiple: int,
            window: tuple[float, str]) -> dict:
    """``gears.modules.choose_teeth`` for a gear of ``design`` with the pitch-curve window
    (largest module, its binding rule) and the design's smallest module and cutters."""
    from plantmech.gears.manufacturability import rules_for
    from plantmech.gears.modules import choose_teeth

    man = design.manufacturing
    return choose_teeth(perimeter, window[0], rules_for(design, tooth).min_module_mm,
                        multiple, man.modules_mm or None, mates, gear, window[1])


def _mate_perimeter(theta, r, a: float, internal: bool, samples: int) -> float:
    """Pitch perimeter (mm) of the gear rolling on the polar curve (theta, r) at centre
    distance a (its contact radii a - r, or r - a inside an internal gear)."""
    from plantmech.gears.teeth import PitchPolyline, polar_contacts

    phib, rb = polar_contacts(theta, r, a, internal)
    span = abs(phib[-1] - phib[0])
    if span < 2 * np.pi * (1 - 1e-4):  # a partial mate: the arc it turns through, closed
        return float(np.sum(np.hypot(np.diff(rb * np.cos(phib)), np.diff(rb * np.sin(phib)))))
    return PitchPolyline.from_polar(phib[:-1], rb[:-1], samples).perimeter


def _bore(min_pitch_radius: float, spec) -> float | None:
    """A bore leaving 1.5 modules of material below the tooth roots; none if < 3 mm."""
    d = 2 * (min_pitch_radius - (spec.dedendum + 1.5) * spec.module)
    return float(min(d, 30.0)) if d >= 3.0 else None


def cut_limits(design):
    """The limits the cut gears of ``design`` must meet (``gears.findings.CutLimits``):
    defaults, with the working pressure angle limit the design file gives
    (seeder ``[gear_checks]``, transplanter ``[limits]``)."""
    from plantmech.gears.findings import CutLimits
    from plantmech.gears.manufacturability import rules_for

    # one source for the limit: the pitch-curve rules' (gears.manufacturability.rules_for)
    return CutLimits(max_working_pressure_angle_deg=rules_for(design)
                     .max_working_pressure_angle_deg)
