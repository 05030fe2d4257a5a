"""The work a filter does, counted where it asks its model: particles scored and particles moved forward.

Every method here reaches the observation only through ``model.log_likelihood(particles, z, t)`` and
moves particles only through the model's motion (``propagate``, ``propose``, or its deterministic part
``f`` around which a quasi-Monte Carlo proposal draws its own noise), whatever it does in between (a
swarm's iterations, an MCMC chain, BIS-PF's joint resampling, a grid's every point; mean shift, which
computes a box's histogram per iteration without the likelihood, says so through ``spend``).  :class:`Counted`
wraps a model and adds, at step ``t``, ``len(particles)`` likelihood evaluations per ``log_likelihood``
call, ``len(particles)`` propagations per call of the motion, and one transition density per pair a
``transition_log_density`` call evaluates (a marginal filter's N x N); the tasks wrap every model they
build, so every filter and tracker is counted by this one mechanism.
A model's calls to itself (a proposal that propagates, a likelihood that adds a term) are not counted
twice.  Equal work is then comparable across methods that spend different work per particle (the SMC
literature's error against cost: Gerber and Chopin, JRSS B 2015).
"""

from collections import Counter
from dataclasses import dataclass, field

import numpy as np


@dataclass
class Work:
    """Per step t: ``evaluations`` (particles scored by the likelihood) and ``propagations`` (particles
    moved forward by the motion or a proposal), summed over every model that shares this tally."""

    evaluations: Counter = field(default_factory=Counter)
    propagations: Counter = field(default_factory=Counter)
    transition_densities: Counter = field(default_factory=Counter)

    def per_step(self, steps: range) -> list[int]:
        """Each step's likelihood evaluations, in the order of ``steps``."""
        return [self.evaluations[t] for t in steps]

    def record(self, steps: int) -> dict[str, float]:
        """A run's likelihood evaluations in total, and its counts per step over ``steps`` steps."""
        evaluations = sum(self.evaluations.values())
        return {"likelihood_evaluations": evaluations, "evaluations_per_step": evaluations / steps,
                "propagations_per_step": sum(self.propagations.values()) / steps,
                "transition_densities_per_step": sum(self.transition_densities.values()) / steps}


class Counted:
    """``model`` with its likelihood evaluations and propagations added to ``work``; otherwise the model
    itself (every other attribute is read from it and written to it)."""

    def __init__(self, model, work: Work):
        object.__setattr__(self, "model", model)
        object.__setattr__(self, "work", work)

    def log_likelihood(self, particles: np.ndarray, observation, t: int) -> np.ndarray:
        self.work.evaluations[t] += len(particles)
        return self.model.log_likelihood(particles, observation, t)

    def propagate(self, particles: np.ndarray, t: int, rng: np.random.Generator) -> np.ndarray:
        self.work.propagations[t] += len(particles)
        return self.model.propagate(particles, t, rng)

    def propose(self, particles: np.ndarray, t: int, rng: np.random.Generator):
        self.work.propagations[t] += len(particles)
        return self.model.propose(particles, t, rng)

    def spend(self, evaluations: int, t: int) -> None:
        """Histograms a method computes outside the likelihood (mean shift's iterations), as evaluations."""
        self.work.evaluations[t] += evaluations

    def f(self, particles: np.ndarray, t: int) -> np.ndarray:
        self.work.propagations[t] += len(particles)
        return self.model.f(particles, t)

    def transition_log_density(self, x_new: np.ndarray, x_old: np.ndarray, t: int) -> np.ndarray:
        self.work.transition_densities[t] += np.broadcast(x_new, x_old).size
        return self.model.transition_log_density(x_new, x_old, t)

    def __getattr__(self, name: str):
        return getattr(self.model, name)

    def __setattr__(self, name: str, value) -> None:
        setattr(self.model, name, value)
