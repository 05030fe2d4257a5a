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
then falls more slowly than N^(-1/2) (``check_apf.py`` shows it).

The second-stage weights are carried into the next step's first stage (W_t), so each step resamples
exactly once, in its first stage; this is the weighted form of the APF analysed by Johansen and Doucet
("A note on auxiliary particle filters", Statistics & Probability Letters 78, 2008), where Pitt and
Shephard resample the second-stage draws once more to an equally weighted set.
"""

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from replication.smc.loop import FilterState, ParticleFilter, ResamplingPolicy, Weighed, prior_proposal
from replication.smc.resampling import RESAMPLERS
from replication.smc.weights import DegenerateWeightsError, normalise


def mean_look_ahead(model, parents: np.ndarray, t: int, rng: np.random.Generator) -> np.ndarray:
    """mu_t^i = E[x_t | x_{t-1}^i] = f(x_{t-1}^i, t), the deterministic part of the model's motion."""
    return model.f(parents, t)


def drawn_look_ahead(model, parents: np.ndarray, t: int, rng: np.random.Generator) -> np.ndarray:
    """mu_t^i ~ p(x_t | x_{t-1}^i), one draw from the model's prior."""
    return model.propagate(parents, t, rng)


LOOK_AHEADS = {"mean": mean_look_ahead, "draw": drawn_look_ahead}


@dataclass
class AuxiliaryParticleFilter(ParticleFilter):
    """The APF on :class:`~replication.smc.loop.ParticleFilter`: ``weigh`` is the two-stage step of
    the module docstring, ``conclude`` records it without a second resampling.  ``resampling.scheme``
    is the first stage's scheme; the first stage resamples at every step (``ess_threshold`` 1).

    ``run`` (the scalar task) and ``start`` / ``step`` (the video task) are the base class's.
    """

    look_ahead: Callable = mean_look_ahead

    def __post_init__(self):
        super().__post_init__()
        if self.proposal is not prior_proposal or self.move is not None:
            raise ValueError("the auxiliary particle filter moves particles by the model's prior only: "
                             "it takes no proposal or move")
        if self.resampling.ess_threshold < 1.0:
            raise ValueError("the auxiliary particle filter resamples in its first stage at every step "
                             f"(ess_threshold 1), got ess_threshold={self.resampling.ess_threshold}")

    def weigh(self, state: FilterState, z) -> Weighed:
        """Steps 1-5 of the module docstring for z_t; the state only advances its t.

        As the base loop does (:meth:`ParticleFilter.weigh`), a stage whose log-weights are all -inf is
        recovered by its weights before the likelihood: a first stage where no look-ahead point explains
        z_t selects parents by W_{t-1} alone (a bootstrap step); a second stage where no moved particle
        does keeps the weights 1 / p(z_t | mu_t^{k_j}), under which the resampled set stands for the
        prediction p(x_t | z_{1:t-1}), as if z_t had carried no information.  Either is flagged in
        ``FilterOutput.degenerate``.

        ``log_evidence`` gains log sum_i W_{t-1}^i p(z_t | mu_t^i) + log (1/N) sum_j w_j, with w_j the
        second-stage weights: the APF's estimate of p(z_t | z_{1:t-1}).
        """
        model, rng, n = state.model, state.rng, self.n_particles
        state.t += 1
        t = state.t
        parents = state.particles
        look_ahead = model.log_likelihood(self.look_ahead(model, parents, t, rng), z, t)  # log p(z_t | mu_t^i)
        try:
            first, log_first = normalise(state.log_weights + look_ahead)
            first_degenerate = False
        except DegenerateWeightsError:
            look_ahead = np.zeros(n)
            first, log_first = normalise(state.log_weights)
            first_degenerate = True
        ancestors = RESAMPLERS[self.resampling.scheme](first, rng)  # never a parent of zero lambda
        particles = model.propagate(parents[ancestors], t, rng)
        predicted = -look_ahead[ancestors]  # finite: a selected parent has lambda > 0
        log_weights = predicted + model.log_likelihood(particles, z, t)
        try:
            weights, log_total = normalise(log_weights)
            degenerate = False
        except DegenerateWeightsError:
            log_weights = predicted
            weights, log_total = normalise(predicted)
            degenerate = True
        state.log_evidence += log_first + log_total - np.log(n)
        return Weighed(particles, weights, log_weights, log_total, degenerate or first_degenerate)

    def conclude(self, state: FilterState, weighed: Weighed) -> None:
        """Record the estimate of the second-stage weighted particles and keep their weights for the
        next first stage; ``resampled`` is True at every step (the first stage resampled)."""
        state.records.add(weighed.particles, weighed.weights, weighed.degenerate)
        state.records.resampled.append(True)
        state.particles, state.log_weights = weighed.particles, weighed.log_weights


def auxiliary_pf(n_particles: int, look_ahead: str = "mean", resampling: str = "systematic") -> AuxiliaryParticleFilter:
    """Pitt and Shephard's APF with N = ``n_particles``, look-ahead points ``look_ahead`` (``mean`` or
    ``draw``), and the first stage resampled at every step with ``resampling`` (multinomial, stratified,
    systematic or residual)."""
    if look_ahead not in LOOK_AHEADS:
        raise ValueError(f"look_ahead must be one of {sorted(LOOK_AHEADS)}, got {look_ahead!r}")
    return AuxiliaryParticleFilter(n_particles=n_particles, resampling=ResamplingPolicy(resampling, 1.0),
                                   look_ahead=LOOK_AHEADS[look_ahead])
