"""The auxiliary particle filter (APF) of Pitt and Shephard, "Filtering via simulation: auxiliary
particle filters", JASA 94 (1999) 590-599, on the harness's one SMC loop.

A step from the weighted particles (x_{t-1}^i, W_{t-1}^i) to z_t:

1. a look-ahead point mu_t^i of x_t given x_{t-1}^i for each particle;
2. first-stage weights lambda_i proportional to W_{t-1}^i p(z_t | mu_t^i): the particles whose
   predicted point explains z_t are favoured *before* they are moved;
3. N parent indices k_j resampled by lambda (the configured scheme);
4. x_t^j ~ p(x_t | x_{t-1}^{k_j}), the model's prior;
5. second-stage log-weights log p(z_t | x_t^j) - log p(z_t | mu_t^{k_j}), which correct for having
   chosen the parents by the look-ahead's likelihood rather than the particle's.

The paper lets mu be "the mean, the mode, a draw or some other likely value" of f(x_t | x_{t-1}).
Both readings the harness can give are named options (``look_ahead``): ``mean``, the deterministic
part of the motion, ``model.f(x, t)`` (the usual choice; the harness's scalar models and its box
model have it), and ``draw``, one draw from ``propagate``, which needs nothing beyond the loop's
model interface.  A draw makes the second-stage weights heavy-tailed where the likelihood is narrow
against the prior's spread: on a linear-Gaussian model observing x_t directly, E[1 / p(z_t | mu)] is
infinite once the state noise variance Q reaches the observation noise variance R, and the error
then falls more slowly than N^(-1/2).

Steps 1-4 are a proposal of the loop (:class:`~replication.smc.loop.Proposal`, :func:`first_stage`), which returns the
log-weights log(sum_i W_{t-1}^i p(z_t | mu_t^i)) - log N - log p(z_t | mu_t^{k_j}); the loop adds
log p(z_t | x_t^j) (step 5), normalises, and adds their log-sum to the log-evidence, which is then the
APF's estimate of p(z_t | z_{1:t-1}); a step no particle explains falls back as in every filter of
the loop.  The second-stage weights are carried into the next step's first stage (W_t), so each step
resamples exactly once, in its first stage; this is the weighted form of the APF analysed by Johansen
and Doucet ("A note on auxiliary particle filters", Statistics & Probability Letters 78, 2008), where
Pitt and Shephard resample the second-stage draws once more to an equally weighted set.
"""

from collections.abc import Callable
from dataclasses import dataclass
from functools import partial

import numpy as np

from replication.smc.loop import FilterState, ParticleFilter, ResamplingPolicy, Weighed
from replication.smc.resampling import RESAMPLERS
from replication.smc.weights import DegenerateWeightsError, normalise


def mean_look_ahead(model, parents: np.ndarray, t: int, rng: np.random.Generator) -> np.ndarray:
    """mu_t^i = E[x_t | x_{t-1}^i] = f(x_{t-1}^i, t), the deterministic part of the model's motion."""
    return model.f(parents, t)


def drawn_look_ahead(model, parents: np.ndarray, t: int, rng: np.random.Generator) -> np.ndarray:
    """mu_t^i ~ p(x_t | x_{t-1}^i), one draw from the model's prior."""
    return model.propagate(parents, t, rng)


LOOK_AHEADS = {"mean": mean_look_ahead, "draw": drawn_look_ahead}


def first_stage(model, particles, log_weights, t, rng, *, z, look_ahead: Callable, scheme: str):
    """Steps 1-4 for observation ``z`` (z_t), as a proposal of the loop: parents chosen by the likelihood
    of their look-ahead points (resampled with ``scheme``), then moved by the prior."""
    looked = model.log_likelihood(look_ahead(model, particles, t, rng), z, t)  # log p(z_t | mu_t^i)
    try:
        first, log_first = normalise(log_weights + looked)
    except DegenerateWeightsError:  # no look-ahead point explains z_t: parents by W_{t-1} alone
        looked = np.zeros(len(particles))
        first, log_first = normalise(log_weights)
    ancestors = RESAMPLERS[scheme](first, rng)  # never a parent of zero lambda
    moved = model.propagate(particles[ancestors], t, rng)
    return moved, log_first - np.log(len(particles)) - looked[ancestors]


@dataclass
class AuxiliaryParticleFilter(ParticleFilter):
    """The APF on :class:`~replication.smc.loop.ParticleFilter`: its proposal is the first stage
    (resampled with ``resampling.scheme``), the loop's weighting the second, and the loop resamples no
    more (``ess_threshold`` 0); ``run`` (the scalar task) and ``start`` / ``step`` (the video task) are
    the base class's."""

    look_ahead: Callable = mean_look_ahead

    def weigh(self, state: FilterState, z) -> Weighed:
        """One step of the loop with the first stage for this z_t as its proposal."""
        self.proposal = partial(first_stage, z=z, look_ahead=self.look_ahead, scheme=self.resampling.scheme)
        return super().weigh(state, z)

    def conclude(self, state: FilterState, weighed: Weighed) -> None:
        """The loop's record of the step, which resampled in its first stage."""
        super().conclude(state, weighed)
        state.records.resampled[-1] = True


def auxiliary_pf(n_particles: int, look_ahead: str = "mean", resampling: str = "systematic") -> AuxiliaryParticleFilter:
    """Pitt and Shephard's APF with N = ``n_particles``, look-ahead points ``look_ahead`` (``mean`` or
    ``draw``), and the first stage resampled at every step with ``resampling`` (multinomial, stratified,
    systematic or residual)."""
    if look_ahead not in LOOK_AHEADS:
        raise ValueError(f"look_ahead must be one of {sorted(LOOK_AHEADS)}, got {look_ahead!r}")
    return AuxiliaryParticleFilter(n_particles=n_particles, resampling=ResamplingPolicy(resampling, 0.0),
                                   look_ahead=LOOK_AHEADS[look_ahead])
