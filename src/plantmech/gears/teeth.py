"""Teeth of non-circular gears by simulated cutting (seed 001, Eq. 11-18 in spirit):
a cutter rolls without slip along the pitch curve and its swept teeth are subtracted from
the blank (shapely Booleans) — a rack where the curve is convex everywhere (external
gears), a pinion-shaped (shaper) cutter for internal gears and curves with concave spans.

Conventions: a pitch curve is a closed polyline (mm) around its gear's rotation centre
at the origin, counter-clockwise; s is arc length from its first point; n(s) the unit
normal pointing away from the centre side (outward for a convex curve). Module m,
pressure angle alpha, addendum ha m, dedendum hf m (defaults 1.0, 1.25). Backlash is a
circumferential allowance per gear: each gear's teeth are thinned by half of it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from plantmech.gears.modules import FIRST_SERIES

TWO_PI = 2.0 * np.pi


@dataclass
class ToothSpec:
    module: float
    pressure_angle_deg: float = 20.0
    addendum: float = 1.0  # x m
    dedendum: float = 1.25  # x m
    backlash_mm: float = 0.0  # circumferential, per pair
    cutter_teeth: int = 20  # the shaper's
    cutter: str = "shaper"  # "shaper" or "rack" (``fit_cutter`` chooses)
    # "envelope": rack-cut teeth from the envelope condition (gears/envelope.py);
    # "simulated": every gear by the Boolean cut of its cutter's positions (the reference)
    method: str = "envelope"

    @property
    def alpha(self) -> float:
        return np.radians(self.pressure_angle_deg)

    @property
    def pitch(self) -> float:
        return np.pi * self.module


def inv(a):
    return np.tan(a) - a


def teeth_count(perimeter: float, module: float, multiple: int = 1) -> tuple[int, float]:
    """Whole number of teeth z (a multiple of ``multiple``, e.g. per lobe) closest to
    perimeter / (pi m), and the exact module perimeter / (pi z) that makes the closed
    curve carry z whole teeth."""
    z = max(multiple, int(round(perimeter / (np.pi * module) / multiple)) * multiple)
    return z, perimeter / (np.pi * z)


MIN_TEETH, MAX_TEETH = 6, 500  # a gear outside these is refused before any cutting


def check_tooth_counts(module: float, perimeters: dict, source: str = "--module") -> None:
    """Refuse a module that leaves any gear with fewer than ``MIN_TEETH`` or more than
    ``MAX_TEETH`` teeth (a 1-tooth "gear", or minutes of cutting and gigabytes for
    thousands of teeth). ``perimeters``: gear name -> pitch-curve perimeter (mm);
    ``source``: where the module came from, for the message. Raises ValueError naming the
    gear, its tooth count and the module."""
    for name, perimeter in perimeters.items():
        z = perimeter / (np.pi * module)
        if not MIN_TEETH <= round(z) <= MAX_TEETH:
            lo, hi = perimeter / (np.pi * MAX_TEETH), perimeter / (np.pi * MIN_TEETH)
            raise ValueError(
                f"{source}: module {module:.4g} mm leaves gear {name} (pitch perimeter "
                f"{perimeter:.1f} mm) with {z:.4g} teeth; gears are cut with "
                f"{MIN_TEETH}..{MAX_TEETH} teeth: choose a module between {lo:.3g} and "
                f"{hi:.3g} mm for it")


def standard_module(perimeter: float, min_teeth: int = 12, multiple: int = 1) -> float:
    """The largest ISO 54 series-I module (``gears.modules``) that leaves at least
    ``min_teeth`` teeth."""
    ok = [m for m in FIRST_SERIES if perimeter / (np.pi * m) >= min_teeth]
    return max(ok) if ok else FIRST_SERIES[0]


def involute_tooth(rp: float, m: float, alpha: float, ha: float, hf: float,
                   thickness: float, n_flank: int = 12) -> np.ndarray:
    """One involute tooth of a spur gear with pitch radius rp, centred on angle 0: points
    (K, 2) from the root at -half a pitch angle, up the right flank, over the tip, down
    the left flank to the root at +half a pitch angle. ``thickness``: tooth thickness on
    the pitch circle (mm)."""
    rb = rp * np.cos(alpha)
    ra, rf = rp + ha * m, rp - hf * m
    half_pitch = np.pi * m / (2 * rp)  # angle of half a pitch
    r0 = max(rb, rf)
    r = np.linspace(r0, ra, n_flank)
    a_r = np.arccos(np.clip(rb / r, -1.0, 1.0))
    psi = thickness / (2 * rp) + inv(alpha) - inv(a_r)  # half tooth angle at r
    psi = np.minimum(psi, half_pitch)
    right = np.c_[r * np.cos(-psi), r * np.sin(-psi)]
    left = np.c_[r * np.cos(psi), r * np.sin(psi)][::-1]
    tip_a = np.linspace(-psi[-1], psi[-1], 5)[1:-1]
    tip = np.c_[ra * np.cos(tip_a), ra * np.sin(tip_a)]
    root_r = np.c_[rf * np.cos(-half_pitch), rf * np.sin(-half_pitch)]
    root_l = np.c_[rf * np.cos(half_pitch), rf * np.sin(half_pitch)]
    pts = [root_r]
    if rf < r0:  # radial flank below the base circle
        pts.append(np.c_[rf * np.cos(-psi[0]), rf * np.sin(-psi[0])])
    pts += [right, tip, left]
    if rf < r0:
        pts.append(np.c_[rf * np.cos(psi[0]), rf * np.sin(psi[0])])
    pts.append(root_l)
    return np.vstack(pts)


def spur_gear_polygon(z: int, spec: ToothSpec, thickness: float | None = None,
                      ha: float | None = None, hf: float | None = None):
    """A whole involute spur gear (shapely Polygon) centred at the origin."""
    import shapely

    m = spec.module
    rp = m * z / 2
    t = np.pi * m / 2 if thickness is None else thickness
    tooth = involute_tooth(rp, m, spec.alpha, spec.addendum if ha is None else ha,
                           spec.dedendum if hf is None else hf, t)
    z_c = tooth[:, 0] + 1j * tooth[:, 1]
    ring = np.concatenate([z_c * np.exp(1j * TWO_PI * k / z) for k in range(z)])
    return shapely.Polygon(np.c_[ring.real, ring.imag]).buffer(0)


@dataclass
class PitchPolyline:
    """A closed pitch curve sampled as a polyline around the origin (CCW)."""

    xy: np.ndarray  # (N, 2)

    @classmethod
    def from_polar(cls, theta, r, samples: int = 4000) -> PitchPolyline:
        """From a closed polar curve sampled at increasing angles over one turn."""
        from plantmech.geometry.periodic import RadiusCurve

        th = np.mod(np.asarray(theta, float), TWO_PI)
        rr = np.asarray(r, float)
        order = np.argsort(th, kind="stable")
        th, rr = th[order], rr[order]
        keep = np.r_[True, np.diff(th) > 1e-9]  # a curve swept more than once: one copy
        th, rr = th[keep], rr[keep]
        if TWO_PI - th[-1] + th[0] <= 1e-9:
            th, rr = th[:-1], rr[:-1]
        # a periodic cubic spline, so the polyline's vertices lie on a smooth curve
        curve = RadiusCurve.from_samples(th, rr, kind="spline", theta0=0.0)
        grid = np.linspace(0.0, TWO_PI, samples, endpoint=False)
        rg = curve(grid)
        return cls(np.c_[rg * np.cos(grid), rg * np.sin(grid)])

    @property
    def seg(self):
        return np.roll(self.xy, -1, axis=0) - self.xy

    @property
    def perimeter(self) -> float:
        return float(np.hypot(*self.seg.T).sum())

    def at(self, s: np.ndarray):
        """Points, unit tangents and outward normals at arc lengths s (mm)."""
        seg = self.seg
        ln = np.hypot(*seg.T)
        cum = np.r_[0.0, np.cumsum(ln)]
        s = np.mod(s, cum[-1])
        k = np.clip(np.searchsorted(cum, s, side="right") - 1, 0, len(ln) - 1)
        f = (s - cum[k]) / ln[k]
        p = self.xy[k] + f[:, None] * seg[k]
        # tangent from a centred difference over neighbouring segments (smooth normals)
        t = seg[k] / ln[k, None] + seg[(k + 1) % len(ln)] / ln[(k + 1) % len(ln), None] * f[
            :, None] + seg[k - 1] / ln[k - 1, None] * (1 - f[:, None])
        t = t / np.hypot(*t.T)[:, None]
        n = np.c_[t[:, 1], -t[:, 0]]  # right of the CCW tangent: outward
        return p, t, n


def cut_gear(pitch: PitchPolyline, spec: ToothSpec, internal: bool = False,
             tooth_at: float = 0.0, rim: float = 8.0, bore: float | None = None,
             steps_per_pitch: int = 12, toothless: tuple[float, float] | None = None):
    """The gear of ``cut_gear_made`` (the polygon alone)."""
    return cut_gear_made(pitch, spec, internal, tooth_at, rim, bore, steps_per_pitch,
                         toothless)[0]


def cut_gear_made(pitch: PitchPolyline, spec: ToothSpec, internal: bool = False,
                  tooth_at: float = 0.0, rim: float = 8.0, bore: float | None = None,
                  steps_per_pitch: int = 12, toothless: tuple[float, float] | None = None):
    """Generate a gear by rolling the shaper cutter (or the rack) along ``pitch``; returns
    (polygon, made) where ``made`` says how its teeth were made: {"method": "envelope" or
    "simulated", "cutter": "rack" or "shaper", "why": why a gear asked for by the envelope
    was simulated, else None}.

    ``spec.method == "envelope"``: the teeth come from the envelope condition of the meshing
    equation (gears/envelope.py: the rack on a convex curve, the shaper where its cutter
    fits every concave span, the curve carries whole teeth and each space's cut is held by
    its window); anything else falls back to simulation and says why.

    External: the cutter rolls outside, the blank is the pitch curve grown by the
    addendum. Internal: the cutter rolls inside, the blank is the ring between the pitch
    curve shrunk by the addendum and grown by dedendum + ``rim``. ``tooth_at`` (mm of
    arc): where a tooth of the gear is centred (teeth repeat every pitch pi m; a partial
    gear's teeth are evenly spaced along its meshing arc). ``toothless``: arc-length
    interval (mm) left uncut; an external gear's toothless sector is turned down to the
    root curve. Returns a shapely Polygon with the bore as a hole.
    """
    import shapely

    if spec.cutter not in ("shaper", "rack"):
        raise ValueError(f"cutter must be 'shaper' or 'rack', not {spec.cutter!r}")
    if spec.method not in ("envelope", "simulated"):
        raise ValueError(f"method must be 'envelope' or 'simulated', not {spec.method!r}")
    if spec.cutter == "rack" and internal:
        raise ValueError("a rack cannot cut an internal gear: use the shaper")
    m, zc = spec.module, spec.cutter_teeth
    rc = m * zc / 2
    P = pitch.perimeter
    # cutter: teeth thicker by half the backlash so the gear's teeth are thinner by it
    tooth = involute_tooth(rc, m, spec.alpha, spec.dedendum, spec.addendum + 0.05,
                           np.pi * m / 2 + spec.backlash_mm / 2)
    wedge = np.vstack([[0.0, 0.0], tooth])
    wz = wedge[:, 0] + 1j * wedge[:, 1]
    pitch_angle = TWO_PI / zc
    n_pos = int(np.ceil(P / spec.pitch * steps_per_pitch))
    s = np.linspace(0.0, P, n_pos, endpoint=False)
    if toothless is not None:
        a, b = toothless
        keep = ~((np.mod(s - a, P)) <= np.mod(b - a, P))
        s = s[keep]
    p, tangent, n = pitch.at(s)
    nz = n[:, 0] + 1j * n[:, 1]
    pz = p[:, 0] + 1j * p[:, 1]
    sign = -1.0 if internal else 1.0
    centre = pz + sign * rc * nz
    face = np.angle(-sign * nz)  # direction from the cutter centre to the contact
    # rolling without slip: the cutter's body angle at the contact moves by -/+ s / rc
    # (external / internal); a cutter space faces the contact where the gear gets a tooth
    s_eff, t_eff = s, tooth_at
    if toothless is not None:
        # a partial gear's teeth are evenly spaced along its meshing arc: run the rolling
        # parameter continuously over that arc, with the wrap inside the toothless gap
        b0 = toothless[1]
        s_eff = b0 + np.mod(s - b0, P)
        t_eff = b0 + np.mod(tooth_at - b0, P)
    base = shapely.Polygon(pitch.xy)
    if internal:
        inner = base.buffer(-spec.addendum * m, join_style="round")
        outer = base.buffer((spec.dedendum + 0.25) * m + rim, join_style="round")
        blank = outer.difference(inner)
    else:
        blank = base.buffer(spec.addendum * m, join_style="round")
    made = {"method": "simulated", "cutter": spec.cutter, "why": None}
    polys = None
    if spec.method == "envelope":
        if spec.cutter == "rack" and not _convex(pitch):
            made["why"] = "a rack on a pitch curve with concave spans (its other teeth gouge)"
        elif spec.cutter == "rack":
            polys = _rack_envelope(pitch, spec, t_eff, toothless)
        else:
            from plantmech.gears.envelope import ShaperEnvelopeUnfit

            try:
                polys = _shaper_envelope(pitch, spec, t_eff, toothless, blank, internal)
            except ShaperEnvelopeUnfit as e:
                made["why"] = str(e)
        if polys is not None:
            made["method"] = "envelope"
    if polys is not None:
        pass
    elif spec.cutter == "rack":
        polys = _rack_teeth(spec, pz, tangent, n, s_eff, t_eff)
    else:
        beta = 0.5 * pitch_angle - sign * (s_eff - t_eff) / rc
        rot = face - beta  # absolute orientation of the cutter's body frame
        # only the cutter teeth within +-3 pitches of the contact can touch the blank
        k0 = np.round(beta / pitch_angle)
        ang = rot[:, None] + (k0[:, None] + np.arange(-3, 4)[None, :]) * pitch_angle
        pts = centre[:, None, None] + np.exp(1j * ang)[:, :, None] * wz[None, None, :]
        polys = shapely.polygons(np.stack([pts.real, pts.imag], -1).reshape(-1, len(wz), 2))
    sweep = shapely.union_all(shapely.make_valid(polys))
    gear = blank.difference(sweep)
    if not internal:
        if toothless is not None:
            gear = gear.difference(_toothless_wedge(pitch, toothless, base, spec))
        if bore:
            gear = gear.difference(shapely.Point(0, 0).buffer(bore / 2, 64))
    gear = _largest(gear)
    return gear, made


def _space_centres(P: float, p: float, t_eff: float,
                   toothless: tuple[float, float] | None) -> np.ndarray:
    """Arc (mm) of the centre of every tooth space of a gear with a tooth at ``t_eff``
    (pitch ``p``, perimeter ``P``): every space of a closed gear; on a partial gear, the
    spaces whose centres lie on its meshing arc (from the toothless arc's end round to
    its start)."""
    if toothless is None:
        z = max(1, int(round(P / p)))
        return t_eff + p / 2 + p * np.arange(z)
    a0, b0 = toothless
    arc = P - np.mod(b0 - a0, P)  # the meshing arc, from b0 on
    k0 = np.ceil((b0 - (t_eff + p / 2)) / p)
    centres = t_eff + p / 2 + p * np.arange(k0, k0 + int(np.ceil(P / p)) + 1)
    return centres[(centres >= b0) & (centres <= b0 + arc)]


def _shaper_envelope(pitch: PitchPolyline, spec: ToothSpec, t_eff: float,
                     toothless: tuple[float, float] | None, blank, internal: bool):
    """The tooth spaces the shaper cuts, by the envelope (``envelope.shaper_space_polygons``),
    after the checks that make it the whole cut: the shaper fits every concave span (else
    its neighbouring teeth gouge, which only the simulated cut shows) and a closed curve
    carries whole teeth (else the simulated cutter's phase jumps at the seam).
    Raises envelope.ShaperEnvelopeUnfit saying which failed."""
    from plantmech.gears.envelope import ShaperEnvelopeUnfit, shaper_space_polygons

    rc = spec.module * spec.cutter_teeth / 2
    rho = smooth_curvature(pitch, internal)[1]
    concave = -rho[np.isfinite(rho) & (rho < 0)]
    if len(concave) and concave.min() <= rc:
        raise ShaperEnvelopeUnfit(f"a concave span's radius of curvature "
                                  f"{concave.min():.3f} mm is below the shaper's pitch "
                                  f"radius {rc:.3f} mm (its other teeth gouge)")
    P, p = pitch.perimeter, spec.pitch
    if toothless is None and abs(P / p - round(P / p)) > 1e-3:
        raise ShaperEnvelopeUnfit(f"the pitch curve carries {P / p:.4f} teeth, not a whole "
                                  "number")
    centres = _space_centres(P, p, t_eff, toothless)
    return shaper_space_polygons(pitch, spec, centres, blank, internal)


def _convex(pitch: PitchPolyline) -> bool:
    """Whether the pitch curve is convex everywhere (``smooth_curvature``): only there is a
    rack's envelope its whole cut (on a concave span the rack's other teeth gouge the
    flanks: such a curve is cut by simulation, which shows it)."""
    rho = smooth_curvature(pitch)[1]
    return bool(np.all(~np.isfinite(rho) | (rho > 0)))


def _rack_envelope(pitch: PitchPolyline, spec: ToothSpec, t_eff: float,
                   toothless: tuple[float, float] | None):
    """The tooth spaces the rack generates (``envelope.rack_space_polygons``), centred at
    t_eff + pitch / 2 + k pitch (mm of arc): every space of a closed gear; on a partial
    gear, the spaces whose centres lie on its meshing arc (from the toothless arc's end
    round to its start)."""
    from plantmech.gears.envelope import rack_space_polygons

    P, p = pitch.perimeter, spec.pitch
    if toothless is None:
        z = max(1, int(round(P / p)))
        centres = t_eff + p / 2 + p * np.arange(z)
    else:
        a0, b0 = toothless
        arc = P - np.mod(b0 - a0, P)  # the meshing arc, from b0 on
        k0 = np.ceil((b0 - (t_eff + p / 2)) / p)
        centres = t_eff + p / 2 + p * np.arange(k0, k0 + int(np.ceil(P / p)) + 1)
        centres = centres[(centres >= b0) & (centres <= b0 + arc)]
    flank, fillet, _ = rack_space_polygons(pitch, spec, centres)
    return np.r_[flank, fillet]


def _rack_teeth(spec: ToothSpec, pz, tangent, n, s_eff, t_eff):
    """The rack's teeth at every station: its pitch line along the unit ``tangent`` of
    the pitch curve at the contact pz (complex, mm) with normal n, rolled without slip,
    so the rack coordinate sigma (mm) sits at sigma - s along the tangent; a rack tooth
    (straight flanks at the pressure angle, thicker by half the backlash) fills every
    space of the gear, centred at t_eff + pitch / 2 + k pitch, from the root (dedendum)
    to beyond the tip."""
    import shapely

    m, pitch = spec.module, spec.pitch
    half = (pitch / 2 + spec.backlash_mm / 2) / 2  # half thickness on the pitch line
    v = np.array([-spec.dedendum, -spec.dedendum, spec.addendum + 0.05,
                  spec.addendum + 0.05]) * m
    u = np.array([-1, 1, 1, -1]) * (half + v * np.tan(spec.alpha))
    k0 = np.round((s_eff - t_eff - pitch / 2) / pitch)
    centre = t_eff + pitch / 2 + (k0[:, None] + np.arange(-3, 4)[None, :]) * pitch
    off = centre - s_eff[:, None]  # (S, 7): tooth centres along the tangent
    tz = tangent[:, 0] + 1j * tangent[:, 1]
    nz = n[:, 0] + 1j * n[:, 1]
    pts = (pz[:, None, None] + tz[:, None, None] * (off[:, :, None] + u[None, None, :])
           + nz[:, None, None] * v[None, None, :])
    return shapely.polygons(np.stack([pts.real, pts.imag], -1).reshape(-1, 4, 2))


def _toothless_wedge(pitch: PitchPolyline, toothless: tuple[float, float], base, spec):
    """Material to remove so a partial gear's toothless arc (mm of arc) is turned down
    to the root curve (a plain locking arc)."""
    import shapely

    a0, b0 = toothless
    q, _, _ = pitch.at(np.array([a0, b0]))
    big = 10 * np.hypot(*pitch.xy.T).max()
    # the sector between the arc's two ends, swept the way the pitch curve runs (its
    # orientation): the polar angles of the points in between need not be monotone
    # (the closing span of a partial gear's polyline can wander), and a wedge drawn
    # through them crossed itself (fuzz cases 4071, 4161, 4475: GEOS side location
    # conflict)
    sense = 1.0 if shapely.LinearRing(pitch.xy).is_ccw else -1.0
    ang0, ang1 = np.arctan2(q[:, 1], q[:, 0])
    sweep = np.mod(sense * (ang1 - ang0), 2 * np.pi)
    ang = ang0 + sense * np.linspace(0.0, sweep, 64)
    wedge = shapely.Polygon(np.vstack([[0.0, 0.0], np.c_[big * np.cos(ang),
                                                          big * np.sin(ang)]]))
    root = base.buffer(-spec.dedendum * spec.module, join_style="round")
    return wedge.difference(root)


def _largest(geom):
    """The largest polygon of a (multi)polygon, cleaned of Boolean debris: zero-width
    spikes and slits and holes under 0.01 mm^2 removed (``outline.clean_outline``)."""
    from plantmech.gears.outline import clean_outline

    return clean_outline(geom)


@dataclass
class GearPair:
    """Two pitch curves in mesh and their teeth. Gear A turns phi_A (body angle of its
    contact, 0..2 pi), gear B's contact is at phi_B(phi_A); B's centre at (a, 0) for an
    external pair, at (-a, 0)... see ``placed``."""

    name: str
    pitch_a: PitchPolyline
    pitch_b: PitchPolyline
    phi_a: np.ndarray  # contact body angles of A over a cycle (rad)
    phi_b: np.ndarray  # matching contact body angles of B (rad)
    a: float
    internal: bool  # True: A is the internal gear, B the planet inside it
    teeth_a: int
    teeth_b: int
    module: float
    r_a: np.ndarray  # A's contact radius at phi_a (mm)
    gear_a: object = None  # shapely polygons
    gear_b: object = None


def polar_contacts(theta_a, r_a, a: float, internal: bool, turn_b: float | None = None):
    """Rolling partner of a polar pitch curve (theta_a increasing over one turn of A):
    contact body angles of B and its radii (external: r_b = a - r_a, B turns the other
    way; internal: r_b = r_a - a, same way)."""
    th = np.asarray(theta_a, float)
    r = np.asarray(r_a, float)
    rb = r - a if internal else a - r
    rate = r / rb
    dphi = np.r_[0.0, np.cumsum(0.5 * (rate[1:] + rate[:-1]) * np.diff(th))]
    return (dphi if internal else -dphi), rb


def fit_cutter(spec: ToothSpec, *pitches: PitchPolyline, internal_first: bool = False,
               largest: int = 20, smallest: int = 8) -> ToothSpec:
    """The cutter for the curves it must cut: a rack where every curve is convex and
    external (the hob or rack of gear shops; it generates the teeth of the basic rack
    exactly), otherwise the shaper with the most teeth (<= ``largest``) whose pitch
    radius is below every concave radius of curvature (a rack or a big cutter would gouge
    concave spans); at least ``smallest`` teeth."""
    from dataclasses import replace

    limit = np.inf
    for i, p in enumerate(pitches):
        rho = smooth_curvature(p, internal_first and i == 0)[1]
        concave = -rho[np.isfinite(rho) & (rho < 0)]
        if len(concave):
            limit = min(limit, float(concave.min()))
    if not np.isfinite(limit) and not internal_first:
        return replace(spec, cutter="rack")
    zc = int(np.clip(np.floor(2 * limit / spec.module) - 1, smallest, largest)) \
        if np.isfinite(limit) else largest
    return replace(spec, cutter_teeth=zc, cutter="shaper")


def with_locking_arc(phi, r):
    """A partial pitch curve (contact angles ``phi`` (rad) sweeping less than a turn, radii
    ``r`` (mm)) closed over the arc its mate never rolls on (seed 000's toothless sector,
    theta_1): the radius runs linearly from the rolling arc's end back to its start.

    In seed 000's intermittent train the ratio law jumps at the dwell ends, so the sun's
    radius differs at the two ends (the dwell example: 30.1 and 49.3 mm; gear 2's radius
    steps at its lock point) and no circle about the centre joins them without radial
    steps; the linear run is the smooth closing, turned down to the root as the toothless
    arc. Without it the periodic spline through the rolling arc alone swings across the
    gap (the 360-sample dwell sun went through the centre and out to 600 mm). Returns
    (angles, radii) with the closing arc's points appended."""
    phi = np.asarray(phi, float)
    r = np.asarray(r, float)
    sense = 1.0 if phi[-1] >= phi[0] else -1.0
    gap = TWO_PI - abs(phi[-1] - phi[0])
    step = float(np.median(np.abs(np.diff(phi))))
    n = max(2, int(np.ceil(gap / max(step, 1e-9))))
    k = np.arange(1, n) / n
    return np.r_[phi, phi[-1] + sense * gap * k], np.r_[r, r[-1] + (r[0] - r[-1]) * k]


def make_pair(name: str, theta_a, r_a, a: float, spec: ToothSpec, internal: bool = False,
              samples: int = 3000, rim: float = 8.0, bore_a: float | None = None,
              bore_b: float | None = None, gear_a=None, pitch_a: PitchPolyline | None = None,
              tooth_at_a: float | None = None,
              mate_envelope: bool | None = None) -> GearPair:
    """Pitch curves and generated teeth of a closed pair; tooth counts from the
    perimeters (they must carry whole teeth at ``spec.module``). The shaper is sized to
    the concave spans (``fit_cutter``).

    By default A gets a tooth at its contact at the start (body angle theta_a[0]) and B a
    space. A gear A already cut for another mesh (a K-H-V middle gear) is passed as
    ``gear_a``/``pitch_a`` with ``tooth_at_a`` (arc, mm, of one of its tooth centres);
    B is then phased to it: a tooth of A delta ahead of the contact meets a space of B
    delta ahead of B's contact (each along its own direction of contact motion).

    ``mate_envelope``: how a B generated by A's cut teeth is made (``envelope_cut_made``):
    by default (None) or True from the envelope condition (an internal pair's within the
    simulated cut's reach, ``envelope.MateReach``); False: simulated.
    Where the envelope cannot stand for the cut (its self-check fails, ...) B is cut by
    simulation; ``pair.made_b`` says which and why."""
    th = np.asarray(theta_a, float)
    r = np.asarray(r_a, float)
    phib, rb = polar_contacts(th, r, a, internal)
    pa = PitchPolyline.from_polar(th, r, samples) if pitch_a is None else pitch_a
    span = abs(phib[-1] - phib[0])
    partial = span < TWO_PI * (1 - 1e-4) and abs(span / TWO_PI - round(span / TWO_PI)) > 1e-4
    pb = PitchPolyline.from_polar(*(with_locking_arc(phib, rb) if partial else (phib, rb)),
                                  samples)
    # the cutter cuts A (B is A's envelope), or B alone when A was cut for another mesh
    spec = fit_cutter(spec, pa, internal_first=internal) if gear_a is None else \
        fit_cutter(spec, pb)
    za = pa.perimeter / spec.pitch
    sa = _arc_to_angle(pa, th[0])
    sb = _arc_to_angle(pb, phib[0])
    delta = 0.0 if tooth_at_a is None else tooth_at_a - sa
    made_a = None  # how A's teeth were made (``cut_gear_made``); None: cut for another mesh
    if gear_a is None:
        gear_a, made_a = cut_gear_made(pa, spec, internal=internal, tooth_at=sa + delta,
                                       rim=rim, bore=bore_a)
    # B's contact runs along decreasing arc for an external pair, increasing for internal
    sb_tooth = sb + (delta if internal else -delta)
    toothless = None
    if partial:
        # B turns less than once while A turns once (a toothless sector on B, e.g. the
        # seeder's sun): leave the arc B's contact never visits uncut
        end = _arc_to_angle(pb, phib[-1])
        # the contact sweeps from sb to end; the arc it never visits lies beyond them
        toothless = (sb, end) if phib[-1] < phib[0] else (end, sb)
        toothless = (toothless[0] + spec.pitch / 2, toothless[1] - spec.pitch / 2)
    # a rack-cut A whose mate B is convex too: B by the envelope of the same rack (Olivier's
    # principle: two gears generated by one tool in the motion the three pitch curves share,
    # rolling at the pitch point, are conjugate), phased so a space of B meets A's tooth
    # — when both curves carry whole teeth (else the odd tooth at A's seam would meet B's
    # teeth elsewhere: B is then A's envelope, which follows A's seam)
    whole = abs(za - round(za)) < 1e-3 and (
        toothless is not None or abs(pb.perimeter / spec.pitch
                                     - round(pb.perimeter / spec.pitch)) < 1e-3)
    b_by_rack = (tooth_at_a is None and spec.method == "envelope" and spec.cutter == "rack"
                 and not internal and whole and fit_cutter(spec, pb).cutter == "rack")
    if b_by_rack:
        gear_b, made_b = cut_gear_made(pb, spec, internal=False,
                                       tooth_at=sb_tooth + spec.pitch / 2, rim=rim,
                                       bore=bore_b, toothless=toothless)
    elif tooth_at_a is None:
        # B is generated by A itself (its envelope), so the pair is exactly conjugate: two
        # shaper-cut gears have their cutters on opposite sides of the pitch point and are
        # conjugate only where the curvature is constant (docs/conventions.md)
        gear_b, made_b = envelope_cut_made(pa, pb, th, r, phib, a, spec,
                                           tooth_at=sa + delta, internal=internal, rim=rim,
                                           bore=bore_b, toothless=toothless,
                                           mate_envelope=mate_envelope)
    else:
        gear_b, made_b = cut_gear_made(pb, spec, internal=False,
                                       tooth_at=sb_tooth + spec.pitch / 2, rim=rim,
                                       bore=bore_b, toothless=toothless)
    zb = (pb.perimeter - (np.mod(toothless[1] - toothless[0], pb.perimeter) + spec.pitch
                          if toothless else 0.0)) / spec.pitch
    pair = GearPair(name, pa, pb, th, phib, a, internal, int(round(za)), int(round(zb)),
                    spec.module, r, gear_a=gear_a, gear_b=gear_b)
    pair.spec = spec
    # B is A's envelope (not cut by the cutter)
    pair.b_cut_by_a = tooth_at_a is None and not b_by_rack
    pair.tooth_at_b = sb_tooth + spec.pitch / 2
    pair.made_a, pair.made_b = made_a, made_b
    return pair


def envelope_cut(pitch_ring: PitchPolyline, pitch_planet: PitchPolyline, theta_ring,
                 r_ring, phi_planet, a: float, spec: ToothSpec, tooth_at: float,
                 internal: bool = True, rim: float = 8.0, bore: float | None = None,
                 toothless: tuple[float, float] | None = None, steps_per_pitch: int = 24):
    """The gear of ``envelope_cut_made`` (the polygon alone)."""
    return envelope_cut_made(pitch_ring, pitch_planet, theta_ring, r_ring, phi_planet, a,
                             spec, tooth_at, internal, rim, bore, toothless,
                             steps_per_pitch)[0]


def envelope_cut_made(pitch_ring: PitchPolyline, pitch_planet: PitchPolyline, theta_ring,
                      r_ring, phi_planet, a: float, spec: ToothSpec, tooth_at: float,
                      internal: bool = True, rim: float = 8.0, bore: float | None = None,
                      toothless: tuple[float, float] | None = None,
                      steps_per_pitch: int = 24, mate_envelope: bool | None = None):
    """Gear B of a pair cut by gear A (here "ring" = A, "planet" = B; A is internal or
    external): a generating A (A's shaper-cut teeth, thicker by the backlash and longer by
    the clearance) is rolled through the cycle by the pitch curves' law, and every
    position near the contact is removed from B's blank (pitch curve grown by the
    addendum). B is the envelope of A's teeth, hence conjugate to them wherever it is not
    undercut. ``theta_ring``/``phi_planet``: contact body angles over the cycle (rad),
    ``r_ring``: A's contact radius there (mm);
    ``toothless``: B's arc (mm) the contact never visits, turned down to the root.

    ``mate_envelope`` True or None (the default), with ``spec.method == "envelope"``: B
    comes from the envelope condition of the meshing equation
    (``envelope.mate_space_polygons``; it checks itself: A's outline at the motion's
    positions must stay out of B's material); inside a ring within the simulated cut's
    reach exactly (``envelope.MateReach``: A's pieces of one pitch, each whole while its
    middle is within 3 pitches and half a piece of the contact; docs/validation.md: the
    mesh check must see the ring's teeth that foul away from the pitch point). Where it
    cannot stand for the cut (``envelope.MateEnvelopeUnfit``, the reason recorded), with
    ``mate_envelope=False`` and with ``spec.method == "simulated"``, A's teeth at stations
    ``steps_per_pitch`` per pitch of relative motion are united (the simulated cut, the
    tests' reference).
    Returns (polygon, made): made = {"method": "envelope" or "simulated", "cutter":
    "mate", "why": why (a fallback's reason, or that B is the Boolean cut of A's
    positions)}."""
    from dataclasses import replace

    import shapely

    m = spec.module
    tool = cut_gear(pitch_ring, replace(spec, addendum=spec.dedendum,
                                        backlash_mm=-spec.backlash_mm),
                    internal=internal, tooth_at=tooth_at, rim=rim)
    base = shapely.Polygon(pitch_planet.xy)
    blank = base.buffer(spec.addendum * m, join_style="round")
    depth = (spec.dedendum + 0.35) * m
    made = {"method": "simulated", "cutter": "mate",
            "why": "generated by its mate's cut teeth (Boolean cut of their positions)"}
    gear = None
    if (mate_envelope or mate_envelope is None) and spec.method == "envelope":
        from plantmech.gears.envelope import (
            MateEnvelopeUnfit,
            MateMotion,
            MateReach,
            mate_space_polygons,
        )

        try:
            if np.any(np.asarray(r_ring) <= 0) or np.any(np.hypot(*pitch_ring.xy.T) <= 0):
                raise MateEnvelopeUnfit("A's pitch curve reaches its centre")
            motion = MateMotion(pitch_ring, theta_ring, phi_planet, a, internal,
                                periodic=toothless is None)
            # inside a ring, the simulated cut's reach exactly (its pieces of A, each
            # whole within 3 pitches): the mesh check must see the teeth that foul away
            # from the pitch point (docs/validation.md)
            reach = MateReach.of(pitch_ring.perimeter, spec.pitch) if internal else None
            gear = mate_space_polygons(tool, motion, blank, m, depth, reach=reach)
            made["method"], made["why"] = "envelope", None
        except MateEnvelopeUnfit as e:
            made["why"] = str(e)
    if gear is None:
        gear = blank.difference(_mate_simulated_sweep(
            tool, pitch_ring, theta_ring, r_ring, phi_planet, a, spec, internal, toothless,
            steps_per_pitch, depth))
    if toothless is not None:
        gear = gear.difference(_toothless_wedge(pitch_planet, toothless, base, spec))
    if bore:
        gear = gear.difference(shapely.Point(0, 0).buffer(bore / 2, 64))
    return _largest(gear), made


def _mate_simulated_sweep(tool, pitch_ring, theta_ring, r_ring, phi_planet, a, spec,
                          internal, toothless, steps_per_pitch, depth):
    """The region the generating A (``tool``) sweeps over B's frame: the union of its teeth
    near the contact at stations ``steps_per_pitch`` per pitch of relative motion (the
    simulated cut, ``envelope_cut_made``'s reference)."""
    import shapely

    # stations spaced by the relative motion (arc rolled or turn of B against A,
    # whichever is faster), so fast-turning spans near cusps are cut as finely as the rest;
    # a partial B (toothless) also gets the cycle's last position
    ta, tb, _ = motion_stations(theta_ring, phi_planet, r_ring, spec.module,
                                spacing=spec.pitch / steps_per_pitch,
                                endpoint=toothless is not None, pressure_angle=spec.alpha)
    # only the band within the tool's tooth depth (and a margin) of its pitch curve can
    # reach B's blank near the contact; the body below it would only slow the union.
    # The ring's teeth within 3 pitches (of arc) of the contact: pieces cut once, chosen
    # per station, turned into the mesh frame (by -theta_A), shifted by -a and turned by
    # phi_B (internal) or phi_B - pi (external: B faces A across the line of centres,
    # see ``placed``) into B's body frame
    base_a = shapely.Polygon(pitch_ring.xy)
    band = base_a.buffer(depth, join_style="round").difference(
        base_a.buffer(-depth, join_style="round"))
    pieces, centres, plen = _pieces(tool.intersection(band), pitch_ring, spec.pitch)
    sel, owner = _near(centres, plen, _arc_of_angle(pitch_ring, ta), 3 * spec.pitch,
                       pitch_ring.perimeter)
    turn = tb if internal else tb - np.pi
    ring = _turn_each(_turn_each(pieces[sel], -ta[owner], dx=-a), turn[owner])
    return shapely.union_all(shapely.make_valid(ring))


def _pieces(gear, pitch: PitchPolyline, length: float):
    """``gear`` (polygon, mm) cut into wedges from its centre, one per ``length`` of arc
    of its pitch curve (about one tooth each). Returns (pieces, arc of each wedge's middle
    (mm), wedge arc (mm))."""
    import shapely

    P = pitch.perimeter
    n = max(8, int(round(P / length)))
    plen = P / n
    q, _, _ = pitch.at(np.arange(n + 1) * plen)
    ang = np.unwrap(np.arctan2(q[:, 1], q[:, 0]))
    big = 10.0 * (np.hypot(*pitch.xy.T).max() + 10.0 * length)
    f = np.linspace(0.0, 1.0, 5)
    rays = ang[:-1, None] + f[None, :] * np.diff(ang)[:, None]  # (n, 5)
    ring = np.stack([big * np.cos(rays), big * np.sin(rays)], -1)
    wedges = shapely.polygons(np.concatenate([np.zeros((n, 1, 2)), ring], axis=1))
    pieces = shapely.intersection(gear, wedges)
    return pieces, (np.arange(n) + 0.5) * plen, plen


def _arc_of_angle(pitch: PitchPolyline, angles) -> np.ndarray:
    """Arc length (mm) from the polyline's first point to its points at polar ``angles``
    (the curve is star-shaped about its centre)."""
    ang = np.unwrap(np.arctan2(pitch.xy[:, 1], pitch.xy[:, 0]))
    cum = np.r_[0.0, np.cumsum(np.hypot(*pitch.seg.T))]
    x = np.mod(np.asarray(angles, float) - ang[0], TWO_PI) + ang[0]
    return np.interp(x, np.r_[ang, ang[0] + TWO_PI], cum)


def _near(centres, plen: float, s, half: float, perimeter: float):
    """Indices of the pieces within ``half`` mm of arc of each station's arc ``s`` (cyclic)
    and, for each, the station it belongs to."""
    n = len(centres)
    k = int(np.ceil(half / plen)) + 1
    j = np.round((np.asarray(s)[:, None] - centres[0]) / plen).astype(int) + np.arange(-k, k + 1)
    j = np.mod(j, n)
    d = np.abs(np.mod(centres[j] - np.asarray(s)[:, None] + perimeter / 2, perimeter)
               - perimeter / 2)
    keep = d <= half + plen / 2
    owner = np.broadcast_to(np.arange(len(s))[:, None], j.shape)
    return j[keep], owner[keep]


def motion_stations(phi_a, phi_b, r_a, module: float, count: int | None = None,
                    spacing: float | None = None, endpoint: bool = False,
                    pressure_angle: float = np.radians(20.0)):
    """Positions of a pair over its cycle spaced evenly in relative motion: per sample
    the larger of the arc rolled on A (mm) and 3 modules times the turn of B relative to
    A (rad; a tooth three modules from the contact moves that far), divided by the cosine
    of the working pressure angle alpha + atan(|dr/dphi| / r) (alpha: the tool's
    ``pressure_angle``, rad; floored at 0.1: a steep flank keeps only that share of the
    backlash as normal clearance). ``count`` stations, or as many as ``spacing`` (mm)
    needs. Returns (phi_a, phi_b, r_a) at the stations."""
    pa, pb, ra = (np.asarray(x, float) for x in (phi_a, phi_b, r_a))
    dr, along = np.diff(ra), 0.5 * (ra[1:] + ra[:-1]) * np.diff(pa)  # mm per sample
    ds = np.hypot(along, dr)
    turn = np.abs(np.diff(pb) - np.diff(pa))
    # a flank at working pressure angle alpha_w keeps only cos(alpha_w) of the backlash
    # as normal clearance: denser where the pitch curve is steep
    steep = np.cos(pressure_angle + np.arctan(np.abs(dr) / np.maximum(np.abs(along), 1e-12)))
    u = np.r_[0.0, np.cumsum(np.maximum(ds, 3.0 * module * turn)
                             / np.maximum(steep, 0.1))]
    if count is None:
        count = int(np.ceil(u[-1] / spacing)) + (1 if endpoint else 0)
    at = np.interp(np.linspace(0.0, u[-1], count, endpoint=endpoint), u, np.arange(len(u)))
    k = np.arange(len(u))
    return np.interp(at, k, pa), np.interp(at, k, pb), np.interp(at, k, ra)


def _arc_to_angle(pitch: PitchPolyline, angle: float) -> float:
    """Arc length (mm) from the polyline's first point to its point at polar ``angle``."""
    k = int(np.argmin(np.abs(np.angle(np.exp(1j * (np.arctan2(pitch.xy[:, 1], pitch.xy[:, 0])
                                                       - angle))))))
    ln = np.hypot(*pitch.seg.T)
    return float(np.r_[0.0, np.cumsum(ln)][k])


def placed(pair: GearPair, phi_a: float, phi_b: float):
    """Both toothed outlines in the mesh frame for contact body angles phi_a, phi_b:
    A at the origin with its contact direction along +x; B at (a, 0) with its contact
    along -x (external), or B at (a, 0) inside A with its contact along +x (internal)."""
    import shapely
    from shapely import affinity

    ga = affinity.rotate(pair.gear_a, -phi_a, origin=(0, 0), use_radians=True)
    if pair.internal:
        gb = affinity.rotate(pair.gear_b, -phi_b, origin=(0, 0), use_radians=True)
        gb = affinity.translate(gb, xoff=pair.a)
    else:
        gb = affinity.rotate(pair.gear_b, np.pi - phi_b, origin=(0, 0), use_radians=True)
        gb = affinity.translate(gb, xoff=pair.a)
    return shapely.make_valid(ga), shapely.make_valid(gb)


def _turn_each(geoms, angles, dx: float = 0.0):
    """Each geometry of ``geoms`` (T,) turned about the origin by its angle (T,), then
    shifted by dx along x (one vectorised coordinate transform)."""
    import shapely

    counts = shapely.get_num_coordinates(geoms)
    c, s_ = np.repeat(np.cos(angles), counts), np.repeat(np.sin(angles), counts)

    def f(xy):
        x, y = xy[:, 0], xy[:, 1]
        return np.c_[c * x - s_ * y + dx, s_ * x + c * y]

    return shapely.transform(geoms, f)


def _turned_bounds(geom, angles):
    """The bounds (4, T): (xmin, ymin, xmax, ymax) of ``geom`` turned about the origin by
    each of ``angles`` (T,), as ``_turn_each`` would place it (the same arithmetic) without
    making the T geometries."""
    import shapely

    x, y = shapely.get_coordinates(geom).T
    c, s_ = np.cos(angles)[:, None], np.sin(angles)[:, None]
    px, py = c * x - s_ * y + 0.0, s_ * x + c * y
    return np.array([px.min(1), py.min(1), px.max(1), py.max(1)])


def _safe_intersection(a, b, grid):
    import shapely

    try:
        return shapely.intersection(a, b, grid_size=grid)
    except shapely.errors.GEOSException:
        return shapely.intersection(a.buffer(1e-4), b.buffer(1e-4))


def mesh_check(pair: GearPair, steps: int = 720, window_pitches: float = 5.0) -> dict:
    """Turn the toothed gears through a full cycle by the pitch curves' rolling law and
    measure, at every step, overlap (interference) and the gap between the outlines,
    inside a window of +-``window_pitches`` pitches around the line of centres (external
    pairs) or over the planet's whole reach (internal pairs).
    Interference depth is estimated per overlap sliver as 2 x area / perimeter (a thin
    sliver), the deepest counting. Backlash as a designer means it: the circumferential
    free play (mm) on B's pitch curve, B's turn between its two flank contacts with A held
    times B's pitch radius at the contact, min and max over the cycle; beside it the normal
    gap (mm), the smallest distance between the outlines' boundaries within 2.5 pitches of
    the contact point (about play / 2 x cos alpha at the nominal position)."""
    import shapely
    import shapely.affinity

    pa, pb, r_contact = motion_stations(pair.phi_a, pair.phi_b, pair.r_a, pair.module,
                                        count=steps, endpoint=True,
                                        pressure_angle=pair.spec.alpha)
    turn_b = -pb if pair.internal else np.pi - pb
    if pair.internal:
        # the planet may touch the ring anywhere around it (far-side tip interference when
        # the tooth counts are close): the window is the planet's whole reach
        r_b = np.hypot(*pair.pitch_b.xy.T)
        window = shapely.Point(pair.a, 0.0).buffer(r_b.max() + 2 * pair.module, 128)
    else:
        r_pitch = np.hypot(*pair.pitch_a.xy.T)
        h = window_pitches * np.pi * pair.module
        window = shapely.box(r_pitch.min() - 3 * pair.module, -h,
                             r_pitch.max() + 3 * pair.module, h)
    grid = 1e-4  # mm: snap rounding keeps the overlays robust on cut outlines
    # clip each gear in its own body frame (the window turned back), then place the small
    # clipped parts: cheaper than turning and repairing the whole outline at every step
    T = len(pa)
    body_a, body_b = shapely.buffer(pair.gear_a, 0), shapely.buffer(pair.gear_b, 0)
    if pair.internal:
        wa = _turn_each(np.full(T, window), pa)
        ga = _turn_each(shapely.buffer(_clip_to_windows(body_a, wa, grid), 0), -pa)
        # the window is a polygon about B's centre: every turned copy of it holds the disc
        # of its inradius, so a gear within that disc is its own clipped part at every
        # station (no overlay to make, one repair)
        inradius = shapely.distance(shapely.Point(pair.a, 0.0), shapely.boundary(window))
        if np.hypot(*shapely.get_coordinates(body_b).T).max() < inradius - 1e-6:
            gb = _turn_each(np.full(T, shapely.buffer(body_b, 0)), turn_b, dx=pair.a)
        else:
            wb = _turn_each(np.full(T, shapely.affinity.translate(window, xoff=-pair.a)),
                            -turn_b)
            gb = _turn_each(shapely.buffer(_clip_to_windows(body_b, wb, grid), 0), turn_b,
                            dx=pair.a)
    else:
        # the window is a rectangle in the mesh frame: place the whole outlines (one
        # vectorised coordinate transform) and clip them by it (GEOS rectangle clipping,
        # one pass over the vertices; no overlay)
        # (first by the window's bounding box in each body frame, so that only the small
        # parts near the window are placed)
        box = shapely.bounds(window)
        wa = _turned_bounds(window, pa)
        wb = _turned_bounds(shapely.affinity.translate(window, xoff=-pair.a), -turn_b)
        ga = shapely.buffer(shapely.clip_by_rect(
            _turn_each(_clip_each(body_a, wa), -pa), *box), 0)
        gb = shapely.buffer(shapely.clip_by_rect(
            _turn_each(_clip_each(body_b, wb), turn_b, dx=pair.a), *box), 0)
    # only the stations whose outlines meet can overlap (the exact predicate on A's
    # prepared outlines first): the others have no overlay to make
    shapely.prepare(ga)
    meet = shapely.intersects(ga, gb)
    inter = np.full(T, shapely.Polygon(), dtype=object)
    try:
        inter[meet] = shapely.intersection(ga[meet], gb[meet], grid_size=grid)
    except shapely.errors.GEOSException:  # one bad step must not sink the whole check
        inter[meet] = [_safe_intersection(x, y, grid)
                       for x, y in zip(ga[meet], gb[meet], strict=True)]
    area = shapely.area(inter)
    # each overlap sliver on its own (one per fouling flank): depth 2 x area / perimeter
    parts, owner = shapely.get_parts(inter, return_index=True)
    pa_, pl_ = shapely.area(parts), shapely.length(parts)
    depth = np.zeros(len(inter))
    np.maximum.at(depth, owner, np.where(pa_ > 1e-6, 2 * pa_ / np.maximum(pl_, 1e-9), 0.0))
    # the gap between the outlines within 2.5 pitches of the contact point (the teeth in
    # and about to come into mesh), where there is no overlap
    free = area <= 1e-6
    gap = np.full(len(inter), np.nan)
    discs = shapely.buffer(shapely.points(r_contact[free], np.zeros(free.sum())),
                           2.5 * np.pi * pair.module, quad_segs=16)
    gap[free] = shapely.distance(
        _in_chunks(shapely.intersection(shapely.boundary(ga[free]), discs)),
        _in_chunks(shapely.intersection(shapely.boundary(gb[free]), discs)))
    # circumferential free play: B turned about its centre each way from its nominal
    # position until its flanks touch A's; (turn forward + turn back) x B's pitch radius at
    # the contact (external a - r_A, internal r_A - a)
    # (stations where the outlines overlap have no free play: the interference check
    # speaks for them)
    r_b = np.abs(pair.a - r_contact)
    play = np.full(len(inter), np.nan)
    near = _ContactSplit(ga[free], gb[free], pair.a, pair.module)
    play[free] = r_b[free] * (
        _turn_to_contact(ga[free], gb[free], pair.a, r_b[free], pair.module, +1, split=near)
        + _turn_to_contact(ga[free], gb[free], pair.a, r_b[free], pair.module, -1,
                           split=near))
    worst = int(np.argmax(depth))
    lo = int(np.nanargmin(play)) if free.any() else None
    hi = int(np.nanargmax(play)) if free.any() else None
    return {"pair": pair.name, "max_interference_mm": float(depth.max()),
            "worst_at_contact_angle_deg": float(np.degrees(pa[worst])) if depth.max() > 0
            else None,
            "backlash_stations": int(free.sum()),
            "min_circumferential_backlash_mm": None if lo is None else float(play[lo]),
            "min_circumferential_backlash_at_deg": None if lo is None
            else float(np.degrees(pa[lo])),
            "max_circumferential_backlash_mm": None if hi is None else float(play[hi]),
            "max_circumferential_backlash_at_deg": None if hi is None
            else float(np.degrees(pa[hi])),
            # the names readers of this record used before (the app): now the free play
            "min_backlash_mm": None if lo is None else float(play[lo]),
            "max_backlash_mm": None if hi is None else float(play[hi]),
            "max_normal_gap_mm": float(np.nanmax(gap)) if free.any() else None,
            "min_normal_gap_mm": float(np.nanmin(gap)) if free.any() else None,
            "ok": bool(depth.max() < 0.01 * pair.module), "steps": steps}


def _in_chunks(lines, size: int = 8):
    """Each (multi)linestring of ``lines`` (T,) as a multilinestring of pieces of ``size``
    segments (the same points: a piece ends where the next begins). GEOS's distance
    compares two linestrings segment by segment but skips a pair of linestrings whose
    boxes are farther apart than the best distance so far: in pieces, only the pieces
    near each other are compared. Anything but (multi)linestrings is left as it is."""
    import shapely

    lines = np.asarray(lines, dtype=object)
    kind = shapely.get_type_id(lines)
    ok = np.isin(kind, (1, 5)) & ~shapely.is_empty(lines)
    out = lines.copy()
    if not ok.any():
        return out
    parts, station = shapely.get_parts(lines[ok], return_index=True)
    xy, part = shapely.get_coordinates(parts, return_index=True)
    n = np.bincount(part, minlength=len(parts))  # vertices per part (>= 2)
    first = np.r_[0, np.cumsum(n)[:-1]]
    chunks = np.maximum(1, np.ceil((n - 1) / size).astype(int))
    chunk_part = np.repeat(np.arange(len(parts)), chunks)
    k = np.arange(len(chunk_part)) - np.repeat(np.r_[0, np.cumsum(chunks)[:-1]], chunks)
    lo = first[chunk_part] + k * size
    hi = np.minimum(lo + size, first[chunk_part] + n[chunk_part] - 1)
    cnt = hi - lo + 1
    idx = np.repeat(lo, cnt) + np.arange(cnt.sum()) - np.repeat(np.cumsum(cnt) - cnt, cnt)
    # (built from the flat coordinates and offsets in one call: pieces per station)
    per_station = np.bincount(station[chunk_part], minlength=int(ok.sum()))
    out[np.nonzero(ok)[0]] = shapely.from_ragged_array(
        shapely.GeometryType.MULTILINESTRING, xy[idx],
        (np.r_[0, np.cumsum(cnt)], np.r_[0, np.cumsum(per_station)]))
    return out


def _clip_each(body, bounds):
    """``body`` clipped by each rectangle of ``bounds`` (4, T): (xmin, ymin, xmax, ymax),
    mm, grown by 1 mm (GEOS rectangle clipping takes one rectangle at a time)."""
    import shapely

    out = np.empty(bounds.shape[1], dtype=object)
    for k, (x0, y0, x1, y1) in enumerate(bounds.T):
        out[k] = shapely.clip_by_rect(body, x0 - 1.0, y0 - 1.0, x1 + 1.0, y1 + 1.0)
    return out


def _clip_to_windows(body, windows, grid: float):
    """``body`` (polygon, mm) intersected with each window of ``windows`` (T,): first the
    body's part in the window's bounding box grown by 1 mm (GEOS rectangle clipping, one
    pass over the vertices), then the overlay with the window in floating point (the
    body's vertices kept as they are; on the ``grid`` (mm) where floating point fails)."""
    import shapely

    out = np.empty(len(windows), dtype=object)
    for k, (w, (x0, y0, x1, y1)) in enumerate(zip(windows, shapely.bounds(windows),
                                                  strict=True)):
        near = shapely.clip_by_rect(body, x0 - 1.0, y0 - 1.0, x1 + 1.0, y1 + 1.0)
        try:
            out[k] = shapely.intersection(near, w)
        except shapely.errors.GEOSException:
            out[k] = shapely.intersection(body, w, grid_size=grid)
    return out


class _ContactSplit:
    """The placed outlines of a pair (mesh frame, per station) cut at the lines
    y = +-h about the line of centres: the inner parts (the teeth in mesh and their
    neighbours) and, per station, whether every other part stays more than ``tau`` = 0.1
    module (mm) from the other gear (``certain``). B (centre at (centre_x, 0)) turned by
    theta moves no point farther than rho_max x theta (rho_max: B's farthest point from
    its centre, mm), so while rho_max x theta <= tau, A and the turned B meet exactly when
    their inner parts do (``_turn_to_contact``). h is the first of ``pitches`` (x the
    circular pitch) that makes a station certain: 1.5 pitches (about a third of an
    external pair's window) suffice for most; the longer contact of an internal pair needs
    more. A station where no h does, or where the cut fails, keeps its whole outlines as
    "inner" parts (not ``certain``: every answer is then the whole outlines'). The cores
    (``ga_core``, ``gb_core``): the inner parts within y = +-``core`` pitches."""

    def __init__(self, ga, gb, centre_x: float, module: float,
                 pitches: tuple[float, ...] = (1.5, 2.5, 4.0), core: float = 0.5):
        import shapely

        self.tau = 0.1 * module
        n = len(ga)
        self.ga_in = np.asarray(ga, dtype=object).copy()
        self.gb_in = np.asarray(gb, dtype=object).copy()
        self.certain = np.zeros(n, bool)
        self.rho_max = np.zeros(n)
        self.ga_core, self.gb_core = self.ga_in.copy(), self.gb_in.copy()
        if n == 0:
            return
        xy = shapely.get_coordinates(gb)
        owner = np.repeat(np.arange(n), shapely.get_num_coordinates(gb))
        np.maximum.at(self.rho_max, owner, np.hypot(xy[:, 0] - centre_x, xy[:, 1]))
        ga, gb = np.asarray(ga, dtype=object), np.asarray(gb, dtype=object)
        shapely.prepare(ga)
        # B's parts more than 1 mm left of every A (an internal pair's planet: its far
        # side) are outer parts too
        x0 = float(shapely.bounds(ga)[:, 0].min()) - 1.0
        if not x0 > shapely.bounds(gb)[:, 0].min():
            x0 = None
        for p in pitches:
            k = np.flatnonzero(~self.certain)
            if len(k) == 0:
                break
            a_in, b_in, certain = self._cut(ga[k], gb[k], p * np.pi * module, x0)
            k = k[certain]
            self.ga_in[k], self.gb_in[k] = a_in[certain], b_in[certain]
            self.certain[k] = True
        # the cores: the inner parts within y = +-``core`` pitches (the tooth pair at the
        # contact), subsets whose meeting is a meeting of the whole (``_turn_to_contact``)
        w, big = core * np.pi * module, 1e7
        self.ga_core = shapely.clip_by_rect(self.ga_in, -big, -w, big, w)
        self.gb_core = shapely.clip_by_rect(self.gb_in, -big, -w, big, w)

    def _cut(self, ga, gb, h: float, x0: float | None = None):
        """(A's inner parts, B's inner parts, certain) of the stations ``ga``, ``gb``
        (A's prepared) cut at y = +-``h`` (mm) and, when given, at x = ``x0`` (mm; the
        inner parts on its right)."""
        import shapely

        n, big = len(ga), 1e7
        left = -big if x0 is None else x0
        strip = shapely.box(left, -h, big, h)
        # the inner parts exactly (a robust overlay, near the strip only); a station where
        # it fails keeps its whole outlines
        a_in, b_in = np.empty(n, dtype=object), np.empty(n, dtype=object)
        cut = np.ones(n, bool)
        for src, dst in ((ga, a_in), (gb, b_in)):
            near = shapely.clip_by_rect(src, left - 1, -h - 1, big, h + 1)
            try:
                dst[:] = shapely.intersection(near, strip)
            except shapely.errors.GEOSException:
                for k in range(n):
                    try:
                        dst[k] = shapely.intersection(near[k], strip)
                    except shapely.errors.GEOSException:
                        cut[k] = False
        # the outer parts only bound distances: rectangle clipping keeps every piece of
        # the outline beyond the lines (it may add edges along them: a smaller distance,
        # never a larger one). Distances to prepared geometries (indexed facets)
        near = np.zeros(n, bool)
        outer = [(-big, h, big, big), (-big, -big, big, -h)]
        if x0 is not None:
            outer.append((-big, -big, x0, big))
        for rect in outer:
            a_out = shapely.clip_by_rect(ga, *rect)
            b_out = shapely.clip_by_rect(gb, *rect)
            shapely.prepare(a_out)
            near |= shapely.dwithin(ga, b_out, self.tau)
            near[cut] |= shapely.dwithin(a_out[cut], b_in[cut], self.tau)
        return a_in, b_in, cut & ~near


class _Turner:
    """Geometries (T,) turned about (centre_x, 0), each by its own angle, again and again:
    the coordinates are read once (``turned`` builds the new geometries from them)."""

    def __init__(self, geoms, centre_x: float):
        import shapely

        self.geoms = np.asarray(geoms, dtype=object)
        self.cx = centre_x
        self.counts = shapely.get_num_coordinates(self.geoms)
        xy = shapely.get_coordinates(self.geoms)
        self.x, self.y = xy[:, 0] - centre_x, xy[:, 1] - 0.0
        self.out = np.empty((len(xy), 2))

    def turned(self, angles, which=None):
        """The geometries (those where ``which``, a mask) turned by ``angles`` (T,) rad."""
        import shapely

        x, y, geoms, counts, out = self.x, self.y, self.geoms, self.counts, self.out
        if which is not None:
            keep = np.repeat(which, counts)
            x, y, geoms, counts = x[keep], y[keep], geoms[which], counts[which]
            out, angles = out[: len(x)], angles[which]
        c, s_ = np.repeat(np.cos(angles), counts), np.repeat(np.sin(angles), counts)
        out[:, 0] = c * x - s_ * y + self.cx
        out[:, 1] = s_ * x + c * y
        return shapely.set_coordinates(geoms.copy(), out)


def _turn_to_contact(ga, gb, centre_x: float, r_b, module: float, sense: int,
                     resolution: float = 1e-4, split: _ContactSplit | None = None):
    """Angle (rad, >= 0, per station) by which B (placed outlines ``gb``, centre at
    (centre_x, 0)) turns about its centre in ``sense`` (+1 counter-clockwise, -1
    clockwise) before it touches A (``ga``), found by bisection to ``resolution`` mm of
    arc at B's pitch radius ``r_b`` (mm, per station); capped at one pitch of arc.

    Each bisection step asks whether A and the turned B meet. With ``split``
    (``_ContactSplit`` of the same outlines) it asks the cores (the tooth pair at the
    contact), then the inner parts near the contact where the cores do not meet: a
    meeting there is a meeting of the whole; no meeting there is the answer
    where the turn moves no point of B farther than the other parts' clearance; the
    remaining stations are asked on the whole outlines. The answers, hence the angles,
    are the whole outlines'."""
    import shapely

    ga = np.asarray(ga, dtype=object)
    shapely.prepare(ga)
    whole_b = _Turner(gb, centre_x)
    if split is not None:
        ga_in = split.ga_in
        shapely.prepare(ga_in)
        inner_b = _Turner(split.gb_in, centre_x)
        shapely.prepare(split.ga_core)
        core_b = _Turner(split.gb_core, centre_x)
    lo = np.zeros(len(ga))
    hi = np.full(len(ga), np.pi * module) / r_b
    for _ in range(int(np.ceil(np.log2(np.pi * module / resolution)))):
        mid = 0.5 * (lo + hi)
        if split is None:
            hit = shapely.intersects(ga, whole_b.turned(sense * mid))
        else:
            # the cores first (parts of the inner parts: a meeting of theirs is one of the
            # whole; they answer most meetings at a third of the vertices)
            hit = shapely.intersects(split.ga_core, core_b.turned(sense * mid))
            rest = ~hit
            if rest.any():
                hit[rest] = shapely.intersects(ga_in[rest],
                                               inner_b.turned(sense * mid, rest))
            # (an uncertain station's inner parts are its whole outlines: answered)
            whole = ~hit & split.certain & (split.rho_max * mid > split.tau)
            if whole.any():
                hit[whole] = shapely.intersects(ga[whole],
                                                whole_b.turned(sense * mid, whole))
        hi = np.where(hit, mid, hi)
        lo = np.where(hit, lo, mid)
    return 0.5 * (lo + hi)


def smooth_curvature(pitch: PitchPolyline, internal: bool = False, samples: int = 2880):
    """(body angles, signed radius of curvature (mm, positive where the gear's material
    side is convex), r, dr/dtheta) of the smooth periodic spline through the outline's
    vertices in polar form (the polyline's own vertex curvature is noise)."""
    from plantmech.geometry.periodic import RadiusCurve

    xy = pitch.xy[:: max(1, len(pitch.xy) // 1440)]
    curve = RadiusCurve.from_samples(np.arctan2(xy[:, 1], xy[:, 0]), np.hypot(*xy.T),
                                     kind="spline", theta0=0.0)
    tt = np.linspace(0.0, TWO_PI, samples, endpoint=False)
    r0, r1, r2 = curve(tt), curve(tt, 1), curve(tt, 2)
    den = r0**2 + 2 * r1**2 - r0 * r2
    with np.errstate(divide="ignore"):
        rho = np.where(den == 0, np.inf, (r0**2 + r1**2) ** 1.5 / den)
    return tt, (-rho if internal else rho), r0, r1


def gear_checks(name: str, pitch: PitchPolyline, spec: ToothSpec, teeth: int,
                internal: bool = False, cut_by: str | None = None) -> dict:
    """Checks of one generated gear from its pitch curve (equivalent-spur-gear rules):

    - radius of curvature: smallest convex and concave values; a concave span is cut
      correctly only if the shaper's pitch radius is smaller than its radius of
      curvature (``cutter_fits``);
    - undercut: where the equivalent spur gear z_eq = 2 rho / m of a convex span has
      fewer teeth than 2 ha / sin^2(alpha) (17.1 at 20 deg, rack limit);
    - pointed: where the equivalent gear's top land is below 0.2 m;
    - working pressure angle: alpha + atan(|dr/dtheta| / r) about the gear centre.
    For an internal gear the material lies outside the pitch curve, so its concave spans
    (seen from the centre) play the role of convex ones. ``cut_by``: the gear whose
    envelope this one is (its mate's teeth are the cutter; no cutter-fit question).
    """
    m, alpha = spec.module, spec.alpha
    tt, rho, r0, r1 = smooth_curvature(pitch, internal)
    convex = np.isfinite(rho) & (rho > 0)
    concave = np.isfinite(rho) & (rho < 0)
    z_lim = 2 * spec.addendum / np.sin(alpha) ** 2
    z_eq = np.where(convex, 2 * rho / m, np.inf)
    undercut = z_eq < z_lim
    d = m * z_eq
    with np.errstate(invalid="ignore", divide="ignore"):
        da = d + 2 * spec.addendum * m
        aa = np.arccos(np.clip(d * np.cos(alpha) / da, -1, 1))
        top = da * (np.pi / (2 * np.where(np.isfinite(z_eq), z_eq, 1e9)) + inv(alpha) - inv(aa))
    pointed = convex & (top < 0.2 * m)
    rc = m * spec.cutter_teeth / 2 if spec.cutter == "shaper" and cut_by is None else np.inf
    min_concave = float(-rho[concave].max()) if concave.any() else None
    press = np.degrees(alpha + np.arctan(np.abs(r1) / r0))
    ang = np.degrees(tt)
    return {
        "name": name,
        "teeth": int(teeth),
        "module_mm": float(m),
        "perimeter_mm": float(pitch.perimeter),
        "internal": internal,
        "min_curvature_radius_mm": float(np.abs(rho[np.isfinite(rho)]).min()),
        "min_convex_curvature_radius_mm": float(rho[convex].min()) if convex.any() else None,
        "min_concave_curvature_radius_mm": min_concave,
        "cutter": spec.cutter if cut_by is None else f"envelope of {cut_by}",
        "cutter_pitch_radius_mm": float(rc) if np.isfinite(rc) else None,
        "cutter_fits": bool(cut_by is not None or min_concave is None or min_concave > rc),
        "undercut": bool(undercut.any()),
        "undercut_at_deg": _spans(ang, undercut),
        "pointed": bool(pointed.any()),
        "pointed_at_deg": _spans(ang, pointed),
        "max_pressure_angle_deg": float(press.max()),
        "max_pressure_angle_at_deg": float(ang[int(np.argmax(press))]),
        "undercut_limit_teeth": float(z_lim),
        "min_equivalent_teeth": float(z_eq.min()) if convex.any() else None,
        "min_equivalent_teeth_at_deg": float(ang[int(np.argmin(z_eq))]) if convex.any()
        else None,
        "min_equivalent_top_land_mm": float(np.nanmin(np.where(convex, top, np.nan)))
        if convex.any() else None,
        "min_equivalent_top_land_at_deg": float(ang[int(np.nanargmin(np.where(
            convex, top, np.nan)))]) if convex.any() else None,
        "min_concave_curvature_at_deg": float(ang[concave][int(np.argmax(rho[concave]))])
        if concave.any() else None,
    }


def _spans(ang, mask) -> list[list[float]]:
    """Body-angle spans (deg) where ``mask`` holds."""
    from plantmech.geometry.periodic import cyclic_runs

    return [[round(float(ang[a]), 2), round(float(ang[b]), 2)] for a, b in cyclic_runs(mask)]
