"""A scalar linear-Gaussian model and its exact posterior, the Kalman filter."""

from dataclasses import dataclass

import numpy as np

from replication.models.additive import AdditiveGaussianModel


@dataclass(frozen=True)
class LinearGaussian(AdditiveGaussianModel):
    """x_t = a x_{t-1} + w_t, z_t = c x_t + v_t."""

    a: float = 0.9
    c: float = 1.0

    def f(self, x, t):
        return self.a * x

    def h(self, x):
        return self.c * x


def kalman_filter(model: LinearGaussian, observations: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Posterior means and variances of x_t given z_1..z_t (Kalman, 1960)."""
    mean, var = model.x0, model.P0
    means, variances = np.empty(len(observations)), np.empty(len(observations))
    for k, z in enumerate(observations):
        mean, var = model.a * mean, model.a**2 * var + model.Q
        gain = var * model.c / (model.c**2 * var + model.R)
        mean, var = mean + gain * (z - model.c * mean), (1.0 - gain * model.c) * var
        means[k], variances[k] = mean, var
    return means, variances
