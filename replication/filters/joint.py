"""What the joint multi-target filters share: one state for all targets, started from each target's prior.

Such a filter (:mod:`replication.filters.bis`, :mod:`replication.filters.mcmc`, ...) is its own
multi-target tracker (:class:`replication.filters.tracker.Joint`); the trackers and tasks that drive one
need only this module, not the filters themselves.
"""

from dataclasses import dataclass

import numpy as np

from replication.filters.frame import BoxTargets, Targets
from replication.smc.loop import FilterOutput, Summaries


@dataclass
class JointState:
    models: list
    rng: np.random.Generator
    particles: list
    log_weights: list
    t: int = 0

    def __post_init__(self):
        self.records = [Summaries() for _ in self.models]
        self.as_one = Targets()

    def box_targets(self) -> BoxTargets | None:
        """The models as one (:class:`~replication.filters.frame.BoxTargets`), or None."""
        return self.as_one(self.models)

    def record(self, i: int, particles: np.ndarray, weights: np.ndarray, degenerate: bool,
               log_weights: np.ndarray | None = None) -> None:
        """Store target i's weighted particles after a step (the next step resamples them); ``log_weights``,
        log(weights), when the caller has them (weights every target shares)."""
        if log_weights is None:
            with np.errstate(divide="ignore"):
                log_weights = np.log(weights)
        self.particles[i], self.log_weights[i] = particles, log_weights
        self.records[i].add(particles, weights, degenerate)
        self.records[i].resampled.append(True)

    def outputs(self) -> list[FilterOutput]:
        return [r.output(log_evidence=float("nan")) for r in self.records]


class JointFilter:
    """What the joint filters share: one state for all targets, started from each target's prior.

    Such a filter is its own multi-target tracker (:class:`replication.filters.tracker.Joint`).
    """

    n_particles: int

    def start(self, models: list, rng: np.random.Generator) -> JointState:
        n = self.n_particles
        return JointState(models, rng, [m.sample_initial(n, rng) for m in models], [np.full(n, -np.log(n)) for _ in models])

    def add(self, state: JointState, model) -> None:
        """A target is born: its particles are drawn from ``model``'s prior (a real video's births)."""
        n = self.n_particles
        state.models.append(model)
        state.particles.append(model.sample_initial(n, state.rng))
        state.log_weights.append(np.full(n, -np.log(n)))
        state.records.append(Summaries())

    def remove(self, state: JointState, index: int) -> None:
        """Target ``index`` dies: it leaves every list of the state."""
        for kept in (state.models, state.particles, state.log_weights, state.records):
            del kept[index]
