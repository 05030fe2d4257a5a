"""BIS-PF: bootstrap importance sampling for multi-target tracking (bis_pf, section 2).

Per frame, with M targets of N particles each:

1. every target runs its own bootstrap PF step: resample from its bootstrap
   histogram W_{t-1}, propagate, and weight by its own likelihood, pi (eq 4);
2. K joint samples are drawn by bootstrap: for each k and each target i an
   index B_i(k) ~ pi_i, independently (eqs 5-7: the proposal Q is the product
   of the per-target posteriors);
3. each joint sample gets the MRF weight w_k = prod over pairs of
   phi(x_i, x_j) = exp(-beta (overlap^2 / (area_i area_j))^2) (eqs 8, 11);
4. the bootstrap histogram W_i(n) = sum of w_k over the k with B_i(k) = n
   (eq 10) is target i's marginal posterior; its mean is the estimate.

The K x M draws are one inverse-CDF call per target; only pairs of targets
whose particle clouds can overlap contribute factors, each over all K at once.
"""

from dataclasses import dataclass

import numpy as np

from replication.smc.loop import FilterOutput
from replication.smc.resampling import multinomial
from replication.smc.weights import DegenerateWeightsError, ess, normalise, weighted_mean, weighted_variance


def box_overlap(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Overlap area of boxes given as (cx, cy, w, h), elementwise."""
    dx = np.minimum(a[..., 0] + a[..., 2] / 2, b[..., 0] + b[..., 2] / 2) - np.maximum(
        a[..., 0] - a[..., 2] / 2, b[..., 0] - b[..., 2] / 2
    )
    dy = np.minimum(a[..., 1] + a[..., 3] / 2, b[..., 1] + b[..., 3] / 2) - np.maximum(
        a[..., 1] - a[..., 3] / 2, b[..., 1] - b[..., 3] / 2
    )
    return np.clip(dx, 0, None) * np.clip(dy, 0, None)


def log_potential(a: np.ndarray, b: np.ndarray, beta: float) -> np.ndarray:
    """log phi(x_i, x_j) = -beta (overlap^2 / (area_i area_j))^2 (bis_pf eq 11)."""
    ratio = box_overlap(a, b) ** 2 / (a[..., 2] * a[..., 3] * b[..., 2] * b[..., 3])
    return -beta * ratio**2


def _extent(particles: np.ndarray) -> np.ndarray:
    """The box (left, top, right, bottom) covering every particle's box."""
    half = particles[:, 2:4] / 2
    return np.concatenate([(particles[:, :2] - half).min(axis=0), (particles[:, :2] + half).max(axis=0)])


def bootstrap_histograms(particles: list, pi: list, k: int, beta: float, rng: np.random.Generator) -> list:
    """The marginal posteriors W_i (eq 10) from K joint bootstrap draws weighted by the MRF (eqs 5-8, 11)."""
    draws = [multinomial(p, rng, size=k) for p in pi]  # B_i(k), eq (5)
    log_w = np.zeros(k)
    extents = [_extent(p) for p in particles]
    for i in range(len(particles)):
        for j in range(i + 1, len(particles)):
            a, b = extents[i], extents[j]
            if a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3]:  # only clouds that can overlap
                log_w += log_potential(particles[i][draws[i]], particles[j][draws[j]], beta)
    w = np.exp(log_w - log_w.max())
    histograms = [np.bincount(d, weights=w, minlength=len(p)) for d, p in zip(draws, particles)]
    return [h / h.sum() for h in histograms]


@dataclass
class JointState:
    models: list
    rng: np.random.Generator
    particles: list
    log_weights: list
    t: int = 0

    def __post_init__(self):
        self.records = [{k: [] for k in ("means", "variances", "ess", "resampled", "degenerate")} for _ in self.models]

    def outputs(self) -> list[FilterOutput]:
        return [
            FilterOutput(
                means=np.asarray(r["means"]),
                variances=np.asarray(r["variances"]),
                ess=np.asarray(r["ess"]),
                resampled=np.asarray(r["resampled"], dtype=bool),
                degenerate=np.asarray(r["degenerate"], dtype=bool),
                log_evidence=float("nan"),
            )
            for r in self.records
        ]


@dataclass
class BISPF:
    """M bootstrap PFs of ``n_particles`` joined by ``n_joint`` (K) bootstrap draws and the MRF potential."""

    n_particles: int = 400
    n_joint: int = 4000
    beta: float = 4.0
    joint = True  # one filter for all targets of a run

    def __post_init__(self):
        if self.n_particles <= 0 or self.n_joint <= 0:
            raise ValueError(f"N and K must be positive, got N={self.n_particles}, K={self.n_joint}")
        if self.beta < 0:
            raise ValueError(f"beta must be non-negative, got {self.beta}")

    def start(self, models: list, rng: np.random.Generator) -> JointState:
        n = self.n_particles
        return JointState(models, rng, [m.sample_initial(n, rng) for m in models], [np.full(n, -np.log(n)) for _ in models])

    def step(self, state: JointState, z) -> None:
        rng, n = state.rng, self.n_particles
        state.t += 1
        proposed, local, degenerate = [], [], []
        for i, model in enumerate(state.models):  # step 1: independent bootstrap PFs
            ancestors = multinomial(np.exp(state.log_weights[i]), rng)
            particles = model.propagate(state.particles[i][ancestors], state.t, rng)
            log_pi = model.log_likelihood(particles, z, state.t)
            try:
                pi, _ = normalise(log_pi)
                degenerate.append(False)
            except DegenerateWeightsError:  # nothing seen: the prediction stands
                pi = np.full(n, 1.0 / n)
                degenerate.append(True)
            proposed.append(particles)
            local.append(pi)
        histograms = bootstrap_histograms(proposed, local, self.n_joint, self.beta, rng)
        for i, (particles, histogram) in enumerate(zip(proposed, histograms)):
            with np.errstate(divide="ignore"):
                state.log_weights[i] = np.log(histogram)
            state.particles[i] = particles
            record = state.records[i]
            record["means"].append(weighted_mean(particles, histogram))
            record["variances"].append(weighted_variance(particles, histogram))
            record["ess"].append(ess(histogram))
            record["resampled"].append(True)
            record["degenerate"].append(degenerate[i])
