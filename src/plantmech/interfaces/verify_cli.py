"""``plantmech verify DESIGN.toml --gears DIR --out DIR``: drive the written gear files
(DXF outlines from ``plantmech gears``) tooth on tooth through the train and check what
the machine gets: transmission error, arm attitude error, tip band, contact loss,
interference, the seeder's dwell. Exit 0: every check met; 2: invalid input (names the
file / field); 4: a check is not met (verification.json says which and where)."""

from __future__ import annotations

import sys
import time
from pathlib import Path

EXIT_OK, EXIT_INPUT, EXIT_NOT_MET = 0, 2, 4
SEEDER_GEARS = ("gear2", "sun", "gear3", "planet")
TRANSPLANTER_GEARS = ("internal", "planet")
KHV_GEARS = ("sun", "middle", "planet")


def register(subparsers) -> None:
    from plantmech.interfaces.cli import _number

    p = subparsers.add_parser("verify", help="tooth-contact check of the written gear files "
                              "through the whole train (seeder, differential and K-H-V "
                              "transplanters, general planetary trains)")
    p.add_argument("design", help="design file (TOML) the gears were made from")
    p.add_argument("--gears", required=True, help="directory written by 'plantmech gears'")
    from plantmech.interfaces.cli import add_output_options

    add_output_options(p)
    p.add_argument("--steps", type=_number(int, 8, strict=False, maximum=36_000), default=720,
                   help="carrier steps per turn (8-36000; 720: 0.5 deg; the driver's turn "
                   "with the carrier held)")
    p.add_argument("--max-te", type=_number(float, 0.0, maximum=360.0), default=0.5,
                   help="limit on each pair's transmission error (mid band), deg")
    p.add_argument("--max-attitude-error", type=_number(float, 0.0, maximum=360.0), default=1.0,
                   help="limit on the arm's attitude error through the train, deg")
    p.add_argument("--max-tip-band", type=_number(float, 0.0, maximum=10_000.0), default=5.0,
                   help="limit on the tip band (both ends of the free play), mm")
    p.add_argument("--density", type=_number(float, 0.0, least=100.0, maximum=30_000.0),
                   default=7850.0,
                   help="gear material density, kg/m^3 (100-30000; loads)")
    p.add_argument("--face-width", type=_number(float, 0.0, maximum=1000.0), default=None,
                   help="gear face width, mm (default: the gears' verification.json, else 12)")
    p.add_argument("--shaft-overhang", type=_number(float, 0.0, maximum=1000.0), default=None,
                   help="bending arm of the tooth force on the planet's shaft, mm: bearing to "
                   "the middle of the gear's face (default: the file's [manufacturing] "
                   "shaft_overhang_mm, else one face width, an assumption the verdict states)")
    p.add_argument("--arm-mass", type=_number(float, 0.0, strict=False, maximum=1000.0),
                   default=1.0,
                   help="arm mass, kg (a slender rod planet axis -> tip)")
    p.add_argument("--payload", type=_number(float, 0.0, strict=False, maximum=1000.0),
                   default=0.5,
                   help="cane / seedling mass at the tip, kg")
    p.add_argument("--carrier-speed", type=_number(float, 0.0, maximum=36_000.0), default=360.0,
                   help="carrier speed for the loads, deg/s (the papers': 360; the driver's "
                   "with the carrier held)")
    p.add_argument("--no-loads", action="store_true", help="skip the multibody loads (they "
                   "need plantmech[loads]: without it they are reported not computed, exit 4)")
    p.add_argument("--no-plots", action="store_true", help="skip PNG plots")
    p.set_defaults(func=run)


def run(args) -> int:
    from plantmech.interfaces.cli import run_command
    from plantmech.outputs.files import OutputError

    gears_dir = Path(args.gears)
    if not gears_dir.is_dir():
        print(f"error: {OutputError(f'--gears {gears_dir}: not a directory')}", file=sys.stderr)
        return EXIT_INPUT
    return run_command(args, _body, inputs=(gears_dir,))


def _body(args, design, run) -> int:
    """Read the gear files, drive them through the train, write into ``run.path``."""
    from plantmech.contact.outlines import GearFileError, read_gear_dxf
    from plantmech.kinds import kind_of

    gears_dir = Path(args.gears)
    out = run.path
    kind = kind_of(design)
    if not kind.has("verify_run"):
        print(f"error: {args.design}: field 'mechanism' = {design.mechanism!r}: 'plantmech "
              "verify' drives the sugarcane seeder's, the rice transplanters' and the general "
              "planetary trains", file=sys.stderr)
        return EXIT_INPUT
    try:
        names = tuple(kind.hook("verify_gears")(design))
    except ValueError as exc:
        print(f"error: {args.design}: {exc}", file=sys.stderr)
        return EXIT_INPUT
    try:
        gears = {n: read_gear_dxf(gears_dir / f"{n}.dxf", n) for n in names}
    except GearFileError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return EXIT_INPUT
    try:
        rec = kind.hook("verify_run")(args, design, gears, out)
    except ValueError as exc:  # the train cannot be built from the file
        where = f"[{kind.section}]: " if kind.section else ""
        print(f"error: {args.design}: {where}{exc}", file=sys.stderr)
        return EXIT_INPUT
    return _report(args, design, gears, gears_dir, run, rec, rec.pop("_loads"))


def seeder_gear_names(design) -> tuple[str, ...]:
    return SEEDER_GEARS


def transplanter_gear_names(design) -> tuple[str, ...]:
    return TRANSPLANTER_GEARS


def khv_gear_names(design) -> tuple[str, ...]:
    return KHV_GEARS


def _run_seeder(args, design, gears, out) -> dict:
    """The seeder's two pairs driven tooth on tooth (and their loads and plots)."""
    from plantmech.contact.seeder import analyse_seeder, seeder_record, seeder_train

    t0 = time.perf_counter()
    train = seeder_train(design)  # ValueError: [train]
    contact = analyse_seeder(train, gears, steps=args.steps)
    limits = _limits(args)
    rec = seeder_record(contact, train, limits)
    loads = None
    if not args.no_loads:
        from plantmech.contact.loads import seeder_loads
        from plantmech.mechanisms.seeder_forward import simulate

        spec = _load_spec(args, Path(args.gears))
        loads = _record_loads(
            rec, lambda: seeder_loads(train, simulate(train, samples=3600), gears, spec))
        _record_strength(rec, design, gears, loads, spec.face_width_mm, args.shaft_overhang)
    rec["wall_time_s"] = round(time.perf_counter() - t0, 3)
    files = []
    if not args.no_plots:
        from plantmech.outputs import verify_plots as vp

        vp.plot_transmission_error(out / "transmission_error.png", contact)
        vp.plot_tip_band(out / "tip_band.png", contact)
        files += ["transmission_error.png", "tip_band.png"]
        if loads is not None:
            vp.plot_loads(out / "loads.png", loads)
            files.append("loads.png")
    rec["files"] = files
    rec["_loads"] = loads
    return rec


def _limits(args) -> dict:
    """The verdict's limits from the command line (deg, deg, mm)."""
    return {"transmission_error_deg": args.max_te,
            "attitude_error_deg": args.max_attitude_error, "tip_band_mm": args.max_tip_band}


def _run_khv(args, design, gears, out) -> dict:
    """The K-H-V train: every arm's middle gear against the sun, its planet against the
    middle."""
    return _run_transplanter(args, design, gears, out, khv=True)


def _run_transplanter(args, design, gears, out, khv: bool = False) -> dict:
    """The differential transplanter (every arm's planet against the internal gear) or
    the K-H-V train (every arm's middle gear against the sun, its planet against the
    middle)."""
    from plantmech.contact.khv import analyse_khv, khv_record
    from plantmech.contact.transplanter import analyse_transplanter, transplanter_record

    t0 = time.perf_counter()
    contact = (analyse_khv if khv else analyse_transplanter)(design, gears, steps=args.steps)
    limits = _limits(args)
    rec = (khv_record if khv else transplanter_record)(contact, limits)
    loads = None
    if not args.no_loads:
        from plantmech.contact.transplanter_loads import differential_loads, khv_loads

        spec = _load_spec(args, Path(args.gears))
        loads = _record_loads(rec, lambda: (khv_loads if khv else differential_loads)(
            design, gears, spec))
        _record_strength(rec, design, gears, loads, spec.face_width_mm, args.shaft_overhang)
    rec["wall_time_s"] = round(time.perf_counter() - t0, 3)
    files = []
    if not args.no_plots:
        from plantmech.outputs import verify_plots as vp

        files = _arm_plots(out, contact, loads, vp.plot_khv_transmission_error if khv
                           else vp.plot_transplanter_transmission_error)
    rec["files"] = files
    rec["_loads"] = loads
    return rec


def _arm_plots(out: Path, contact, loads, plot_error) -> list[str]:
    """The plots of a train whose arms the analysis follows (the transplanters and the
    general train): transmission error (``plot_error``), tip band, loads."""
    from plantmech.outputs import verify_plots as vp

    plot_error(out / "transmission_error.png", contact)
    vp.plot_transplanter_tip_band(out / "tip_band.png", contact)
    files = ["transmission_error.png", "tip_band.png"]
    if loads is not None:
        vp.plot_transplanter_loads(out / "loads.png", loads,
                                   getattr(contact, "turning", "carrier"))
        files.append("loads.png")
    return files


def _run_planetary(args, design, gears, out) -> dict:
    """A general planetary train (``mechanism = "planetary"``): every pair of every arm
    tooth on tooth, chained to the arm, and its loads (``contact/planetary.py``)."""
    from plantmech.contact.planetary import (
        analyse_planetary,
        planetary_loads,
        planetary_record,
    )

    t0 = time.perf_counter()
    contact = analyse_planetary(design, gears, steps=args.steps)
    rec = planetary_record(contact, _limits(args))
    loads = None
    if not args.no_loads:
        spec = _load_spec(args, Path(args.gears))
        loads = _record_loads(rec, lambda: planetary_loads(design, gears, spec))
        _record_strength(rec, design, gears, loads, spec.face_width_mm, args.shaft_overhang)
    rec["wall_time_s"] = round(time.perf_counter() - t0, 3)
    files = []
    if not args.no_plots:
        from plantmech.outputs import verify_plots as vp

        files = _arm_plots(out, contact, loads, vp.plot_train_transmission_error)
    rec["files"] = files
    rec["_loads"] = loads
    return rec


def _record_loads(rec: dict, compute):
    """Run ``compute()`` (a loads dict) into ``rec``: the loads without their series, and
    the energy-balance check (< 1 %) in the checks and the verdict; a loads computation
    refused with a ValueError is recorded as skipped. Returns the loads (None if skipped)."""
    from plantmech.extras import MissingExtra, require
    from plantmech.objectives import Check

    try:
        require("loads", "the multibody loads")
    except MissingExtra as exc:  # the contact is checked; the verdict says what is missing
        note = f"not computed: {exc} (or --no-loads to leave them out)"
        rec["loads"] = {"not_computed": note}
        rec["checks"].append(Check("loads: energy balance error", None, "< 1", False, "%",
                                   note=note).as_dict())
        rec["ok"] = False
        return None
    try:
        loads = compute()
    except ValueError as exc:
        rec["loads"] = {"skipped": str(exc)}
        return None
    rec["loads"] = {k: v for k, v in loads.items() if k != "series"}
    err = loads["energy_balance"]["max_error_fraction_of_energy_range"]
    ch = Check("loads: energy balance error", 100 * err, "< 1", err < 0.01, "%")
    rec["checks"].append(ch.as_dict())
    rec["ok"] = rec["ok"] and ch.ok
    return loads


def _record_strength(rec: dict, design, gears, loads, face_width_mm: float,
                     overhang_mm: float | None = None) -> None:
    """The strength table (``contact/strength.py``) into ``rec`` and its safeties into the
    checks and the verdict; said "not computed" where there are no loads."""
    if loads is None:
        rec["strength"] = {"not_computed": "no loads (--no-loads, or the loads were skipped)"}
        return
    from plantmech.contact.strength import strength_record

    st = strength_record(design, gears, loads, face_width_mm, overhang_mm)
    rec["strength"] = st
    rec["checks"] += st["checks"]
    rec["ok"] = rec["ok"] and all(c["ok"] for c in st["checks"])


def _strength_lines(st: dict, who: str = "carrier") -> list[str]:
    """The printed strength table: per gear the root and flank stress and safety at the
    worst contact (arm, carrier angle, tooth; ``who``: the driver's angle with the carrier
    held); the shafts."""
    if "not_computed" in st:
        return [f"  strength not computed: {st['not_computed']}"]
    mat = st["material"]
    lines = [f"  strength ({st['method']}; {mat['label']}, K_A {st['rating']['K_A']:g}, "
             f"face width {st['face_width_mm']:g} mm):"]
    for g in st["gears"]:
        for kind in ("root", "flank"):
            w = g[kind]
            lines.append(
                f"    {'ok  ' if w['safety'] >= w['min_safety'] else 'FAIL'} {g['gear']:<9} "
                f"{kind:<5} {w['stress_MPa']:8.1f} MPa  safety {w['safety']:6.2f} (min "
                f"{w['min_safety']:g})  at arm {w['arm']}, {who} {w['carrier_angle_deg']:.1f}"
                f" deg, tooth {w['tooth'] or '-'} (replacement z {w['equivalent_teeth']:g}, F_t "
                f"{w['tangential_force_N']:.0f} N)")
    for why in st.get("not_rated", []):
        lines.append(f"    not rated: {why}")
    for sh in st["shafts"]:
        if "skipped" in sh:
            lines.append(f"    shaft of the {sh['gear']}: not checked ({sh['skipped']})")
            continue
        lines.append(
            f"    {'ok  ' if sh['ok'] else 'FAIL'} {sh['gear']} shaft d {sh['diameter_mm']:.1f}"
            f" mm: torque {sh['torque_N_m']:.2f} N m, torsion {sh['torsion_MPa']:.0f} MPa, "
            f"bending {sh['bending_MPa']:.0f} MPa, von Mises {sh['von_mises_MPa']:.0f} MPa, "
            f"safety {sh['safety']:.2f} (min {sh['min_safety']:g}), wall "
            f"{sh.get('wall_mm', float('nan')):.1f} mm; {st['shaft_overhang']['text']}")
    return lines


def _load_spec(args, gears_dir: Path):
    """The loads' inputs from the command line (face width: the gears' record's)."""
    from plantmech.contact.loads import LoadSpec

    return LoadSpec(density_kg_m3=args.density,
                    face_width_mm=args.face_width or _face_width(gears_dir),
                    arm_mass_kg=args.arm_mass, payload_kg=args.payload,
                    carrier_speed_deg_s=args.carrier_speed)


def _report(args, design, gears, gears_dir, run, rec, loads) -> int:
    """Write verification.json, print the figures, the checks, the caveats and the verdict
    (last, the same object as the record's ``verdict``); the exit code is the verdict's."""
    from plantmech.outputs.caveats import caveats, with_caveats
    from plantmech.outputs.files import check_line, write_json
    from plantmech.outputs.verdict import verdict, verdict_line

    out = run.path
    rec["design"] = str(args.design)
    rec["gears_dir"] = str(gears_dir)
    rec["teeth_found_on_outlines"] = {n: g.teeth for n, g in gears.items()}
    files = ["verification.json"] + rec["files"]
    rec["files"] = files
    # the record's ok is every check's; the verdict is built from the same checks once
    v = rec["verdict"] = verdict(rec["checks"], problems=[] if rec["ok"] or not all(
        c["ok"] for c in rec["checks"]) else ["tooth-contact verification"])
    not_run = ("loads not checked (--no-loads)" if args.no_loads else
               f"loads not checked ({rec['loads']['skipped']})" if "skipped" in rec.get(
                   "loads", {}) else "")
    if not_run:
        rec["not_checked"] = [not_run]
    rec["caveats"] = caveats(design, rec["checks"])
    st = rec.get("strength", {})
    arm = st.get("shaft_overhang")
    bent = any("skipped" not in sh for sh in st.get("shafts", []))  # a shaft was checked
    if bent and arm["source"] != "file":  # the file's: a limit_from_file caveat
        rec["caveats"].append({"kind": "assumption" if arm["source"] == "default"
                               else "option", "field": "shaft_overhang_mm",
                               "value": arm["mm"], "text": arm["text"]})
    with_caveats(v, rec["caveats"])  # the verdict carries what it rests on
    write_json(out / "verification.json", rec)
    print(f"{design.name}: tooth-contact verification, {rec['steps']} steps "
          f"({rec['step_deg']:.2f} deg), {rec['wall_time_s']:.1f} s")
    # the word of every angle: the carrier's turn, or the driver's where the carrier is held
    # (the frame of a pair on fixed centres: nothing turns there)
    who = rec.get("angles_of", "carrier")
    if "carrier" in rec:
        print(f"  carrier {rec['carrier']}")
    for p in rec["pairs"]:
        te, bl = p["transmission_error_deg"], p["backlash_band_deg"]
        print(f"  {p['pair']}: transmission error max |mid| "
              + ("n/a" if te["max_abs_mid"] is None else f"{te['max_abs_mid']:.4f} deg"
                 + _where(te.get("max_abs_mid_at"), who))
              + ", backlash band "
              + ("n/a" if bl["median"] is None else
                 f"{bl['min']:.4f}-{bl['max']:.4f} deg (median {bl['median']:.4f})")
              + f", contact lost {p['contact_lost_steps']} steps, "
              f"interference {p['interference_steps']} steps")
        for s in (p["contact_lost"] + p["interference"])[:4]:
            print(f"      at {who} {s['carrier_angle_deg'][0]:.1f}-"
                  f"{s['carrier_angle_deg'][1]:.1f} deg: "
                  + ", ".join(f"{k} {v}" for k, v in s.items()
                              if k not in ("carrier_angle_deg", "steps")))
    if "dwell" in rec:
        d = rec["dwell"]
        gear = d.get("held_gear", "gear 2")  # a planetary train's record names its gear
        print(f"  dwell at {who} {d['carrier_angle_deg'][0]:.1f}-"
              f"{d['carrier_angle_deg'][1]:.1f} deg: {gear} held {d['locked_steps']} of "
              f"{d['steps']} steps, jammed {d['jammed_steps']} steps"
              + "".join(f", at {who} {j['carrier_angle_deg'][0]:.1f}-"
                        f"{j['carrier_angle_deg'][1]:.1f} deg ({gear} tooth "
                        f"{j.get('gear2_tooth', j.get('tooth'))})" for j in d["jammed"][:3]))
    if loads is not None:
        tq = loads["input_torque_N_m"]
        per_input = "".join(f", {k} {v['min']:.2f} to {v['max']:.2f}" for k, v in tq.items()
                            if isinstance(v, dict))
        per_input += "".join(f", {k} holding the fixed centres {v['min']:.2f} to "
                             f"{v['max']:.2f} (no input)"
                             for k, v in loads.get("holding_torque_N_m", {}).items())
        forces = ", ".join(f"{v:.0f} N ({k.removesuffix('_max').replace('_', '-')})"
                           for k, v in loads["tangential_tooth_force_N"].items())
        speed = f"{args.carrier_speed:g} deg/s" + ("" if who == "carrier" else f" of the {who}")
        print(f"  loads at {speed} ({loads['model'].split(':')[0]}): "
              f"input torque {tq['min']:.2f} to {tq['max']:.2f} N m{per_input}; "
              f"tangential tooth force up to {forces}")
        for imp in loads.get("dwell_impacts", []):
            print(f"    dwell impact at {who} {imp['carrier_angle_deg']:.2f} deg (rigid model): "
                  f"kinetic energy {imp['kinetic_energy_jump_J']:+.3f} J, drive work "
                  f"{imp['drive_work_J']:+.3f} J, peak input torque "
                  f"{imp['peak_input_torque_N_m']:.1f} N m")
    elif "loads" in rec:
        print(f"  loads skipped: {rec['loads']['skipped']}" if "skipped" in rec["loads"]
              else f"  loads {rec['loads']['not_computed']}")
    if "strength" in rec:
        for line in _strength_lines(rec["strength"], who):
            print(line)
    for c in rec["checks"]:
        print(check_line(c, 40, 4))
    print("wrote: " + ", ".join(str(run.final(out / f)) for f in files))
    print(verdict_line(v, "the gear files drive the train within every limit"
                       + (f"; {not_run}" if not_run else ""), rec["caveats"]))
    return v["exit_code"]


def _where(at: dict | None, who: str = "carrier") -> str:
    """' (at carrier X deg, <gear> tooth N)' for a located figure, else '' (``who``: what
    the angle turns, the driver with the carrier held)."""
    if not at:
        return ""
    tooth = next((f"{k[:-6]} tooth {v}" for k, v in at.items() if k.endswith("_tooth")), "")
    return f" (at {who} {at['carrier_angle_deg']:.1f} deg, {tooth})"


def _face_width(gears_dir: Path) -> float:
    """The face width the gears were written with (their verification.json), else 12 mm."""
    import math

    from plantmech.inputs import read_input_json

    try:  # read bounded: a FIFO or a device there is no record (never a hang)
        rec = read_input_json(gears_dir / "verification.json", "gears record", 64_000_000, 32)
        width = float(rec["face_width_mm"])
    except (ValueError, KeyError, TypeError):
        return 12.0
    return width if math.isfinite(width) and 0 < width <= 1000 else 12.0
