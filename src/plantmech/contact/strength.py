"""Tooth-root and flank strength of the gears and the strength of their shafts, from the
loads ``plantmech verify`` computes (``contact/loads.py``, ``contact/transplanter_loads.py``).

Non-circular gears lie outside ISO 6336. They are rated, as the commercial tools rate them,
by a **replacement spur gear per contact**: at every carrier step the two pitch curves touch
at one point; each is replaced by the spur gear of the pitch curve's radius of curvature there
(z = 2 rho / m, a ring where the material is concave), and the replacement pair is rated by
the spur-gear formulas. It is an approximation (the tooth is not an involute of that circle
away from the pitch point, and the neighbouring teeth differ); docs/manufacturing.md says how
to read it.

Formulas (spur gears, beta = 0; signed radii rho > 0 external, < 0 a ring):

- Force. The loads give the mesh torque T on the driven gear; the contact normal makes the
  tool pressure angle alpha with the pitch tangent, which leans mu = atan(|r'| / r) off the
  normal to the radius, so T = F_n r cos(alpha + mu) on the flank that leans the far way
  (taken for both: which flank carries the load is not resolved, the conservative one) and
  the replacement gear's tangential force is F_t = F_n cos(alpha).
- Flank (ISO 6336-2 method B): sigma_H = Z_H Z_E Z_eps sqrt(K F_t / b (1/rho_1 + 1/rho_2) / 2)
  (= the standard sqrt(F_t / (b d_1) (u + 1) / u)), Z_H = sqrt(2 / (cos alpha sin alpha)),
  Z_E = sqrt(1 / (pi ((1 - nu_1^2) / E_1 + (1 - nu_2^2) / E_2))), Z_eps = sqrt((4 - eps) / 3).
- Root (ISO 6336-3 method B): sigma_F = K F_t / (b m) Y_F Y_S, Y_F and Y_S by the 30 deg
  tangent of the rack-generated fillet (rack: dedendum h_fP, tip radius rho_fP = 0.38 m), the
  load at the outer point of single tooth contact; a ring by the basic rack (z -> inf, ISO's
  approximation for internal gears). Plastics (VDI 2736-2): the load at the tooth tip and
  Y_eps = 0.25 + 0.75 / eps.
- K = K_A K_v K_beta K_alpha = ``Rating.K_A`` (1.25: light shocks), the others 1 (slow,
  stiff, narrow gears; stated, not computed).
- Safety: S_F = sigma_Flim Y_ST / sigma_F (metals, Y_ST = 2; plastics: VDI's permissible root
  stress, Y_ST = 1), S_H = sigma_Hlim / sigma_H; life factors 1 (endurance).
- Shaft in the bore (diameter d): torsion tau = 16 T / (pi d^3), bending sigma_b = 32 F_n l /
  (pi d^3) with the gear overhung by l from its bearing, von Mises sqrt(sigma_b^2 + 3 tau^2)
  against the material's yield strength; the wall between the bore and the smallest root.
  The overhang l is a design input (``[manufacturing] shaft_overhang_mm``, or ``plantmech
  verify --shaft-overhang``); without it l = one face width, an assumption the record and
  the verdict state (``overhang``; docs/manufacturing.md, "Shaft overhang").
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from plantmech.kinds import kind_of

TWO_PI = 2.0 * np.pi


@dataclass(frozen=True)
class Material:
    """A gear material: elastic constants, allowable stresses (MPa) and the rating method."""

    name: str
    label: str
    E_MPa: float
    nu: float
    sigma_Hlim_MPa: float  # flank endurance limit
    sigma_Flim_MPa: float  # root: ISO's nominal (x Y_ST = 2) or VDI's permissible stress
    yield_MPa: float  # shaft / hub
    plastic: bool
    min_root_safety: float
    min_flank_safety: float
    source: str

    @property
    def root_limit_MPa(self) -> float:
        """The root stress the safety is measured against: sigma_Flim Y_ST (Y_ST = 2 for
        metals, ISO 6336-3; 1 for plastics, VDI 2736's permissible stress)."""
        return self.sigma_Flim_MPa * (1.0 if self.plastic else 2.0)


MATERIALS = {
    "steel": Material("steel", "C45 quenched and tempered (about 230 HB)", 206_000.0, 0.30,
                      590.0, 250.0, 490.0, False, 1.4, 1.0,
                      "ISO 6336-5 through-hardened wrought steel, quality MQ (charts, "
                      "approximate); EN 10083-2 yield"),
    "cast_iron": Material("cast_iron", "grey cast iron EN-GJL-250", 110_000.0, 0.26,
                          360.0, 60.0, 250.0, False, 1.4, 1.0,
                          "ISO 6336-5 grey cast iron (charts, approximate); tensile strength "
                          "for the shaft (brittle)"),
    "pom": Material("pom", "POM copolymer, 23 deg C, 1e7 cycles, grease lubricated", 2_800.0,
                    0.35, 45.0, 40.0, 65.0, True, 2.0, 1.4,
                    "VDI 2736-2 (typical values of its tables, approximate)"),
    "pa66": Material("pa66", "PA66, conditioned, 23 deg C, 1e7 cycles, grease lubricated",
                     1_700.0, 0.40, 36.0, 30.0, 50.0, True, 2.0, 1.4,
                     "VDI 2736-2 (typical values of its tables, approximate)"),
}
DEFAULT_MATERIAL = "steel"


@dataclass(frozen=True)
class Rating:
    """Rating factors (stated, not computed): application factor K_A, dynamic, face and
    transverse load factors 1; the rack's tip radius (x m); the smallest shaft safety."""

    K_A: float = 1.25
    K_v: float = 1.0
    K_beta: float = 1.0
    K_alpha: float = 1.0
    rack_tip_radius: float = 0.38
    min_shaft_safety: float = 1.5

    @property
    def K(self) -> float:
        return self.K_A * self.K_v * self.K_beta * self.K_alpha


def material_of(design) -> Material:
    """The design's gear material ([manufacturing] material, default steel)."""
    name = getattr(getattr(design, "manufacturing", None), "material", None) or DEFAULT_MATERIAL
    return MATERIALS[name]


def elasticity_factor(m1: Material, m2: Material | None = None) -> float:
    """Z_E (sqrt MPa): 189.8 for steel on steel (ISO 6336-2)."""
    m2 = m2 or m1
    return float(np.sqrt(1.0 / (np.pi * ((1 - m1.nu**2) / m1.E_MPa + (1 - m2.nu**2)
                                         / m2.E_MPa))))


def zone_factor(alpha: float) -> float:
    """Z_H of a spur pair without profile shift at pressure angle ``alpha`` (rad): 2.495 at
    20 deg."""
    return float(np.sqrt(2.0 / (np.cos(alpha) * np.sin(alpha))))


def contact_ratio(rho1, rho2, m: float, alpha: float, addendum: float):
    """Transverse contact ratio of the replacement pair (signed pitch radii, mm; a ring
    negative): (g_a1 + g_a2 - a sin alpha) / p_b with the ring's tip inside its pitch
    circle."""
    rho1, rho2 = np.asarray(rho1, dtype=float), np.asarray(rho2, dtype=float)
    ha = addendum * m
    pb = np.pi * m * np.cos(alpha)

    def reach(r):  # sqrt(r_a^2 - r_b^2) - r sin(alpha), signed for a ring
        ra = np.abs(r) + np.where(r > 0, ha, -ha)
        rb = np.abs(r) * np.cos(alpha)
        return np.sqrt(np.maximum(ra**2 - rb**2, 0.0)) - np.abs(r) * np.sin(alpha)

    g1 = reach(rho1)
    g2 = np.where(rho2 > 0, reach(rho2), -reach(rho2))  # a ring: its tip reaches less far
    g1r = np.where(rho1 > 0, g1, -g1)
    return (g1r + g2) / pb


def form_factors(z, alpha: float, dedendum: float, rack_tip_radius: float, eps=None,
                 load_at_tip: bool = False, addendum: float = 1.0):
    """(Y_F, Y_S) of external spur gears of z teeth (array) cut by a rack (pressure angle
    alpha rad, dedendum, tip radius and the gear's addendum x m, no profile shift), ISO
    6336-3 method B: the 30
    deg tangent's root chord s_Fn and fillet radius rho_F, the bending arm h_Fe of the load at
    the outer point of single tooth contact (``eps``: the pair's contact ratio) or at the tip
    (``load_at_tip``: method C / VDI 2736, Y_Fa and Y_Sa)."""
    z = np.asarray(z, dtype=float)
    h_fp, r_fp = dedendum, rack_tip_radius  # x m
    E = np.pi / 4 - h_fp * np.tan(alpha) - (1 - np.sin(alpha)) * r_fp / np.cos(alpha)
    G = r_fp - h_fp
    H = 2.0 / z * (np.pi / 2 - E) - np.pi / 3
    theta = np.full_like(z, np.pi / 6)
    for _ in range(60):
        theta = 2 * G / z * np.tan(theta) - H
    s_fn = z * np.sin(np.pi / 3 - theta) + np.sqrt(3) * (G / np.cos(theta) - r_fp)
    rho_f = r_fp + 2 * G**2 / (np.cos(theta) * (z * np.cos(theta) ** 2 - 2 * G))
    d, db = z, z * np.cos(alpha)  # x m
    da = z + 2.0 * addendum
    if load_at_tip or eps is None:
        den = da
    else:
        e = np.maximum(np.asarray(eps, dtype=float), 1.0)
        den = 2 * np.sqrt((np.sqrt((da / 2) ** 2 - (db / 2) ** 2)
                           - np.pi * d * np.cos(alpha) / z * (e - 1)) ** 2 + (db / 2) ** 2)
    a_en = np.arccos(np.clip(db / den, -1.0, 1.0))
    inv = np.tan(alpha) - alpha
    gamma_e = (np.pi / 2) / z + inv - (np.tan(a_en) - a_en)
    a_fen = a_en - gamma_e
    h_fe = 0.5 * ((np.cos(gamma_e) - np.sin(gamma_e) * np.tan(a_fen)) * den
                  - z * np.cos(np.pi / 3 - theta) - G / np.cos(theta) + r_fp)
    y_f = 6 * h_fe * np.cos(a_fen) / (s_fn**2 * np.cos(alpha))
    L = s_fn / h_fe
    q_s = s_fn / (2 * rho_f)
    y_s = (1.2 + 0.13 * L) * q_s ** (1.0 / (1.21 + 2.3 / L))
    return y_f, y_s


#: the working pressure angle (deg) the force model stops at (cos 89 deg = 0.017)
MAX_WORKING_DEG = 89.0
#: tooth count a ring's replacement is rated at (ISO 6336-3's basic-rack approximation)
RACK_TEETH = 2000.0
#: the fewest replacement teeth the root is rated on: below it the 30 deg tangent
#: construction of ``form_factors`` breaks down (measured on the 20 deg rack: Y_F 6.6, 12.1,
#: 52.3, 95.7, 0.49 at z = 5, 4, 3, 2, 1.5, not growing as the tooth narrows; Y_S undefined
#: at z <= 2); such a span is undercut or pointed (the manufacturability findings), its
#: root is "not rated" in the record, never a number
ROOT_RATED_MIN_TEETH = 5.0


def pair_stresses(F_t, b: float, m: float, rho1, rho2, alpha: float, addendum: float,
                  dedendum: float, material: Material, rating: Rating = Rating()) -> dict:
    """Flank and root stresses (MPa) of replacement spur pairs: tangential force ``F_t`` (N),
    face width b and module m (mm), signed radii of curvature of the two pitch curves at the
    contact (mm, a ring's material concave: negative); arrays broadcast."""
    F_t = np.asarray(F_t, dtype=float)
    rho1, rho2 = np.asarray(rho1, dtype=float), np.asarray(rho2, dtype=float)
    eps = np.clip(contact_ratio(rho1, rho2, m, alpha, addendum), 1.0, 2.0)
    z_e, z_h = elasticity_factor(material), zone_factor(alpha)
    z_eps = np.sqrt((4 - eps) / 3)
    curv = 0.5 * (1 / rho1 + 1 / rho2)  # (u + 1) / (u d_1), 1/mm
    sigma_h = z_h * z_e * z_eps * np.sqrt(rating.K * F_t / b * np.maximum(curv, 0.0))
    out = {"contact_ratio": eps, "sigma_H_MPa": sigma_h, "Z_H": z_h, "Z_E": z_e,
           "Z_eps": z_eps}
    tip = material.plastic
    y_eps = 0.25 + 0.75 / eps if tip else 1.0
    for k, rho in (("1", rho1), ("2", rho2)):
        z = np.where(rho > 0, 2 * np.abs(rho) / m, RACK_TEETH)
        with np.errstate(invalid="ignore"):  # z below ROOT_RATED_MIN_TEETH: not rated
            y_f, y_s = form_factors(np.maximum(z, ROOT_RATED_MIN_TEETH), alpha, dedendum,
                                    rating.rack_tip_radius, eps, tip, addendum)
        out[f"z_{k}"] = np.where(rho > 0, 2 * rho / m, 2 * rho / m)
        out[f"Y_F_{k}"], out[f"Y_S_{k}"] = y_f, y_s
        rated = z >= ROOT_RATED_MIN_TEETH
        out[f"root_rated_{k}"] = rated
        with np.errstate(invalid="ignore"):
            out[f"sigma_F_{k}_MPa"] = np.where(
                rated, rating.K * F_t / (b * m) * y_f * y_s * y_eps, np.nan)
    return out


def tangential_force(torque, r, mu, alpha: float):
    """F_t (N) of the replacement gear from the mesh torque on a gear (N m) at pitch radius
    r (mm) of the contact, whose pitch tangent leans mu (rad) off the normal to the radius:
    F_n = |T| / (r cos(alpha + |mu|)) (the flank leaning the far way), F_t = F_n cos alpha;
    a working pressure angle alpha + |mu| at or beyond ``MAX_WORKING_DEG`` (the flank pushes
    along the radius: the mesh locks) is taken at it, so the stresses come out huge and the
    safeties near zero, never negative or infinite."""
    cos_w = np.maximum(np.cos(alpha + np.abs(np.asarray(mu, dtype=float))),
                       np.cos(np.radians(MAX_WORKING_DEG)))
    return np.abs(np.asarray(torque, dtype=float)) * 1e3 / (np.asarray(r) * cos_w) \
        * np.cos(alpha)


#: where the shaft overhang (the bending arm) came from, for the record and the verdict
OVERHANG_DEFAULT, OVERHANG_FILE, OVERHANG_OPTION = "default", "file", "option"


def overhang(design, face_width_mm: float, option_mm: float | None = None) -> dict:
    """The shaft overhang l (mm) the shaft check bends the shaft with, and where it came
    from: ``option_mm`` (``verify --shaft-overhang``), else the file's ``[manufacturing]
    shaft_overhang_mm``, else the default, one face width (an assumption: the gear's face
    midplane one face width from the bearing). {"mm", "source", "text"}."""
    man = getattr(design, "manufacturing", None)
    from_file = getattr(man, "shaft_overhang_mm", None)
    if option_mm is not None:
        return {"mm": float(option_mm), "source": OVERHANG_OPTION,
                "text": f"shaft overhang {option_mm:g} mm taken from --shaft-overhang"}
    if from_file is not None:
        return {"mm": float(from_file), "source": OVERHANG_FILE,
                "text": f"shaft overhang {from_file:g} mm taken from the file "
                        "([manufacturing] shaft_overhang_mm)"}
    return {"mm": float(face_width_mm), "source": OVERHANG_DEFAULT,
            "text": f"shaft overhang {face_width_mm:g} mm (one face width) taken from the "
                    "default, an assumption: give [manufacturing] shaft_overhang_mm (the "
                    "bearing to the gear's face middle) or --shaft-overhang"}


def shaft_check(d_mm: float, torque_N_m: float, normal_force_N: float, overhang_mm: float,
                material: Material, root_radius_mm: float | None = None,
                rating: Rating = Rating()) -> dict:
    """A solid shaft of diameter ``d_mm`` in the bore: torsion, bending by the tooth force
    overhung by ``overhang_mm`` from the bearing, von Mises against the yield strength; the
    wall between the bore and the smallest root radius (mm)."""
    d = float(d_mm)
    tau = 16 * torque_N_m * 1e3 / (np.pi * d**3)
    sigma_b = 32 * normal_force_N * overhang_mm / (np.pi * d**3)
    vm = float(np.sqrt(sigma_b**2 + 3 * tau**2))
    out = {"diameter_mm": round(d, 3), "torque_N_m": round(float(torque_N_m), 4),
           "normal_force_N": round(float(normal_force_N), 2),
           "overhang_mm": round(float(overhang_mm), 3),
           "torsion_MPa": round(float(tau), 2), "bending_MPa": round(float(sigma_b), 2),
           "von_mises_MPa": round(vm, 2), "yield_MPa": material.yield_MPa,
           "safety": round(material.yield_MPa / vm, 3) if vm > 0 else None,
           "min_safety": rating.min_shaft_safety}
    if root_radius_mm is not None:
        out["wall_mm"] = round(float(root_radius_mm - d / 2), 3)
    out["ok"] = out["safety"] is None or out["safety"] >= rating.min_shaft_safety
    return out


def bore_diameter(outline) -> float | None:
    """Diameter (mm) of a gear file's bore: the hole ring nearest the centre (2 x its mean
    distance from the centre); None without a hole."""
    rings = [np.asarray(r, dtype=float) for r in outline.rings]
    if len(rings) < 2:
        return None
    outer = int(np.argmax([np.abs(np.sum(r[:, 0] * np.roll(r[:, 1], -1)
                                         - np.roll(r[:, 0], -1) * r[:, 1])) for r in rings]))
    holes = [r for i, r in enumerate(rings) if i != outer]
    if outline.internal:  # a ring gear's rim: no bore
        return None
    dist = [float(np.hypot(h[:, 0], h[:, 1]).mean()) for h in holes]
    return 2.0 * min(dist)


def root_radius(outline) -> float:
    """Smallest distance (mm) from the centre to the toothed boundary (the deepest root)."""
    ring = np.asarray(outline.ring, dtype=float)
    return float(np.hypot(ring[:, 0], ring[:, 1]).min())


def shaft_rating(gear: str, bore_mm: float | None, torque_N_m: float, normal_force_N: float,
                 arm: dict, material: Material, root_radius_mm: float | None,
                 rating: Rating = Rating()) -> tuple[dict, list, list]:
    """(row, checks, findings) of the shaft in ``gear``'s bore (``shaft_check``, bent over
    the overhang ``arm`` of ``overhang``, whose source the row and the finding state): a
    safety below ``rating.min_shaft_safety`` is a finding naming the gear; no bore: not
    checked."""
    from plantmech.gears.findings import finding

    if bore_mm is None:
        return {"gear": gear, "skipped": f"the {gear} file has no bore"}, [], []
    row = {"gear": gear, **shaft_check(bore_mm, torque_N_m, normal_force_N, arm["mm"],
                                       material, root_radius_mm, rating),
           "overhang_source": arm["source"]}
    checks = [{"name": f"strength: {gear} shaft safety", "value": row["safety"], "unit": "",
               "limit": f">= {rating.min_shaft_safety:g}", "ok": bool(row["ok"])}]
    found = [] if row["ok"] else [finding(
        gear, "shaft_strength", row["safety"], rating.min_shaft_safety, "",
        {"bore_mm": row["diameter_mm"]},
        f"a {bore_mm:.1f} mm shaft in the bore carries {row['torque_N_m']:.2f} N m and a "
        f"{row['normal_force_N']:.0f} N tooth force overhung by {arm['mm']:g} mm ("
        + ("one face width, the default: an assumption" if arm["source"] == OVERHANG_DEFAULT
           else "from the file" if arm["source"] == OVERHANG_FILE else "--shaft-overhang")
        + f"): von Mises {row['von_mises_MPa']:.0f} MPa against a yield of "
        f"{material.yield_MPa:g} MPa")]
    return row, checks, found


# --- contact geometry of each family ---------------------------------------------------


def differential_contacts(design, psi, gears: dict | None = None) -> dict:
    """Per arm j ("internal_planet_{j+1}"): at carrier angles ``psi`` (rad, clockwise from the
    start) the signed radii of curvature (mm) of the planet (gear 1) and the internal gear
    (gear 2, a ring where it wraps the planet) at the contact, the planet's pitch radius and
    the lean mu (rad), the body angles of the contact in the gear files' frames
    (``contact/transplanter.py``: internal -p / n, planet -Q(p)), and, given the gear files
    ``gears``, the module (mm) they were cut with (``_module_of``)."""
    from plantmech.contact.transplanter import planet_turn
    from plantmech.geometry.periodic import polar_curvature_radius
    from plantmech.mechanisms.transplanter_design import design_param, simulate_transplanter

    pair, motion, *_ = simulate_transplanter(design, samples=360)
    n = pair.lobes
    k = design.drive.speed_ratio
    k = (n - 1) / n if k is None else k
    mm = n * (1.0 - k)
    phase0 = float(np.radians(design_param(design, None, "initial_phase_deg")))
    h = pair.p[1] - pair.p[0]
    ddR = np.gradient(pair.dR, h, axis=1)
    rho_int = polar_curvature_radius(pair.R, pair.dR, ddR, 1.0 / n, 0.0)[0]
    rp = pair.planet_radius
    dQ = pair.R / (n * rp)
    rho_pl = polar_curvature_radius(rp, pair.dR, ddR, dQ, np.gradient(dQ, h, axis=1))[0]
    mu = np.arctan(n * np.abs(pair.dR[0]) / pair.R[0])
    J = int(design.carrier.arms)
    out = {}
    for j in range(J):
        ph = phase0 + mm * np.asarray(psi) + n * TWO_PI * j / J
        pm = np.mod(ph, TWO_PI)

        def at(v, pm=pm):
            return np.interp(pm, pair.p, v)

        out[f"internal_planet_{j + 1}"] = {
            "arm": j + 1, "gears": ("planet", "internal"),
            "rho": (at(rho_pl), -at(rho_int)),
            "radius_driven": at(rp[0]), "mu": at(mu),
            "body_angle": (np.mod(-planet_turn(pair, ph), TWO_PI), np.mod(-ph / n, TWO_PI))}
    if gears is not None:
        m = _module_of(design, gears)
        for g in out.values():
            g["module_mm"] = m
    return out


def khv_contacts(design, psi, gears: dict | None = None) -> dict:
    """Per arm j of a K-H-V train (the loads' meshes ``sun_middle_{j+1}``,
    ``middle_planet_{j+1}``, ``contact/transplanter_loads.khv_loads``): the signed radii of
    curvature (mm) of the driven and the driving gear at the contact, the driven gear's
    pitch radius, mu, and the module (the sun's pitch perimeter over pi z, z its outline's
    teeth; else the design's sun teeth). The sun contact lies at contact progress sigma =
    psi + 2 pi j / J (the sun's body angle carrier0 - sigma, its file's frame); the middle
    meets the planet at sigma' with M(sigma') = M(sigma) + pi, where the planet (the sun's
    mirror) has the sun's radius r_s(sigma'); the middle is the sun's mate at a: rho = a -
    r_s, phi' = r_s / (a - r_s). The middle's and the planet's teeth are not located (their
    file frames follow the contact analysis, ``contact/khv.py``)."""
    from plantmech.gears.manufacturability import shape_pair
    from plantmech.gears.teeth import PitchPolyline
    from plantmech.mechanisms.transplanter_design import simulate_transplanter

    pair, *_ = simulate_transplanter(design, samples=360)
    sg, rs, a = pair.sigma, pair.r_sun[0], float(pair.a[0])
    h = sg[1] - sg[0]
    r1 = np.gradient(rs, h)
    r2 = np.gradient(r1, h)
    (sun, mid), mu = shape_pair(sg[:-1], rs[None, :-1], r1[None, :-1], r2[None, :-1], a)
    rho_s, rho_m, mu = sun.curvature_radius[0], mid.curvature_radius[0], mu[0]
    Mt = pair.M[0]
    c0 = float(np.radians(design.carrier.initial_angle_deg))
    teeth = gears["sun"].teeth if gears and "sun" in gears else design.sun_gear.teeth
    perim = PitchPolyline.from_polar(sg[:-1], rs[:-1], len(sg) - 1).perimeter
    m = perim / (np.pi * teeth)
    J = int(design.carrier.arms)
    out = {}

    def at(v, x):
        return np.interp(np.mod(x, TWO_PI), sg[:-1], v, period=TWO_PI)

    for j in range(J):
        sig = np.asarray(psi, dtype=float) + TWO_PI * j / J
        s2 = np.interp(np.mod(np.interp(np.mod(sig, TWO_PI), sg, Mt) + np.pi, Mt[-1]), Mt, sg)
        none = np.full(sig.shape, np.nan)
        out[f"sun_middle_{j + 1}"] = {
            "arm": j + 1, "gears": ("middle", "sun"), "module_mm": m,
            "rho": (at(rho_m, sig), at(rho_s, sig)), "radius_driven": a - at(rs[:-1], sig),
            "mu": at(mu, sig), "body_angle": (none, np.mod(c0 - sig, TWO_PI))}
        out[f"middle_planet_{j + 1}"] = {
            "arm": j + 1, "gears": ("planet", "middle"), "module_mm": m,
            "rho": (at(rho_s, s2), at(rho_m, s2)), "radius_driven": at(rs[:-1], s2),
            "mu": at(mu, s2), "body_angle": (none, none)}
    return out


def seeder_contacts(design, psi, gears: dict | None = None) -> dict:
    """The sugarcane seeder's two meshes (the loads' ``sun_gear2``: gear 2 driven by the
    fixed sun; ``gear3_planet``: the planet driven by gear 3, ``contact/loads.
    seeder_loads``) at carrier angles ``psi`` (rad, clockwise from the start): the signed
    radii of curvature (mm) of the driven and the driving gear at the contact (gear 2 and
    gear 3 from their pitch curves, the sun and the planet as their mates rho = a - r,
    ``gears.manufacturability.shape_pair``), the driven gear's pitch radius there (the
    radius the loads divide the mesh torque by), mu, the body angles of the contact in the
    gear files' frames (``contact/seeder.analyse_seeder``: gear 2 at contact0 + psi_2, the
    sun at its start less psi, gear 3 at contact0 + psi_2, the planet at its start less its
    turn) and the module (gear 2's and gear 3's pitch perimeter over one turn over pi z, z
    the teeth on the outline; ``mechanisms.gear_pairs`` cuts them so). ``rated``: False in
    a toothless dwell, where gear 2 is held by the sun's locking arc and no tooth carries
    the load."""
    from plantmech.contact.seeder import _rolling_turn, seeder_train
    from plantmech.gears.manufacturability import shape_pair
    from plantmech.gears.teeth import PitchPolyline
    from plantmech.mechanisms.seeder_forward import simulate, sun_rolling_start

    train = seeder_train(design)
    nom = simulate(train, samples=3600)
    psi = np.asarray(psi, dtype=float)
    grid = nom.carrier_angle

    def along(values):  # a nominal quantity at psi (one carrier turn, periodic)
        return np.interp(np.mod(psi, TWO_PI), grid, values, period=TWO_PI)

    u = np.interp(np.mod(psi, TWO_PI), grid, np.unwrap(nom.gear2_angle))
    planet_rel = np.interp(np.mod(psi, TWO_PI), grid, np.unwrap(nom.planet_rel))
    dwell = np.zeros(psi.shape, dtype=bool) if nom.in_dwell is None else \
        along(nom.in_dwell.astype(float)) > 0.5
    starts = {"gear2": sun_rolling_start(train), "gear3": float(train.gear3.theta0)}
    frames = {
        "sun": -_rolling_turn(train.gear2, starts["gear2"], train.gear2_contact0, train.a1)
        - psi,
        "planet": -_rolling_turn(train.gear3, train.gear3.theta0, train.gear3_contact0,
                                 train.a2) - planet_rel}
    n = 3600
    out = {}
    for mesh, name, mate, curve, a, c0 in (
            ("sun_gear2", "gear2", "sun", train.gear2, train.a1, train.gear2_contact0),
            ("gear3_planet", "gear3", "planet", train.gear3, train.a2, train.gear3_contact0)):
        th = starts[name] + np.linspace(0.0, TWO_PI, n + 1)
        r = curve(th)
        if not curve.periodic and starts[name] == curve.theta0:
            r[-1] = float(curve.spline(curve.theta0 + TWO_PI))  # as gear_pairs cuts it
        perim = PitchPolyline.from_polar(th[:-1], r[:-1], n).perimeter
        z = gears[name].teeth if gears and name in gears else None
        r0, r1, r2 = curve.derivatives(th[:-1])
        (gear, mate_shape), mu = shape_pair(th[:-1], r0[None], r1[None], r2[None], a,
                                            (name, mate))
        body = c0 + u  # the gear's body angle at the contact

        x, grid = np.mod(body - th[0], TWO_PI), th[:-1] - th[0]

        def at(v, x=x, grid=grid):
            return np.interp(x, grid, v, period=TWO_PI)

        rho_g, rho_m = at(gear.curvature_radius[0]), at(mate_shape.curvature_radius[0])
        r_g = at(r0)
        driven_is_gear = name == "gear2"  # the sun drives gear 2; gear 3 drives the planet
        out[mesh] = {
            "arm": 1, "gears": (name, mate) if driven_is_gear else (mate, name),
            "module_mm": perim / (np.pi * z) if z else np.nan,
            "rho": (rho_g, rho_m) if driven_is_gear else (rho_m, rho_g),
            "radius_driven": r_g if driven_is_gear else a - r_g,
            "mu": at(mu[0]),
            "body_angle": ((np.mod(body, TWO_PI), np.mod(frames[mate], TWO_PI))
                           if driven_is_gear else
                           (np.mod(frames[mate], TWO_PI), np.mod(body, TWO_PI))),
            "rated": ~dwell if mesh == "sun_gear2" else np.ones(psi.shape, dtype=bool)}
    return out


#: carrier angle (deg) either side of a rigid-model impact left out of the rating: the
#: solver's ringing after the seeder's dwell impacts (Table 4: 8400 N at the impact step,
#: 830 N 1 deg on, 220 N at 2 deg, 100 N at 3 deg against 80 N before it) has died down
#: to the neighbours' level within 3 deg at the loads' 0.25 deg steps
IMPACT_WINDOW_DEG = 3.0


def _not_rated(geo: dict, impacts: list[float]) -> list[str]:
    """What the strength table leaves out, in words: the impacts' windows and the steps a
    mesh carries no tooth load (a toothless dwell)."""
    out = [f"carrier {c - IMPACT_WINDOW_DEG:.2f}-{c + IMPACT_WINDOW_DEG:.2f} deg: a "
           "toothless dwell's end, an impact of the rigid loads model (its peak force "
           "depends on the mesh stiffness, not modelled)" for c in impacts]
    for name, g in geo.items():
        rated = np.asarray(g.get("rated", True))
        if rated.ndim and not rated.all():
            out.append(f"{name}: {int((~rated).sum())} of {rated.size} steps in the "
                       "toothless dwell (the locking arcs hold the gear, no tooth is loaded)")
    return out


def _module_of(design, gears) -> float:
    """The module (mm) the gear files were cut with: the internal gear's pitch perimeter
    over pi z (z: the teeth found on its outline)."""
    from plantmech.gears.internal import internal_perimeter
    from plantmech.mechanisms.transplanter_design import simulate_transplanter

    pair, *_ = simulate_transplanter(design, samples=360)
    return float(internal_perimeter(pair)[0]) / (np.pi * gears["internal"].teeth)


def _periodic_interp(theta, grid_values):
    """Values of a quantity tabulated on the uniform body-angle grid 2 pi k / N, at
    ``theta`` (rad, any real), linear."""
    n = grid_values.shape[-1]
    grid = TWO_PI * np.arange(n) / n
    return np.interp(np.mod(theta, TWO_PI), grid, grid_values, period=TWO_PI)


def planetary_contacts(design, psi, gears: dict | None = None) -> dict:
    """Per pair and arm (the loads' mesh names ``<driver>_<follower>[_<arm>]``): at carrier
    angles ``psi`` (rad, the carrier's own sense from the start) the signed radii of
    curvature (mm, a ring's material concave: negative) of the follower (gear 1, the one the
    mesh torque is on) and the driver (gear 2) at the contact, the follower's pitch radius
    there, the lean mu (rad), the body angles of the contact (``trains.model.
    contact_angles``; arm j's found by the carrier shift that gives its contact radii), and
    the pair's module: its follower's pitch perimeter over pi z, z the teeth found on its
    file's outline (``gears``), else ``trains.gearing.pair_modules`` (the modules
    ``plantmech gears`` cuts without --module)."""
    from plantmech.geometry.periodic import polar_curvature_radius
    from plantmech.trains.curves import second_derivative
    from plantmech.trains.gearing import _perimeter, built_train, gear_names, pair_modules
    from plantmech.trains.model import contact_angles, simulate

    built = built_train(design)
    motion = simulate(built, design.samples)
    names = gear_names(design)
    modules = [m["module_mm"] for m in pair_modules(design, built)]
    for k, (_, follower) in enumerate(names):
        if gears and follower in gears and gears[follower].teeth:
            modules[k] = _perimeter(built.followers[k], 3000) / (np.pi * gears[follower].teeth)
    J = motion.tip.shape[1]
    psi = np.asarray(psi, dtype=float)
    curv = []
    for k in range(len(built.laws)):
        kind = built.train.pairs[k].kind
        out = []
        for curve, ring in ((built.followers[k], kind == "internal_ring_follower"),
                            (built.drivers[k], kind == "internal")):
            rc = polar_curvature_radius(curve.r[:1], curve.dr[:1],
                                        second_derivative(curve)[:1], 1.0, 0.0)[0]
            out.append((-rc if ring else rc, curve.r[0], curve.dr[0]))
        curv.append(out)
    grid = motion.carrier_angle
    result = {}
    for j in range(J):
        # arm j meets the fixed parts as arm 0 does a carrier shift earlier or later: the
        # shift whose follower radii are arm j's (motion.contact_radii)
        best = None
        for shift in ((0.0,) if j == 0 else (TWO_PI * j / J, -TWO_PI * j / J)):
            ang = contact_angles(built, grid + shift)
            err = max(float(np.abs(_periodic_interp(ang[k][1][0], curv[k][0][1])
                                   - motion.contact_radii[k][1][0, j]).max())
                      for k in range(len(built.laws)))
            if best is None or err < best[0]:
                best = (err, shift)
        angles = contact_angles(built, psi + best[1])
        for k in range(len(built.laws)):
            th_f, th_d = angles[k][1][0], angles[k][0][0]
            (rho_f, r_f, _), (rho_d, r_d, dr_d) = curv[k]
            label = f"{names[k][0]}_{names[k][1]}" + ("" if J == 1 else f"_{j + 1}")
            result[label] = {
                "arm": j + 1, "gears": (names[k][1], names[k][0]), "module_mm": modules[k],
                "rho": (_periodic_interp(th_f, rho_f), _periodic_interp(th_d, rho_d)),
                "radius_driven": _periodic_interp(th_f, r_f),
                "mu": np.arctan(np.abs(_periodic_interp(th_d, dr_d))
                                / _periodic_interp(th_d, r_d)),
                "body_angle": (np.mod(th_f, TWO_PI), np.mod(th_d, TWO_PI)),
                "shift_error_mm": best[0]}
    return result


def strength_record(design, gears: dict, loads: dict, face_width_mm: float,
                    overhang_mm: float | None = None) -> dict:
    """The strength table of a train's gears and the planet's shaft from ``plantmech
    verify``'s loads (the transplanters', ``contact/transplanter_loads``; the seeder's,
    ``contact/loads``; a general planetary train's, ``contact/planetary``): per gear the
    largest root and flank stress over every arm and carrier step and the smallest safety
    with its arm, carrier angle and tooth; the shaft in the planet's bore; the findings
    (``gears.findings``) of every safety below its minimum. ``overhang_mm``: the shaft's
    bending arm given on the command line (``overhang``: else the file's, else one face
    width, said so)."""
    from plantmech.gears.findings import finding
    from plantmech.gears.manufacturability import rules_for

    rules = rules_for(design)
    material = material_of(design)
    rating = Rating()
    alpha = rules.alpha
    series = loads["series"]
    psi = np.radians(np.asarray(series["carrier_angle_deg"], dtype=float))
    # the contact geometry of the design's kind (plantmech.kinds: "strength_contacts")
    geo = kind_of(design).hook("strength_contacts")(design, psi, gears)
    # a toothless dwell's ends are impacts of the rigid model (``contact/loads.
    # dwell_impacts``): the force there is the solver's spread over its steps, not the
    # mesh's (it depends on a stiffness the model has not got): left out, as the energy
    # balance leaves them out, and said so in the record
    impacts = [float(i["carrier_angle_deg"]) for i in loads.get("dwell_impacts", [])]
    psi_deg = np.degrees(psi)
    near_impact = np.zeros(psi.shape, dtype=bool)
    for c in impacts:
        near_impact |= np.abs((psi_deg - c + 180.0) % 360.0 - 180.0) <= IMPACT_WINDOW_DEG
    worst: dict[tuple, dict] = {}
    unrated: dict[str, list] = {}  # gear -> [steps loaded but not rated, loaded, min z_eq]
    shaft_load = {"torque": 0.0, "normal": 0.0}
    order: list[str] = []
    for name, g in geo.items():
        # a mesh's steps without teeth in contact (a toothless dwell's locking arcs) carry
        # no tooth load, an impact's no rated one: not rated
        rated = np.asarray(g.get("rated", True)) & ~near_impact
        force = np.where(rated, np.asarray(series[f"tooth_force_{name}_N"], dtype=float),
                         0.0)
        torque = force * g["radius_driven"] * 1e-3  # N m on the driven gear
        F_t = tangential_force(torque, g["radius_driven"], g["mu"], alpha)
        m = g["module_mm"]
        s = pair_stresses(F_t, face_width_mm, m, *g["rho"], alpha, rules.addendum,
                          rules.dedendum, material, rating)
        if g["gears"][0] == "planet":
            shaft_load["torque"] = max(shaft_load["torque"], float(np.abs(torque).max()))
            shaft_load["normal"] = max(shaft_load["normal"], float((F_t / np.cos(alpha)).max()))
        for idx, gear in enumerate(g["gears"]):
            if gear not in order:
                order.append(gear)
            root = s[f"sigma_F_{idx + 1}_MPa"]
            loaded = F_t > 0
            short = loaded & ~np.asarray(s[f"root_rated_{idx + 1}"])
            if short.any():
                u = unrated.setdefault(gear, [0, 0, np.inf])
                u[0] += int(short.sum())
                u[1] += int(loaded.sum())
                u[2] = min(u[2], float(np.min(s[f"z_{idx + 1}"][short])))
            for kind, stress in (("root", root), ("flank", s["sigma_H_MPa"])):
                if np.all(np.isnan(stress)):
                    continue
                t = int(np.nanargmax(stress))
                key = (gear, kind)
                if key in worst and worst[key]["stress_MPa"] >= stress[t]:
                    continue
                body = float(g["body_angle"][idx][t])
                body_deg = round(float(np.degrees(body)), 2) if np.isfinite(body) else None
                worst[key] = {
                    "stress_MPa": float(stress[t]), "arm": g["arm"], "module_mm": m,
                    "carrier_angle_deg": round(float(np.degrees(psi[t])), 2),
                    "tooth": int(gears[gear].tooth_at(body))
                    if gear in gears and np.isfinite(body) else None,
                    "body_angle_deg": body_deg,
                    "equivalent_teeth": round(float(s[f"z_{idx + 1}"][t]), 2),
                    "tangential_force_N": round(float(F_t[t]), 1),
                    "working_pressure_angle_deg": round(float(np.degrees(alpha + g["mu"][t])),
                                                        2)}
    table, findings, checks = [], [], []
    for gear in order:
        row = {"gear": gear, "teeth": gears[gear].teeth,
               "module_mm": round(worst[(gear, "flank")]["module_mm"], 4)}
        for kind, limit, smin in (("root", material.root_limit_MPa, material.min_root_safety),
                                  ("flank", material.sigma_Hlim_MPa,
                                   material.min_flank_safety)):
            w = worst.get((gear, kind))
            if w is None:  # every loaded step below ROOT_RATED_MIN_TEETH
                row[kind] = {"not_computed": "every loaded contact on a replacement spur "
                             f"gear of fewer than {ROOT_RATED_MIN_TEETH:g} teeth"}
                continue  # said in not_rated
            safety = limit / w["stress_MPa"] if w["stress_MPa"] > 0 else np.inf
            w = {k: v for k, v in w.items() if k != "module_mm"}
            row[kind] = dict(w, stress_MPa=round(w["stress_MPa"], 2),
                             safety=round(float(safety), 3), min_safety=smin,
                             limit_MPa=limit)
            checks.append({"name": f"strength: {gear} {kind} safety",
                           "value": round(float(safety), 3), "unit": "",
                           "limit": f">= {smin:g}", "ok": bool(safety >= smin)})
            if safety < smin:
                findings.append(finding(
                    gear, f"{kind}_strength", safety, smin, "",
                    {"arm": w["arm"], "carrier_angle_deg": w["carrier_angle_deg"],
                     "tooth": w["tooth"], "body_angle_deg": w["body_angle_deg"]},
                    f"{'tooth-root' if kind == 'root' else 'flank'} stress "
                    f"{w['stress_MPa']:.0f} MPa against {limit:g} MPa ({material.label}) "
                    f"on the replacement spur gear of {w['equivalent_teeth']:g} teeth"))
        table.append(row)
    arm = overhang(design, face_width_mm, overhang_mm)
    shaft, c, f = shaft_rating("planet", bore_diameter(gears["planet"]),
                               shaft_load["torque"], shaft_load["normal"], arm,
                               material, root_radius(gears["planet"]), rating)
    checks += c
    findings += f
    return {"method": ("VDI 2736-2" if material.plastic else "ISO 6336-2/-3 method B")
            + ": replacement spur gear per contact (an approximation, docs/manufacturing.md)",
            "material": asdict(material), "rating": asdict(rating),
            "tooth": {"pressure_angle_deg": rules.pressure_angle_deg,
                      "addendum": rules.addendum, "dedendum": rules.dedendum},
            "face_width_mm": face_width_mm, "shaft_overhang": arm,
            "not_rated": _not_rated(geo, impacts) + [
                f"{gear} root: {n} of {of} loaded steps on a replacement spur gear of "
                f"fewer than {ROOT_RATED_MIN_TEETH:g} teeth (down to {zmin:.2f}), where "
                "ISO 6336-3's form factors do not hold: the tooth is undercut or pointed "
                "there (the manufacturability findings); the root safety is the rated "
                "steps' only" for gear, (n, of, zmin) in unrated.items()],
            "gears": table,
            "shafts": [shaft],
            "findings": findings, "checks": checks}
