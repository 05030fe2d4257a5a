"""PSO-PF: particle swarm optimisation moves the predicted particles towards high likelihood.

Fang, Tong and Xu's visual-tracking variant as pinned in ``baselines.md`` §1:
fitness F = the likelihood; personal bests start at the predicted particles,
the global best is the best of them, velocities start at zero; then for
k = 1..K

    v_i <- w v_i + c1 r1 (pbest_i - x_i) + c2 r2 (gbest - x_i),  r1, r2 ~ U(0, 1) per dimension,
    x_i <- x_i + v_i,

with |v| clamped per dimension, stopping early once log F(gbest) reaches
``stop_log_likelihood``.  The particles are then weighted by the likelihood
at their moved positions; the proposal correction is ignored, as in the
papers, which biases the filter (the move returns a zero correction).

``personal_bests: frame`` (baselines.md) starts pbest_i at the predicted
particle every frame; ``history`` starts it at the best of the predicted
particle and the positions particle i ended every earlier frame at, all
re-scored on the current frame: ism_pf section 5.2 says PSO-PF's cost grows
"with the number of historical moments" when computing each particle's
personal historical best, which only re-evaluation makes true.  Histories
follow the particle index, as in ISM-PF.
"""

from dataclasses import dataclass, field

import numpy as np

from replication.filters.qmc import NQMCProposal
from replication.filters.registry import drawn
from replication.smc.loop import ParticleFilter, ResamplingPolicy, prior_proposal

PERSONAL_BESTS = ("frame", "history")


@dataclass
class PSOMove:
    iterations: int = 10
    inertia: float = 0.729  # constriction coefficients (Clerc and Kennedy 2002)
    c1: float = 1.494
    c2: float = 1.494
    max_velocity: tuple[float, ...] = (8.0, 8.0, 2.0, 2.0)
    stop_log_likelihood: float | None = None
    personal_bests: str = "frame"
    history: list = field(default_factory=list, repr=False)

    def __post_init__(self):
        if self.personal_bests not in PERSONAL_BESTS:
            raise ValueError(f"unknown PSO personal_bests {self.personal_bests!r}; choose one of {PERSONAL_BESTS}")
        if self.iterations < 0:
            raise ValueError(f"iterations must be non-negative, got {self.iterations}")
        self.max_velocity = np.asarray(self.max_velocity, dtype=float)

    def __call__(self, particles, log_likelihood, rng):
        x = particles.copy()
        fitness = log_likelihood(x)
        best, best_fitness = x.copy(), fitness.copy()
        if self.personal_bests == "history" and self.history:
            best, best_fitness = self.history_bests(x, fitness, log_likelihood)
        velocity = np.zeros_like(x)
        if self.max_velocity.size not in (1, int(np.prod(x.shape[1:]))):
            raise ValueError(f"max_velocity has {self.max_velocity.size} entries for a state of shape {x.shape[1:]}")
        limit = self.max_velocity.reshape(x.shape[1:]) if self.max_velocity.size > 1 else self.max_velocity[0]
        for _ in range(self.iterations):
            leader = best[np.argmax(best_fitness)]
            if self.stop_log_likelihood is not None and best_fitness.max() >= self.stop_log_likelihood:
                break
            r1, r2 = rng.random(x.shape), rng.random(x.shape)
            velocity = self.inertia * velocity + self.c1 * r1 * (best - x) + self.c2 * r2 * (leader - x)
            velocity = np.clip(velocity, -limit, limit)
            x = x + velocity
            fitness = log_likelihood(x)
            improved = fitness > best_fitness
            best[improved], best_fitness[improved] = x[improved], fitness[improved]
        if self.personal_bests == "history":
            self.history.append(x.copy())
        return x, np.zeros(len(x))

    def history_bests(self, x, fitness, log_likelihood) -> tuple[np.ndarray, np.ndarray]:
        """pbest_i and log F(pbest_i) over x_i and particle i's earlier positions, re-scored in one call."""
        earlier = np.stack(self.history)  # (frames, N, d)
        rescored = log_likelihood(earlier.reshape(-1, earlier.shape[-1])).reshape(earlier.shape[:2])
        positions, values = np.concatenate([x[None], earlier]), np.vstack([fitness, rescored])
        frame = np.argmax(values, axis=0)  # ties keep the predicted particle
        columns = np.arange(len(x))
        return positions[frame, columns], values[frame, columns]


@drawn("orange", "-", "s")
def pso(n_particles: int, resampling: str = "systematic", ess_threshold: float = 1.0, points: str | None = None,
        **swarm) -> ParticleFilter:
    """Bootstrap PF with a PSO move between prediction and weighting; ``swarm`` are :class:`PSOMove` fields.

    ``points`` (e.g. ``good_cos``) draws the prediction's noise from that
    randomly shifted QMC point set instead (gps_qmcpf's PSO + good point set).
    """
    proposal = prior_proposal if points is None else NQMCProposal(randomise=True, points=points)
    return ParticleFilter(n_particles, ResamplingPolicy(resampling, ess_threshold), proposal, PSOMove(**swarm))
