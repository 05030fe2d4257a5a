"""MFMC: mean-field Monte Carlo (Yu and Wu, CVPR 2004), as pinned in baselines.md §3.

Each target keeps its own bootstrap particle set (the bis_pf step 1); the
mean-field fixed point is then iterated ``iterations`` times, all targets at
once (Jacobi):

    q_i(n) ∝ pi_i(n) exp( sum_{j in Γ(i)} sum_m q_j(m) log psi(x_i^n, x_j^m) ),

starting from q_i = pi_i, with psi the bis_pf potential (eq 11) so that the
MRF methods differ only in inference.  Γ(i): targets whose clouds can overlap.  A pair's N x N table of log psi is
zero outside the particles of i that reach j's cloud and those of j that reach
i's, so only that block is formed.
"""

from dataclasses import dataclass

import numpy as np

from replication.filters.bis import DistributedFilter, cloud_extents, log_potential_table, neighbours, reaching
from replication.filters.joint import JointState
from replication.filters.registry import drawn
from replication.smc.weights import normalise


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
        blocks = {}  # (i, j) -> (rows of i, columns of j, log psi between them)
        for i, j in neighbours(particles):
            rows, cols = reaching(particles[i], low[j], high[j]), reaching(particles[j], low[i], high[i])
            blocks[i, j] = rows, cols, log_potential_table(particles[i][rows], particles[j][cols], float(self.beta))
        with np.errstate(divide="ignore"):
            log_pi = [np.log(p) for p in pi]
        q = list(pi)
        for _ in range(self.iterations):
            field = [np.zeros(len(p)) for p in pi]
            for (i, j), (rows, cols, table) in blocks.items():  # expected log-potential under the other's q
                field[i][rows] += table @ q[j][cols]
                field[j][cols] += table.T @ q[i][rows]
            q = [normalise(lp + f)[0] for lp, f in zip(log_pi, field)]
        return q
