"""MCMC-PF: Metropolis-Hastings over the joint state with the MRF (Khan, Balch, Dellaert 2004).

As pinned in baselines.md §2.  Each frame:

1. start the chain from a random carried sample, every target moved by its motion;
2. run B + N iterations (B = ``burn_in`` x N): pick a target i uniformly, propose
   X'_i from the predictive mixture (a random carried sample r', then the motion
   model), accept with
   min(1, L(z_i | X'_i) prod_j psi(X'_i, X_j) / (L(z_i | X_i) prod_j psi(X_i, X_j))),
   the prior terms cancelling because the proposal is the predictive mixture;
3. keep the N states after burn-in (equal weights): the estimate is their mean;
   the ``carry`` (10 in bis_pf) best of them by likelihood times potentials
   (tracked incrementally; the predictive prior is not scored) go to the next frame.

The proposals do not depend on the chain, so all of a frame's proposals and
their likelihoods are drawn in one vectorised pass per target; the chain itself
is a short scalar loop over the potentials of the moved target's neighbours.
psi is the bis_pf potential (eq 11), as for the other MRF methods.
"""

import math
from dataclasses import dataclass

import numpy as np

from replication.filters.bis import JointFilter, JointState


def _log_psi(a, b, beta: float) -> float:
    """log psi for two boxes (cx, cy, w, h) as plain floats: bis_pf eq (11)."""
    dx = min(a[0] + a[2] / 2, b[0] + b[2] / 2) - max(a[0] - a[2] / 2, b[0] - b[2] / 2)
    dy = min(a[1] + a[3] / 2, b[1] + b[3] / 2) - max(a[1] - a[3] / 2, b[1] - b[3] / 2)
    if dx <= 0 or dy <= 0:
        return 0.0
    ratio = (dx * dy) ** 2 / (a[2] * a[3] * b[2] * b[3])
    return -beta * ratio * ratio


@dataclass
class MCMCPF(JointFilter):
    n_particles: int = 6000  # samples kept per frame after burn-in
    burn_in: float = 0.25  # share of N discarded first
    carry: int = 10  # best samples carried to the next frame
    beta: float = 4.0

    def __post_init__(self):
        if self.n_particles <= 0 or not 0 <= self.burn_in < 10 or self.carry <= 0 or self.beta < 0:
            raise ValueError(f"need N > 0, 0 <= burn_in, carry > 0, beta >= 0; got {self}")

    def start(self, models: list, rng: np.random.Generator) -> JointState:
        state = super().start(models, rng)
        state.carried = [p[: self.carry] for p in state.particles]  # the joint samples the next frame starts from
        return state

    def step(self, state: JointState, z) -> None:
        rng, m = state.rng, len(state.models)
        state.t += 1
        carried = state.carried
        burn = int(self.burn_in * self.n_particles)
        total = burn + self.n_particles
        targets = rng.integers(m, size=total)
        sources = rng.integers(len(carried[0]), size=total)
        proposals = np.empty((total, carried[0].shape[1]))
        log_like = np.empty(total)
        for i, model in enumerate(state.models):  # every proposal and its likelihood, one pass per target
            chosen = np.flatnonzero(targets == i)
            proposals[chosen] = model.propagate(carried[i][sources[chosen]], state.t, rng)
            log_like[chosen] = model.log_likelihood(proposals[chosen], z, state.t)
        start = int(rng.integers(len(carried[0])))
        current = [model.propagate(p[start : start + 1], state.t, rng)[0] for model, p in zip(state.models, carried)]
        current_like = [float(model.log_likelihood(c[None], z, state.t)[0]) for model, c in zip(state.models, current)]
        uniforms = np.log(rng.random(total))
        kept = np.empty((self.n_particles, m, proposals.shape[1]))
        score = np.empty(self.n_particles)  # log of likelihoods times potentials of each kept state
        current_psi = sum(_log_psi(current[i], current[j], self.beta) for i in range(m) for j in range(i + 1, m))
        for k in range(total):
            i, proposal = targets[k], proposals[k]
            delta_psi = sum(
                _log_psi(proposal, current[j], self.beta) - _log_psi(current[i], current[j], self.beta)
                for j in range(m)
                if j != i
            )
            with np.errstate(invalid="ignore"):
                log_ratio = log_like[k] - current_like[i] + delta_psi
            if log_ratio >= uniforms[k] or (current_like[i] == -math.inf and log_like[k] > -math.inf):
                current[i], current_like[i] = proposal, log_like[k]
                current_psi += delta_psi
            if k >= burn:
                kept[k - burn] = current
                score[k - burn] = sum(current_like) + current_psi
        best = np.argsort(score)[-self.carry :]
        weights = np.full(self.n_particles, 1.0 / self.n_particles)
        for i in range(m):
            state.record(i, kept[:, i], weights, False)
        state.carried = [kept[best, i] for i in range(m)]
