"""The bootstrap (SIR) particle filter of Gordon, Salmond and Smith (1993)."""

from replication.filters.registry import drawn
from replication.smc.loop import ParticleFilter, ResamplingPolicy


@drawn("blue")
def bootstrap(n_particles: int, resampling: str = "systematic", ess_threshold: float = 0.5) -> ParticleFilter:
    """Prior proposal, weights by the likelihood; resample with ``resampling`` when ESS < ess_threshold * N."""
    return ParticleFilter(n_particles=n_particles, resampling=ResamplingPolicy(resampling, ess_threshold))
