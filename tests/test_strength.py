"""Tooth-root, flank and shaft strength (contact/strength.py) against ISO 6336's spur-gear
formulas by hand, published factor values, and the curvature of the pitch curves."""

import tomllib

import numpy as np
import pytest

from plantmech.contact import strength as st
from tests.conftest import EXAMPLES

A20 = np.radians(20.0)


def test_published_factors():
    # ISO 6336-2: Z_E = 189.8 sqrt(MPa) for steel on steel, Z_H = 2.495 at 20 deg, x = 0
    assert st.elasticity_factor(st.MATERIALS["steel"]) == pytest.approx(189.8, abs=0.1)
    assert st.zone_factor(A20) == pytest.approx(2.495, abs=0.001)
    # ISO 6336-3 / DIN 3990 method C (load at the tip), basic rack 20 deg, h_fP = 1.25 m,
    # rho_fP = 0.38 m, x = 0: Y_Fa, Y_Sa read from the standard's charts
    for z, yfa, ysa in ((20, 2.80, 1.55), (40, 2.40, 1.67), (100, 2.18, 1.79)):
        yf, ys = st.form_factors(np.array([z]), A20, 1.25, 0.38, load_at_tip=True)
        assert yf[0] == pytest.approx(yfa, rel=0.01) and ys[0] == pytest.approx(ysa, rel=0.01)
    # method B: the load at the outer point of single contact has the shorter arm
    yb, sb = st.form_factors(np.array([20.0]), A20, 1.25, 0.38, eps=np.array([1.6]))
    assert yb[0] < 2.80 and sb[0] > 1.55


def _hand_contact_ratio(z1, z2, m, alpha=A20, ha=1.0):
    r1, r2 = z1 * m / 2, z2 * m / 2
    a = r1 + r2
    rb1, rb2 = r1 * np.cos(alpha), r2 * np.cos(alpha)
    return (np.sqrt((r1 + ha * m) ** 2 - rb1**2) + np.sqrt((r2 + ha * m) ** 2 - rb2**2)
            - a * np.sin(alpha)) / (np.pi * m * np.cos(alpha))


def test_circular_pair_equals_the_hand_calculation():
    """Two circular gears (z 20 / 40, m 2.5, b 12 mm, F_t 1000 N): sigma_H by ISO 6336-2's
    sigma_H = Z_H Z_E Z_eps sqrt(K_A F_t (u + 1) / (b d_1 u)); the plastic pair's root stress
    by VDI 2736's sigma_F = K_A F_t / (b m) Y_Fa Y_Sa Y_eps with the charts' Y_Fa, Y_Sa."""
    z1, z2, m, b, F = 20, 40, 2.5, 12.0, 1000.0
    K_A = st.Rating().K_A
    eps = _hand_contact_ratio(z1, z2, m)
    assert 1.5 < eps < 1.8
    d1, u = z1 * m, z2 / z1
    hand_h = 2.495 * 189.8 * np.sqrt((4 - eps) / 3) * np.sqrt(K_A * F * (u + 1) / (b * d1 * u))
    s = st.pair_stresses(F, b, m, z1 * m / 2, z2 * m / 2, A20, 1.0, 1.25,
                         st.MATERIALS["steel"])
    assert float(s["contact_ratio"]) == pytest.approx(eps, rel=1e-9)
    assert float(s["sigma_H_MPa"]) == pytest.approx(hand_h, rel=0.02)
    pom = st.MATERIALS["pom"]
    p = st.pair_stresses(F, b, m, z1 * m / 2, z2 * m / 2, A20, 1.0, 1.25, pom)
    hand_f = K_A * F / (b * m) * 2.80 * 1.55 * (0.25 + 0.75 / eps)
    assert float(p["sigma_F_1_MPa"]) == pytest.approx(hand_f, rel=0.02)
    # an internal pair (ring 80 teeth, planet 20): u = -4, (u + 1) / u = 3 / 4
    ring = st.pair_stresses(F, b, m, 25.0, -100.0, A20, 1.0, 1.25, st.MATERIALS["steel"])
    e_int = float(ring["contact_ratio"])
    hand_int = 2.495 * 189.8 * np.sqrt((4 - e_int) / 3) * np.sqrt(K_A * F * 0.75 / (b * 50))
    assert float(ring["sigma_H_MPa"]) == pytest.approx(hand_int, rel=1e-3)
    assert e_int > eps  # an internal mesh has the longer path of contact


def test_replacement_gear_of_a_circular_internal_pair_is_the_pair_itself():
    """A lobed internal gear of constant radius 100 mm (4 lobes) is a circular internal
    pair: the planet has radius 25 mm and the replacement gears are the two circles at every
    carrier angle (mu = 0)."""
    from plantmech.design import load_design

    doc = tomllib.loads((EXAMPLES / "rice_transplanter.toml").read_text())
    doc["internal_gear"]["radii_mm"] = [100.0] * 12
    design = load_design(doc, name="circular.toml")
    psi = np.linspace(0, 2 * np.pi, 37)
    geo = st.differential_contacts(design, psi)
    assert len(geo) == 3
    for g in geo.values():
        assert np.allclose(g["rho"][0], 25.0, rtol=1e-4)
        assert np.allclose(g["rho"][1], -100.0, rtol=1e-4)
        assert np.allclose(g["radius_driven"], 25.0, rtol=1e-6) and np.allclose(g["mu"], 0)
    # the tangential force at mu = 0 is T / r
    assert st.tangential_force(2.5, 25.0, 0.0, A20) == pytest.approx(100.0)


def test_ellipse_vertex_replacement_gears():
    """An ellipse (A = 30, B = 24 mm) about its focus: the replacement gear at the major
    vertex has radius B^2 / A, at the minor vertex A^2 / B."""
    from plantmech.geometry.periodic import polar_curvature_radius

    A, B = 30.0, 24.0
    e = np.sqrt(1 - (B / A) ** 2)
    p = B**2 / A
    th = np.linspace(0, 2 * np.pi, 20001)
    r = p / (1 + e * np.cos(th))
    dr = p * e * np.sin(th) / (1 + e * np.cos(th)) ** 2
    ddr = np.gradient(dr, th)
    rho = polar_curvature_radius(r, dr, ddr, 1.0, 0.0)
    assert rho[0] == pytest.approx(B**2 / A, rel=1e-5)
    k = int(np.argmin(np.abs(r - A)))  # the minor vertex: r = A
    assert rho[k] == pytest.approx(A**2 / B, rel=1e-4)
    m = 2.0
    s = st.pair_stresses(500.0, 10.0, m, rho[0], rho[0], A20, 1.0, 1.25,
                         st.MATERIALS["steel"])
    assert float(s["z_1"]) == pytest.approx(2 * B**2 / A / m, rel=1e-5)


def test_shaft_check_closed_forms():
    steel = st.MATERIALS["steel"]
    # 10 mm shaft, 10 N m: tau = 16 T / (pi d^3) = 50.93 MPa; 100 N at 12 mm: 12.22 MPa
    sh = st.shaft_check(10.0, 10.0, 100.0, 12.0, steel, root_radius_mm=20.0)
    assert sh["torsion_MPa"] == pytest.approx(16e4 / (np.pi * 1e3), abs=0.01)
    assert sh["bending_MPa"] == pytest.approx(32 * 1200 / (np.pi * 1e3), abs=0.01)
    vm = np.hypot(sh["bending_MPa"], np.sqrt(3) * sh["torsion_MPa"])
    assert sh["von_mises_MPa"] == pytest.approx(vm, abs=0.02)
    assert sh["safety"] == pytest.approx(490 / vm, rel=1e-3) and sh["wall_mm"] == 15.0
    # the same loads in a 3 mm bore: a finding naming the gear
    arm = {"mm": 12.0, "source": st.OVERHANG_DEFAULT, "text": ""}
    row, checks, found = st.shaft_rating("planet", 3.0, 10.0, 100.0, arm, steel, 20.0)
    assert row["safety"] < 1 and not checks[0]["ok"]
    assert found[0]["gear"] == "planet" and found[0]["check"] == "shaft_strength"
    assert "the default: an assumption" in found[0]["why"]
    assert row["overhang_mm"] == 12.0 and row["overhang_source"] == "default"
    assert st.shaft_rating("planet", None, 10.0, 100.0, arm, steel, 20.0)[0]["skipped"]
    # the bending stress is proportional to the overhang: half the arm, half the bending
    half = st.shaft_check(10.0, 10.0, 100.0, 6.0, steel)
    assert half["bending_MPa"] == pytest.approx(sh["bending_MPa"] / 2, abs=0.01)


def test_shaft_overhang_source():
    """The overhang: the option over the file over the default (one face width), each
    saying where it came from."""
    from plantmech.design import DesignError, load_design

    doc = tomllib.loads((EXAMPLES / "rice_transplanter.toml").read_text())
    design = load_design(doc, name="d.toml")
    d = st.overhang(design, 12.0)
    assert (d["mm"], d["source"]) == (12.0, "default") and "assumption" in d["text"]
    doc.setdefault("manufacturing", {})["shaft_overhang_mm"] = 6.0
    filed = load_design(doc, name="d.toml")
    f = st.overhang(filed, 12.0)
    assert (f["mm"], f["source"]) == (6.0, "file") and "from the file" in f["text"]
    o = st.overhang(filed, 12.0, 9.0)
    assert (o["mm"], o["source"]) == (9.0, "option")
    doc["manufacturing"]["shaft_overhang_mm"] = -1.0
    with pytest.raises(DesignError, match="shaft_overhang_mm"):
        load_design(doc, name="d.toml")


def test_material_is_read_from_the_design_file():
    from plantmech.design import DesignError, load_design

    doc = tomllib.loads((EXAMPLES / "rice_transplanter.toml").read_text())
    assert st.material_of(load_design(doc, name="d.toml")).name == "steel"
    doc["manufacturing"] = {"material": "pa66"}
    assert st.material_of(load_design(doc, name="d.toml")).plastic
    doc["manufacturing"] = {"material": "wood"}
    with pytest.raises(DesignError, match="manufacturing.material"):
        load_design(doc, name="d.toml")


def test_planetary_contacts_follow_the_ellipse():
    """Three identical ellipses (A = 25, e = 0.18) rolling about their foci: at every
    contact each gear's radius of curvature is the ellipse's, (r (2A - r))^1.5 / (A B) at
    focal radius r (B^2 / A at the near vertex, A^2 / B at the minor one); arm 2 is found by
    the carrier shift that reproduces its contact radii."""
    from plantmech.design import load_design

    design = load_design(EXAMPLES / "rotary_transplanter_elliptic.toml")
    A, e = 25.0, 0.18
    B = A * np.sqrt(1 - e**2)
    psi = np.linspace(0, 2 * np.pi, 721)[:-1]
    geo = st.planetary_contacts(design, psi)
    assert set(geo) == {"sun_idler1_1", "idler1_planet_1", "sun_idler1_2", "idler1_planet_2"}
    for g in geo.values():
        assert g["shift_error_mm"] < 1e-3 and g["module_mm"] > 0
        r = g["radius_driven"]
        expect = (r * (2 * A - r)) ** 1.5 / (A * B)
        assert np.allclose(g["rho"][0], expect, rtol=2e-3)
        # the two gears touch where they are alike: the same curvature
        assert np.allclose(g["rho"][1], g["rho"][0], rtol=2e-3)
        assert g["rho"][0].min() == pytest.approx(B**2 / A, rel=2e-3)
        assert g["rho"][0].max() == pytest.approx(A**2 / B, rel=2e-3)


def test_circular_planetary_strength_equals_the_hand_calculation(tmp_path):
    """The elliptic train made circular (e = 0, one arm): three 25 mm gears at module 2.5
    (20 teeth each, a standard module); from the multibody loads, the table's flank stress at
    its worst step equals ISO 6336-2's by hand from that step's tooth force (mu = 0: F_t =
    T / r), and the root stress ISO 6336-3's with the form factors of 20 teeth."""
    from plantmech.contact.loads import LoadSpec
    from plantmech.contact.outlines import read_gear_dxf
    from plantmech.contact.planetary import gear_file_names, planetary_loads
    from plantmech.design import load_design
    from plantmech.interfaces.cli import main

    text = (EXAMPLES / "rotary_transplanter_elliptic.toml").read_text()
    text = text.replace("eccentricity = 0.18", "eccentricity = 0.0").replace("arms = 2 ",
                                                                             "arms = 1 ")
    text = text.replace("special_module = true", "special_module = false")
    path = tmp_path / "circular.toml"
    path.write_text(text)
    gdir = tmp_path / "g"
    assert main(["gears", str(path), "--out", str(gdir), "--module", "2.5"]) == 0
    design = load_design(path)
    gears = {n: read_gear_dxf(gdir / f"{n}.dxf", n) for n in gear_file_names(design)}
    assert all(g.teeth == 20 for g in gears.values())
    loads = planetary_loads(design, gears, LoadSpec(), samples=720, steps=360)
    rec = st.strength_record(design, gears, loads, 12.0)
    rows = {g["gear"]: g for g in rec["gears"]}
    assert set(rows) == {"idler1", "sun", "planet"}
    K_A, b, m, r = st.Rating().K_A, 12.0, 2.5, 25.0
    eps = _hand_contact_ratio(20, 20, m)
    force = {k[len("tooth_force_"):-2]: v for k, v in loads["series"].items()
             if k.startswith("tooth_force_")}
    psi = np.asarray(loads["series"]["carrier_angle_deg"])
    w = rows["planet"]["flank"]
    F = float(np.interp(w["carrier_angle_deg"], psi, force["idler1_planet"]))
    hand_h = 2.495 * 189.8 * np.sqrt((4 - eps) / 3) * np.sqrt(K_A * F * 2 / (b * 2 * r))
    assert w["stress_MPa"] == pytest.approx(hand_h, rel=0.02)
    assert w["tangential_force_N"] == pytest.approx(F, rel=0.01)
    yf, ys = st.form_factors(np.array([20.0]), A20, 1.25, 0.38, eps=np.array([eps]))
    root = rows["planet"]["root"]
    F = float(np.interp(root["carrier_angle_deg"], psi, force["idler1_planet"]))
    assert root["stress_MPa"] == pytest.approx(K_A * F / (b * m) * yf[0] * ys[0], rel=0.02)
    assert root["safety"] == pytest.approx(2 * 250 / root["stress_MPa"], rel=1e-3)
    assert rec["shafts"][0]["gear"] == "planet"


def test_khv_contacts_of_a_circular_train():
    """A K-H-V train with a circular sun (radius 40 mm): the middle turning once per carrier
    turn has the sun's radius (a = 80 mm), so every contact's replacement gears are two 40 mm
    circles, the driven radius 40 mm and mu = 0; the sun's contact body angle runs back
    with the carrier (carrier0 - psi)."""
    from plantmech.design import load_design

    doc = tomllib.loads((EXAMPLES / "rice_transplanter_khv.toml").read_text())
    doc["sun_gear"]["radii_mm"] = [40.0] * len(doc["sun_gear"]["radii_mm"])
    design = load_design(doc, name="circular_khv.toml")
    psi = np.linspace(0, 2 * np.pi, 73)[:-1]
    geo = st.khv_contacts(design, psi)
    assert len(geo) == 2 * design.carrier.arms
    for g in geo.values():
        assert np.allclose(g["rho"][0], 40.0, rtol=1e-4)
        assert np.allclose(g["rho"][1], 40.0, rtol=1e-4)
        assert np.allclose(g["radius_driven"], 40.0, rtol=1e-6) and np.allclose(g["mu"], 0)
    c0 = np.radians(design.carrier.initial_angle_deg)
    sun_angle = geo["sun_middle_1"]["body_angle"][1]
    assert np.allclose(np.exp(1j * sun_angle), np.exp(1j * (c0 - psi)))


def test_tangential_force_grows_with_the_working_pressure_angle():
    # T = 10 N m at r = 50 mm: T / r = 200 N; at mu = 40.7 deg and a 25 deg tool the flank
    # pushes at 65.7 deg: F_t = 200 cos 25 / cos 65.7 = 2.2 x 200 N
    a25 = np.radians(25.0)
    f = st.tangential_force(10.0, 50.0, np.radians(40.7), a25)
    assert f == pytest.approx(200 * np.cos(a25) / np.cos(np.radians(65.7)), rel=1e-9)
    assert f / 200 == pytest.approx(2.2, abs=0.01)
    # a locking mesh (alpha + mu >= 89 deg): finite, at the 89 deg force, never negative
    lock = st.tangential_force(10.0, 50.0, np.radians(80.0), a25)
    assert lock == pytest.approx(200 * np.cos(a25) / np.cos(np.radians(89.0)))


def test_seeder_contacts_of_a_circular_train():
    """The dedicated seeder file with circular gears 2 and 3 (radius 63.5 mm at a1 = a2 =
    127 mm, no dwell): at every carrier step both meshes' replacement gears are two 63.5 mm
    circles, the driven radius 63.5 mm and mu = 0; every step is rated; gear 2 is driven by
    the sun, the planet by gear 3."""
    from plantmech.design import load_design

    doc = tomllib.loads((EXAMPLES / "sugarcane_table4.toml").read_text())
    for g in ("gear2", "gear3"):
        doc["train"][g]["radii_mm"] = [63.5] * 8
    del doc["train"]["dwell"]
    design = load_design(doc, name="circular_seeder.toml")
    psi = np.linspace(0, 2 * np.pi, 73)[:-1]
    geo = st.seeder_contacts(design, psi)
    assert set(geo) == {"sun_gear2", "gear3_planet"}
    assert geo["sun_gear2"]["gears"] == ("gear2", "sun")
    assert geo["gear3_planet"]["gears"] == ("planet", "gear3")
    for g in geo.values():
        assert np.allclose(g["rho"][0], 63.5, rtol=1e-4)
        assert np.allclose(g["rho"][1], 63.5, rtol=1e-4)
        assert np.allclose(g["radius_driven"], 63.5, rtol=1e-6)
        assert np.allclose(g["mu"], 0, atol=1e-9) and g["rated"].all()
    # the fixed sun turns back by the carrier angle relative to the carrier: its contact's
    # body angle runs back with psi
    sun = geo["sun_gear2"]["body_angle"][1]
    assert np.allclose(np.exp(1j * (sun - sun[0])), np.exp(-1j * psi), atol=1e-6)


def test_root_below_five_replacement_teeth_is_not_rated():
    """Replacement spur gears of 1-4 teeth (a sharp span at a coarse module): ISO 6336-3's
    30 deg tangent construction gives Y_F 95.7 at z = 2 and 0.49 at z = 1.5 (no monotone
    trend) and no Y_S at z <= 2; the root stress there is NaN and flagged not rated, the
    flank stress still computed; at z >= 5 the root stress is K F_t / (b m) Y_F Y_S."""
    mat = st.MATERIALS["steel"]
    rho = np.array([0.6, 1.5, 2.4, 6.0, 50.0])  # mm at module 1: z = 1.2, 3, 4.8, 12, 100
    s = st.pair_stresses(np.full(5, 100.0), 10.0, 1.0, rho, np.full(5, 50.0),
                         np.radians(20), 1.0, 1.25, mat)
    assert list(s["root_rated_1"]) == [False, False, False, True, True]
    assert np.isnan(s["sigma_F_1_MPa"][:3]).all() and np.isfinite(s["sigma_F_1_MPa"][3:]).all()
    assert np.isfinite(s["sigma_H_MPa"]).all()
    y_f, y_s = st.form_factors(np.array([12.0]), np.radians(20), 1.25,
                               st.Rating().rack_tip_radius,
                               np.clip(s["contact_ratio"][3:4], 1, 2), mat.plastic, 1.0)
    assert s["sigma_F_1_MPa"][3] == pytest.approx(
        st.Rating().K * 100.0 / 10.0 * float(y_f[0] * y_s[0]), rel=1e-9)
