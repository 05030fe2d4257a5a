"""The work a filter does, counted on its model (replication.smc.work): hand cases per method."""

import numpy as np
import pytest

from replication.filters.registry import builder
from replication.models.box import BoxModel
from replication.models.ungm import UNGM
from replication.smc.work import Counted, Work


def _ungm(steps=6):
    model = UNGM(steps=steps)
    return model, model.simulate(np.random.default_rng(0))[1]


def _counted_run(method, steps=6):
    model, observations = _ungm(steps)
    work = Work()
    output = method.run(Counted(model, work), observations, np.random.default_rng(1))
    return work, output, model, observations


def test_a_bootstrap_step_with_n_particles_is_n_evaluations_and_n_propagations():
    work, *_ = _counted_run(builder("bootstrap")(n_particles=100))
    assert dict(work.evaluations) == dict(work.propagations) == {t: 100 for t in range(1, 7)}
    assert work.record(6) == {"likelihood_evaluations": 600, "evaluations_per_step": 100.0,
                              "propagations_per_step": 100.0, "transition_densities_per_step": 0.0}


def test_counting_changes_nothing_the_filter_computes():
    work, output, model, observations = _counted_run(builder("bootstrap")(n_particles=50))
    plain = builder("bootstrap")(n_particles=50).run(model, observations, np.random.default_rng(1))
    assert np.array_equal(output.means, plain.means) and np.array_equal(output.ess, plain.ess)


def test_a_swarm_of_k_iterations_scores_n_times_k_plus_2_as_written():
    """PSO scores the predicted swarm (N), each of its K iterations (N K), and the loop weights the moved
    particles again (N): N (K + 2) per step."""
    work, *_ = _counted_run(builder("pso")(n_particles=40, iterations=3, max_velocity=[2.0]))
    assert set(work.evaluations.values()) == {40 * (3 + 2)}


def test_the_grid_filter_scores_every_grid_point_and_its_transition_every_pair():
    work, *_ = _counted_run(builder("point_mass")(n_points=201, half_width=40.0), steps=3)
    assert dict(work.evaluations) == {1: 201, 2: 201, 3: 201}
    assert all(0 < pairs <= 201 * 201 for pairs in work.transition_densities.values())  # pruned support


def test_gps_qmcpf_pays_n_squared_transition_densities_for_its_marginal_and_nqmcpf_none():
    """GPS-QMCPF weights its support-box points by the predictive mixture (eq 7): N points x N components;
    NQMCPF moves each particle around f with a QMC point, as the bootstrap filter does."""
    work, *_ = _counted_run(builder("gps_qmcpf")(n_particles=30))
    assert set(work.evaluations.values()) == {30} and set(work.transition_densities.values()) == {30 * 30}
    work, *_ = _counted_run(builder("nqmcpf")(n_particles=30))
    assert set(work.propagations.values()) == {30} and not work.transition_densities


class _Flat:
    def prepare(self, frame):
        return None

    def log_likelihood(self, boxes, prepared):
        return np.zeros(len(boxes))


def test_mcmc_scores_every_proposal_of_its_chain_and_each_target_start():
    """Per frame: burn-in + N proposals, each scored once, plus each of the M targets' starting state."""
    work = Work()
    models = [Counted(BoxModel(np.array([20.0 + 30 * i, 20, 10, 10]), _Flat(), step_sd=(1.0, 1.0, 0.1, 0.1)), work)
              for i in range(3)]
    method = builder("mcmc")(n_particles=200, burn_in=0.25, carry=5)
    state = method.start(models, np.random.default_rng(2))
    for _ in range(4):
        method.step(state, np.zeros((80, 120, 3)))
    assert set(work.evaluations.values()) == {50 + 200 + 3}
    assert set(work.propagations.values()) == {50 + 200 + 3}


@pytest.mark.parametrize("name", ["mipf", "bis"])
def test_distributed_filters_score_n_particles_per_target(name):
    work = Work()
    models = [Counted(BoxModel(np.array([20.0 + 30 * i, 20, 10, 10]), _Flat(), step_sd=(1.0, 1.0, 0.1, 0.1)), work)
              for i in range(3)]
    params = {"n_particles": 100} if name == "mipf" else {"n_particles": 100, "n_joint": 300}
    method = builder(name)(**params)
    state = method.start(models, np.random.default_rng(2))
    for _ in range(2):
        method.step(state, np.zeros((80, 120, 3)))
    assert set(work.evaluations.values()) == {3 * 100}


def test_mean_shift_counts_a_histogram_per_box_per_iteration_beside_the_likelihood():
    """MSPF per step: one evaluation to cache the frame's bins, its mean-shift iterations (a box's histogram
    each), and the loop's weighting of the N moved particles."""
    from replication.vision.colour import ColourLikelihood
    from replication.vision.histogram import ColourHistogram

    image = np.full((90, 120, 3), 128, np.uint8)
    image[30:50, 40:60] = (30, 30, 220)
    box = np.array([50.0, 40, 20, 20])

    def counted(work):
        likelihood = ColourLikelihood.from_frame(image, box, ColourHistogram(bins=(8, 8, 4), grid=(8, 8)), 0.1)
        return Counted(BoxModel(box, likelihood, step_sd=(3.0, 3.0, 0.0, 0.0)), work)

    for max_iter, low, high in ((0, 1 + 50, 1 + 50), (4, 1 + 50 + 1, 1 + 50 + 4 * 50)):
        work = Work()
        builder("mspf")(n_particles=50, max_iter=max_iter).run(counted(work), [image] * 3, np.random.default_rng(0))
        assert all(low <= n <= high for n in work.evaluations.values()) and len(work.evaluations) == 3


def test_harmony_search_scores_its_memory_every_improvisation_and_the_weighting():
    """HSPF without its stopping rules: per particle HMS harmonies, then NI improvisations, then the loop's
    weighting: N (HMS + NI + 1) per step."""
    hspf = builder("hspf")(n_particles=20, ni=4, hms=3, radius=2.0, idle=None, precision=None, quality=None)
    work, *_ = _counted_run(hspf)
    assert set(work.evaluations.values()) == {20 * (3 + 4 + 1)}


def test_ism_scores_the_predicted_particles_and_weights_the_moved_ones():
    """ISM-PF as written: the sharing move scores the N predicted particles and the loop weights the N moved
    ones, 2N per step; re-scoring the personal bests' window on each frame adds N per earlier frame kept."""
    for bests, expected in (("stored", [50, 50, 50, 50]), ("rescored", [50, 75, 100, 125])):
        work = Work()
        model = Counted(BoxModel(np.array([50.0, 40, 10, 10]), _Flat(), step_sd=(1.0, 1.0, 0.1, 0.1)), work)
        builder("ism")(n_particles=25, bests=bests).run(model, [np.zeros((80, 120, 3))] * 4, np.random.default_rng(0))
        assert work.per_step(range(1, 5)) == expected
