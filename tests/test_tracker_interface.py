"""The one tracker interface: independent filters (MIPF) and joint filters behind ``start``/``step``/``track``,
with collectors for per-step outputs; the same numbers as driving the filters by hand."""

import zlib

import numpy as np

from replication import BISPF, bootstrap
from replication.filters.joint import JointFilter
from replication.filters.tracker import Adaptation, Independent, Joint, Marginal, tracker
from replication.smc.loop import ParticleFilter


class Walk:
    """A box doing a random walk in x; its likelihood peaks at x = z (the observation)."""

    def __init__(self, x0):
        self.x0 = x0

    def sample_initial(self, n, rng):
        return np.column_stack([self.x0 + rng.standard_normal(n), np.zeros(n), np.full(n, 4.0), np.full(n, 4.0)])

    def propagate(self, particles, t, rng):
        moved = particles.copy()
        moved[:, 0] += rng.standard_normal(len(particles))
        return moved

    def propose(self, particles, t, rng):
        return self.propagate(particles, t, rng), 0.0

    def log_likelihood(self, particles, z, t):
        return -0.5 * (particles[:, 0] - z) ** 2

    def adapt(self, estimate, t):
        pass


def streams(name):
    return np.random.default_rng(zlib.crc32(name.encode()))


def test_the_method_decides_the_tracker():
    assert isinstance(tracker(lambda: bootstrap(50)), Independent)
    assert isinstance(tracker(lambda: BISPF(n_particles=50, n_joint=100)), Joint)
    assert isinstance(BISPF(), JointFilter)


def test_independent_tracker_is_each_filter_alone():
    """MIPF is the identity interaction: target k's filter on stream ``filter<k>`` as if run alone."""
    frames = [10.0, 11.0, 12.5, 13.0]
    models = {3: Walk(10.0), 7: Walk(30.0)}
    mipf = tracker(lambda: bootstrap(200))
    mipf.start(models, streams)
    estimates = list(mipf.track(frames))
    assert len(estimates) == len(frames) == len(mipf.frame_seconds) and min(mipf.frame_seconds) > 0
    for index, (target, model) in enumerate(models.items()):
        alone = ParticleFilter(200).run(model, frames, streams(f"filter{target}"))
        np.testing.assert_array_equal(mipf.outputs()[index].means, alone.means)
        np.testing.assert_array_equal(np.array([e[index] for e in estimates]), alone.means)


def test_joint_tracker_is_the_filter_stepped_by_hand():
    frames = [10.0, 11.0, 12.0]
    models = [Walk(10.0), Walk(12.0)]
    method = BISPF(n_particles=100, n_joint=300)
    joint = tracker(lambda: method)
    joint.start(dict(enumerate(models)), streams)
    list(joint.track(frames))
    state = method.start(models, streams("filter"))
    for z in frames:
        method.step(state, z)
    for ours, theirs in zip(joint.outputs(), state.outputs()):
        np.testing.assert_array_equal(ours.means, theirs.means)


def test_collectors_keep_a_marginal_per_step_and_no_alpha_without_an_adaptive_likelihood():
    class Likelihood:
        def __init__(self):
            self.history = []

    model = Walk(10.0)
    model.likelihood = Likelihood()
    mipf = tracker(lambda: bootstrap(100))
    mipf.start({0: model}, streams)
    strip, alpha = Marginal(0, "x", bins=20, extent=40.0), Adaptation(0)
    list(mipf.track([10.0, 10.5], [strip, alpha]))
    assert len(strip.value) == 2
    np.testing.assert_allclose([d.sum() for d in strip.value], 1.0)
    assert strip.value[-1][4:6].sum() > 0.9  # x near 10: the cells [8, 10) and [10, 12)
    assert alpha.value == []  # the likelihood has a history, nothing adapted it
    bis = tracker(lambda: BISPF(n_particles=50, n_joint=100))
    bis.start({0: model}, streams)
    alpha = Adaptation(0)
    list(bis.track([10.0], [alpha]))
    assert alpha.value is None  # the joint filters' models do not adapt
