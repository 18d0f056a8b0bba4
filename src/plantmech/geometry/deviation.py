"""Distances (mm) between a simulated tip path and the planned trajectory: one path
(``trajectory_deviation``, the Hausdorff distance's two halves) or P paths against one plan
(``trajectory_deviation_batch``, the optimizer's layer-2 deviation)."""

from __future__ import annotations

import functools
from typing import TYPE_CHECKING

import numpy as np

from plantmech.geometry.trajectory import ClosedTrajectory

if TYPE_CHECKING:
    from plantmech.design import SeederDesign


def _distance_to_closed_polyline(points: np.ndarray, poly: np.ndarray) -> np.ndarray:
    """Distance (mm) of each point to a closed polyline: nearest vertex (k-d tree),
    then the perpendicular foot on its two adjacent segments."""
    from scipy.spatial import cKDTree

    _, k = cKDTree(poly).query(points)
    n = len(poly)
    best = np.hypot(*(points - poly[k]).T)
    for a, b in ((k - 1) % n, k), (k, (k + 1) % n):
        seg = poly[b] - poly[a]
        t = np.einsum("ij,ij->i", points - poly[a], seg) / np.maximum(
            np.einsum("ij,ij->i", seg, seg), 1e-300)
        foot = poly[a] + np.clip(t, 0.0, 1.0)[:, None] * seg
        best = np.minimum(best, np.hypot(*(points - foot).T))
    return best


def trajectory_deviation(traj: ClosedTrajectory, tip: np.ndarray, samples: int = 80000) -> dict:
    """Distances (mm) between a simulated tip path (closed, sampled) and the planned
    curve: largest distance of a tip sample from the curve, and of a curve point from
    the tip path (together the Hausdorff distance), point-to-segment. The second is
    limited by the tip sampling: a chord of the sampled path cuts sharp corners."""
    _, u = traj.arc_length_samples(samples)
    plan = traj(u)
    d1 = _distance_to_closed_polyline(tip, plan)
    d2 = _distance_to_closed_polyline(plan, tip)
    return {"max_tip_to_plan": float(d1.max()), "rms_tip_to_plan": float(np.sqrt(np.mean(d1**2))),
            "max_plan_to_tip": float(d2.max())}


def trajectory_deviation_batch(design: SeederDesign, tips: np.ndarray,
                               samples: int = 20000, coarse: int = 4) -> np.ndarray:
    """Largest distance (mm) of each design's tip samples (P, S, 2) from the planned
    trajectory, point to segment of the plan at ``samples`` equal arc lengths: the
    nearest vertex of every ``coarse``-th (one k-d tree query for all designs; a small
    tree is ~3x faster to search), then the 2 ``coarse`` plan segments around it."""
    tree, start, seg, length2 = _plan_polyline(tuple(map(tuple, design.trajectory.points)),
                                               samples, coarse)
    P, S, _ = tips.shape
    x, y = tips[..., 0].ravel(), tips[..., 1].ravel()
    _, kc = tree.query(np.c_[x, y])
    rx, ry = x[:, None] - start[0][kc], y[:, None] - start[1][kc]
    sx, sy = seg[0][kc], seg[1][kc]
    t = np.clip((rx * sx + ry * sy) / length2[kc], 0.0, 1.0)
    rx -= t * sx
    ry -= t * sy
    d2 = (rx * rx + ry * ry).min(axis=1)
    return np.sqrt(d2).reshape(P, S).max(axis=1)


@functools.lru_cache(maxsize=8)
def _plan_polyline(points: tuple, samples: int, coarse: int):
    """The planned curve through ``points`` at ``samples`` equal arc lengths, as a k-d
    tree of every ``coarse``-th point and, per tree point, the 2 ``coarse`` segments
    around it (starts and vectors (2, n / coarse, 2 coarse), squared lengths): an
    optimizer asks for the same plan every generation."""
    from scipy.spatial import cKDTree

    traj = ClosedTrajectory.through(np.asarray(points, dtype=float))
    _, u = traj.arc_length_samples(samples)
    plan = traj(u)
    n = len(plan)
    a = (np.arange(0, n, coarse)[:, None] + np.arange(-coarse, coarse)[None, :]) % n
    vec = plan[(a + 1) % n] - plan[a]
    start = np.ascontiguousarray(plan[a].transpose(2, 0, 1))
    seg = np.ascontiguousarray(vec.transpose(2, 0, 1))
    return cKDTree(plan[::coarse]), start, seg, np.maximum((vec * vec).sum(axis=2), 1e-300)
