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


def kalman_filter(model: LinearGaussian, observations: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """Posterior means and variances of x_t given z_1..z_t (Kalman, 1960), and the log marginal
    likelihood log p(z_1..z_T) = sum_t log N(z_t; c m_t|t-1, c^2 P_t|t-1 + R)."""
    mean, var, log_evidence = model.x0, model.P0, 0.0
    means, variances = np.empty(len(observations)), np.empty(len(observations))
    for k, z in enumerate(observations):
        mean, var = model.a * mean, model.a**2 * var + model.Q
        s = model.c**2 * var + model.R
        log_evidence += -0.5 * (np.log(2.0 * np.pi * s) + (z - model.c * mean) ** 2 / s)
        gain = var * model.c / s
        mean, var = mean + gain * (z - model.c * mean), (1.0 - gain * model.c) * var
        means[k], variances[k] = mean, var
    return means, variances, float(log_evidence)
