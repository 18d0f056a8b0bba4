"""Teeth for a general planetary train: every pair of a ``mechanism = "planetary"`` design
as the toothed gear pairs of ``gears.teeth`` and its pitch curves judged by
``gears.manufacturability``, the same code the seeder and the transplanters use.

``gear_pairs`` hands ``workflows.run_gears`` (``plantmech gears``) one
``gears.teeth.GearPair`` per pair of the chain; ``pitch_curve_findings`` the failing
pitch-curve manufacturability rules (module window, working pressure angle) before any
tooth is cut. Nothing here cuts, checks or writes a gear itself.

Frames. Every pair is cut from its first gear's pitch curve sampled from body angle 0 of
that gear's own frame (``trains.curves``), so gear A's frame is the train's driver frame
and B's (``gears.teeth.polar_contacts``: its contact angle 0 touches A's 0) is the train's
follower frame (``trains.pairs``: theta_f = sense F(theta_d), F(0) = 0). An idler (a pair
without a driver table) is therefore the previous pair's gear B, already cut: it is passed
on with its teeth (``make_pair(gear_a=..., tooth_at_a=...)``) and its mate is phased to them,
as in the K-H-V train.

Modules (docs/design-file.md, ``train.pairs[].teeth``). A group of pairs joined by idlers
shares one module; it comes from the group's first pair: its ``teeth`` z (the module that
makes the driver's pitch perimeter P carry exactly z teeth, m = P / (pi z)), else
``--module``, else the workshop's choice (``gears.modules.choose_teeth``): the largest
standard module in the window the group's pitch curves allow (``assess``: undercut, concave
spans, hub, tooth count; the design's smallest module), turned into the whole tooth count on
the driver nearest perimeter / (pi m) that is a multiple of the driver's lobes and of an
integer follower_turns q (the follower then carries z / q whole teeth).
"""

from __future__ import annotations

import math

import numpy as np

from plantmech.trains.curves import TWO_PI, Curve, second_derivative

#: the gear that is cut first (A) for each kind: the driver, except for a ring follower
_RING_FIRST = {"external": False, "internal": False, "internal_ring_follower": True}


class TeethError(ValueError):
    """A train whose gears cannot be given teeth as asked (message names the field)."""


def _idler(p) -> bool:
    """Whether a pair (of a design file, or a ``PairSpec``) has no gear of its own to drive
    it: no driver, follower or law (the previous follower drives)."""
    return p.driver is None and p.follower is None and getattr(p, "law", None) is None


def gear_names(design) -> list[tuple[str, str]]:
    """(driver, follower) gear names of every pair (no underscores: ``run_gears`` splits
    a pair's name on them): ``sun``; a follower ``planet`` (the last), ``idler<k>`` (it
    drives the next pair) or ``gear<k>`` (shaft k); a compound driver on shaft k
    ``gear<k>b``."""
    pairs = design.train.pairs
    names, previous = [], "sun"
    for k, p in enumerate(pairs):
        if k == 0:
            driver = "sun"
        elif _idler(p):
            driver = previous
        else:
            driver = f"gear{k}b"
        last = k == len(pairs) - 1
        idler_next = not last and _idler(pairs[k + 1])
        follower = "planet" if last else (f"idler{k + 1}" if idler_next else f"gear{k + 1}")
        names.append((driver, follower))
        previous = follower
    return names


def _groups(design) -> list[int]:
    """For every pair, the index of the pair that starts its module group."""
    out = []
    for k, p in enumerate(design.train.pairs):
        idler = k > 0 and _idler(p)
        out.append(out[-1] if idler else k)
    return out


def _sampled(curve: Curve, samples: int) -> tuple[np.ndarray, np.ndarray]:
    """Body angles 0..2 pi (both ends) and radii (mm) of design 0 of ``curve``; an open
    curve's turn from its break (``trains.curves``): the last radius is its left limit
    there, as the seeder's gears with a break are cut (``mechanisms.gear_pairs``)."""
    th = np.linspace(0.0, TWO_PI, samples)
    r = curve(th[None, :])[0][0]
    if curve.open:
        r[-1] = float(curve.r_end[0])
    return th, r


def _perimeter(curve: Curve, samples: int) -> float:
    from plantmech.gears.teeth import PitchPolyline

    th, r = _sampled(curve, samples)
    return PitchPolyline.from_polar(th[:-1], r[:-1], samples).perimeter


def _lobes(spec) -> int:
    return int(getattr(spec, "lobes", 1) or 1) if spec is not None else 1


def _bore(min_pitch_radius: float, spec, rules) -> float | None:
    """A bore leaving ``rules.hub_modules`` modules of material below the tooth roots
    (mm, at most 30); none when below ``rules.min_bore_mm``."""
    d = 2 * (min_pitch_radius - (spec.dedendum + rules.hub_modules) * spec.module)
    return float(min(d, 30.0)) if d >= max(rules.min_bore_mm, 1e-9) else None


def built_train(design):
    """The built train (P = 1) of a planetary design; TeethError names the pair."""
    from plantmech.trains.spec import TrainSpecError, build_from_design

    try:
        return build_from_design(design)
    except TrainSpecError as exc:
        raise TeethError(f"field '{exc}") from None


def _cut_first(built, k: int) -> tuple[Curve, bool]:
    """(curve of the gear cut first, is it a ring) of pair k."""
    kind = built.train.pairs[k].kind
    if _RING_FIRST[kind]:
        return built.followers[k], True
    return built.drivers[k], kind == "internal"


def _odd_note(k: int, z: int) -> str:
    """What pair k's odd tooth count z, chosen for two mates on the same pitch curve, says."""
    return (f"pair {k + 1}: {z} teeth (odd) chosen: the two gears have the same pitch curve, "
            "and an odd count makes them identical and interchangeable (a tooth meets a "
            "space)")


def pair_modules(design, built, module: float | None = None, samples: int = 3000,
                 min_teeth: int = 20) -> list[dict]:
    """Per pair: {module_mm, teeth_a, teeth_driver, source, perimeter_a_mm}: the module of
    its group (module docstring: from the group's first pair's driver, z_d whole and a
    multiple of its lobes and of an integer follower_turns q, so the follower carries
    z_d / q whole teeth; by default ``gears.modules.choose_teeth`` in the group's window,
    its record in ``choice``; ``min_teeth`` is no longer read) and the tooth counts of
    the gear cut first and of the driver. Raises ValueError naming the field or option
    when a gear would get fewer than 6 or more than 500 teeth."""
    from plantmech.gears.manufacturability import binding
    from plantmech.gears.modules import choose_teeth, odd_neighbours
    from plantmech.gears.teeth import check_tooth_counts, teeth_count

    pairs = design.train.pairs
    groups = _groups(design)
    names = gear_names(design)
    perims = [(_perimeter(built.drivers[k], samples), _perimeter(built.followers[k], samples))
              for k in range(len(pairs))]
    # the gear that carries whole teeth all round: the driver, or with a toothless dwell
    # the given follower (seed 000's gear 2; the sun is a partial gear)
    whole = [perims[k][1] if p.dwell is not None else perims[k][0] for k, p in enumerate(pairs)]
    chosen: dict[int, tuple[float, str]] = {}
    notes: dict[int, str] = {}
    choices: dict[int, dict] = {}
    verdicts = rules = None
    out = []
    for k, p in enumerate(pairs):
        g = groups[k]
        if g not in chosen:
            spec = p.driver if p.driver is not None else p.follower
            q = p.follower_turns
            multiple = _lobes(spec)
            n1, n2 = p.turns_pair()
            if abs(n2 / n1 - q) < 1e-9:  # z_f = z_d n1 / n2: z_d a multiple of n2
                multiple = multiple * n2 // math.gcd(multiple, n2)
            twins = p.dwell is None and _identical_mates(built, k)
            driver_perimeter = whole[k]
            if p.teeth is not None and module is None:
                source = f"train.pairs.{k}.teeth"
                if p.teeth % multiple:
                    raise ValueError(f"{source}: {p.teeth} teeth on the driver leave the "
                                     f"follower (turning {q:g} times per driver turn) or a "
                                     f"lobe without whole teeth: use a multiple of {multiple}")
                m = driver_perimeter / (np.pi * p.teeth)
                if twins and p.teeth % 2 == 0:
                    notes[k] = (f"{source}: the two gears of pair {k + 1} have the same pitch "
                                f"curve, but {p.teeth} teeth (even) make them different gears "
                                "(a tooth meets a space): an odd count makes them identical "
                                "and interchangeable")
            elif module is not None:
                source = "--module"
                check_tooth_counts(module, {names[k][0]: driver_perimeter}, source)
                z, m = teeth_count(driver_perimeter, module, multiple)
                if twins and z % 2 == 0 and multiple % 2:  # the nearest odd count
                    x = driver_perimeter / (np.pi * module * multiple)
                    z = multiple * min(odd_neighbours(x), key=lambda c: (abs(c - x), c))
                    m = driver_perimeter / (np.pi * z)
                    notes[k] = _odd_note(k, z)
            else:  # the workshop's choice (gears.modules.choose_teeth) in the group's window
                source = f"the default module of train.pairs.{k}"
                if verdicts is None:
                    verdicts, rules = assess(design, built)
                members = [j for j in range(len(pairs)) if groups[j] == g]
                high = min(float(verdicts[j].module_high[0]) for j in members)
                tight = min(members, key=lambda j: float(verdicts[j].module_high[0]))
                mates = {f"{names[j][i]}": perims[j][i] for j in members for i in (0, 1)}
                odd = bool(twins and multiple % 2)
                choice = choose_teeth(driver_perimeter, high, rules.min_module_mm, multiple,
                                      design.manufacturing.modules_mm or None, mates,
                                      names[k][0], binding(verdicts[tight])[0], odd=odd)
                m = choice["module_mm"]
                choices[g] = choice
                if odd:
                    notes[k] = _odd_note(k, choice["teeth"])
            chosen[g] = (m, source)
        m, source = chosen[g]
        check_tooth_counts(m, {names[k][0]: perims[k][0], names[k][1]: perims[k][1]}, source)
        a_perimeter = perims[k][1] if _RING_FIRST[p.kind] or p.dwell is not None \
            else perims[k][0]
        out.append({"module_mm": float(m), "teeth_a": int(round(a_perimeter / (np.pi * m))),
                    "teeth_driver": int(round(perims[k][0] / (np.pi * m))), "source": source,
                    "perimeter_a_mm": float(a_perimeter), "note": notes.get(k),
                    "choice": choices.get(g) if groups[k] == k else None})
    return out


def _identical_mates(built, k: int) -> bool:
    """Whether pair k's two gears have the same pitch curve (turned, or turned over): an
    external pair turning 1:1 whose follower's radius table is the driver's shifted round
    the grid, or reversed (two ellipses about their foci). Two equal circles are not: a
    circle meshes with its mate in any phase, so its tooth count is free."""
    law = built.laws[k]
    if law.kind != "external" or abs(float(np.ravel(law.follower_turns)[0]) - 1) > 1e-12 \
            or law.driver.open:
        return False
    a, b = built.drivers[k].r[0], built.followers[k].r[0]
    if a.shape != b.shape:
        return False
    tol = 1e-6 * float(a.max())
    if float(a.max() - a.min()) <= tol:
        return False
    for c in (b, b[::-1]):
        corr = np.fft.irfft(np.fft.rfft(a) * np.conj(np.fft.rfft(c)), a.size)
        shift = int(np.argmax(corr))
        if np.abs(np.roll(c, shift) - a).max() <= tol:
            return True
    return False


def gear_pairs(design, module: float | None = None, backlash: float = 0.1,
               samples: int = 3000, min_teeth: int = 20, tooth: dict | None = None,
               method: str = "envelope"):
    """Toothed gear pairs of every pair of a planetary train, [(GearPair, ToothSpec)],
    for ``workflows.run_gears``; ``tooth``: checked tooth proportions
    (``workflows.tooth_proportions``); ``method`` as ``workflows.gear_pairs``. A pair is
    named "<A>_<B>" (``gear_names``; A the gear cut first: the driver, or the ring of an
    ``internal_ring_follower`` pair). Raises ValueError naming the field (``train.pairs.<k>``)
    for what the teeth cannot follow yet: an idler that is a ring on one side, a ring
    follower whose driver was cut for the pair before or which drives an idler."""
    from plantmech.gears.manufacturability import rules_for
    from plantmech.gears.teeth import ToothSpec, make_pair

    built = built_train(design)
    rules = rules_for(design, tooth)
    pairs = design.train.pairs
    names = gear_names(design)
    modules = pair_modules(design, built, module, samples, min_teeth)
    out = []
    for k, p in enumerate(pairs):
        field = f"train.pairs.{k}"
        idler = k > 0 and _idler(p)
        feeds_idler = k + 1 < len(pairs) and _idler(pairs[k + 1])
        spec = ToothSpec(module=modules[k]["module_mm"], backlash_mm=backlash, method=method,
                         **(tooth or {}))
        a = float(built.laws[k].a[0])
        if p.dwell is not None:
            gp = _toothless_pair(built, k, names[k], spec, samples, rules)
        elif p.kind == "internal_ring_follower":
            if idler or feeds_idler:
                raise ValueError(f"{field}.kind: a ring follower next to an idler is not cut "
                                 "by 'plantmech gears' yet (give the ring's driver its own "
                                 "driver table and no idler after the ring)")
            th, r = _sampled(built.followers[k], samples)
            gp = make_pair(f"{names[k][1]}_{names[k][0]}", th, r, a, spec, internal=True,
                           samples=samples, bore_b=_bore(float((r - a).min()), spec, rules))
        elif idler:
            prev_kind = pairs[k - 1].kind
            if p.kind != "external" or prev_kind == "internal_ring_follower":
                raise ValueError(f"{field}.kind: an idler that meshes inside a ring on one "
                                 "side is not cut by 'plantmech gears' yet (only external "
                                 "meshes on both sides of an idler)")
            prev = out[-1][0]
            th, r = _sampled(built.drivers[k], samples)
            gp = make_pair(f"{names[k][0]}_{names[k][1]}", th, r, a, spec, samples=samples,
                           gear_a=prev.gear_b, pitch_a=prev.pitch_b, tooth_at_a=prev.tooth_at_b,
                           bore_b=_bore(float((a - r).min()), spec, rules))
        else:
            internal = p.kind == "internal"
            th, r = _sampled(built.drivers[k], samples)
            rf = r - a if internal else a - r
            gp = make_pair(f"{names[k][0]}_{names[k][1]}", th, r, a, spec, internal=internal,
                           samples=samples,
                           bore_a=None if internal else _bore(float(r.min()), spec, rules),
                           bore_b=_bore(float(rf.min()), spec, rules))
        gp.module_source = modules[k]["source"]
        gp.teeth_note = modules[k]["note"]
        gp.module_choice = modules[k]["choice"]
        out.append((gp, spec))
    return out


def _toothless_pair(built, k: int, names: tuple[str, str], spec, samples: int, rules):
    """The pair of a toothless dwell (seed 000's sun and gear 2), cut as the seeder's
    (``mechanisms.gear_pairs``): gear A is the given follower over one turn of its body
    from its lock point (its body angle at the contact where the dwell starts), B the sun,
    the partial gear ``gears.teeth.make_pair`` makes of a mate that turns less than once
    (its toothless arc, the one the contact never visits, left uncut). Named
    "<follower>_<sun>"; A's frame is the follower's body frame, B's contact angle 0
    touches A at the lock."""
    from plantmech.gears.teeth import make_pair

    p = built.train.pairs[k]
    if p.kind != "external":
        raise ValueError(f"train.pairs.{k}.dwell: a toothless dwell on an {p.kind} pair is not "
                         "cut by 'plantmech gears' yet (an external pair is, as seed 000's)")
    law, gap = built.laws[k], built.toothless[k]
    delta = float(np.ravel(p.direction)[0])
    theta_lock = delta + law.driver_direction - float(gap.lock[0, 0, 0])  # the sun's
    start = float(law.invert(np.array([[law.sense * theta_lock]]))[0, 0])  # gear A's
    follower = built.followers[k]
    if follower.open and abs(np.angle(np.exp(1j * start))) < 1e-6:
        th, r = _sampled(follower, samples)  # the lock is its break: its open turn
    else:
        th = start + np.linspace(0.0, TWO_PI, samples)
        r = follower(th[None, :])[0][0]
    a = float(law.a[0])
    return make_pair(f"{names[1]}_{names[0]}", th, r, a, spec, samples=samples,
                     bore_a=_bore(float(r.min()), spec, rules),
                     bore_b=_bore(float((a - r).min()), spec, rules))


def pair_shapes(built, names: list[tuple[str, str]], modules: list | None = None):
    """``gears.manufacturability.PairShape`` of every pair of P built trains, both gears
    sampled along the driver's grid t (rad): the driver r(t); the follower rho = kappa r +
    c a (``trains.pairs``) at body-angle rate phi' = r / rho, phi'' = c a r' / rho^2; the
    ring's material outside its pitch curve (``internal``); mu = atan(|r'| / r); for an
    internal pair the equivalent internal difference 2 (rho_ring - rho_planet) where the
    ring's pitch curve is convex (it wraps the planet), +inf elsewhere. ``modules``: a
    fixed module per pair (mm) or None (the window chooses)."""
    from dataclasses import replace

    from plantmech.gears.manufacturability import PairShape, shape_from_polar
    from plantmech.trains.pairs import _KIND

    out = []
    for k, law in enumerate(built.laws):
        d = law.driver
        r, r1, r2 = d.r, d.dr, second_derivative(d)
        t = d.theta
        _, kappa, c, _, _ = _KIND[law.kind]
        a = law.a[:, None]
        rho = kappa * r + c * a
        dphi = r / rho
        ddphi = c * a * r1 / rho**2
        ring_d, ring_f = law.kind == "internal", law.kind == "internal_ring_follower"
        # the law's driver is the pair's given follower when it gives one (seed 000's gear 2)
        rolled, mate = names[k][::-1] if built.train.pairs[k].follower is not None \
            else names[k]
        gd = shape_from_polar(rolled, t, r, r1, r2, internal=ring_d)
        gf = shape_from_polar(mate, t, rho, kappa * r1, kappa * r2, dphi, ddphi,
                              internal=ring_f)
        # t spans one driver turn, q follower turns: the follower's own perimeter; with a
        # toothless dwell the derived sun carries its teeth on the rolling arc t spans
        if built.train.pairs[k].dwell is None:
            gf = replace(gf, perimeter=gf.perimeter / law.follower_turns)
        diff = None
        if ring_d or ring_f:
            ring, planet = (gd, gf) if ring_d else (gf, gd)
            wraps = ring.curvature_radius < 0  # ring material concave: it wraps the planet
            diff = np.where(wraps, 2 * (-ring.curvature_radius - planet.curvature_radius),
                            np.inf)
        fixed = None if modules is None or modules[k] is None else np.asarray(modules[k])
        out.append(PairShape(f"{names[k][0]}_{names[k][1]}", (gd, gf),
                             np.arctan(np.abs(r1) / r), diff, fixed))
    return out


def assess(design, built=None, modules: list | None = None):
    """[PairVerdict] of every pair of a planetary design under its cutting rules
    (``gears.manufacturability.rules_for``), and the rules."""
    from plantmech.gears.manufacturability import assess_pair, rules_for
    from plantmech.trains.curves import use_kernels

    built = built or built_train(design)
    rules = rules_for(design)
    names = gear_names(design)
    if use_kernels(built.designs * built.laws[0].g.shape[1]) and all(
            law.g_end is None for law in built.laws):  # a population: one fused pass
        return fused_verdicts(built, names, rules, modules), rules
    return [assess_pair(s, rules) for s in pair_shapes(built, names, modules)], rules


def fused_verdicts(built, names: list[tuple[str, str]], rules, modules: list | None = None):
    """[PairVerdict] of every pair of P built trains: ``assess_pair`` of ``pair_shapes``
    with each gear's extremes reduced per design in one pass (``trains.fused.
    pair_extremes``) instead of its (P, N) shape tables; the same verdicts (minima and
    places equal, perimeters to 1e-15 relative: tests/test_trains_fused.py). Closed
    curves only (an open curve's break: ``pair_shapes``)."""
    from plantmech.gears.manufacturability import gear_bounds, pair_verdict
    from plantmech.trains import fused as fz
    from plantmech.trains.pairs import _KIND

    def deg(angle):
        return np.degrees(np.mod(angle, TWO_PI))

    out = []
    for k, law in enumerate(built.laws):
        d = law.driver
        N = d.r.shape[1]
        h = TWO_PI / N
        t = d.theta
        _, kappa, c, _, _ = _KIND[law.kind]
        ring_d, ring_f = law.kind == "internal", law.kind == "internal_ring_follower"
        v, i = fz.pair_extremes(np.ascontiguousarray(d.r, dtype=float),
                                np.ascontiguousarray(d.dr, dtype=float),
                                np.ascontiguousarray(law.a, dtype=float), float(kappa),
                                float(c), ring_d, ring_f, float(t[0]), h)
        spec = built.train.pairs[k]
        rolled, mate = names[k][::-1] if spec.follower is not None else names[k]
        per_f = v[:, fz.PERIMETER_F]
        if spec.dwell is None:
            per_f = per_f / law.follower_turns
        bounds, where = gear_bounds(rolled, (v[:, fz.CONVEX_D], deg(t[i[:, fz.AT_CONVEX_D]])),
                                    (v[:, fz.CONCAVE_D], deg(t[i[:, fz.AT_CONCAVE_D]])),
                                    (v[:, fz.RADIUS_D], deg(t[i[:, fz.AT_RADIUS_D]])),
                                    v[:, fz.PERIMETER_D], rules, ring_d)
        b, w = gear_bounds(mate, (v[:, fz.CONVEX_F], deg(v[:, fz.PHI_CONVEX_F])),
                           (v[:, fz.CONCAVE_F], deg(v[:, fz.PHI_CONCAVE_F])),
                           (v[:, fz.RADIUS_F], deg(v[:, fz.PHI_RADIUS_F])), per_f, rules,
                           ring_f)
        bounds.update(b)
        where.update(w)
        name = f"{names[k][0]}_{names[k][1]}"
        if ring_d or ring_f:
            bounds[f"internal difference {name}"] = (v[:, fz.DIFFERENCE]
                                                      / rules.min_internal_difference)
            where[f"internal difference {name}"] = (rolled,
                                                    deg(t[i[:, fz.AT_DIFFERENCE]]))
        fixed = None if modules is None or modules[k] is None else np.asarray(modules[k])
        out.append(pair_verdict(name, [(rolled, v[:, fz.PERIMETER_D]), (mate, per_f)],
                                bounds, where,
                                (np.arctan(v[:, fz.MU_RATIO]), deg(t[i[:, fz.AT_MU]])),
                                fixed, rules))
    return out


def pitch_curve_findings(design, modules: list | None = None) -> list[dict]:
    """The failing pitch-curve manufacturability rules of every pair (module window and
    working pressure angle, ``gears.manufacturability.findings``) as ``gears.findings``
    findings naming the gear and its body angle, so ``plantmech gears`` judges a planetary
    train by the rules it applies to the seeder and the transplanters. ``modules``: the
    module of each pair (mm; None: the window chooses one); default: the modules the teeth
    are cut with (``pair_modules`` from the design's teeth, else the default module)."""
    from plantmech.gears import manufacturability as mf
    from plantmech.gears.findings import finding

    built = built_train(design)
    if modules is None:  # the modules the teeth are cut with (without --module)
        modules = [m["module_mm"] for m in pair_modules(design, built)]
    verdicts, rules = assess(design, built, modules)
    out = []
    for v in verdicts:
        for f in mf.findings(v, rules):
            where = {} if f["body_angle_deg"] is None else {"body_angle_deg": f["body_angle_deg"]}
            check = ("cuttable_module" if f["check"] == "module window"
                     else "working_pressure_angle")
            out.append(finding(f["gear"], check, f["value"], f["limit"], f["unit"], where,
                               f"pair {v.name}: {f['why']}"))
    return out
