"""Joint multi-target filters with the bis_pf MRF: BIS-PF (bis_pf, section 2) and MRF-JPF (Khan et al. 2004).

BIS-PF:

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

MRF-JPF: N joint particles, each holding every target's state; each target's
part moves by its own motion model; the joint weight is the product of the
targets' likelihoods and of the pairwise potentials (the same phi as BIS-PF,
so the two differ only in inference); resampled jointly every frame.  Its cost
and variance grow exponentially with the number of targets.
"""

from dataclasses import dataclass

import numpy as np
from numba import njit

from replication.filters.registry import drawn
from replication.smc.loop import (
    FilterOutput,
    FilterState,
    ParticleFilter,
    ResamplingPolicy,
    Summaries,
    model_proposal,
)
from replication.filters.joint import JointFilter, JointState
from replication.smc.resampling import inverse_cdf_rows, multinomial
from replication.smc.weights import DegenerateWeightsError, normalise


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


def cloud_extents(particles: list) -> tuple[np.ndarray, np.ndarray]:
    """Each target's cloud extent, the box covering every particle's box: (M, 2) left-top and
    right-bottom corners, from one ``reduceat`` over the stacked clouds."""
    stacked = np.concatenate(particles)
    starts = np.cumsum([0] + [len(p) for p in particles[:-1]])
    half = stacked[:, 2:4] / 2
    return np.minimum.reduceat(stacked[:, :2] - half, starts), np.maximum.reduceat(stacked[:, :2] + half, starts)


def neighbours(particles: list) -> list[tuple[int, int]]:
    """Pairs (i < j) of targets whose particle clouds can overlap: the MRF's edges this frame."""
    low, high = cloud_extents(particles)
    meet = ((low[:, None] < high[None, :]) & (low[None, :] < high[:, None])).all(axis=-1)
    return [(int(i), int(j)) for i, j in zip(*np.nonzero(np.triu(meet, 1)))]


def reaching(boxes: np.ndarray, low: np.ndarray, high: np.ndarray) -> np.ndarray:
    """Indices of the ``boxes`` that meet the extent [low, high]: the only ones another cloud can touch."""
    half = boxes[:, 2:4] / 2
    return np.flatnonzero(((boxes[:, :2] - half < high) & (boxes[:, :2] + half > low)).all(axis=1))


def pairwise_log_potential(states: list, beta: float, pairs: list | None = None) -> np.ndarray:
    """sum over target pairs whose clouds can overlap (``pairs``, else found from ``states``) of
    log phi, for aligned samples states[i][k]."""
    total = np.zeros(len(states[0]))
    for i, j in neighbours(states) if pairs is None else pairs:
        total += log_potential(states[i], states[j], beta)
    return total


def bootstrap_histograms(particles: list, pi: list, k: int, beta: float, rng: np.random.Generator) -> list:
    """The marginal posteriors W_i (eq 10) from K joint bootstrap draws weighted by the MRF (eqs 5-8, 11).

    The draws B_i(k) are each target's K uniforms, drawn target after target, through the linear
    inverse CDF of :func:`~replication.smc.resampling.multinomial` (for targets of one N, all rows in
    one call: :func:`~replication.smc.resampling.inverse_cdf_rows`); the potentials of the
    neighbouring pairs and the K-draw tallies are compiled loops over the drawn indices
    (:func:`_draw_log_potential`, :func:`_tally`), with no (K, 4) copy of each target's drawn
    states; the arithmetic and its order are those of :func:`pairwise_log_potential` and
    ``np.bincount``, so the histograms are the same to the bit.
    """
    pairs = np.array(neighbours(particles), dtype=np.int64).reshape(-1, 2)  # eq (8); draws lie in their clouds
    if len({len(p) for p in particles}) == 1:
        draws = inverse_cdf_rows(np.stack(pi), rng.random((len(pi), k)))  # B_i(k), eq (5): one pass for all targets
        log_w = _draw_log_potential(np.stack(particles).astype(float, copy=False), draws, pairs, float(beta))
    else:  # targets with different N: the numpy form
        draws = np.stack([multinomial(p, rng, size=k) for p in pi])
        log_w = pairwise_log_potential([p[d] for p, d in zip(particles, draws)], beta, [tuple(q) for q in pairs])
    w = np.exp(log_w - log_w.max())
    tallies = _tally(draws, w, max(len(p) for p in particles))
    return [h[: len(p)] / h[: len(p)].sum() for h, p in zip(tallies, particles)]  # np.bincount's minlength=len(p)


@njit(cache=True, inline="always")
def _edges(box):
    """A box (cx, cy, w, h) as (right, left, bottom, top, w, h), computed as :func:`box_overlap` does."""
    return box[0] + box[2] / 2, box[0] - box[2] / 2, box[1] + box[3] / 2, box[1] - box[3] / 2, box[2], box[3]


@njit(cache=True, inline="always", error_model="numpy")
def _log_phi(a, area_a, b, beta):
    """:func:`log_potential` of boxes a and b given as :func:`_edges` (and a's w h as ``area_a``), in the
    same operations and order as its numpy form, so the compiled loops give its numbers to the bit."""
    dx = min(a[0], b[0]) - max(a[1], b[1])
    dy = min(a[2], b[2]) - max(a[3], b[3])
    overlap = (dx if not dx < 0 else 0.0) * (dy if not dy < 0 else 0.0)  # np.clip(., 0, None)
    ratio = overlap * overlap / (area_a * b[4] * b[5])
    return -beta * (ratio * ratio)


@njit(cache=True, error_model="numpy")
def log_potential_table(a, b, beta):
    """The (len(a), len(b)) table of log phi(a_r, b_c): ``log_potential(a[:, None], b[None, :], beta)``
    in one compiled pass, without its dozen (R, C) temporaries (MFMC's pair blocks)."""
    edges_b = np.empty((6, b.shape[0]))  # one row per edge, so that the inner loop runs along rows
    for c in range(b.shape[0]):
        edges_b[:, c] = _edges(b[c])
    out = np.empty((a.shape[0], b.shape[0]))
    for r in range(a.shape[0]):
        edges_a, area_a = _edges(a[r]), a[r, 2] * a[r, 3]
        for c in range(b.shape[0]):
            out[r, c] = _log_phi(edges_a, area_a, edges_b[:, c], beta)
    return out


@njit(cache=True, error_model="numpy")
def _draw_log_potential(states, draws, pairs, beta):
    """sum over the pairs (i, j) of log phi(x_i[B_i(k)], x_j[B_j(k)]) for every joint draw k."""
    total = np.zeros(draws.shape[1])
    for p in range(pairs.shape[0]):
        i, j = pairs[p, 0], pairs[p, 1]
        for k in range(draws.shape[1]):
            a, b = states[i, draws[i, k]], states[j, draws[j, k]]
            total[k] += _log_phi(_edges(a), a[2] * a[3], _edges(b), beta)
    return total


@njit(cache=True)
def _tally(draws, w, n):
    """Each target's ``np.bincount(B_i, weights=w, minlength=n)``, in the order of the draws."""
    out = np.zeros((draws.shape[0], n))
    for i in range(draws.shape[0]):
        for k in range(draws.shape[1]):
            out[i, draws[i, k]] += w[k]
    return out


@dataclass
class DistributedState:
    """The targets of a distributed filter: one :class:`~replication.smc.loop.FilterState` each, sharing ``rng``.

    ``models``, ``particles``, ``log_weights`` and ``records`` are read off the targets' states,
    as a :class:`JointState` holds them.
    """

    targets: list[FilterState]
    rng: np.random.Generator
    t: int = 0

    @property
    def models(self) -> list:
        return [target.model for target in self.targets]

    @property
    def particles(self) -> list:
        return [target.particles for target in self.targets]

    @property
    def log_weights(self) -> list:
        return [target.log_weights for target in self.targets]

    @property
    def records(self) -> list[Summaries]:
        return [target.records for target in self.targets]

    def outputs(self) -> list[FilterOutput]:
        return [target.records.output(log_evidence=float("nan")) for target in self.targets]


class DistributedFilter(JointFilter):
    """M particle filters, one per target, on the one :class:`~replication.smc.loop.ParticleFilter` loop,
    whose weights an ``interact`` stage couples between the loop's two halves.

    Each frame every target's filter proposes from its model (the motion prior, or a proposal
    fusing detections) and is weighted by its own likelihood: pi (bis_pf's step 1, and the
    starting point of MFMC and DMOT); ``interact(particles, pi, state)`` returns each target's
    final normalised weights, from which the loop records the estimate and resamples
    (``resampling``: multinomial every step, as bis_pf's step 1 resamples every frame).  The
    targets share one random stream.
    """

    resampling = ResamplingPolicy("multinomial", 1.0)

    @property
    def loop(self) -> ParticleFilter:
        return ParticleFilter(self.n_particles, self.resampling, proposal=model_proposal)

    def start(self, models: list, rng: np.random.Generator) -> DistributedState:
        state = DistributedState([], rng)
        for model in models:
            self.add(state, model)
        return state

    def add(self, state: DistributedState, model) -> None:
        """A target is born at the state's step: its filter starts from ``model``'s prior."""
        target = self.loop.start(model, state.rng)
        target.t = state.t
        state.targets.append(target)

    def remove(self, state: DistributedState, index: int) -> None:
        del state.targets[index]

    def step(self, state: DistributedState, z) -> None:
        loop = self.loop
        state.t += 1
        weighed = [loop.weigh(target, z) for target in state.targets]
        final = self.interact([w.particles for w in weighed], [w.weights for w in weighed], state)
        for target, w, weights in zip(state.targets, weighed, final):
            loop.conclude(target, w.reweighted(weights))


@drawn("blue", "-", "s")
@dataclass
class MIPF(DistributedFilter):
    """M independent bootstrap PFs: the distributed step with the identity interaction (the final weights are pi).

    On a fixed set of targets MIPF runs as one :class:`~replication.smc.loop.ParticleFilter` per
    target (``filter: bootstrap``); this form shares the joint filters' step so that on a real
    video, with births and deaths, MIPF and BIS-PF differ only in their interaction.
    """

    n_particles: int = 400

    def __post_init__(self):
        if self.n_particles <= 0:
            raise ValueError(f"N must be positive, got N={self.n_particles}")

    def interact(self, particles: list, pi: list, state: JointState) -> list:
        return pi


@drawn("vermillion", "-", "*")
@dataclass
class BISPF(DistributedFilter):
    """M bootstrap PFs of ``n_particles`` joined by ``n_joint`` (K) bootstrap draws and the MRF potential."""

    n_particles: int = 400
    n_joint: int = 4000
    beta: float = 4.0

    def __post_init__(self):
        if self.n_particles <= 0 or self.n_joint <= 0:
            raise ValueError(f"N and K must be positive, got N={self.n_particles}, K={self.n_joint}")
        if self.beta < 0:
            raise ValueError(f"beta must be non-negative, got {self.beta}")

    def interact(self, particles: list, pi: list, state: JointState) -> list:
        return bootstrap_histograms(particles, pi, self.n_joint, self.beta, state.rng)


@drawn("green", "-", "h")
@dataclass
class MRFJPF(JointFilter):
    """Joint particle filter over all targets with the MRF interaction (Khan, Balch, Dellaert 2004)."""

    n_particles: int = 6000
    beta: float = 4.0

    def __post_init__(self):
        if self.n_particles <= 0 or self.beta < 0:
            raise ValueError(f"need N > 0 and beta >= 0, got N={self.n_particles}, beta={self.beta}")

    def step(self, state: JointState, z) -> None:
        rng, n = state.rng, self.n_particles
        state.t += 1
        ancestors = multinomial(np.exp(state.log_weights[0]), rng)  # one joint resampling: rows stay aligned
        moved = [model.propagate(p[ancestors], state.t, rng) for model, p in zip(state.models, state.particles)]
        log_w = sum(model.log_likelihood(p, z, state.t) for model, p in zip(state.models, moved))
        log_w = log_w + pairwise_log_potential(moved, self.beta)
        try:
            weights, _ = normalise(log_w)
            degenerate = False
        except DegenerateWeightsError:
            weights, degenerate = np.full(n, 1.0 / n), True
        for i, particles in enumerate(moved):
            state.record(i, particles, weights, degenerate)
