"""Compiled kernel of the differential internal-engagement train (seed 001 Eq. 1-10):
designs x arms x samples in one pass, no (P, J, S) temporaries (numba, cached).

Imported by ``mechanisms.transplanter.simulate_differential`` when it runs, never at
start-up. Every line is the numpy expression it replaced, element by element, in the
same order of operations (see simulate_differential for the physics).
"""

from __future__ import annotations

import math

import numba
import numpy as np

TWO_PI = 2.0 * np.pi


@numba.njit(cache=True, nogil=True)
def differential_motion(grid, Q, q_rate, dq_rate, lobes, advance, phase0, Q0, carrier0,
                        axis_distance, offset, psi, S, H1, beta, break_angle, play,
                        centre, A, B, phi2, ang, tip_rate, planet_rate):
    """Fill the (P, J, S) outputs centre, A, B (complex, mm), phi2, ang (rad), tip_rate
    (complex, mm/rad), planet_rate (d gamma_2 / d psi).

    grid (D+1,): lobe phases of the tables Q, q_rate = dQ/dp, dq_rate = d2Q/dp2 (P, D+1);
    lobes n, advance m (lobes per carrier turn); per design (P,): phase0 (lobe phase of
    arm 0's mesh point at the start), Q0 (Q there), carrier0 (phi_H0), axis_distance
    (a + carrier offset), S, H1, beta, break_angle, play (backlash, rad; 0: none);
    offset (J,): arm j's carrier offset 2 pi j / J; psi (S,): carrier angles."""
    P, J, N = centre.shape
    h = grid[1] - grid[0]
    last = grid.shape[0] - 2
    for p in range(P):
        bend = complex(math.cos(break_angle[p]), math.sin(break_angle[p]))
        for j in range(J):
            for s in range(N):
                # mesh point of arm j: lobe phase, its dense interval and Hermite parameter
                ph = phase0[p] + (advance * psi[s] + lobes * offset[j])
                turns = math.floor(ph / TWO_PI)
                frac = ph - turns * TWO_PI
                k = min(max(int(frac / h), 0), last)
                t = (frac - grid[k]) / h
                t2 = t * t
                t3 = t2 * t
                h00, h10 = 2 * t3 - 3 * t2 + 1, (t3 - 2 * t2 + t) * h
                h01, h11 = -2 * t3 + 3 * t2, (t3 - t2) * h
                q = (h00 * Q[p, k] + h10 * q_rate[p, k] + h01 * Q[p, k + 1]
                     + h11 * q_rate[p, k + 1]) + TWO_PI * turns
                rate = (h00 * q_rate[p, k] + h10 * dq_rate[p, k] + h01 * q_rate[p, k + 1]
                        + h11 * dq_rate[p, k + 1])
                phiH = carrier0[p] - (offset[j] + psi[s])
                centre[p, j, s] = axis_distance[p] * complex(math.cos(phiH), math.sin(phiH))
                phi2[p, j, s] = phiH + (q - Q0[p])
                planet_rate[p, j, s] = advance * rate
            if play[p] != 0.0:  # mechanisms.backlash.backlash_offset, per row
                first, prev = planet_rate[p, j, 0], planet_rate[p, j, N - 1]
                for s in range(N):
                    nxt = planet_rate[p, j, s + 1] if s + 1 < N else first
                    slope = nxt - prev
                    prev = planet_rate[p, j, s]
                    phi2[p, j, s] = phi2[p, j, s] + -0.5 * play[p] * np.sign(slope)
            for s in range(N):  # the planting arm (Eq. 9-10)
                a = phi2[p, j, s] + beta[p]
                along = complex(math.cos(a), math.sin(a))
                c = centre[p, j, s]
                ang[p, j, s] = a
                B[p, j, s] = c + S[p] * along
                A[p, j, s] = c + H1[p] * (along * bend)
                tip_rate[p, j, s] = -1j * c + (1j * S[p]) * (planet_rate[p, j, s] - 1.0) * along
