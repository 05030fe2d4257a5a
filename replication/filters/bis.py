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

from dataclasses import dataclass, field

import numpy as np
from numba import njit

from replication.compiled import pairwise_sum
from replication.filters.registry import drawn
from replication.smc.loop import (
    FilterOutput,
    FilterState,
    ParticleFilter,
    ResamplingPolicy,
    Summaries,
    model_proposal,
)
from replication.filters.frame import BoxTargets, Targets, gather_rows, normalise_rows
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
    right-bottom corners (:func:`_extents`)."""
    return _extents(np.ascontiguousarray(np.concatenate(particles), dtype=float), np.cumsum([len(p) for p in particles]))


@njit(cache=True)
def _extents(stacked, ends):
    """Over each target's rows (up to ``ends[i]``), the least cx - w/2, cy - h/2 and the largest
    cx + w/2, cy + h/2, NaN from the first NaN on: ``np.minimum.reduceat`` and ``np.maximum.reduceat``."""
    low, high = np.full((ends.size, 2), np.inf), np.full((ends.size, 2), -np.inf)
    start = 0
    for i in range(ends.size):
        for r in range(start, ends[i]):
            for c in range(2):
                half = stacked[r, c + 2] / 2
                lower, upper = stacked[r, c] - half, stacked[r, c] + half
                if not np.isnan(low[i, c]) and (lower < low[i, c] or np.isnan(lower)):
                    low[i, c] = lower
                if not np.isnan(high[i, c]) and (upper > high[i, c] or np.isnan(upper)):
                    high[i, c] = upper
        start = ends[i]
    return low, high


def neighbours(particles: list) -> list[tuple[int, int]]:
    """Pairs (i < j) of targets whose particle clouds can overlap: the MRF's edges this frame."""
    return _meeting(*cloud_extents(particles))


@njit(cache=True)
def _meeting(low, high):
    """The pairs (i < j), in order, whose extents overlap on both axes."""
    pairs = []
    for i in range(low.shape[0]):
        for j in range(i + 1, low.shape[0]):
            if low[i, 0] < high[j, 0] and low[j, 0] < high[i, 0] and low[i, 1] < high[j, 1] and low[j, 1] < high[i, 1]:
                pairs.append((i, j))
    return pairs


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
    (:func:`_draw_log_potential`, :func:`_marginals`), with no (K, 4) copy of each target's drawn
    states; the arithmetic and its order are those of :func:`pairwise_log_potential`,
    ``np.bincount`` and numpy's sums, so the histograms are the same to the bit.
    """
    pairs = np.array(neighbours(particles), dtype=np.int64).reshape(-1, 2)  # eq (8); draws lie in their clouds
    if len({len(p) for p in particles}) == 1:
        n = len(pi[0])
        draws = inverse_cdf_rows(np.stack(pi), rng.random((len(pi), k)))  # B_i(k), eq (5): one pass for all targets
        log_w = _draw_log_potential(np.stack(particles).astype(float, copy=False), draws, pairs, float(beta))
        return list(_marginals(draws, log_w, n))
    draws = np.stack([multinomial(p, rng, size=k) for p in pi])  # targets with different N: the numpy form
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
    """sum over the pairs (i, j) of log phi(x_i[B_i(k)], x_j[B_j(k)]) for every joint draw k (each
    particle's :func:`_edges` formed once)."""
    edges = np.empty((states.shape[0], states.shape[1], 6))
    for i in range(states.shape[0]):
        for n in range(states.shape[1]):
            edges[i, n] = _edges(states[i, n])
    total = np.zeros(draws.shape[1])
    finite = beta < np.inf
    for p in range(pairs.shape[0]):
        i, j = pairs[p, 0], pairs[p, 1]
        for k in range(draws.shape[1]):
            a, b = edges[i, draws[i, k]], edges[j, draws[j, k]]
            if (finite and min(a[0], b[0]) - max(a[1], b[1]) < 0 and min(a[2], b[2]) - max(a[3], b[3]) < np.inf
                    and a[4] * a[5] * b[4] * b[5] > 0):
                continue  # apart along x: log phi is -0.0, adding nothing (where no NaN or infinity would arise)
            total[k] += _log_phi(a, a[4] * a[5], b, beta)
    return total


@njit(cache=True)
def _marginals(draws, log_w, n):
    """W_i (M, n) from the draws and their log MRF weights: ``w = exp(log_w - max)``, each target's
    :func:`_tally`, divided by its sum (numpy's order)."""
    top = log_w.max() if not np.isnan(log_w).any() else np.nan
    w = np.empty(log_w.size)
    for k in range(log_w.size):
        w[k] = np.exp(log_w[k] - top)
    out = _tally(draws, w, n)
    for i in range(out.shape[0]):
        total = pairwise_sum(out[i])
        for u in range(n):
            out[i, u] = out[i, u] / total
    return out


@njit(cache=True)
def _tally(draws, w, n):
    """Each target's ``np.bincount(B_i, weights=w, minlength=n)``, in the order of the draws."""
    out = np.zeros((draws.shape[0], n))
    for i in range(draws.shape[0]):
        for k in range(draws.shape[1]):
            out[i, draws[i, k]] += w[k]
    return out


EVERY_STEP = ResamplingPolicy("multinomial", 1.0)  # bis_pf's step 1 resamples every frame


@dataclass
class DistributedState:
    """The targets of a distributed filter: one :class:`~replication.smc.loop.FilterState` each, sharing ``rng``.

    ``models``, ``particles``, ``log_weights`` and ``records`` are read off the targets' states,
    as a :class:`JointState` holds them.
    """

    targets: list[FilterState]
    rng: np.random.Generator
    t: int = 0
    as_one: Targets = field(default_factory=Targets)

    def box_targets(self) -> BoxTargets | None:
        """The targets' models as one (:class:`~replication.filters.frame.BoxTargets`), or None."""
        return self.as_one(self.models)

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

    resampling = EVERY_STEP

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
        boxes = state.box_targets() if state.targets and self.resampling == EVERY_STEP else None
        if boxes is not None:
            return self.whole_frame(state, z, boxes)
        loop = self.loop
        state.t += 1
        weighed = [loop.weigh(target, z) for target in state.targets]
        final = self.interact([w.particles for w in weighed], [w.weights for w in weighed], state)
        for target, w, weights in zip(state.targets, weighed, final):
            loop.conclude(target, w.reweighted(weights))

    def whole_frame(self, state: DistributedState, z, boxes: BoxTargets) -> None:
        """:meth:`step` with every target's motion, likelihood, weights and resampling done for all targets
        at once (:mod:`replication.filters.frame`): the loop's weigh of each target, the interaction, then
        its conclude, with the same random draws in the same order and the same numbers."""
        targets, n, rng = state.targets, self.n_particles, state.rng
        m = len(targets)
        state.t += 1
        for target in targets:
            target.t += 1
        offsets = np.arange(m + 1) * n
        moved = boxes.propagate(np.concatenate([target.particles for target in targets]), offsets, state.t, rng)
        log_likelihood = boxes.log_likelihood(moved, offsets, z, state.t).reshape(m, n)
        weights, log_totals, degenerate = normalise_rows(np.stack([target.log_weights for target in targets]), log_likelihood,
                                                          corrected=True)
        moved = moved.reshape(m, n, -1)
        final = self.interact(list(moved), list(weights), state)
        for target, particles, pi, log_total, flag in zip(targets, moved, final, log_totals, degenerate):
            target.log_evidence += log_total
            target.records.add(particles, pi, bool(flag))
            target.records.resampled.append(True)
        ancestors = inverse_cdf_rows(np.stack(final), rng.random((m, n)))  # each target's multinomial, in turn
        resampled = gather_rows(moved, ancestors)
        log_weights = np.full((m, n), -np.log(n))
        for target, particles, uniform in zip(targets, resampled, log_weights):
            target.particles, target.log_weights = particles, uniform


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
        with np.errstate(divide="ignore"):
            log_weights = np.log(weights)
        for i, particles in enumerate(moved):
            state.record(i, particles, weights, degenerate, log_weights)
