"""Scalar models with additive Gaussian noise: x_t = f(x_{t-1}, t) + w_t, z_t = h(x_t) + v_t."""

import math
from dataclasses import dataclass

import numpy as np

from replication.compiled import elementwise

LOG_2PI = math.log(2.0 * math.pi)


@elementwise("float64(float64, float64, float64, float64)")
def log_normal_density(x, mean, variance, log_variance):
    """log N(x; mean, variance) = -(((x - mean)^2 / variance + log variance) + log 2 pi) / 2, one compiled
    pass over the particles in numpy's operations and order (so its bits), with no temporaries."""
    residual = x - mean
    return -0.5 * (residual * residual / variance + log_variance + LOG_2PI)


@elementwise("float64(float64, float64, float64)")
def _shifted(mean, scale, noise):
    """mean + scale * noise in one pass, as numpy computes it."""
    return mean + scale * noise


@dataclass(frozen=True)
class AdditiveGaussianModel:
    """x_0 ~ N(x0, P0); w_t ~ N(0, Q); v_t ~ N(0, R).  Subclasses give ``f`` and ``h``.

    ``P0 = 0`` is allowed and means x_0 = x0 exactly.  Particles are arrays of
    shape (N,).
    """

    Q: float = 10.0
    R: float = 1.0
    x0: float = 0.1
    P0: float = 2.0
    steps: int = 50

    def __post_init__(self):
        if self.Q <= 0 or self.R <= 0:
            raise ValueError(f"noise variances must be positive, got Q={self.Q}, R={self.R}")
        if self.P0 < 0:
            raise ValueError(f"P0 must be non-negative, got {self.P0}")
        if int(self.steps) != self.steps or self.steps <= 0:
            raise ValueError(f"steps must be a positive integer, got {self.steps}")

    def f(self, x: np.ndarray, t: int) -> np.ndarray:
        raise NotImplementedError

    def h(self, x: np.ndarray) -> np.ndarray:
        raise NotImplementedError

    def sample_initial(self, n: int, rng: np.random.Generator) -> np.ndarray:
        return self.x0 + np.sqrt(self.P0) * rng.standard_normal(n)

    def propagate(self, particles: np.ndarray, t: int, rng: np.random.Generator) -> np.ndarray:
        noise = rng.standard_normal(particles.shape)
        return _shifted(self.f(particles, t), math.sqrt(self.Q), noise, out=noise)  # one array fewer

    def log_likelihood(self, particles: np.ndarray, observation: float, t: int) -> np.ndarray:
        """log N(z_t; h(x), R)."""
        return log_normal_density(observation, self.h(particles), self.R, math.log(self.R))

    def transition_log_density(self, x_new: np.ndarray, x_old: np.ndarray, t: int) -> np.ndarray:
        """log N(x_new; f(x_old, t), Q), broadcasting x_new against x_old."""
        return log_normal_density(x_new, self.f(x_old, t), self.Q, math.log(self.Q))

    def simulate(self, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
        """A trajectory x_1..x_T and its observations z_1..z_T."""
        x = self.sample_initial(1, rng)
        states, observations = np.empty(self.steps), np.empty(self.steps)
        for t in range(1, self.steps + 1):
            x = self.propagate(x, t, rng)
            states[t - 1] = x[0]
            observations[t - 1] = self.h(x)[0] + np.sqrt(self.R) * rng.standard_normal()
        return states, observations
