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

from replication.compiled import pairwise_program, pairwise_sum
from replication.errors import NotFinite
from replication.models.box import BoxModel, _moved
from replication.smc.weights import DegenerateWeightsError
from replication.smc.work import Counted
from replication.vision.joint import ColourLikelihoods


class BoxTargets:
    """M targets' box models as one: ``propagate`` and ``log_likelihood`` over their particles stacked
    (R, d), target i's rows ``offsets[i]:offsets[i + 1]``, counted as each model's own calls would be
    (:class:`~replication.smc.work.Counted`)."""

    def __init__(self, models: list, boxes: list[BoxModel], likelihoods: ColourLikelihoods):
        self.works = [model.work if isinstance(model, Counted) else None for model in models]
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

    def propagate(self, particles: np.ndarray, offsets: np.ndarray, t: int, rng: np.random.Generator) -> np.ndarray:
        """Each target's ``BoxModel.propagate`` of its rows, in target order: its (blocks, n_i, width)
        normals are the next slice of one draw."""
        sources, first = self.first._sources, self.first
        self._count("propagations", offsets, t)
        draws = rng.standard_normal(sources.blocks * len(particles) * sources.width)
        return _moved_targets(particles, draws, np.asarray(offsets, dtype=np.int64), sources.blocks, sources.width,
                              sources.block, sources.column, sources.scale, first.kind == "constant_velocity",
                              float(first.period), float(first.min_size))

    def log_likelihood(self, particles: np.ndarray, offsets: np.ndarray, frame, t: int) -> np.ndarray:
        """Each target's ``BoxModel.log_likelihood`` of its rows, the frame's features computed once."""
        self._count("evaluations", offsets, t)
        return self.likelihoods.log_likelihood(particles, offsets, self.first.prepared(frame, t))

    def _count(self, what: str, offsets: np.ndarray, t: int) -> None:
        for work, n in zip(self.works, np.diff(offsets)):
            if work is not None:
                getattr(work, what)[t] += int(n)


def _same_motion(box: BoxModel, other: BoxModel) -> bool:
    return (box.kind == other.kind and box.period == other.period and box.min_size == other.min_size
            and box._sources.blocks == other._sources.blocks and box._sources.width == other._sources.width
            and all(np.array_equal(a, b) for a, b in zip(box._sources[2:], other._sources[2:])))


@njit(cache=True, error_model="numpy")
def _moved_targets(particles, draws, offsets, blocks, width, block, column, scale, constant_velocity, period, min_size):
    """:func:`~replication.models.box._moved` of each target's rows with its slice of ``draws``."""
    out = np.empty_like(particles)
    for i in range(offsets.size - 1):
        first, last = offsets[i], offsets[i + 1]
        n = last - first
        own = draws[blocks * width * first : blocks * width * last].reshape((blocks, n, width))
        out[first:last] = _moved(particles[first:last], own, block, column, scale, constant_velocity, period, min_size)
    return out


def normalise_rows(log_weights: np.ndarray, log_likelihood: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The loop's weighting of each target (``ParticleFilter.weigh`` after the prior proposal, whose log p/q
    is 0) for rows (M, N): ``log_weights + 0 + log_likelihood`` normalised (:func:`normalise_in_place`),
    or where a row is all -inf its predicted ``log_weights + 0`` (a degenerate step): (weights, log-sums,
    degenerate).  Raises what :func:`~replication.smc.weights.normalise` raises where even that fails."""
    weights, log_totals, degenerate = np.empty_like(log_weights), np.empty(len(log_weights)), np.zeros(len(log_weights), bool)
    refuse(_normalise_rows(log_weights, log_likelihood, pairwise_program(log_weights.shape[1]), weights, log_totals,
                           degenerate))
    return weights, log_totals, degenerate


NOT_FINITE, DEGENERATE = 1, 2  # what normalise_in_place cannot normalise (0: done)


def refuse(status: int) -> None:
    """Raise what :func:`~replication.smc.weights.normalise` raises for a failed :func:`normalise_in_place`."""
    if status == NOT_FINITE:
        raise NotFinite("log-weights contain NaN or +inf")
    if status == DEGENERATE:
        raise DegenerateWeightsError("every log-weight is -inf")


@njit(cache=True)
def _normalise_rows(log_weights, log_likelihood, program, weights, log_totals, degenerate):
    """Into ``weights`` etc. row by row; stops at a row it cannot weight, returning why (else 0)."""
    for i in range(log_weights.shape[0]):
        row = weights[i]
        for k in range(row.size):
            row[k] = (log_weights[i, k] + 0.0) + log_likelihood[i, k]
        status, log_totals[i] = normalise_in_place(row, program)
        if status == DEGENERATE:  # no particle explains the frame: keep the predicted weights
            degenerate[i] = True
            for k in range(row.size):
                row[k] = log_weights[i, k] + 0.0
            status, log_totals[i] = normalise_in_place(row, program)
        if status:
            return status
    return 0


@njit(cache=True)
def normalise_in_place(row, program):
    """:func:`~replication.smc.weights.normalise` of ``row`` into it, in its operations and order (exp of the
    differences from the maximum, numpy's pairwise sum: ``program``, then the division): (0, log of the
    sum), or (NOT_FINITE, NaN) on a NaN or +inf and (DEGENERATE, NaN) when every entry is -inf."""
    top = _top(row)
    if np.isnan(top) or top == np.inf:
        return NOT_FINITE, np.nan
    if top == -np.inf:
        return DEGENERATE, np.nan
    for k in range(row.size):
        row[k] = np.exp(row[k] - top)
    total = pairwise_sum(row, program)
    for k in range(row.size):
        row[k] = row[k] / total
    return 0, top + np.log(total)


@njit(cache=True)
def _top(values):
    """``values.max()``: NaN if any value is NaN."""
    top = -np.inf
    for value in values:
        if np.isnan(value):
            return value
        top = max(top, value)
    return top
