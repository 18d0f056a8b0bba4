"""Files a workshop can use for generated gears: DXF (closed outlines in mm, one layer
per gear), SVG, STL (extruded, watertight) and STEP (build123d, optional extra)."""

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


def write_stl(path: Path, poly, face_width: float) -> bool:
    """Extrude to ``face_width`` mm and write an STL; returns watertightness."""
    import trimesh

    mesh = trimesh.creation.extrude_polygon(poly, height=face_width)
    mesh.export(path)
    return bool(mesh.is_watertight)


def write_step(path: Path, poly, face_width: float) -> str | None:
    """STEP through build123d (``pip install plantmech[step]``): outlines as B-spline
    edges through the outline points, extruded. Returns None, or why it was skipped."""
    try:
        import build123d as bd
    except ImportError:
        return "build123d is not installed (pip install 'plantmech[step]')"

    def face_of(ring):
        # one spline per smooth run of the outline (a flank, a tip land, a root fillet),
        # split where the direction turns by more than 25 deg: a single spline through a
        # toothed outline loops at the corners (its face came out 70 % too large)
        xy = np.asarray(ring, dtype=float)[:, :2]
        xy = xy[:-1] if np.allclose(xy[0], xy[-1]) else xy
        d = np.diff(np.vstack([xy, xy[:1]]), axis=0)
        keep = np.hypot(*d.T) > 1e-3
        xy = xy[keep]
        d = np.diff(np.vstack([xy, xy[:1]]), axis=0)
        heading = np.arctan2(d[:, 1], d[:, 0])
        turn = np.abs(np.angle(np.exp(1j * (heading - np.roll(heading, 1)))))
        corners = np.flatnonzero(turn > np.radians(25.0))
        if len(corners) == 0:
            corners = np.array([0])
        xy = np.roll(xy, -corners[0], axis=0)
        corners = np.r_[corners - corners[0], len(xy)]
        edges = []
        for a, b in zip(corners[:-1], corners[1:], strict=True):
            run = [bd.Vector(float(x), float(y), 0.0) for x, y in xy[a:b + 1]] if b < len(xy) \
                else [bd.Vector(float(x), float(y), 0.0) for x, y in np.vstack([xy[a:], xy[:1]])]
            edges.append(bd.Edge.make_spline(run) if len(run) > 3 else
                         bd.Edge.make_line(run[0], run[-1]) if len(run) == 2 else
                         bd.Edge.make_spline(run))
        return bd.Face(bd.Wire(edges))

    rings = list(_rings(poly))
    face = face_of(rings[0])
    for hole in rings[1:]:
        face = face - face_of(hole)
    solid = bd.extrude(face, amount=face_width)
    bd.export_step(solid, str(path))
    return None


def plot_pair(path: Path, pair, placed_a, placed_b) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 6))
    for poly, colour in ((placed_a, "tab:blue"), (placed_b, "tab:orange")):
        geoms = getattr(poly, "geoms", [poly])
        for g in geoms:
            if g.geom_type != "Polygon":
                continue
            for ring in _rings(g):
                ax.fill(ring[:, 0], ring[:, 1], color=colour, alpha=0.35, lw=0)
                ax.plot(ring[:, 0], ring[:, 1], color=colour, lw=0.5)
    ax.plot([0, pair.a], [0, 0], "k+-", lw=0.5, ms=10)
    ax.set_aspect("equal")
    ax.set_xlabel("x / mm")
    ax.set_ylabel("y / mm")
    ax.set_title(f"{pair.name}: {pair.teeth_a} / {pair.teeth_b} teeth, m = {pair.module:.4f} mm,"
                 f" a = {pair.a:.3f} mm")
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    plt.close(fig)
