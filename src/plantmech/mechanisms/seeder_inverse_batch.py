"""The inverse design of seed 000 (sections 3.2-3.3) for a whole population of candidate
trajectories at once: arrays over designs x samples, no Python loop per design or per
sample. The batched form of ``seeder_inverse.inverse_design`` without a toothless dwell
(layer 1 of the layered optimization moves type-value points of a dwell-free train),
step for step the same model: extreme radii -> L1, L2; carrier direction on a dense
grid for the assembly branch that turns the carrier once clockwise; the tip at uniform
carrier angle by the Illinois method; the planned ratio law from the periodic spline;
the stage split, closure normalisation and pitch radii; the motion the train realizes.
Tested against the single-design function to round-off (tests/test_seeder_inverse_batch.py).

Infeasible rows are graded as ``inverse_design``'s diagnostics would be: the number of
errors plus the carrier angle they cover / 30 deg (``error_score``), so that an
optimizer sees a slope towards feasibility.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from plantmech.geometry.periodic import (
    periodic_spline_node_slopes,
    periodic_spline_running_integral,
)
from plantmech.geometry.trajectory_batch import TrajectoryBatch
from plantmech.mechanisms.seeder_inverse import dense_grid_size, invert_carrier, wrap_angle

TWO_PI = 2.0 * np.pi


@dataclass
class InversePopulation:
    """Inverse designs of P trajectories, sampled at n uniform carrier angles ``psi``.
    ``feasible`` (P,); ``error_score`` (P,) 0 where feasible. Arrays of infeasible rows
    hold placeholders. Lengths mm, angles rad (conventions of ``seeder_inverse``)."""

    feasible: np.ndarray
    error_score: np.ndarray
    psi: np.ndarray  # (n,) clockwise carrier angle from the initial position
    L1: np.ndarray  # (P,)
    L2: np.ndarray
    carrier_abs: np.ndarray  # (P, n) absolute carrier direction phi_1
    arm_angle_realized: np.ndarray  # (P, n) absolute arm angle the gear train gives
    tip_realized: np.ndarray  # (P, n, 2)
    point_carrier_angle: np.ndarray  # (P, N) carrier angle at each type-value point
    pitch_radius_min: np.ndarray  # (P, 4) smallest r1..r4 (mm)
    closure_error: np.ndarray  # (P, 2) stage 1, stage 2 (rad)
    pitch_tangent_angle: np.ndarray | None = None  # (P, 2) largest mu of each pair (rad)


def _unwrap_rows(phase: np.ndarray) -> np.ndarray:
    """np.unwrap along axis 1, with its rounding (jumps of at least pi are replaced by
    their 2 pi complement), computed only where a jump is."""
    d = np.diff(phase, axis=1)
    jump = np.abs(d) >= np.pi
    out = phase.copy()
    if jump.any():
        dj = d[jump]
        dmod = np.mod(dj + np.pi, TWO_PI) - np.pi
        dmod = np.where((dmod == -np.pi) & (dj > 0), np.pi, dmod)
        corr = np.zeros_like(d)
        corr[jump] = dmod - dj
        out[:, 1:] += np.cumsum(corr, axis=1)
    return out


def extreme_radii(tb: TrajectoryBatch, per_span: int = 16, candidates: int = 2,
                  fused: bool = True):
    """((u, rho) of the farthest, (u, rho) of the nearest) point of each trajectory to O,
    each (P,): the ``candidates`` best local extremes of ``per_span`` samples per knot
    span, each refined by safeguarded Newton on d(rho^2)/du = 0 within one sample step (to
    1e-9 mm of parameter; rho itself is flat there, so a search on rho alone cannot
    resolve the place), and the better kept (two near-equal bumps are told apart by
    their refined values, not by their samples). ``fused``: the Newton steps in the numba
    kernel ``seeder_inverse_kernel.refine_extremes`` (False: the NumPy loop, the
    reference in the tests)."""
    m = per_span * tb.N
    h = tb.period / m
    u = h[:, None] * np.arange(m)[None, :]
    xy = tb(u)
    rho2 = xy[..., 0] ** 2 + xy[..., 1] ** 2
    out = []
    for largest in (True, False):
        r = rho2 if largest else -rho2
        local = (r >= np.roll(r, 1, axis=1)) & (r >= np.roll(r, -1, axis=1))
        k = np.argsort(np.where(local, -r, np.inf), axis=1)[:, :candidates]  # (P, c)
        lo = np.take_along_axis(u, k, axis=1) - h[:, None]
        hi, x = lo + 2.0 * h[:, None], lo + h[:, None]

        def slope(at, largest=largest):  # d(rho^2)/du / 2: > 0 before a max (min)
            p, d1, _ = tb.derivatives(at)
            f = (p * d1).sum(axis=-1)
            return f if largest else -f

        # a candidate without a turn inside its bracket keeps its sample (a flat stretch)
        done = ~((slope(lo) > 0) & (slope(hi) < 0))
        if fused:  # each candidate on its own in numba: the same steps, no temporaries
            from plantmech.mechanisms.seeder_inverse_kernel import refine_extremes

            x = refine_extremes(tb.coef, tb.knots, tb.period, lo, hi, x, done, largest)
        for _ in range(0 if fused else 40):
            p, d1, d2 = tb.derivatives(x)
            f = (p * d1).sum(axis=-1)
            fp = (d1 * d1).sum(axis=-1) + (p * d2).sum(axis=-1)
            # keep the bracket: f goes + to - through a maximum, - to + through a minimum
            rising = f > 0 if largest else f < 0
            lo, hi = np.where(rising, x, lo), np.where(rising, hi, x)
            with np.errstate(divide="ignore", invalid="ignore"):
                step = f / fp
            nx = x - step
            nx = np.where(np.isfinite(nx) & (nx >= lo) & (nx <= hi), nx, 0.5 * (lo + hi))
            x = np.where(done, x, nx)
            done |= (np.abs(step) < 1e-9) | (hi - lo < 1e-9)
            if done.all():
                break
        p = tb(x)
        rho = np.hypot(p[..., 0], p[..., 1])
        j = np.argmax(rho if largest else -rho, axis=1)
        rows = np.arange(tb.P)
        out.append((np.mod(x[rows, j], tb.period), rho[rows, j]))
    return out


def _carrier_geometry(tb, u, L1, L2):
    """Tip (P, m, 2), its polar angle beta_3 and the unsigned angle beta_1 at O between
    the carrier and the tip (Eq. 2-3) at parameters u (P, m)."""
    xy = tb(u)
    x, y = xy[..., 0], xy[..., 1]
    rho = np.hypot(x, y)
    L1c, L2c = L1[:, None], L2[:, None]
    with np.errstate(divide="ignore", invalid="ignore"):  # rho = 0: a degenerate row
        cos_b1 = np.clip((L1c**2 + rho**2 - L2c**2) / (2 * L1c * rho), -1.0, 1.0)
    return xy, np.arctan2(y, x), np.arctan2(np.sqrt(np.clip(1.0 - cos_b1**2, 0.0, None)),
                                            cos_b1)


def _branch_sign(tb, u, u_min, u_max, sigma_inner):
    """sigma (P, m): ``sigma_inner`` on the arc from u_min to u_max, its opposite else."""
    per = tb.period[:, None]
    x = u - u_min[:, None]
    x -= per * np.floor(x / per)
    on_inner = x < np.mod(u_max - u_min, tb.period)[:, None]
    return np.where(on_inner, sigma_inner[:, None], -sigma_inner[:, None])


def _carrier_direction(tb, u, L1, L2, u_min, u_max, sigma_inner):
    """Absolute carrier angle phi_1 = beta_3 + sigma beta_1 (P, m) at parameters u (P, m),
    and the tip there."""
    xy, beta3, beta1 = _carrier_geometry(tb, u, L1, L2)
    return beta3 + _branch_sign(tb, u, u_min, u_max, sigma_inner) * beta1, xy


def _runs(mask: np.ndarray) -> np.ndarray:
    """Number of cyclic True runs per row of ``mask`` (P, m)."""
    starts = (mask & ~np.roll(mask, 1, axis=1)).sum(axis=1)
    return np.where(mask.all(axis=1), 1, starts)


def _run_score(mask, step_deg):
    """Diagnostics' grading for runs of flagged samples: one error per cyclic run plus the
    carrier angle each run spans (first to last flagged sample) / 30 deg."""
    runs = _runs(mask)
    return runs + (mask.sum(axis=1) - runs) * step_deg / 30.0


def _running_integral(values: np.ndarray, step: float) -> np.ndarray:
    """``periodic_spline_running_integral`` of each row of ``values`` (P, n) -> (P, n + 1)."""
    return periodic_spline_running_integral(values.T, step).T


def _node_slopes(values: np.ndarray, step: float) -> np.ndarray:
    """``periodic_spline_node_slopes`` along axis 1 of ``values`` (P, n[, k])."""
    return np.moveaxis(periodic_spline_node_slopes(np.moveaxis(values, 1, 0), step), 0, 1)


def _split_and_close(g, split_exponent, a1, a2, step):
    """Eq. 7-9 for P ratio laws g = d psi_4 / d psi (P, n): stage 1 takes C g^p, normalised
    so gear 2 closes, stage 2 the rest, normalised so the planet closes under the same
    (periodic spline) integration. Returns (pitch radii r1..r4 (P, 4, n) mm, the planet's
    running turn (P, n + 1) rad, closure errors of both stages (P, 2) rad)."""
    p = split_exponent
    shape = g**p
    c = TWO_PI / _running_integral(shape, step)[:, -1]
    h = c[:, None] * shape  # d psi_2 / d psi = 1 / i_1
    q = g ** (1 - p) / c[:, None]
    q = q * (TWO_PI / _running_integral(h * q, step)[:, -1])[:, None]  # 1 / i_2
    gear2 = _running_integral(h, step)
    planet_train = _running_integral(h * q, step)
    r2 = a1[:, None] / (1.0 + h)
    r4 = a2[:, None] / (1.0 + q)
    radii = np.stack([a1[:, None] - r2, r2, a2[:, None] - r4, r4], axis=1)
    closure = np.c_[np.abs(gear2[:, -1] - TWO_PI), np.abs(planet_train[:, -1] - gear2[:, -1])]
    return radii, planet_train, closure


def pitch_tangent_angle(radii: np.ndarray, a1: np.ndarray, step: float,
                        nan_ok: bool = False) -> np.ndarray:
    """Largest angle mu (rad) between the pitch tangent and the normal to the radius vector
    of each pair, (P, 2), from the pitch radii r1..r4 (P, 4, n) on the uniform carrier grid:
    gears 2 and 3 share a shaft turning d theta / d psi = h = a1 / r2 - 1 relative to the
    carrier, so tan mu = abs(dr / d psi) / (h r) along gear 2 (sun pair) and gear 3 (planet
    pair); the working pressure angle is the tool's plus mu (``gears.manufacturability``).
    ``nan_ok``: samples with NaN radii (a toothless dwell) are left out of the maximum; the
    slopes are then central differences (local: a spline's would be NaN everywhere)."""
    r2, r3 = radii[:, 1], radii[:, 2]
    h = a1[:, None] / r2 - 1.0
    out = []
    for r in (r2, r3):
        dr = ((np.roll(r, -1, axis=1) - np.roll(r, 1, axis=1)) / (2 * step) if nan_ok
              else _node_slopes(r, step))
        mu = np.arctan(np.abs(dr) / (np.abs(h) * r))
        out.append(np.nanmax(mu, axis=1) if nan_ok else mu.max(axis=1))
    return np.stack(out, axis=1)


def inverse_population(points, samples: int = 360, a1: float | None = None,
                       a2: float | None = None, split_exponent: float = 0.5,
                       min_pitch_radius: float = 5.0) -> InversePopulation:
    """Inverse designs of the trajectories through ``points`` (P, N, 2) mm, or of a
    ``TrajectoryBatch`` (no dwell); see ``seeder_inverse.inverse_design`` for the model
    and the checks."""
    tb = points if isinstance(points, TrajectoryBatch) else TrajectoryBatch(points)
    P, N, n = tb.P, tb.N, int(samples)
    score = np.zeros(P)
    alive = ~tb.bad
    score[tb.bad] = 10.0  # no curve at all (as a fitting failure)
    (u_max, rho_max), (u_min, rho_min) = extreme_radii(tb)
    L1, L2 = 0.5 * (rho_max - rho_min), 0.5 * (rho_max + rho_min)
    degenerate = alive & ((rho_min < 1e-6) | (L1 < 1e-6))
    score[degenerate] = 1.0
    alive &= ~degenerate
    L1s = np.where(alive, L1, 1.0)
    A1 = np.full(P, a1) if a1 is not None else 0.5 * L1s
    A2 = np.full(P, a2) if a2 is not None else 0.5 * L1s
    geometry = alive & ~((A1 <= 0) | (A2 <= 0) | (A1 + A2 < L1s - 1e-9)
                         | (np.abs(A1 - A2) > L1s))
    score[alive & ~geometry] = 1.0
    alive &= geometry

    m = dense_grid_size(n, N)
    grid = np.linspace(0.0, 1.0, m + 1)
    u_dense = u_max[:, None] + tb.period[:, None] * grid[None, :]
    L2s = np.where(alive, L2, 1.0)
    xy, beta3, beta1 = _carrier_geometry(tb, u_dense, L1s, L2s)
    inner = _branch_sign(tb, u_dense, u_min, u_max, np.ones(P))
    turns = {}
    for s in (1.0, -1.0):
        phi = _unwrap_rows(beta3 + s * inner * beta1)
        turns[s] = (np.abs((phi[:, -1] - phi[:, 0]) + TWO_PI) < 1e-3, phi)
    # as the single-design function: the branch sigma = -1 wins when both turn once
    use_neg = turns[-1.0][0]
    sigma = np.where(use_neg, -1.0, 1.0)
    phi_dense = np.where(use_neg[:, None], turns[-1.0][1], turns[1.0][1])
    no_turn = alive & ~(turns[1.0][0] | use_neg)
    score[no_turn] = 1.0
    alive &= ~no_turn
    psi_dense = phi_dense[:, :1] - phi_dense
    dpsi = np.diff(psi_dense, axis=1)
    backwards = dpsi <= 0
    back = alive & backwards.any(axis=1)
    runs = _runs(backwards)
    score = np.where(back, runs + np.degrees(np.where(backwards, -dpsi, 0.0).sum(axis=1))
                     / 30.0, score)
    alive &= ~back
    psi_dense = np.where(alive[:, None], psi_dense, grid[None, :] * TWO_PI)  # monotone

    psi = np.linspace(0.0, TWO_PI, n, endpoint=False)
    u, phi_k = invert_carrier(psi, u_dense, phi_dense, psi_dense, alive,
                               lambda x: _carrier_direction(tb, x, L1s, L2s, u_min, u_max,
                                                            sigma)[0])
    phi, tip = _carrier_direction(tb, u, L1s, L2s, u_min, u_max, sigma)
    phi = phi_k + wrap_angle(phi - phi_k)
    ex, ey = L1s[:, None] * np.cos(phi), L1s[:, None] * np.sin(phi)
    arm = _unwrap_rows(np.arctan2(tip[..., 1] - ey, tip[..., 0] - ex))
    planet_rel = arm - phi
    planet_rel = planet_rel - planet_rel[:, :1]
    net_arm = arm[:, -1] - arm[:, 0] + wrap_angle(arm[:, 0] - arm[:, -1])
    # carrier angle at each type-value point: exact, unwrapped by the dense grid
    u_pts = tb.knots[:, :-1]
    x_pts = u_pts - u_max[:, None]
    x_pts -= tb.period[:, None] * np.floor(x_pts / tb.period[:, None])
    j = np.clip(np.floor(x_pts / tb.period[:, None] * m).astype(int), 0, m - 1)
    phi_pts, _ = _carrier_direction(tb, u_pts, L1s, L2s, u_min, u_max, sigma)
    phi_j = phi_dense[np.arange(P)[:, None], j]
    point_psi = phi_dense[:, :1] - (phi_j + wrap_angle(phi_pts - phi_j))
    spins = alive & (np.abs(net_arm) > 1e-3)
    score[spins] = 1.0
    alive &= ~spins

    step = TWO_PI / n
    step_deg = 360.0 / n
    g = _node_slopes(planet_rel - psi, step) + 1.0
    bad = g <= 0
    reverses = alive & bad.any(axis=1)
    score = np.where(reverses, _run_score(bad, step_deg), score)
    alive &= ~reverses

    radii, planet_train, closure = _split_and_close(np.where(alive[:, None], g, 1.0),
                                                    split_exponent, A1, A2, step)
    train_rel = planet_train[:, :-1]  # anchored at the start, where the plan is 0
    arm_real = phi + train_rel + (arm[:, :1] - phi[:, :1])
    tip_real = np.stack([ex + L2s[:, None] * np.cos(arm_real),
                         ey + L2s[:, None] * np.sin(arm_real)], axis=-1)
    small = radii < min_pitch_radius
    pitch = alive & small.any(axis=(1, 2))
    score = np.where(pitch, sum(_run_score(small[:, i], step_deg) for i in range(4)), score)
    unclosed = alive & (closure.max(axis=1) >= 1e-9)
    score = np.where(unclosed, score + 1.0, score)
    alive &= ~pitch & ~unclosed
    return InversePopulation(
        pitch_tangent_angle=pitch_tangent_angle(radii, A1, step),
        feasible=alive, error_score=np.where(alive, 0.0, np.maximum(score, 1.0)), psi=psi,
        L1=L1, L2=L2, carrier_abs=phi, arm_angle_realized=arm_real, tip_realized=tip_real,
        point_carrier_angle=point_psi, pitch_radius_min=radii.min(axis=2),
        closure_error=closure)
