"""Whole-frame steps: every target's motion, likelihood and weights in one compiled call each.

A joint filter on M targets moves, scores and normalises each target's particles in turn, a chain of
Python calls per target and frame (propose, the likelihood's wrappers, normalise, resample) that costs as
much as the compiled work it wraps on bis_pf's balls.  When every target is a plain
:class:`~replication.models.box.BoxModel` (the motion prior as proposal) with one motion and a colour
likelihood of one sample pattern, :class:`BoxTargets` does each of those once for all targets: the
targets' normals drawn in one call (the same numbers, in the same order, as one call per target), moved
in one compiled pass, and scored by one call of the colour kernel
(:class:`~replication.vision.joint.ColourLikelihoods`); :func:`normalise_rows` then weights every
target at once.  Each gives the bits of the per-target path; a filter falls back to that path for any
other model (a proposal fusing detections, a fused likelihood).
"""

import numpy as np
from numba import njit

from replication.errors import NotFinite
from replication.models.box import BoxModel
from replication.smc.loop import ParticleFilter, prior_proposal
from replication.smc.resampling import inverse_cdf_rows
from replication.smc.weights import DegenerateWeightsError, exp_sum
from replication.smc.work import Counted
from replication.vision.joint import ColourLikelihoods


class BoxTargets:
    """M targets' box models as one: ``propagate`` and ``log_likelihood`` over their particles stacked
    (R, d), target i's rows ``offsets[i]:offsets[i + 1]``, counted as each model's own calls would be
    (:class:`~replication.smc.work.Counted`)."""

    def __init__(self, models: list, boxes: list[BoxModel], likelihoods: ColourLikelihoods):
        works = [model.work if isinstance(model, Counted) else None for model in models]
        self.works = ([(works[0], len(works))] if works[0] is not None and all(w is works[0] for w in works)  # a run's tally
                      else [(work, 1) for work in works])  # each tally, and how many targets in a row count into it
        self.first, self.likelihoods = boxes[0], likelihoods

    @classmethod
    def of(cls, models: list) -> "BoxTargets | None":
        """The models as one, or None unless each is a :class:`BoxModel` (or one counted), all with the
        first's motion and frame cache, and with colour likelihoods of one pattern."""
        boxes = [model.model if isinstance(model, Counted) else model for model in models]
        if not boxes or any(type(box) is not BoxModel for box in boxes):
            return None
        first = boxes[0]
        if not all(_same_motion(box, first) and box.cache is first.cache for box in boxes[1:]):
            return None
        likelihoods = ColourLikelihoods.of([box.likelihood for box in boxes])
        return None if likelihoods is None else cls(models, boxes, likelihoods)

    def propagate(self, particles: np.ndarray, offsets: np.ndarray, t: int, rng) -> np.ndarray:
        """Each target's ``BoxModel.propagate`` of its rows, in target order: its (blocks, n_i, width)
        normals are the next slice of one draw from ``rng``, or its own draw from its own generator
        (``rng`` a list of them: independent filters)."""
        first = self.first
        self._count("propagations", offsets, t)
        per_row = first._sources.blocks * first._sources.width
        if isinstance(rng, np.random.Generator):
            draws = rng.standard_normal(per_row * len(particles))
        else:
            draws = np.concatenate([own.standard_normal(per_row * int(n)) for own, n in zip(rng, np.diff(offsets))])
        return first.moved(particles, draws, offsets)

    def log_likelihood(self, particles: np.ndarray, offsets: np.ndarray, frame, t: int) -> np.ndarray:
        """Each target's ``BoxModel.log_likelihood`` of its rows, the frame's features computed once."""
        self._count("evaluations", offsets, t)
        return self.likelihoods.log_likelihood(particles, offsets, self.first.prepared(frame, t))

    def _count(self, what: str, offsets: np.ndarray, t: int) -> None:
        """Each target's rows added to its tally at step t, as its own call would (integers: in any order)."""
        first = 0
        for work, targets in self.works:
            if work is not None:
                getattr(work, what)[t] += int(offsets[first + targets] - offsets[first])
            first += targets


def independent_frame(filters: list, states: list, boxes: BoxTargets, frame) -> bool:
    """One step of independent bootstrap filters (:class:`~replication.smc.loop.ParticleFilter` with the prior
    proposal, no move, multinomial resampling: MIPF's on the balls), every target at once: the loop's weigh
    and conclude of each target, each from its own generator (its normals, then its uniforms if it
    resamples), with the same numbers.  False, doing nothing, for filters this does not cover."""
    first = filters[0]
    if not all(type(f) is ParticleFilter and f.proposal is prior_proposal and f.move is None and f.n_particles == first.n_particles
               and f.resampling == first.resampling for f in filters) or first.resampling.scheme != "multinomial":
        return False
    m, n = len(states), first.n_particles
    for state in states:
        state.t += 1
    offsets = np.arange(m + 1) * n
    moved = boxes.propagate(np.concatenate([s.particles for s in states]), offsets, states[0].t, [s.rng for s in states])
    log_likelihood = boxes.log_likelihood(moved, offsets, frame, states[0].t).reshape(m, n)
    predicted = np.stack([s.log_weights for s in states])
    weights, log_totals, degenerate = normalise_rows(predicted, log_likelihood, corrected=False)
    moved = moved.reshape(m, n, -1)
    resampling = []
    for i, state in enumerate(states):
        state.log_evidence += log_totals[i]
        state.records.add(moved[i], weights[i], bool(degenerate[i]))
        wants = first.resampling.wants(state.records.ess[-1], n)
        state.records.resampled.append(wants)
        if wants:
            resampling.append(i)
        else:  # the weighed log-weights, as Weighed.log_weights forms them
            unnormalised = predicted[i] if degenerate[i] else predicted[i] + log_likelihood[i]
            state.particles, state.log_weights = moved[i], unnormalised - log_totals[i]
    if resampling:
        uniforms = np.stack([states[i].rng.random(n) for i in resampling])
        resampled = gather_rows(moved[resampling], inverse_cdf_rows(weights[resampling], uniforms))
        uniform = np.full((len(resampling), n), -np.log(n))
        for i, particles, log_weights in zip(resampling, resampled, uniform):
            states[i].particles, states[i].log_weights = particles, log_weights
    return True


class Targets:
    """A joint filter's state's view of its models as one: ``targets(models)`` is ``BoxTargets.of(models)``,
    made again only when the models change (a target born or dead); the models themselves are taken not
    to change (a colour likelihood's reference is fixed)."""

    def __init__(self):
        self.models, self.made = (), None

    def __call__(self, models: list) -> BoxTargets | None:
        key = tuple(id(model) for model in models)
        if key != self.models:
            self.models, self.made = key, BoxTargets.of(models)
        return self.made


def _same_motion(box: BoxModel, other: BoxModel) -> bool:
    return (box.kind == other.kind and box.period == other.period and box.min_size == other.min_size
            and box._sources.blocks == other._sources.blocks and box._sources.width == other._sources.width
            and all(np.array_equal(a, b) for a, b in zip(box._sources[2:], other._sources[2:])))


def normalise_rows(log_weights: np.ndarray, log_likelihood: np.ndarray, corrected: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The loop's weighting of each target (``ParticleFilter.weigh``) for rows (M, N): the predicted
    ``log_weights`` (plus 0 when ``corrected``: the log p / q that ``model_proposal`` adds, 0 for a box
    model; the prior proposal adds nothing), plus ``log_likelihood``, normalised
    (:func:`normalise_in_place`), or where a row is all -inf the predicted weights (a degenerate step):
    (weights, log-sums, degenerate).  Raises what :func:`~replication.smc.weights.normalise` raises where
    even that fails."""
    weights, log_totals, degenerate = np.empty_like(log_weights), np.empty(len(log_weights)), np.zeros(len(log_weights), bool)
    refuse(_normalise_rows(log_weights, log_likelihood, corrected, weights, log_totals, degenerate))
    return weights, log_totals, degenerate


NOT_FINITE, DEGENERATE = 1, 2  # what normalise_in_place cannot normalise (0: done)


def refuse(status: int) -> None:
    """Raise what :func:`~replication.smc.weights.normalise` raises for a failed :func:`normalise_in_place`."""
    if status == NOT_FINITE:
        raise NotFinite("log-weights contain NaN or +inf")
    if status == DEGENERATE:
        raise DegenerateWeightsError("every log-weight is -inf")


@njit(cache=True)
def _normalise_rows(log_weights, log_likelihood, corrected, weights, log_totals, degenerate):
    """Into ``weights`` etc. row by row; stops at a row it cannot weight, returning why (else 0)."""
    for i in range(log_weights.shape[0]):
        row = weights[i]
        for k in range(row.size):
            row[k] = _predicted(log_weights[i, k], corrected) + log_likelihood[i, k]
        status, log_totals[i] = normalise_in_place(row)
        if status == DEGENERATE:  # no particle explains the frame: keep the predicted weights
            degenerate[i] = True
            for k in range(row.size):
                row[k] = _predicted(log_weights[i, k], corrected)
            status, log_totals[i] = normalise_in_place(row)
        if status:
            return status
    return 0


@njit(cache=True, inline="always")
def _predicted(log_weight, corrected):
    return log_weight + 0.0 if corrected else log_weight


@njit(cache=True)
def normalise_in_place(row):
    """:func:`~replication.smc.weights.normalise` of ``row`` into it, in its operations and order (exp of the
    differences from the maximum summed in numpy's order as they are made: ``exp_sum``, then the division): (0, log of the
    sum), or (NOT_FINITE, NaN) on a NaN or +inf and (DEGENERATE, NaN) when every entry is -inf."""
    top = _top(row)
    if np.isnan(top) or top == np.inf:
        return NOT_FINITE, np.nan
    if top == -np.inf:
        return DEGENERATE, np.nan
    total = exp_sum(row, top, row)
    for k in range(row.size):
        row[k] = row[k] / total
    return 0, top + np.log(total)


@njit(cache=True)
def gather_rows(particles, ancestors):
    """Each target's resampled particles, ``particles[i][ancestors[i]]`` for particles (M, N, d) and
    ancestors (M, N'), in one pass."""
    m, count = ancestors.shape
    out = np.empty((m, count, particles.shape[2]))
    for i in range(m):
        for k in range(count):
            out[i, k] = particles[i, ancestors[i, k]]
    return out


@njit(cache=True)
def _top(values):
    """``values.max()``: NaN if any value is NaN."""
    top = -np.inf
    for value in values:
        if np.isnan(value):
            return value
        top = max(top, value)
    return top
