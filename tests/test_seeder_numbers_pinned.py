"""Pinned numbers of the bundled seeder examples (issue 16's acceptance: the engine's speed
work keeps every number to 1e-6 in its units).

The values below were recorded from the code before that work (main at commit 34d81d3, the
pure-NumPy/SciPy population path: SciPy ``CubicSpline(...).antiderivative()`` rolling
integrals, ``solve_centre_distances``, (P, S) objective arrays) with
``scripts/seeder_numbers.py dump`` and copied here; they are not computed by the code under
test. The populations are drawn as that script draws them (seeded), and the first rows
evaluated.
"""

from pathlib import Path

import numpy as np
import pytest

from plantmech.design import SectionAngles, load_design
from plantmech.workflows import (
    evaluate_seeder_population,
    run_seeder_forward,
    run_seeder_inverse,
    seeder_inverse_checks_population,
)

EX = Path(__file__).resolve().parents[1] / "examples"
ROWS = 5

TABLE4_RADII_VALUES = [[30.498032058802462, 19.427215292199083, 38.717184336537656,
                        2.21632565851939, 1.3123573744006076, 0.23280036138452936,
                        1.7869005270514036, 50.55198234290155, 0.3902309556825515,
                        82.81025513351949],
                       [30.79739859324337, 19.916563376009385, 38.80457711265611,
                        2.2029793659018226, 1.3135719394484688, 0.17755839640452212,
                        1.791424287615273, 51.08227784088133, 0.34572489911898796,
                        83.73678465653121],
                       [30.846551738942296, 19.815884862518505, 38.639984344104,
                        2.2683037762774005, 1.294695679199786, 0.23799244889920912,
                        1.7158325546319289, 53.88086465349811, 0.30264907641864436,
                        84.49809036735029],
                       [38.76233367417026, 16.983656074496242, 33.073893982208375,
                        1.9914721577957604, 1.2006605663160068, 0.14796653862613787,
                        1.8528609678698846, 51.52163664062583, 0.41299223082583725,
                        81.75310155175293],
                       [35.42609772303457, 20.73560957047469, 38.72272734429767,
                        2.2774121446711284, 1.3059089738309921, 0.13823022643610017,
                        1.9712388986946452, 49.734674358700616, 0.3276519962808062,
                        84.55649037778211]]
TABLE4_RADII_A = [[128.71022727082502, 127.74437669795411, 129.00166359059045, 128.39119497841963,
                   126.73764814898702],
                  [156.45837071429696, 154.8447848574608, 154.94074971156235, 155.07606099081318,
                   154.94255780734267]]
TABLE4_RADII_SECTIONS = [[6.242848682479407, 0.9544192870237611, 1.3395291993439997,
                          2.1606342670907797, 2.683235637826483, 3.7061481319192175],
                         [6.22982807466605, 0.9682316097330766, 1.349395846738042,
                          2.1723187949334566, 2.7127247062009796, 3.647038687876187],
                         [6.264729219618205, 0.9437462583922006, 1.352360093628233,
                          2.170805716005652, 2.6835385804717484, 3.8544880779932162],
                         [6.250541278201484, 0.8372684968955159, 1.4811956377854638,
                          2.319169153241982, 2.831028986417226, 3.4661003604775518],
                         [6.243387945366171, 0.9085273777933727, 1.3879718443850388,
                          2.1991143637168515, 2.7337327131951423, 3.616849879087676]]
TABLE4_RADII_CLOSURE = [[1.4210854715202004e-14, 1.7763568394002505e-14],
                        [1.0658141036401503e-14, 1.9539925233402755e-14],
                        [3.8191672047105385e-14, 8.881784197001252e-16],
                        [8.881784197001252e-16, 4.529709940470639e-14],
                        [3.2862601528904634e-14, 4.618527782440651e-14]]
TABLE4_RADII_TIP = [[[703.2030758664562, 266.4759540595643],
                     [671.7081592802022, 280.83962936270854],
                     [602.7823593925982, 274.16072453934726],
                     [529.4591894855519, 236.18545461384426]],
                    [[703.2030758664562, 266.4759540595643],
                     [673.7123033349787, 277.7220013832723],
                     [606.0789141534009, 270.700220247744],
                     [530.3431856841661, 235.43939493769753]],
                    [[703.2030758664562, 266.4759540595643],
                     [660.3962198561237, 297.5420422525788],
                     [592.2297290775507, 284.8068295918346],
                     [522.4772886143655, 241.9563550948902]]]
TABLE4_PARAMS_VALUES = [[26.28099957373604, 19.392327330874856, 37.62775914608484,
                         2.211346501696566, 1.319508797641852, 0.24584268343204144,
                         1.786900527051557, 50.55198234290155, 0.3902309556825515,
                         82.81025513351949],
                        [30.981818973315566, 19.84323344861282, 38.80947198488317,
                         2.2169002037506287, 1.3184400793288578, 0.19276981259764803,
                         1.7914242876141828, 51.08227784088133, 0.34572489911898796,
                         83.73678465653121],
                        [30.77767237886159, 19.890664217185453, 37.89672309738436,
                         2.2523500001162677, 1.2743815366928666, 0.2534005157836505,
                         1.7158325546252269, 53.88086465349811, 0.30264907641864436,
                         84.49809036735029],
                        [40.53612317955721, 16.096507254905916, 31.955502475583415,
                         1.9145950055673429, 1.160273330558893, 0.10670954926117102,
                         1.8528609678687606, 51.52163664062583, 0.41299223082583725,
                         81.75310155175293],
                        [31.970124814778682, 20.80739343800419, 37.76794519796223,
                         2.272145160821438, 1.3084122438339545, 0.15750046235510584,
                         1.9712388986921063, 49.734674358700616, 0.3276519962808062,
                         84.55649037778211]]
TABLE4_SPLINE_CHECK_VALUES = [[25.69203244939142, 20.606179258771256, 39.34450227703255,
                               2.188004542618164, 1.2708443013616595, 0.14676235713773134,
                               2.089191292384225, 49.11501048985961, 0.3829080423809835,
                               81.55215109719491],
                              [31.558944738336056, 20.390644995516787, 40.4833228326508,
                               2.225202929771524, 1.3021408230894869, 0.11000960962496276,
                               2.2410023040116513, 49.520469387256576, 0.3391516694115445,
                               82.55707216038408],
                              [33.147241118264155, 21.270636568758043, 41.32685456802537,
                               2.2944172343723457, 1.265504240965314, 0.1660086468211767,
                               2.2227914615998348, 52.293343878847026, 0.2993524480032466,
                               83.29189846414255],
                              [42.03018949645551, 19.36854246069801, 31.2193488023426,
                               2.0073292495996182, 1.173494363145633, 0.0594497442324062,
                               2.3511679146639213, 50.039877214800775, 0.41376750764359294,
                               80.3623498019422],
                              [37.05592590846765, 21.110420596095775, 39.59750842597525,
                               2.2912380734318862, 1.2989011703805196, 0.09418522050212996,
                               2.5810560063475494, 48.078469309132245, 0.31599880771064115,
                               83.37613352484985]]
OPTIMIZED_RADII_VALUES = [[30.442298002989627, 3.529429266653384, 25.811585148023262,
                           1.4675651013572355, 0.9266680683256987, 1.1027621152152791,
                           0.4327481793521886, 76.41093682181543, 0.1119212956532624,
                           88.48560389245822],
                          [30.37749697441104, 5.371502806845125, 32.61298836488305,
                           1.5231389942937212, 0.9744204881789699, 1.2199747997990602,
                           0.4080182542657552, 74.91511436661213, 0.11276337271014888,
                           87.82797495034687],
                          [29.27971933708969, 4.303938682466605, 31.561342373497812,
                           1.612033616146314, 1.1065542894279672, 1.3553954075939405,
                           0.4011089680445985, 75.13928852366125, 0.10102547487290243,
                           89.6854939112791],
                          [29.026672999280773, 7.5282552834985985, 35.39898147840882,
                           1.6059690346362894, 1.070948210552307, 1.3972568626633382,
                           0.562119907521849, 76.12505767577736, 0.122864741547425,
                           87.04317724476931],
                          [29.704524682172615, 6.018558196865971, 34.21065109575074,
                           1.685659548738523, 1.1971246838994294, 1.3660736324069476,
                           0.3642865495165743, 75.96663421613019, 0.10556560339760054,
                           88.80512485430783]]
OPTIMIZED_PARAMS_VALUES = [[29.670743157470902, 3.5092375826265148, 25.695616984576326,
                            1.4553138160829093, 0.9232723937254321, 1.0988325098281952,
                            0.4327481793521886, 76.41093682181543, 0.1119212956532624,
                            88.48560389245822],
                           [30.11919258463523, 5.440471675010464, 32.06072173679339,
                            1.5149935560141388, 0.9700916838895259, 1.2337453577420578,
                            0.4080182542657552, 74.91511436661213, 0.11276337271014888,
                            87.82797495034687],
                           [30.121060285313373, 4.575963976562239, 32.11022980942583,
                            1.685632421373294, 1.1087433867725838, 1.3130037920994662,
                            0.4011089680445985, 75.13928852366125, 0.10102547487290243,
                            89.6854939112791],
                           [29.555644761378844, 7.374349484296662, 36.42660720428302,
                            1.6174105300134731, 1.0653566988561942, 1.3534653710824356,
                            0.5621199075218435, 76.12505767577736, 0.122864741547425,
                            87.04317724476931],
                           [29.7413934087626, 5.875716617805637, 34.74947298226407,
                            1.6791197124435628, 1.201357999376176, 1.3434031251848275,
                            0.3642865495165743, 75.96663421613019, 0.10556560339760054,
                            88.80512485430783]]
SEEDER_INVERSE_3600 = {'L1': 254.25202450924172,
                       'L2': 498.93437861769854,
                       'a1': 127.12601225462086,
                       'a2': 127.12601225462086,
                       'point_carrier_angle': [2.207161830342181, 2.3656379446018003,
                                               2.5333056463751915, 2.654508236173219,
                                               2.8124187881943032, 3.1136086419403957,
                                               3.3814917488104754, 3.5444937119278506,
                                               3.7018344755659935, 3.867907293926257,
                                               4.062170748737225, 4.303946700986623,
                                               4.49051330162381, 4.6873687052167465,
                                               4.861760963856881, 5.074537443945193,
                                               5.255137848517636, 5.4432727583247065,
                                               5.692329806318519, 5.954365869370035,
                                               6.242743570077721, 0.2374533173673059,
                                               0.4576338091115597, 0.67788192711447,
                                               0.9026105858862532, 1.168666512660967,
                                               1.3047144355275517],
                       'u_start': 1057.9870539113108}
SEEDER_LAYER1_VALUES = [['nan', 'nan', 'nan', 'nan', 'nan', 'nan', 'nan', 'nan', 'nan', 'nan',
                         'nan', 'nan', 'nan'],
                        ['nan', 'nan', 'nan', 'nan', 'nan', 'nan', 'nan', 'nan', 'nan', 'nan',
                         'nan', 'nan', 'nan'],
                        [151.492692, 220.094469, 454.418745, 305.408077, 44.374438, 76.754274,
                         302.541595, 36.7224, 18.5196, 36.6658, 2.375997, 1.148827, 0.048711],
                        [151.642002, 217.551757, 450.156149, 302.706208, 43.881646, 80.592156,
                         299.457234, 36.6458, 19.0864, 37.2275, 2.439536, 1.152335, 0.001656]]
TABLE4_FORWARD_SECTION_PSI = {'a': 6.247204335548425,
                              'b': 0.9300463966883907,
                              'c': 1.386989564853822,
                              'd': 2.2073431312850116,
                              'e': 2.7598435267411605,
                              'f': 3.6394709221415003}
TABLE4_FORWARD_CHECKS = [['picking_swing', 33.7109], ['seeding_swing', 20.4803],
                         ['sowing_angle', 38.3002], ['seeding_peak_speed', 2.17792],
                         ['return_min_speed_static', 1.284637],
                         ['return_min_speed_dynamic', 0.102825],
                         ['cuttable_module_sun_gear2', 1.850342870385483],
                         ['working_pressure_angle_sun_gear2', 50.528557297640425],
                         ['cuttable_module_gear3_planet', 0.35622562261350993],
                         ['working_pressure_angle_gear3_planet', 83.25929360911354]]


def close(got, want, tol=1e-6):
    """Equal to ``tol`` in the values' units (relative above 1000), NaN where NaN."""
    got, want = np.asarray(got, dtype=float), np.asarray(want, dtype=float)
    assert got.shape == want.shape
    scale = np.maximum(1.0, np.abs(want) / 1000.0)
    same_nan = np.isnan(got) == np.isnan(want)
    assert same_nan.all(), f"NaN pattern differs: {got} vs {want}"
    diff = np.where(np.isnan(want), 0.0, np.abs(got - want) / scale)
    assert diff.max() <= tol, f"largest difference {diff.max():.3g}: {got} vs {want}"


def population(name, params=False, variant=False):
    """The seeded population of ``scripts/seeder_numbers.py`` (40 designs drawn), its
    first ROWS evaluated."""
    d = load_design(EX / name)
    if variant:
        base = run_seeder_forward(d)
        d.train.interpolation = "spline"
        d.train.closure = "check"
        d.train.closure_tolerance_deg = 10.0
        d.train.a1_mm, d.train.a2_mm = base.train.a1, base.train.a2
        d.train.sections_deg = SectionAngles(**{k: float(np.degrees(base.section_psi[k]))
                                                for k in "abcdef"})
    rng = np.random.default_rng(7)
    t = d.train
    P = 40
    R2 = np.asarray(t.gear2.radii_mm) + rng.uniform(-2, 2, (P, len(t.gear2.radii_mm)))
    R3 = np.asarray(t.gear3.radii_mm) + rng.uniform(-2, 2, (P, len(t.gear3.radii_mm)))
    p = None
    if params:
        p = {"L1_mm": t.L1_mm + rng.uniform(-1, 1, P),
             "initial_arm_angle_deg": t.initial_arm_angle_deg + rng.uniform(-1, 1, P),
             "gear2_contact_angle_deg": t.gear2.contact_angle_deg + rng.uniform(-2, 2, P),
             "gear3_contact_angle_deg": t.gear3.contact_angle_deg + rng.uniform(-2, 2, P),
             "backlash_deg": rng.uniform(0, 0.5, P)}
        p = {k: v[:ROWS] for k, v in p.items()}
    return evaluate_seeder_population(d, R2[:ROWS], R3[:ROWS], samples=720, dense=2048,
                                      params=p)


def test_table4_population_numbers():
    pop = population("sugarcane_table4.toml")
    close(pop.evaluation.values, TABLE4_RADII_VALUES)
    close([pop.motion.a1, pop.motion.a2], TABLE4_RADII_A)
    close(pop.section_psi, TABLE4_RADII_SECTIONS)
    close(pop.motion.closure_error, TABLE4_RADII_CLOSURE)
    close(pop.motion.tip[:3, ::37][:, :4], TABLE4_RADII_TIP)


@pytest.mark.parametrize("name, params, variant, want", [
    ("sugarcane_table4.toml", True, False, TABLE4_PARAMS_VALUES),
    ("sugarcane_table4.toml", False, True, TABLE4_SPLINE_CHECK_VALUES),
    ("sugarcane_seeder_optimized.toml", False, False, OPTIMIZED_RADII_VALUES),
    ("sugarcane_seeder_optimized.toml", True, False, OPTIMIZED_PARAMS_VALUES),
])
def test_population_variants(name, params, variant, want):
    """Per-design parameters (L1, arm angle, contact angles, backlash), the spline
    interpolant with given centre distances and sections, and the optimized example."""
    close(population(name, params, variant).evaluation.values, want)


def test_inverse_numbers():
    d = load_design(EX / "sugarcane_seeder.toml")
    d.trajectory.samples = 3600
    r = run_seeder_inverse(d).result
    for key, want in SEEDER_INVERSE_3600.items():
        close(getattr(r, key), want)


def test_layer1_population_numbers():
    d = load_design(EX / "sugarcane_seeder.toml")
    rng = np.random.default_rng(3)
    pts = np.asarray(d.trajectory.points)
    X = pts[None] + rng.uniform(-3, 3, (12,) + pts.shape)
    got = seeder_inverse_checks_population(d, X[:4], 360)
    close(got["values"], SEEDER_LAYER1_VALUES)


def test_table4_forward_numbers():
    job = run_seeder_forward(load_design(EX / "sugarcane_table4.toml"))
    close([job.section_psi[k] for k in "abcdef"],
          [TABLE4_FORWARD_SECTION_PSI[k] for k in "abcdef"])
    got = {c.name: c.value for c in job.checks}
    for name, value in TABLE4_FORWARD_CHECKS:
        close(got[name], np.nan if value is None or isinstance(value, str) else value)
