"""Files a workshop can use for generated gears: DXF (closed outlines in mm, one layer
per gear), SVG, STL (extruded over z = 0..face width, written only as one watertight body
and checked again after reading the file back) and STEP (build123d, optional extra:
the outline as cubic B-spline edges within a stated tolerance, z = 0..face width,
checked after import)."""

from __future__ import annotations

from pathlib import Path

import numpy as np


def _rings(poly):
    yield np.asarray(poly.exterior.coords)
    for hole in poly.interiors:
        yield np.asarray(hole.coords)


def write_dxf(path: Path, gears: dict) -> None:
    """One closed LWPOLYLINE per boundary ring, one layer per gear, units mm."""
    import ezdxf
    from ezdxf import units

    doc = ezdxf.new("R2010")
    doc.units = units.MM
    doc.header["$INSUNITS"] = units.MM
    doc.header["$MEASUREMENT"] = 1  # metric
    msp = doc.modelspace()
    for i, (name, poly) in enumerate(gears.items()):
        doc.layers.add(name, color=1 + i % 7)
        for ring in _rings(poly):
            msp.add_lwpolyline(ring[:-1, :2], close=True, dxfattribs={"layer": name})
    doc.saveas(path)


def write_svg(path: Path, poly, name: str = "gear") -> None:
    """An SVG in mm (y up flipped to SVG's y down), even-odd fill so the bore is a hole."""
    x0, y0, x1, y1 = poly.bounds
    pad = 5.0
    w, h = x1 - x0 + 2 * pad, y1 - y0 + 2 * pad
    d = []
    for ring in _rings(poly):
        pts = [f"{x - x0 + pad:.4f},{y1 - y + pad:.4f}" for x, y in ring[:-1, :2]]
        d.append("M" + " L".join(pts) + " Z")
    svg = (f'<svg xmlns="http://www.w3.org/2000/svg" width="{w:.3f}mm" height="{h:.3f}mm" '
           f'viewBox="0 0 {w:.4f} {h:.4f}">\n<title>{name}</title>\n'
           f'<path d="{" ".join(d)}" fill="#888" fill-rule="evenodd" stroke="black" '
           f'stroke-width="0.1"/>\n</svg>\n')
    path.write_text(svg, encoding="utf-8")


def solid_check(mesh) -> dict:
    """What an extruded mesh is: {"bodies", "watertight", "volume_mm3"}: bodies are the
    connected components of the faces over shared edges (what trimesh's ``split`` finds,
    zero-volume fragments included), counted with scipy without building them: ``split`` repairs
    every open fragment, which needs networkx (not a dependency: a gear at module 10 that
    fell apart ended in a ModuleNotFoundError instead of its refusal)."""
    import numpy as np
    from trimesh import graph

    # engine named: without it trimesh tries each engine under ``except BaseException`` and
    # a Ctrl-C or SIGTERM there became "ImportError: no graph engines available!" (a
    # traceback; found by tests/test_signal_moments.py)
    bodies = graph.connected_components(mesh.face_adjacency,
                                        nodes=np.arange(len(mesh.faces)), min_len=1,
                                        engine="scipy")
    return {"bodies": int(len(bodies)), "watertight": bool(mesh.is_watertight),
            "volume_mm3": float(mesh.volume)}


def _one_body(check: dict) -> bool:
    return check["bodies"] == 1 and check["watertight"] and check["volume_mm3"] > 0


def write_stl(path: Path, poly, face_width: float) -> dict:
    """Extrude ``poly`` (mm) over z = 0..``face_width`` mm and write it as STL, only if it
    is one watertight body of positive volume; the written file is read back and checked
    again (a file that is not what it claims is removed). Returns {"written", "bodies",
    "watertight", "volume_mm3", "why"} (why: None, or the reason nothing was written)."""
    import trimesh

    mesh = trimesh.creation.extrude_polygon(poly, height=face_width)
    check = solid_check(mesh)
    if not _one_body(check):
        return check | {"written": False, "why": (
            f"the extruded outline is {check['bodies']} bodies (watertight "
            f"{check['watertight']}, volume {check['volume_mm3']:.1f} mm^3): refused, "
            "not written")}
    mesh.export(path)
    back = solid_check(trimesh.load(path, force="mesh"))
    if not _one_body(back):
        path.unlink()
        return back | {"written": False, "why": (
            f"the written STL read back as {back['bodies']} bodies (watertight "
            f"{back['watertight']}): removed")}
    return back | {"written": True, "why": None}


STEP_TOLERANCE_MM = 5e-3  # the STEP outline's largest distance from the cut outline (mm)
STEP_IMPORT_LIMIT_S = 5.0  # a STEP file whose import back takes more CPU is reported (s)


def _bspline_edge(curve):
    """A build123d Edge made exactly from a ``geometry.bspline.BSplineCurve`` (its poles,
    knots and degree, z = 0; build123d's ``Edge.make_bspline``, an OCP
    Geom_BSplineCurve)."""
    import build123d as bd

    return bd.Edge.make_bspline([(float(x), float(y), 0.0) for x, y in curve.control_points],
                                [float(k) for k in curve.knots], curve.degree)


def _edge_points(edge, per_span: int = 24, spacing: float = 0.02) -> np.ndarray:
    """(m, 2) points along an imported edge, read from its B-spline (poles, knots,
    degree as stored in the file; OCP ``GeomConvert`` for any other curve type),
    at least ``per_span`` per knot span and at most ``spacing`` mm apart, evaluated with
    scipy (the polyline through them is within spacing^2 / (8 R) of the curve: 0.1 um
    at R = 0.5 mm)."""
    from OCP.BRep import BRep_Tool
    from OCP.BRepAdaptor import BRepAdaptor_Curve
    from OCP.GeomConvert import GeomConvert

    from plantmech.geometry.bspline import BSplineCurve

    adaptor = BRepAdaptor_Curve(edge.wrapped)
    first, last = adaptor.FirstParameter(), adaptor.LastParameter()
    bs = GeomConvert.CurveToBSplineCurve_s(BRep_Tool.Curve_s(edge.wrapped, first, last))
    if bs.IsPeriodic():  # the same curve, its knots clamped (a read-back copy)
        bs.SetNotPeriodic()
    knots = np.repeat([bs.Knot(i) for i in range(1, bs.NbKnots() + 1)],
                      [bs.Multiplicity(i) for i in range(1, bs.NbKnots() + 1)])
    poles = np.array([[bs.Pole(i).X(), bs.Pole(i).Y()] for i in range(1, bs.NbPoles() + 1)])
    curve = BSplineCurve(knots, bs.Degree(), poles)
    t = np.unique(np.r_[first, knots[(knots > first) & (knots < last)], last])
    frac = np.arange(per_span) / per_span
    coarse = curve(np.r_[(t[:-1, None] + np.diff(t)[:, None] * frac).ravel(), last])
    # as many points again in each span as make them at most ``spacing`` mm apart
    span_len = np.add.reduceat(np.hypot(*np.diff(coarse, axis=0).T),
                               np.arange(0, len(coarse) - 1, per_span))
    n = np.maximum(per_span, np.ceil(span_len / spacing).astype(int))
    u = np.concatenate([a + (b - a) * np.arange(k) / k
                        for a, b, k in zip(t[:-1], t[1:], n, strict=True)] + [[last]])
    return curve(u)


def _face_area(face) -> float:
    """The area (mm^2) of a build123d face, integrated adaptively (OCP BRepGProp, 1e-6)."""
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps

    props = GProp_GProps()
    BRepGProp.SurfaceProperties_s(face.wrapped, props, 1e-6)
    return float(props.Mass())


def _distance_to_segments(points: np.ndarray, polylines) -> float:
    """The largest distance (mm) of ``points`` ((m, 2)) from the nearest segment of any
    of ``polylines`` ((n_i, 2) each), through an R-tree of the segments (shapely)."""
    import shapely

    segs = np.vstack([np.stack([p[:-1, :2], p[1:, :2]], axis=1) for p in polylines])
    tree = shapely.STRtree(shapely.linestrings(segs))
    _, dist = tree.query_nearest(shapely.points(points), return_distance=True, all_matches=False)
    return float(dist.max())


def write_step(path: Path, poly, face_width: float,
               tolerance: float = STEP_TOLERANCE_MM) -> dict:
    """STEP through build123d (``pip install plantmech[step]``): each ring of the cut
    outline split at its corners into smooth runs, each run an exact cubic B-spline edge
    within ``tolerance`` mm of the outline (``geometry.bspline.fit_ring``: a few dozen
    poles per flank instead of thousands of straight edges, so the file imports in
    seconds), the face (the bore a hole) extruded over z = 0..``face_width`` mm like the
    STL. The file is imported back and checked: one valid solid, z range, volume against
    the outline's area x face width (0.1 %), and the largest distance between its outline
    (every edge of the solid's bottom face, sampled densely from the B-spline stored in
    the file) and the cut outline, both ways (recorded as ``max_deviation_mm``, must be
    within ``tolerance``). Returns {"written", "why", ...measurements (``write_s``,
    ``import_s``, ``size_bytes``, ``edges``, ``poles``)}; why is None, or why nothing was
    written; a file that imports slower than ``STEP_IMPORT_LIMIT_S`` is kept and reported
    (``slow_import``)."""
    import time

    try:
        import build123d as bd
    except ImportError:
        return {"written": False, "skipped": True,
                "why": "build123d is not installed (pip install 'plantmech[step]')"}

    from plantmech.geometry.bspline import fit_ring

    t0 = time.perf_counter()
    rings = [np.asarray(poly.exterior.coords)] + [np.asarray(h.coords) for h in poly.interiors]
    fits = [fit_ring(r, tolerance) for r in rings]

    def face_of(curves):
        return bd.Face(bd.Wire([_bspline_edge(c) for c in curves]))

    face = face_of(fits[0])
    if len(fits) > 1:
        face = bd.Face(face.outer_wire(), [face_of(f).outer_wire() for f in fits[1:]])
    solid = bd.extrude(face, amount=face_width, dir=(0, 0, 1))
    bd.export_step(solid, str(path))
    write_s = time.perf_counter() - t0
    t0, c0 = time.perf_counter(), time.process_time()
    solids = bd.import_step(str(path)).solids()
    import_s = time.perf_counter() - t0
    # the limit is held to the import's CPU time: on a shared machine the wall time
    # measures the neighbours too (the import is single-threaded)
    import_cpu_s = time.process_time() - c0
    rec = {"tolerance_mm": tolerance, "write_s": round(write_s, 3),
           "import_s": round(import_s, 3), "import_cpu_s": round(import_cpu_s, 3),
           "size_bytes": path.stat().st_size,
           "solids": len(solids), "edges": sum(len(f) for f in fits),
           "poles": sum(len(c.control_points) for f in fits for c in f),
           "outline_vertices": sum(len(r) - 1 for r in rings)}
    why = None
    if len(solids) != 1 or not solids[0].is_valid:
        why = f"the STEP file read back as {len(solids)} solids (valid: " \
              f"{[s.is_valid for s in solids]})"
    else:
        s = solids[0]
        bb = s.bounding_box()
        bottom = min(s.faces(), key=lambda f: f.center().Z)
        # a prism: its volume is its bottom face's area x its height, the area integrated
        # adaptively (OCC's default volume integration, build123d's ``volume``, is off by
        # up to 1 % on faces bounded by many-span B-splines)
        volume = _face_area(bottom) * (bb.max.Z - bb.min.Z)
        rec |= {"z_mm": [round(bb.min.Z, 6), round(bb.max.Z, 6)], "volume_mm3": volume}
        pts = np.vstack([_edge_points(e) for e in bottom.edges()])
        # the file's outline to the cut outline, and every cut outline vertex to the
        # file's outline (its edges as dense polylines)
        dev = max(_distance_to_segments(pts, rings),
                  _distance_to_segments(np.vstack([r[:-1, :2] for r in rings]),
                                        [_edge_points(e) for e in bottom.edges()]))
        rec["max_deviation_mm"] = dev
        if abs(bb.min.Z) > 1e-6 or abs(bb.max.Z - face_width) > 1e-6:
            why = f"the STEP solid spans z {bb.min.Z:.3f}..{bb.max.Z:.3f} mm, not 0..{face_width}"
        elif abs(volume - poly.area * face_width) > 1e-3 * poly.area * face_width:
            why = (f"the STEP solid's volume {volume:.1f} mm^3 differs from the outline's "
                   f"{poly.area * face_width:.1f} mm^3 by more than 0.1 %")
        elif not dev <= tolerance:
            why = f"the STEP outline deviates {dev:.4f} mm from the cut outline (> {tolerance})"
    if why is not None:
        path.unlink()
    rec["slow_import"] = why is None and import_cpu_s > STEP_IMPORT_LIMIT_S
    return rec | {"written": why is None, "why": why}


def plot_pair(path: Path, pair, placed_a, placed_b, names=("A", "B")) -> None:
    """The pair in mesh at the start of the cycle: gear A (blue, centre at the origin) and
    gear B (orange, centre at (a, 0)), each named in the legend with its tooth count."""
    from matplotlib.figure import Figure  # no pyplot: the caller's backend is left alone
    from matplotlib.patches import Patch, PathPatch
    from matplotlib.path import Path as MplPath

    fig = Figure(figsize=(8, 6))
    ax = fig.subplots()
    handles = []
    for poly, colour, name, z, centre in (
            (placed_a, "tab:blue", names[0], pair.teeth_a, "(0, 0)"),
            (placed_b, "tab:orange", names[1], pair.teeth_b, f"({pair.a:.1f}, 0)")):
        geoms = getattr(poly, "geoms", [poly])
        for g in geoms:
            if g.geom_type != "Polygon":
                continue
            rings = list(_rings(g))
            # one compound path per polygon, so a bore or an internal gear's toothed hole
            # stays a hole
            outline = MplPath.make_compound_path(*[MplPath(r[:, :2], closed=True)
                                                for r in rings])
            # add_artist: the limits come from the rings plotted below (the same vertices;
            # add_patch would walk the whole outline's path in Python for them again)
            ax.add_artist(PathPatch(outline, facecolor=colour, alpha=0.35, lw=0))
            for ring in rings:
                ax.plot(ring[:, 0], ring[:, 1], color=colour, lw=0.5)
        kind = " (internal gear)" if pair.internal and colour == "tab:blue" \
            and name != "internal" else ""
        handles.append(Patch(color=colour, alpha=0.5,
                             label=f"{name}{kind}: {z} teeth, centre {centre} mm"))
    ax.plot([0, pair.a], [0, 0], "k+-", lw=0.5, ms=10)
    ax.legend(handles=handles, loc="upper right", fontsize=8)
    ax.set_aspect("equal")
    ax.set_xlabel("x / mm")
    ax.set_ylabel("y / mm")
    ax.set_title(f"{pair.name}: {pair.teeth_a} / {pair.teeth_b} teeth, m = {pair.module:.4f} mm,"
                 f" a = {pair.a:.3f} mm")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=130)
