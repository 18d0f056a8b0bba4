"""Sampling of deviations and of sweep designs (vectorised, reproducible per chunk)."""

from __future__ import annotations

import itertools

import numpy as np
from scipy.special import ndtr, ndtri

from plantmech.studies.spec import Distribution


def sample(dist: Distribution, u: np.ndarray) -> np.ndarray:
    """Deviations from uniform variates ``u`` in (0, 1) by the inverse CDF (so a Latin
    hypercube or plain random ``u`` serve alike)."""
    u = np.asarray(u, dtype=float)
    if dist.distribution == "normal":
        return dist.mean + dist.sigma * ndtri(u)
    if dist.distribution == "uniform":
        lo, hi = bounds(dist)
        return lo + (hi - lo) * u
    c = dist.limit / dist.sigma  # truncated normal: CDF restricted to [-c, c]
    lo, hi = ndtr(-c), ndtr(c)
    return dist.mean + dist.sigma * ndtri(lo + (hi - lo) * u)


def bounds(dist: Distribution) -> tuple[float, float]:
    """(low, high) of a uniform distribution."""
    if dist.plus_minus is not None:
        return dist.mean - dist.plus_minus, dist.mean + dist.plus_minus
    return float(dist.low), float(dist.high)


def mean(dist: Distribution) -> float:
    if dist.distribution == "uniform":
        lo, hi = bounds(dist)
        return 0.5 * (lo + hi)
    return dist.mean


def std(dist: Distribution) -> float:
    """Standard deviation: sigma; (high - low) / sqrt(12); for the normal truncated at
    +-c sigma: sigma sqrt(1 - 2 c phi(c) / (2 Phi(c) - 1))."""
    if dist.distribution == "normal":
        return float(dist.sigma)
    if dist.distribution == "uniform":
        lo, hi = bounds(dist)
        return (hi - lo) / np.sqrt(12.0)
    c = dist.limit / dist.sigma
    phi = np.exp(-0.5 * c * c) / np.sqrt(2 * np.pi)
    return float(dist.sigma * np.sqrt(1.0 - 2.0 * c * phi / (2.0 * ndtr(c) - 1.0)))


def chunk_rng(seed: int, chunk: int) -> np.random.Generator:
    """The random stream of one chunk: the same (seed, chunk) gives the same samples, in
    any order and on any worker (what makes a resumed study equal to an uninterrupted
    one)."""
    return np.random.default_rng([int(seed), int(chunk)])


def latin_hypercube(n: int, dims: int, rng: np.random.Generator) -> np.ndarray:
    """(n, dims) points in (0, 1): one in each of n equal strata per dimension, strata
    paired at random."""
    u = (np.arange(n)[:, None] + rng.random((n, dims))) / n
    for k in range(dims):
        u[:, k] = u[rng.permutation(n), k]
    return u


def grid(levels: list[np.ndarray]) -> np.ndarray:
    """(prod levels, dims) full factorial of the given level values."""
    return np.array(list(itertools.product(*levels)), dtype=float).reshape(-1, len(levels))
