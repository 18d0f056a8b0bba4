"""Gear outlines read back from the DXF files that ``plantmech gears`` writes (closed
polylines in mm, one layer per gear, each gear in its own body frame: centre at the
origin, body angle 0 along +x, angles counter-clockwise).

Nothing here uses the pitch curves: the teeth are found on the outline itself (tooth tips
are the local extremes of the radius about the gear centre)."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

TWO_PI = 2.0 * np.pi
#: largest gear file read (bytes; 'plantmech gears' writes well under 1 MB a gear)
MAX_GEAR_FILE_BYTES = 64_000_000
#: most outline points in one gear file
MAX_GEAR_VERTICES = 2_000_000


class GearFileError(ValueError):
    """A gear file is missing, unreadable or does not hold a closed gear outline."""


@dataclass
class GearOutline:
    """One gear: its toothed boundary ``ring`` (N, 2) in mm (not repeated at the end),
    every boundary ring (rim, bore), whether the teeth point inward (an internal gear),
    and the body angles (rad, 0..2 pi, increasing) of its tooth tips."""

    name: str
    ring: np.ndarray
    rings: list
    internal: bool
    tip_angles: np.ndarray
    source: str = ""
    tooth_of_vertex: np.ndarray = field(default=None, repr=False)

    @property
    def teeth(self) -> int:
        return int(len(self.tip_angles))

    def polygon(self):
        """The gear's material as a shapely polygon (largest ring outside, others holes)."""
        import shapely

        areas = [abs(_area(r)) for r in self.rings]
        k = int(np.argmax(areas))
        holes = [r for i, r in enumerate(self.rings) if i != k]
        return shapely.make_valid(shapely.Polygon(self.rings[k], holes))

    def tooth_at(self, body_angle) -> np.ndarray:
        """Tooth number (1-based, counted counter-clockwise from body angle 0) nearest to
        ``body_angle`` (rad)."""
        ang = np.mod(np.asarray(body_angle, dtype=float), TWO_PI)
        tips = self.tip_angles
        d = np.abs(np.angle(np.exp(1j * (ang[..., None] - tips))))
        return np.argmin(d, axis=-1) + 1

    def rotated(self, angle: float) -> GearOutline:
        """The same gear with its outline turned by ``angle`` (rad, counter-clockwise) in
        its body frame (a gear file cut with the wrong phase)."""
        c, s = np.cos(angle), np.sin(angle)
        rot = np.array([[c, -s], [s, c]])
        return outline_from_rings(self.name, [r @ rot.T for r in self.rings], self.source)


def _area(ring: np.ndarray) -> float:
    x, y = ring[:, 0], ring[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


def outline_from_rings(name: str, rings: list, source: str = "") -> GearOutline:
    """A GearOutline from closed rings (each (N, 2), mm); the toothed ring is the one
    with the most vertices; it is internal when it is a hole of a larger ring."""
    rings = [np.asarray(r, dtype=float)[:, :2] for r in rings]
    rings = [r[:-1] if len(r) > 1 and np.allclose(r[0], r[-1]) else r for r in rings]
    if not rings or max(len(r) for r in rings) < 8:
        raise GearFileError(f"{source or name}: layer '{name}' holds no closed gear outline")
    k = int(np.argmax([len(r) for r in rings]))
    ring = rings[k]
    areas = [abs(_area(r)) for r in rings]
    internal = bool(areas[k] < max(areas) * (1 - 1e-9))
    peaks = _tip_vertices(ring, internal)
    if len(peaks) < 3:
        raise GearFileError(f"{source or name}: layer '{name}': found {len(peaks)} teeth on "
                            "the outline (a gear needs at least 3)")
    tips = np.unique(np.round(np.mod(np.arctan2(peaks[:, 1], peaks[:, 0]), TWO_PI), 12))
    out = GearOutline(name, ring, rings, internal, tips, source)
    ang = np.arctan2(ring[:, 1], ring[:, 0])
    out.tooth_of_vertex = out.tooth_at(ang)
    return out


def _tip_vertices(ring: np.ndarray, internal: bool, m: int = 4096) -> np.ndarray:
    """Points (n, 2) at the teeth's middles (the tips): the radius is resampled
    uniformly in arc length, the tooth frequency is the strongest harmonic of its slope
    above the 5th (the slow change of the radius around a non-circular gear lies below it,
    and weighs less in the slope), the radius
    is smoothed over one tooth pitch, and each run above the smooth curve (below, for an
    internal gear) is a tooth whose middle is halfway along the run.

    A run is a tooth only where it rises above the smooth curve by at least a quarter of
    the median run's rise: on an arc without teeth (a partial gear's locking arc, teeth
    cut down to the root) the radius and its running mean are equal, so float rounding
    or a dent of 0.01 mm there makes runs of any length "above" it (the seeder's sun at
    module 1.5 showed a tooth 0.04 mm high in the middle of its 40 deg locking arc, where
    its real teeth rise 1.8 mm)."""
    seg = np.hypot(*(np.roll(ring, -1, axis=0) - ring).T)
    s = np.r_[0.0, np.cumsum(seg)]
    length = s[-1]
    r = np.hypot(ring[:, 0], ring[:, 1])
    sig = -r if internal else r
    su = np.linspace(0.0, length, m, endpoint=False)
    ru = np.interp(su, s, np.r_[sig, sig[0]])
    # the spectrum of the radius's slope (harmonic k weighted by k): a lobed gear's slow
    # radius change (a few lobes, tens of mm) would outweigh its teeth's (mm) otherwise
    spec = np.abs(np.fft.rfft(ru - ru.mean())) * np.arange(m // 2 + 1)
    k = 5 + int(np.argmax(spec[5:m // 8]))
    w = max(3, int(round(m / k)))
    kernel = np.ones(w) / w
    smooth = np.convolve(np.r_[ru[-w:], ru, ru[:w]], kernel, mode="same")[w:-w]
    above = ru > smooth
    # runs of ``above`` (cyclic); short runs (< a quarter pitch) are noise
    edges = np.flatnonzero(np.diff(np.r_[above[-1], above].astype(int)))
    if len(edges) == 0:
        return np.zeros((0, 2))
    starts = [e for e in edges if above[e]]
    runs, rise = [], []
    for a in starts:
        b = a
        while above[b % m] and b - a < m:
            b += 1
        if b - a < w / 4:
            continue
        runs.append((a, b))
        rise.append(float(np.max((ru - smooth)[np.arange(a, b) % m])))
    tips = []
    floor = 0.25 * float(np.median(rise)) if rise else 0.0
    for (a, b), h in zip(runs, rise, strict=True):
        if h < floor:
            continue
        # the tooth's middle: halfway along the run (a symmetric tooth's centre line)
        mid = su[a % m] + 0.5 * (b - a) * length / m
        tips.append(np.mod(mid, length))
    closed = np.vstack([ring, ring[:1]])
    return np.c_[np.interp(tips, s, closed[:, 0]), np.interp(tips, s, closed[:, 1])]


def read_gear_dxf(path: Path, layer: str | None = None) -> GearOutline:
    """The gear on ``layer`` (default: the file's only layer with polylines) of a DXF."""
    import io

    import ezdxf

    from plantmech.design import MAX_SIZE_MM
    from plantmech.inputs import read_input_bytes

    path = Path(path)
    if not path.exists() and not path.is_symlink():
        raise GearFileError(f"{path}: gear file not found")
    data = read_input_bytes(path, "gear file (DXF)", MAX_GEAR_FILE_BYTES, GearFileError)
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        text = data.decode("cp1252", errors="replace")  # an older DXF's code page
    try:
        doc = ezdxf.read(io.StringIO(text))
        entities = list(doc.modelspace())
    except (ezdxf.DXFError, ValueError, IndexError, KeyError, TypeError, AttributeError,
            EOFError) as exc:
        raise GearFileError(f"{path}: not a readable DXF file ({type(exc).__name__}: "
                            f"{str(exc)[:200]})") from None
    by_layer: dict[str, list] = {}
    vertices = 0
    for e in entities:
        kind = e.dxftype()
        try:
            if kind == "LWPOLYLINE":
                pts = np.asarray(e.get_points("xy"), dtype=float).reshape(-1, 2)
                closed = bool(e.closed)
            elif kind == "POLYLINE":
                pts = np.asarray([v.dxf.location[:2] for v in e.vertices],
                                 dtype=float).reshape(-1, 2)
                closed = bool(e.is_closed)
            else:
                continue
        except (ezdxf.DXFError, ValueError, IndexError, TypeError, AttributeError) as exc:
            raise GearFileError(f"{path}: a damaged {kind} ({type(exc).__name__}: "
                                f"{str(exc)[:200]})") from None
        where = str(e.dxf.layer)[:64]  # for messages
        vertices += len(pts)
        if vertices > MAX_GEAR_VERTICES:
            raise GearFileError(f"{path}: more than {MAX_GEAR_VERTICES:,} outline points; "
                                "not a gear file of 'plantmech gears'")
        if not closed and not (len(pts) > 2 and np.allclose(pts[0], pts[-1])):
            raise GearFileError(f"{path}: layer '{where}': a polyline of "
                                f"{len(pts)} points is not closed")
        if not np.all(np.isfinite(pts)):
            raise GearFileError(f"{path}: layer '{where}': a polyline has a "
                                "non-finite coordinate")
        far = float(np.abs(pts).max(initial=0.0))
        if far > MAX_SIZE_MM:
            raise GearFileError(f"{path}: layer '{where}': a coordinate of {far:.6g} mm; a "
                                f"gear lies within +-{MAX_SIZE_MM:g} mm of its centre")
        if len(pts) >= 3:
            c = pts - pts.mean(axis=0)
            sv = np.linalg.svd(c, compute_uv=False)
            if sv[0] == 0 or sv[-1] <= 1e-9 * sv[0]:
                raise GearFileError(f"{path}: layer '{where}': a polyline of {len(pts)} "
                                    "points encloses no area (its points lie on one line)")
        by_layer.setdefault(e.dxf.layer, []).append(pts)
    if not by_layer:
        raise GearFileError(f"{path}: no closed polylines (gear outlines) in the file")
    if layer is None:
        if len(by_layer) > 1:
            raise GearFileError(f"{path}: several layers {sorted(by_layer)}; name the gear")
        layer = next(iter(by_layer))
    if layer not in by_layer:
        raise GearFileError(f"{path}: no layer '{layer}' (layers: {sorted(by_layer)})")
    return outline_from_rings(layer, by_layer[layer], str(path))
