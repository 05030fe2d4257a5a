"""MFMC: mean-field Monte Carlo (Yu and Wu, CVPR 2004), as pinned in baselines.md §3.

Each target keeps its own bootstrap particle set (the bis_pf step 1); the
mean-field fixed point is then iterated ``iterations`` times, all targets at
once (Jacobi):

    q_i(n) ∝ pi_i(n) exp( sum_{j in Γ(i)} sum_m q_j(m) log psi(x_i^n, x_j^m) ),

starting from q_i = pi_i, with psi the bis_pf potential (eq 11) so that the
MRF methods differ only in inference.  Γ(i): targets whose clouds can overlap.  A pair's N x N table of log psi is
zero outside the particles of i that reach j's cloud and those of j that reach
i's, so only that block is formed.  The whole interaction is one compiled call (:func:`_mean_field`).
"""

from dataclasses import dataclass

import numpy as np
from numba import njit
from numba.typed import List

from replication.compiled import matvec
from replication.filters.bis import DistributedFilter, _meeting, cloud_extents, log_potential_table
from replication.filters.frame import normalise_in_place, refuse
from replication.filters.joint import JointState
from replication.filters.registry import drawn


@drawn("purple", "-", "<")
@dataclass
class MFMC(DistributedFilter):
    n_particles: int = 400
    iterations: int = 5
    beta: float = 4.0

    def __post_init__(self):
        if self.n_particles <= 0 or self.iterations < 0 or self.beta < 0:
            raise ValueError(f"need N > 0, iterations >= 0, beta >= 0; got {self}")

    def interact(self, particles: list, pi: list, state: JointState) -> list:
        low, high = cloud_extents(particles)
        pairs = np.array(_meeting(low, high), dtype=np.int64).reshape(-1, 2)
        q, status = _mean_field(np.stack(particles).astype(float, copy=False), np.stack(pi), low, high, pairs,
                                float(self.beta), int(self.iterations))
        refuse(status)
        return list(q)


@njit(cache=True, error_model="numpy")
def _mean_field(states, pi, low, high, pairs, beta, iterations):
    """The fixed-point iterations for M targets of N particles (``states`` (M, N, d), ``pi`` (M, N)) and the
    neighbouring ``pairs``: (q (M, N), 0), or NOT_FINITE / DEGENERATE where a q_i cannot be normalised.

    A pair's block holds log psi between i's particles reaching j's extent (``low``, ``high``) and j's
    reaching i's; each iteration adds, pair by pair, block @ q_j to i's field and block^T @ q_i to j's
    (:func:`~replication.compiled.matvec`: numpy's BLAS calls), then normalises pi_i exp(field_i) as
    :func:`~replication.smc.weights.normalise` does (:func:`~replication.filters.frame.normalise_in_place`):
    the numbers of the numpy form to the bit."""
    m, n = pi.shape
    rows, cols, blocks = List(), List(), List()
    for p in range(pairs.shape[0]):
        i, j = pairs[p, 0], pairs[p, 1]
        rows.append(_reaching(states[i], low[j], high[j]))
        cols.append(_reaching(states[j], low[i], high[i]))
        blocks.append(log_potential_table(states[i][rows[p]], states[j][cols[p]], beta))
    log_pi = np.log(pi)
    q = pi.copy()
    for _ in range(iterations):
        field = np.zeros((m, n))
        for p in range(pairs.shape[0]):  # expected log-potential under the other's q
            i, j, block = pairs[p, 0], pairs[p, 1], blocks[p]
            if block.shape[0] == 0 or block.shape[1] == 0:  # numpy adds nothing, or exact zeros
                continue
            to_i = matvec(block, q[j][cols[p]])
            for r in range(rows[p].size):
                field[i, rows[p][r]] += to_i[r]
            to_j = matvec(block.T, q[i][rows[p]])
            for c in range(cols[p].size):
                field[j, cols[p][c]] += to_j[c]
        q = np.empty((m, n))
        for i in range(m):
            for k in range(n):
                q[i, k] = log_pi[i, k] + field[i, k]
            status, _ = normalise_in_place(q[i])
            if status:
                return q, status
    return q, 0


@njit(cache=True)
def _reaching(boxes, low, high):
    """Indices of the ``boxes`` that meet the extent [low, high] (:func:`~replication.filters.bis.reaching`)."""
    keep = np.empty(boxes.shape[0], np.int64)
    count = 0
    for r in range(boxes.shape[0]):
        inside = True
        for c in range(2):
            half = boxes[r, c + 2] / 2
            inside = inside and boxes[r, c] - half < high[c] and boxes[r, c] + half > low[c]
        if inside:
            keep[count] = r
            count += 1
    return keep[:count]
