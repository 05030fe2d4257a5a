"""One tracker interface for one or many targets (issue 17, item 5).

A :class:`Tracker` owns its time loop, as Stone Soup's ``tracker/base.py``
shapes one: ``start(models, streams)`` with every target's model, then
``step(frame)`` per frame (or :meth:`Tracker.track`, which runs the loop over
frames, times it and yields each frame's estimates).  What a task wants per
step beyond the estimates is asked of :class:`Collector` objects, as particles
(N. Chopin) keeps collectors: each one looks at the tracker after every step
and keeps what it needs, instead of the task reaching into filter state.

Three kinds of tracker sit behind it:

* :class:`Independent`: one single-target filter per target (any of the
  ``start(model, rng)`` / ``step(state, frame)`` filters: the
  :class:`~replication.smc.loop.ParticleFilter` loop and its variants, the
  point-mass filter, the one-box OpenCV trackers), with the identity
  interaction: MIPF is literally this;
* :class:`Joint`: a joint multi-target filter (:mod:`replication.filters.joint`)
  (BIS-PF, MFMC, DMOT, MRF-JPF, MCMC-PF) that steps all targets together;
* both expose each target's posterior (:meth:`Tracker.posterior`) as weighted
  states; a one-box tracker states a point mass at its box.

Random streams: ``streams(name)`` gives a named generator (``Run.rng``); an
independent tracker draws target k's from ``filter<k>``, a joint one its single
stream from ``filter``, as the task did before this interface, so numbers stay.
"""

from abc import ABC, abstractmethod
from collections.abc import Callable, Iterable, Iterator, Mapping

import numpy as np

from replication.filters.frame import Targets, independent_frame
from replication.filters.joint import JointFilter
from replication.smc.loop import FilterOutput
from replication.stopwatch import Stopwatch

Streams = Callable[[str], np.random.Generator]


class Tracker(ABC):
    """Tracks a fixed set of targets through frames; ``targets`` are their labels, in order."""

    targets: list
    models: list
    frame_seconds: list[float]  # wall time spent in each ``step`` by ``track`` (frame production excluded)
    stopwatch: Stopwatch  # both clocks over every ``step`` of ``track`` (its ``cpu``: this thread's CPU time)
    adapts: bool = False  # whether the models adapt at the estimates after each step

    @abstractmethod
    def start(self, models: Mapping, streams: Streams) -> None:
        """Begin with ``models`` (target label -> state-space model) at frame 0."""

    @abstractmethod
    def step(self, frame) -> list[np.ndarray]:
        """Filter one frame; each target's estimate (posterior mean) now."""

    @abstractmethod
    def posterior(self, index: int) -> tuple[np.ndarray, np.ndarray]:
        """Target ``index``'s (0-based position in ``targets``) weighted states now: (states, log-weights)."""

    @abstractmethod
    def outputs(self) -> list[FilterOutput]:
        """Per-target summaries of every step so far."""

    def track(self, frames: Iterable, collectors: Iterable["Collector"] = ()) -> Iterator[list[np.ndarray]]:
        """Step through ``frames`` (frame 1 on), calling every collector after each step; yields the estimates.

        ``frame_seconds`` holds the wall time in :meth:`step` only, one entry per frame, and ``stopwatch``
        both clocks summed: producing a frame (rendering, decoding) is the iterator's, and collectors are
        not the tracker's cost.
        """
        collectors = list(collectors)
        self.frame_seconds, self.stopwatch = [], Stopwatch()
        for frame in frames:
            with self.stopwatch:
                estimates = self.step(frame)
            self.frame_seconds.append(self.stopwatch.last_wall)
            for collector in collectors:
                collector.collect(self)
            yield estimates


class Independent(Tracker):
    """One single-target filter per target and no interaction between them (MIPF).

    ``build()`` makes a fresh filter (one per target).  After each target's step
    its model may adapt at its estimate (fusion_pf's adaptive likelihood), before
    the next target steps, as each filter would alone.
    """

    adapts = True

    def __init__(self, build: Callable[[], object]):
        self.build = build

    def start(self, models, streams):
        self.targets, self.models = list(models), list(models.values())
        self.filters = []
        for target, model in models.items():
            method = self.build()
            self.filters.append((method, method.start(model, streams(f"filter{target}"))))
        self.as_one = Targets()

    def step(self, frame):
        boxes = self.as_one(self.models)  # box models with colour likelihoods: nothing to adapt
        if boxes is None or not independent_frame([f for f, _ in self.filters], [s for _, s in self.filters], boxes, frame):
            for method, state in self.filters:
                method.step(state, frame)
                state.model.adapt(state.records.means[-1], state.t)
        return [state.records.means[-1] for _, state in self.filters]

    def posterior(self, index):
        return self.filters[index][1].posterior()

    def outputs(self):
        return [state.output() for _, state in self.filters]


class Joint(Tracker):
    """A multi-target filter that steps every target at once (``start(models, rng)``, ``step(state, frame)``)."""

    def __init__(self, method: JointFilter):
        self.method = method

    def start(self, models, streams):
        self.targets, self.models = list(models), list(models.values())
        self.state = self.method.start(self.models, streams("filter"))

    def step(self, frame):
        self.method.step(self.state, frame)
        return [records.means[-1] for records in self.state.records]

    def posterior(self, index):
        return self.state.particles[index], self.state.log_weights[index]

    def outputs(self):
        return self.state.outputs()


def tracker(build: Callable[[], object]) -> Tracker:
    """The tracker for a configured method: ``build()`` makes the method.  A multi-target filter is its own
    tracker; any single-target filter becomes one filter per target (the identity interaction)."""
    method = build()
    return Joint(method) if isinstance(method, JointFilter) else Independent(build)


class Collector(ABC):
    """Keeps something of the tracker after every step (particles' collectors); ``value`` is the result."""

    @abstractmethod
    def collect(self, tracker: Tracker) -> None: ...


class Marginal(Collector):
    """One target's posterior over one coordinate (``axis``: x or y) per step: a weighted histogram over
    ``bins`` cells of [0, ``extent``) (bis_pf's modes strip)."""

    def __init__(self, index: int, axis: str = "x", bins: int = 60, extent: float = 1.0):
        self.index, self.axis, self.bins, self.extent = index, "xy".index(axis), bins, extent
        self.value: list[np.ndarray] = []

    def collect(self, tracker):
        particles, log_weights = tracker.posterior(self.index)
        weights = np.exp(log_weights - log_weights.max())
        density, _ = np.histogram(particles[:, self.axis], bins=self.bins, range=(0, self.extent), weights=weights)
        self.value.append(density / max(density.sum(), 1e-300))


class Adaptation(Collector):
    """A target's adaptive-likelihood weights (fusion_pf's alpha_k, one per step so far) when its model
    adapts at the tracker's estimates; ``value`` stays None for a likelihood without them or a tracker
    whose models do not adapt (the joint filters)."""

    def __init__(self, index: int = 0):
        self.index = index
        self.value: list | None = None

    def collect(self, tracker):
        history = getattr(tracker.models[self.index].likelihood, "history", None)
        self.value = list(history) if tracker.adapts and history is not None else None
