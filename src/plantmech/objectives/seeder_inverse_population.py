"""Layer-1 checks of seed 000 for a whole population of planned trajectories at once
(arrays over designs; no Python loop per design): Table 1's planning limits from the
fitted curves, the section-4.1 attitude objectives and the speed objectives of the
inverse-designed motion. The same quantities as ``objectives.seeder`` for one design
(``planning_checks`` is computed here; the attitude and speeds are tested against
``attitude_by_section`` and ``speed_by_section``). Lengths mm, angles deg at this
boundary, speeds m/s.
"""

from __future__ import annotations

import numpy as np

from plantmech.geometry.trajectory_batch import TrajectoryBatch
from plantmech.objectives.seeder_population import section_values

TWO_PI = 2.0 * np.pi
PLANNING = ("small_ring_height", "small_ring_width", "large_ring_height", "large_ring_width",
            "cd_central_angle", "sowing_height_difference", "centre_to_trench_bottom")


def _contains(u0, u1, u, period):
    """u inside the parameter span [u0, u1] (wrapped), all (P,)."""
    return u0 + np.mod(u - u0, period) <= u1


def loop_spans(tb: TrajectoryBatch, n: int = 160, fused: bool = True):
    """Split each "8" at its self-crossing: (count (P,), spans (P, 2, 2)) with the loops'
    parameter spans [(u_i, u_j), (u_j, u_i + period)], NaN where the curve does not cross
    itself exactly once. The crossing of the inscribed n-gon is refined on the curve by
    Newton's method on traj(u_i) = traj(u_j), kept at the polygon estimate when the
    crossing is tangential or Newton wanders off it. ``fused``: Newton's steps in the
    numba kernel ``seeder_inverse_kernel.refine_crossings`` (False: the NumPy loop, the
    reference in the tests)."""
    count, i, j = tb.self_crossings(n)
    one = count == 1
    h = tb.period / n
    ui0 = np.where(one, i, 0) * h + 0.5 * h
    uj0 = np.where(one, j, 0) * h + 0.5 * h
    ui, uj = ui0.copy(), uj0.copy()
    stuck = np.zeros(tb.P, bool)
    if fused:  # the same steps in numba (seeder_inverse_kernel), no per-step temporaries
        from plantmech.mechanisms.seeder_inverse_kernel import refine_crossings

        ui, uj, stuck = refine_crossings(tb.coef, tb.knots, tb.period, ui, uj, one)
    for _ in range(0 if fused else 20):
        u = np.c_[ui, uj]
        p, d1, _ = tb.derivatives(u)
        f = p[:, 0] - p[:, 1]  # (P, 2)
        a, b, c, d = d1[:, 0, 0], -d1[:, 1, 0], d1[:, 0, 1], -d1[:, 1, 1]
        det = a * d - b * c
        stuck |= det == 0.0  # singular Jacobian: tangential crossing
        det = np.where(det == 0.0, 1.0, det)
        s0, s1 = (d * f[:, 0] - b * f[:, 1]) / det, (a * f[:, 1] - c * f[:, 0]) / det
        moving = ~stuck
        ui, uj = np.where(moving, ui - s0, ui), np.where(moving, uj - s1, uj)
        if (np.maximum(np.abs(s0), np.abs(s1))[moving & one] < 1e-12).all():
            break
    away = stuck | ~((np.abs(ui - ui0) < h) & (np.abs(uj - uj0) < h))
    ui, uj = np.where(away, ui0, ui), np.where(away, uj0, uj)
    ui, uj = np.mod(ui, tb.period), np.mod(uj, tb.period)
    ui, uj = np.minimum(ui, uj), np.maximum(ui, uj)
    spans = np.stack([np.c_[ui, uj], np.c_[uj, ui + tb.period]], axis=1)
    return count, np.where(one[:, None, None], spans, np.nan)


def planning_values(tb: TrajectoryBatch, sections: dict[str, int]):
    """Table 1 of seed 000 for each trajectory: (values (P, 7) in ``PLANNING`` order, NaN
    where undefined; reason (P,) object array: why the ring sizes are undefined, else
    ""). Ring sizes are the exact extents of the loops through a, b (small) and d, e, f
    (large); the trench bottom the exact lowest point (stationary points of the cubics)."""
    P, period = tb.P, tb.period
    count, spans = loop_spans(tb)
    ua, ue = tb.knots[:, sections["a"]], tb.knots[:, sections["e"]]
    in_a = np.stack([_contains(spans[:, k, 0], spans[:, k, 1], ua, period) for k in (0, 1)],
                    axis=1)
    in_e = np.stack([_contains(spans[:, k, 0], spans[:, k, 1], ue, period) for k in (0, 1)],
                    axis=1)
    split = (count == 1) & (in_a[:, 0] != in_a[:, 1]) & (in_e[:, 0] != in_e[:, 1]) & (
        in_a[:, 0] != in_e[:, 0])
    reason = np.full(P, "", dtype=object)
    reason[count != 1] = [f"the trajectory crosses itself {c} times; an '8' crosses once, "
                          "so its two ring buckles are undefined" for c in count[count != 1]]
    reason[(count == 1) & ~split] = "points a and e lie in the same loop of the '8'"
    rows = np.arange(P)
    small = spans[rows, np.argmax(in_a, axis=1)]
    large = spans[rows, np.argmax(in_e, axis=1)]
    values = np.full((P, 7), np.nan)
    if split.any():
        s = np.where(split[:, None], small, np.c_[np.zeros(P), period])
        g = np.where(split[:, None], large, np.c_[np.zeros(P), period])
        rs, rl = tb.coordinate_range(s[:, 0], s[:, 1]), tb.coordinate_range(g[:, 0], g[:, 1])
        ext = np.c_[rs[:, 1, 1] - rs[:, 1, 0], rs[:, 0, 1] - rs[:, 0, 0],
                    rl[:, 1, 1] - rl[:, 1, 0], rl[:, 0, 1] - rl[:, 0, 0]]
        values[:, :4] = np.where(split[:, None], ext, np.nan)
    pts = tb.points
    pc, pd, pe = pts[:, sections["c"]], pts[:, sections["d"]], pts[:, sections["e"]]
    turn = np.arctan2(pd[:, 1], pd[:, 0]) - np.arctan2(pc[:, 1], pc[:, 0])
    values[:, 4] = np.abs(np.degrees(np.angle(np.exp(1j * turn))))
    values[:, 5] = np.abs(pd[:, 1] - pe[:, 1])
    values[:, 6] = -tb.coordinate_range(np.zeros(P), period)[:, 1, 0]
    return values, reason


def _sections(point_psi, sections: dict[str, int]) -> np.ndarray:
    """(P, 6) carrier angles (rad) of the section points a..f."""
    return np.stack([point_psi[:, sections[k]] for k in "abcdef"], axis=1)


def attitude_values(psi, arm_deg, point_psi, sections: dict[str, int]) -> np.ndarray:
    """(P, 3) picking swing, seeding swing, |sowing angle| (deg, to 4 decimals as
    ``attitude_checks`` reports them): the arm attitude relative to the initial one,
    largest change from a within ab, from d within de, and its value at e
    (``seeder_population.section_values``)."""
    P, n = np.shape(arm_deg)
    vals = section_values(psi, arm_deg, _sections(point_psi, sections), np.zeros((P, n, 2)))
    return np.c_[np.round(vals[:, 0], 4), np.round(vals[:, 1], 4),
                 np.abs(np.round(vals[:, 2], 4))]


def speed_values(psi, velocity, point_psi, sections: dict[str, int],
                 travel_m_s=None) -> tuple[np.ndarray, np.ndarray]:
    """((P, 3) seeding peak (static, over de), return minimum static and dynamic (over
    ef) in m/s; travel speeds (P,) m/s) from tip velocities (P, n, 2) m/s. ``travel_m_s``
    None: zero-speed seeding at e (the machine cancels the tip's horizontal velocity
    there, seed 000 Eq. 18 as read in docs/conventions.md)
    (``seeder_population.section_values``)."""
    P, n = np.shape(velocity)[:2]
    vals = section_values(psi, np.zeros((P, n)), _sections(point_psi, sections), velocity,
                          travel_m_s=None if travel_m_s is None else float(travel_m_s))
    return vals[:, 5:8], vals[:, 4]
