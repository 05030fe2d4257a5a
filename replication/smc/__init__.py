"""Sequential Monte Carlo core: weights, resampling and the one filter loop.

Nothing here knows about images; a model is anything with ``sample_initial``,
``propagate`` and ``log_likelihood`` (see :class:`replication.smc.loop.StateSpaceModel`).
"""

from replication.smc.loop import FilterOutput, ParticleFilter, ResamplingPolicy
from replication.smc.resampling import RESAMPLERS, multinomial, residual, stratified, systematic
from replication.smc.weights import ess, normalise, weighted_mean, weighted_variance

__all__ = [
    "RESAMPLERS",
    "FilterOutput",
    "ParticleFilter",
    "ResamplingPolicy",
    "ess",
    "multinomial",
    "normalise",
    "residual",
    "stratified",
    "systematic",
    "weighted_mean",
    "weighted_variance",
]
