"""The point-mass filter as a method: the Bayes-optimal reference row of the scalar tables."""

from dataclasses import dataclass

import numpy as np

from replication.filters.registry import drawn
from replication.models.point_mass import point_mass_filter
from replication.smc.loop import FilterOutput


@drawn("black", "--", "")
@dataclass(frozen=True)
class PointMassFilter:
    """Grid filter with ``n_points`` over ``[-half_width, half_width]``; uses no randomness."""

    n_points: int = 1601
    half_width: float = 80.0

    def __post_init__(self):
        if self.n_points < 3 or self.half_width <= 0:
            raise ValueError(f"need n_points >= 3 and half_width > 0, got {self.n_points}, {self.half_width}")

    def run(self, model, observations, rng=None) -> FilterOutput:
        means, variances = point_mass_filter(model, observations, self.n_points, self.half_width)
        steps = len(observations)
        return FilterOutput(
            means=means,
            variances=variances,
            ess=np.full(steps, np.nan),
            resampled=np.zeros(steps, dtype=bool),
            degenerate=np.zeros(steps, dtype=bool),
            log_evidence=float("nan"),
        )
