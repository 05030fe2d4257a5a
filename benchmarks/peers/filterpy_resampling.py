"""filterpy's resamplers (``filterpy.monte_carlo``: systematic, stratified, multinomial, residual)
on the same normalised weights as ours, one call per repeat; filterpy has no particle filter.

Each estimate is the mean of N W_i over the N indices i drawn, whose expectation is N sum_i W_i^2
for an unbiased scheme (one that draws particle i N W_i times on average): the driver checks it
against that within Monte Carlo error.  (A function of the weights, unlike i / N, shows a scheme
that favours the heavy particles.)
"""

from filterpy.monte_carlo import (
    multinomial_resample,
    residual_resample,
    stratified_resample,
    systematic_resample,
)
from harness import main


def resampled(resample):
    return lambda weights, n, model: resample(weights)


def mean_weight(indices, weights):
    return [len(weights) * weights[indices].mean()]


if __name__ == "__main__":
    schemes = (systematic_resample, stratified_resample, multinomial_resample, residual_resample)
    main({f"resample ({scheme.__name__.removesuffix('_resample')})": resampled(scheme) for scheme in schemes},
         ("filterpy", "numpy"), per_step=False, estimates=mean_weight)
