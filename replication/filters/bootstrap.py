"""The bootstrap (SIR) particle filter of Gordon, Salmond and Smith (1993)."""

from replication.smc.loop import ParticleFilter, ResamplingPolicy


def bootstrap(n_particles: int, resampling: dict | None = None) -> ParticleFilter:
    """Prior proposal, weights by the likelihood, resampling per ``resampling`` (scheme, ess_threshold)."""
    return ParticleFilter(n_particles=n_particles, resampling=ResamplingPolicy(**(resampling or {})))
