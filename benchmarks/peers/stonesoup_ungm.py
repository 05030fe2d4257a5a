"""Stone Soup's bootstrap particle filter on the UNGM: ``ParticlePredictor`` (its default
``DynamicsProposal``: the transition model with noise), ``ParticleUpdater`` and
``SystematicResampler`` at every step, the weighted mean of the updated particles at every step
(ours also records their variance and ESS: Stone Soup's cost leaves them out), only the last
generation kept (Stone Soup's ``parent`` link).

The models are written here against Stone Soup's interfaces (``stonesoup/models/base.py``):
the transition x_t = 0.5 x + 25 x / (1 + x^2) + 8 cos(1.2 (t - 1)) + N(0, Q) is a
``GaussianTransitionModel`` whose ``function`` gets the prior state, so ours' t - 1 is the prior's
timestamp in seconds after the start (the state at ours' t carries the timestamp start + t s); the
measurement z = x^2 / 20 + N(0, R) is a ``NonLinearGaussianMeasurement``.  Both draw their noise
with ``GaussianModel.rvs`` (scipy, numpy's global generator) and weigh with its ``logpdf``.

The updater is given no resampler and the resampler is called after it (what ``ParticleUpdater``
does inside when given one), so that the filtering mean is the weighted mean before resampling,
as ours and ``particles`` report it.
"""

import datetime

import numpy as np
from harness import main
from stonesoup.base import Property
from stonesoup.models.measurement.nonlinear import NonLinearGaussianMeasurement
from stonesoup.models.transition.nonlinear import GaussianTransitionModel
from stonesoup.predictor.particle import ParticlePredictor
from stonesoup.resampler.particle import SystematicResampler
from stonesoup.types.array import CovarianceMatrix, StateVector, StateVectors
from stonesoup.types.detection import Detection
from stonesoup.types.hypothesis import SingleHypothesis
from stonesoup.types.state import ParticleState
from stonesoup.updater.particle import ParticleUpdater

START = datetime.datetime(2000, 1, 1)
SECOND = datetime.timedelta(seconds=1)


class UNGMTransition(GaussianTransitionModel):
    q: float = Property(doc="process noise variance Q")

    @property
    def ndim_state(self):
        return 1

    def covar(self, **kwargs):
        return CovarianceMatrix([[self.q]])

    def function(self, state, noise=False, **kwargs):
        if noise is True:
            noise = self.rvs(num_samples=state.state_vector.shape[1], **kwargs)
        x, t_minus_1 = state.state_vector, (state.timestamp - START) / SECOND
        return 0.5 * x + 25.0 * x / (1.0 + x**2) + 8.0 * np.cos(1.2 * t_minus_1) + noise


class Square(NonLinearGaussianMeasurement):
    """z = x^2 / 20 + N(0, noise_covar)."""

    @property
    def ndim_meas(self):
        return 1

    def function(self, state, noise=False, **kwargs):
        if noise is True:
            noise = self.rvs(num_samples=state.state_vector.shape[1], **kwargs)
        return state.state_vector[self.mapping, :] ** 2 / 20.0 + noise


def filtering_means(observations, n, model):
    predictor = ParticlePredictor(UNGMTransition(q=model["Q"]))
    measurement_model = Square(ndim_state=1, mapping=(0,), noise_covar=CovarianceMatrix([[model["R"]]]))
    updater, resampler = ParticleUpdater(measurement_model), SystematicResampler()
    initial = model["x0"] + np.sqrt(model["P0"]) * np.random.standard_normal((1, n))
    state = ParticleState(StateVectors(initial), log_weight=np.full(n, -np.log(n)), timestamp=START)
    means = []
    for t, z in enumerate(observations, start=1):
        prediction = predictor.predict(state, timestamp=START + t * SECOND)
        detection = Detection(StateVector([z]), prediction.timestamp, measurement_model=measurement_model)
        updated = updater.update(SingleHypothesis(prediction, detection))
        means.append(float(updated.mean[0, 0]))
        state = resampler.resample(updated)
    return means


if __name__ == "__main__":
    main({"bootstrap PF step": filtering_means}, ("stonesoup", "numpy", "scipy"), per_step=True)
