"""The one particle-filter loop: propose -> move -> weight -> estimate -> resample.

Variants plug in as small strategy objects instead of copying the loop:

* a :class:`Proposal` replaces the prior ``x_t ~ p(x_t | x_{t-1})`` (for example a
  quasi-Monte-Carlo mixture proposal) and returns the log-weights it implies;
* a :class:`Move` shifts the proposed particles (PSO, harmony search, mean shift)
  and returns the log-weight correction for the shift (zero where a paper
  ignores it).

The bootstrap filter of Gordon, Salmond and Smith (1993) is the loop with
neither.
"""

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from replication.errors import RunFailed
from replication.smc.resampling import RESAMPLERS
from replication.libm import log
from replication.smc.weights import DegenerateWeightsError, moments, normalise

LogLikelihood = Callable[[np.ndarray], np.ndarray]


class StateSpaceModel(Protocol):
    """What the loop needs of a model; observations may be numbers or images."""

    def sample_initial(self, n: int, rng: np.random.Generator) -> np.ndarray: ...

    def propagate(self, particles: np.ndarray, t: int, rng: np.random.Generator) -> np.ndarray: ...

    def log_likelihood(self, particles: np.ndarray, observation, t: int) -> np.ndarray: ...


class Proposal(Protocol):
    """Draw x_t given the weighted particles at t-1; return (particles, log_weights before the likelihood)."""

    def __call__(
        self,
        model: StateSpaceModel,
        particles: np.ndarray,
        log_weights: np.ndarray,
        t: int,
        rng: np.random.Generator,
    ) -> tuple[np.ndarray, np.ndarray]: ...


class Move(Protocol):
    """Move proposed particles towards high likelihood; return (particles, log-weight correction)."""

    def __call__(
        self, particles: np.ndarray, log_likelihood: LogLikelihood, rng: np.random.Generator
    ) -> tuple[np.ndarray, np.ndarray]: ...


def prior_proposal(model, particles, log_weights, t, rng):
    """The bootstrap proposal: x_t^i ~ p(x_t | x_{t-1}^i), weights carried over unchanged."""
    return model.propagate(particles, t, rng), log_weights


def model_proposal(model, particles, log_weights, t, rng):
    """The model's own proposal (``model.propose``: x_t and log p(x_t | x_{t-1}) / q), e.g. one fusing
    detections (:mod:`replication.models.boosted`); the bootstrap proposal for a model whose q is its prior."""
    moved, log_correction = model.propose(particles, t, rng)
    return moved, log_weights + log_correction


@dataclass(frozen=True)
class ResamplingPolicy:
    """Resample with ``scheme`` whenever ``ESS < ess_threshold * N``; a threshold of 1 means every step."""

    scheme: str = "systematic"
    ess_threshold: float = 0.5

    def __post_init__(self):
        RESAMPLERS[self.scheme]  # an unknown scheme is one line naming the known ones
        if not 0.0 <= self.ess_threshold <= 1.0:
            raise ValueError(f"ess_threshold must lie in [0, 1], got {self.ess_threshold}")

    def wants(self, ess_value: float, n: int) -> bool:
        return self.ess_threshold >= 1.0 or ess_value < self.ess_threshold * n


@dataclass
class FilterOutput:
    """Per-step summaries of one filter run (index 0 is the first observation)."""

    means: np.ndarray
    variances: np.ndarray
    ess: np.ndarray
    resampled: np.ndarray
    degenerate: np.ndarray
    log_evidence: float

    @property
    def resample_count(self) -> int:
        return int(self.resampled.sum())


def expect_output(output, shape: tuple[int, ...], method: str) -> FilterOutput:
    """``output`` if it is a :class:`FilterOutput` whose means have ``shape`` (one estimate per step), else
    the run fails (:class:`~replication.errors.RunFailed`) saying what ``method`` returned instead."""
    if not isinstance(output, FilterOutput):
        raise RunFailed(f"method {method!r}: run returned a {type(output).__name__}, not a FilterOutput")
    if np.shape(output.means) != shape:
        raise RunFailed(f"method {method!r}: run returned means of shape {np.shape(output.means)}, not {shape} "
                        "(one estimate per step)")
    return output


@dataclass
class Summaries:
    """What a filter records of its weighted particles after each step; becomes a FilterOutput."""

    means: list = field(default_factory=list)
    variances: list = field(default_factory=list)
    ess: list = field(default_factory=list)
    resampled: list = field(default_factory=list)
    degenerate: list = field(default_factory=list)

    def add(self, particles: np.ndarray, weights: np.ndarray, degenerate: bool) -> None:
        mean, variance, ess = moments(particles, weights)
        self.means.append(mean)
        self.variances.append(variance)
        self.ess.append(ess)
        self.degenerate.append(degenerate)

    def output(self, log_evidence: float) -> FilterOutput:
        return FilterOutput(
            means=np.asarray(self.means),
            variances=np.asarray(self.variances),
            ess=np.asarray(self.ess),
            resampled=np.asarray(self.resampled, dtype=bool),
            degenerate=np.asarray(self.degenerate, dtype=bool),
            log_evidence=log_evidence,
        )


@dataclass
class Buffers:
    """The arrays of N numbers a filter's steps write and read back within the step (its log-weights, its
    weights, and the equal log-weights after resampling), kept from step to step: a new array of a large N
    costs its page faults again at every step unless the C library's allocator keeps freed memory (the
    runner raises its thresholds, a plain script does not)."""

    arrays: dict = field(default_factory=dict)

    def get(self, name: str, shape: tuple) -> np.ndarray:
        """The array ``name`` of ``shape``, written by its caller before it is read."""
        array = self.arrays.get(name)
        if array is None or array.shape != shape:
            array = self.arrays[name] = np.empty(shape)
        return array

    def uniform(self, n: int) -> np.ndarray:
        """log W_i = -log N for N particles (the same array while N stays: a step never writes into it)."""
        array = self.arrays.get("uniform")
        if array is None or array.size != n:
            array = self.arrays["uniform"] = np.full(n, -math.log(n))
        return array


@dataclass
class FilterState:
    """A filter between steps: its particles, log-weights, random stream and what it has recorded."""

    model: StateSpaceModel
    rng: np.random.Generator
    particles: np.ndarray
    log_weights: np.ndarray
    t: int = 0
    log_evidence: float = 0.0
    records: Summaries = field(default_factory=Summaries)
    buffers: Buffers = field(default_factory=Buffers, repr=False)

    def output(self) -> FilterOutput:
        return self.records.output(self.log_evidence)

    def posterior(self) -> tuple[np.ndarray, np.ndarray]:
        """The weighted particles now (after any resampling): (particles, log-weights)."""
        return self.particles, self.log_weights


@dataclass
class ParticleFilter:
    """A particle filter with N particles, a proposal, an optional move and a resampling policy."""

    n_particles: int
    resampling: ResamplingPolicy = field(default_factory=ResamplingPolicy)
    proposal: Proposal = prior_proposal
    move: Move | None = None

    def __post_init__(self):
        if int(self.n_particles) != self.n_particles or self.n_particles <= 0:
            raise ValueError(f"n_particles must be a positive integer, got {self.n_particles}")
        self.n_particles = int(self.n_particles)

    def run(self, model: StateSpaceModel, observations, rng: np.random.Generator) -> FilterOutput:
        """Filter ``observations`` (z_1 .. z_T) and return the per-step estimates."""
        state = self.start(model, rng)
        for z in observations:
            self.step(state, z)
        return state.output()

    def start(self, model: StateSpaceModel, rng: np.random.Generator) -> FilterState:
        """Particles from the prior at t = 0, equally weighted; filters can then be stepped in lockstep."""
        n, buffers = self.n_particles, Buffers()
        return FilterState(model, rng, model.sample_initial(n, rng), buffers.uniform(n), buffers=buffers)

    def step(self, state: FilterState, z) -> None:
        """Propose, move, weight, estimate and maybe resample for the next observation z_t."""
        self.conclude(state, self.weigh(state, z))

    def weigh(self, state: FilterState, z) -> "Weighed":
        """The first half of a step: propose, move and weight for z_t; the state only advances its t.

        A step where every log-weight is -inf (no particle explains z_t) is
        recovered by keeping the predicted weights (those before the
        likelihood), as if z_t had carried no information; it is flagged in
        ``FilterOutput.degenerate`` (log_evidence then gets the predicted mass only).
        """
        model, rng = state.model, state.rng
        state.t += 1
        t = state.t
        particles, log_weights = self.proposal(model, state.particles, state.log_weights, t, rng)
        if self.move is not None:
            particles, correction = self.move(particles, lambda x: model.log_likelihood(x, z, t), rng)
            log_weights = log_weights + correction
        predicted, likelihood = log_weights, model.log_likelihood(particles, z, t)
        shape = np.broadcast_shapes(np.shape(log_weights), np.shape(likelihood))
        log_weights = np.add(log_weights, likelihood, out=state.buffers.get("log_weights", shape))
        try:
            weights, log_total = normalise(log_weights, state.buffers.get("weights", shape))
            degenerate = False
        except DegenerateWeightsError:
            log_weights = predicted
            weights, log_total = normalise(predicted, state.buffers.get("weights", np.shape(predicted)))
            degenerate = True
        state.log_evidence += log_total
        return Weighed(particles, weights, log_weights, log_total, degenerate)

    def conclude(self, state: FilterState, weighed: "Weighed") -> None:
        """The second half: record the estimate of the weighted particles, then resample if the policy wants."""
        n, particles = self.n_particles, weighed.particles
        state.records.add(particles, weighed.weights, weighed.degenerate)
        do_resample = self.resampling.wants(state.records.ess[-1], n)
        if do_resample:
            particles = particles[RESAMPLERS[self.resampling.scheme](weighed.weights, state.rng)]
            log_weights = state.buffers.uniform(n)
        else:
            log_weights = weighed.log_weights
        state.records.resampled.append(do_resample)
        state.particles, state.log_weights = particles, log_weights


@dataclass
class Weighed:
    """A step's weighted particles before resampling: normalised ``weights``, and their logs as the
    unnormalised log-weights and their log-sum (formed only when asked for: a step that resamples
    never needs them)."""

    particles: np.ndarray
    weights: np.ndarray
    log_unnormalised: np.ndarray
    log_total: float
    degenerate: bool

    @property
    def log_weights(self) -> np.ndarray:
        """log W_i = lw_i - logsumexp(lw)."""
        return self.log_unnormalised - self.log_total

    def reweighted(self, weights: np.ndarray) -> "Weighed":
        """The same particles under other normalised weights (a multi-target interaction's)."""
        with np.errstate(divide="ignore"):
            return Weighed(self.particles, weights, log(weights), 0.0, self.degenerate)
