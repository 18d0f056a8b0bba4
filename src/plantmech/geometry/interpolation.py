"""Interpolation helpers over populations: ``np.interp`` for every row at once."""

from __future__ import annotations

import numpy as np


def interp_rows(x: np.ndarray, xp: np.ndarray, fp: np.ndarray,
                shared_x: bool = False) -> np.ndarray:
    """``np.interp`` for every row of a population at once: row d of the result
    interpolates (xp[d], fp[d]) at x[d] (x (P, ...)), or at x itself for every row when
    ``shared_x``; xp increasing along the row; xp or fp may be one (N,) row shared by all.
    Outside a row's range the end values, as ``np.interp``. Shape (P, ...)."""
    xp, fp = np.asarray(xp, dtype=float), np.asarray(fp, dtype=float)
    P = max(xp.shape[0] if xp.ndim == 2 else 1, fp.shape[0] if fp.ndim == 2 else 1)
    x = np.asarray(x, dtype=float)
    xq = np.broadcast_to(x, (P, *x.shape)) if shared_x else x
    flat = xq.reshape(P, -1)
    n = xp.shape[-1]
    if xp.ndim == 1:  # one table: one search
        lo, hi = xp[0], xp[-1]
        q = np.clip(flat, lo, hi)
        h = (hi - lo) / (n - 1)
        if np.all(np.abs(np.diff(xp) - h) <= 1e-12 * max(abs(hi), abs(lo), 1.0)):
            # a uniform grid: the interval by arithmetic, corrected for round-off
            i = np.clip(((q - lo) / h).astype(np.intp), 0, n - 2)
            i -= (q < xp[i]) & (i > 0)
            i += (q >= xp[i + 1]) & (i < n - 2)
        else:
            i = np.clip(np.searchsorted(xp, q, side="right") - 1, 0, n - 2)
        x0, x1 = xp[i], xp[i + 1]
    else:  # a table per row: rows shifted apart so that one sorted search finds every row
        lo, hi = xp[:, :1], xp[:, -1:]
        q = np.clip(flat, lo, hi)
        rel = xp - lo
        step = float(rel[:, -1].max()) + 1.0
        shift = step * np.arange(P, dtype=float)[:, None]
        i = np.searchsorted((rel + shift).ravel(), (q - lo + shift).ravel(), side="right")
        i = np.clip(i.reshape(P, -1) - n * np.arange(P)[:, None] - 1, 0, n - 2)
        x0 = np.take_along_axis(xp, i, axis=1)
        x1 = np.take_along_axis(xp, i + 1, axis=1)
    if fp.ndim == 1:
        f0, f1 = fp[i], fp[i + 1]
    else:
        f0 = np.take_along_axis(np.broadcast_to(fp, (P, n)), i, axis=1)
        f1 = np.take_along_axis(np.broadcast_to(fp, (P, n)), i + 1, axis=1)
    w = np.divide(q - x0, x1 - x0, out=np.zeros_like(q), where=x1 > x0)
    return (f0 + w * (f1 - f0)).reshape(P, *x.shape[(0 if shared_x else 1):])
