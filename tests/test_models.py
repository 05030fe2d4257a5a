"""Models against their equations, and the point-mass filter against exact posteriors."""

import numpy as np
import pytest

from replication import PointMassFilter
from replication.models import UNGM, LinearGaussian, kalman_filter, point_mass_filter


def test_ungm_transition_and_observation_hand_computed():
    model = UNGM()
    # t = 1: 0.5*2 + 25*2/5 + 8cos(0) = 1 + 10 + 8
    assert model.f(np.array([2.0]), 1)[0] == pytest.approx(19.0)
    assert model.f(np.array([0.0]), 2)[0] == pytest.approx(8 * np.cos(1.2))
    assert model.h(np.array([10.0]))[0] == pytest.approx(5.0)
    # log N(z; x^2/20, R=1) at z = h(x): the peak of a unit-variance Gaussian
    assert model.log_likelihood(np.array([10.0]), 5.0, 1)[0] == pytest.approx(-0.5 * np.log(2 * np.pi))


def test_simulation_is_reproducible_and_has_model_noise():
    model = UNGM(steps=2000)
    states, observations = model.simulate(np.random.default_rng(3))
    again = model.simulate(np.random.default_rng(3))
    np.testing.assert_array_equal(states, again[0])
    residuals = observations - model.h(states)
    assert residuals.var() == pytest.approx(model.R, rel=0.1)
    process = states[1:] - model.f(states[:-1], np.arange(2, 2001))
    assert process.var() == pytest.approx(model.Q, rel=0.1)


def test_known_initial_state():
    model = UNGM(x0=1.0, P0=0.0)
    assert np.all(model.sample_initial(5, np.random.default_rng(0)) == 1.0)


@pytest.mark.parametrize("P0", [0.0, 1.0, 5.0])
def test_point_mass_filter_equals_kalman_on_linear_gaussian(P0):
    model = LinearGaussian(a=0.95, c=0.8, Q=2.0, R=0.3, x0=1.0, P0=P0, steps=40)
    observations = model.simulate(np.random.default_rng(1))[1]
    kalman_means, kalman_variances, _ = kalman_filter(model, observations)
    means, variances = point_mass_filter(model, observations, n_points=1601, half_width=60.0)
    np.testing.assert_allclose(means, kalman_means, atol=1e-8)
    np.testing.assert_allclose(variances, kalman_variances, atol=1e-8)


def test_point_mass_filter_is_converged_on_ungm():
    """The UNGM grid (spacing 0.1 on [-80, 80]) agrees with one of half the spacing to 1e-6."""
    model = UNGM(steps=60)
    for seed in range(3):
        observations = model.simulate(np.random.default_rng(seed))[1]
        coarse, _ = point_mass_filter(model, observations, n_points=1601, half_width=80.0)
        fine, _ = point_mass_filter(model, observations, n_points=3201, half_width=80.0)
        wide, _ = point_mass_filter(model, observations, n_points=2001, half_width=100.0)
        np.testing.assert_allclose(coarse, fine, atol=1e-6)
        np.testing.assert_allclose(coarse, wide, atol=1e-6)


def test_point_mass_mean_is_the_best_estimator_on_average():
    """Across trajectories the grid posterior mean has lower MSE than a large particle filter's."""
    from replication import bootstrap

    model = UNGM(steps=50)
    grid_se, pf_se = [], []
    for seed in range(30):
        rng = np.random.default_rng(seed)
        states, observations = model.simulate(rng)
        grid_se.append(np.mean((PointMassFilter().run(model, observations).means - states) ** 2))
        pf_se.append(np.mean((bootstrap(100).run(model, observations, rng).means - states) ** 2))
    assert np.mean(grid_se) <= np.mean(pf_se)


def test_model_parameters_are_checked():
    with pytest.raises(ValueError, match="variances"):
        UNGM(Q=0.0)
    with pytest.raises(ValueError, match="steps"):
        UNGM(steps=0)
    with pytest.raises(ValueError, match="P0"):
        UNGM(P0=-1.0)


@pytest.mark.parametrize("kind", ["random_walk", "constant_velocity"])
def test_box_motion_is_a_x_plus_w_e(kind):
    """propagate draws x_t = A x_{t-1} + W e: its sample mean and covariance match f and W W^T (eq 14)."""
    from replication.models.box import BoxModel

    model = BoxModel(np.array([50.0, 40.0, 20.0, 10.0]), None, kind=kind, accel_sd=0.8, period=2.0,
                     step_sd=(3.0, 2.0, 0.4, 0.3))
    start = np.tile(model.x0, (200_000, 1))
    if kind == "constant_velocity":
        start[:, 4:6] = (1.5, -0.5)
        assert model.f(start[:1], 1)[0, :2] == pytest.approx([53.0, 39.0])  # x + v T
    moved = model.propagate(start, 1, np.random.default_rng(0))
    np.testing.assert_allclose(moved.mean(axis=0), model.f(start[:1], 1)[0], atol=0.02)
    w = model.noise_factor
    np.testing.assert_allclose(np.cov(moved.T), w @ w.T, atol=0.03)
    if kind == "constant_velocity":  # one acceleration moves position and velocity: rank 4 in 6-D
        assert np.linalg.matrix_rank(w @ w.T) == 4


def test_kalman_log_evidence_is_the_joint_gaussian_density_of_the_observations():
    """z_1..z_T is jointly Gaussian: mean c a^t x0, Cov[z_t, z_u] = c^2 Cov[x_t, x_u] + R [t = u]."""
    from scipy.stats import multivariate_normal

    model = LinearGaussian(a=0.8, c=1.5, Q=2.0, R=0.5, x0=0.3, P0=1.2, steps=6)
    observations = model.simulate(np.random.default_rng(3))[1]
    t = np.arange(1, model.steps + 1)
    lag = np.minimum.outer(t, t)
    cov_x = model.a ** np.add.outer(t, t) * model.P0 + model.Q * sum(
        model.a ** (np.add.outer(t, t) - 2 * s) * (lag >= s) for s in range(1, model.steps + 1)
    )
    cov_z = model.c**2 * cov_x + model.R * np.eye(model.steps)
    exact = multivariate_normal(model.c * model.a**t * model.x0, cov_z).logpdf(observations)
    assert kalman_filter(model, observations)[2] == pytest.approx(exact, rel=1e-10)


def test_a_fixed_size_box_keeps_the_first_box_size_whatever_the_noise():
    from replication.models.box import BoxModel

    rng = np.random.default_rng(0)
    model = BoxModel(np.array([50.0, 40.0, 20.0, 20.0]), None, kind="constant_velocity", size="fixed",
                     step_sd=(0.0, 0.0, 0.5, 0.5), initial_sd=(1.0, 1.0, 0.5, 0.5))
    particles = model.sample_initial(200, rng)
    for t in range(1, 300):
        particles = model.propagate(particles, t, rng)
    assert (particles[:, 2:4] == 20.0).all() and particles[:, :2].std() > 1.0  # the centre moves, the size not
    drifting = BoxModel(np.array([50.0, 40.0, 20.0, 20.0]), None, kind="constant_velocity",
                        step_sd=(0.0, 0.0, 0.5, 0.5))
    assert drifting.propagate(drifting.sample_initial(200, rng), 1, rng)[:, 2:4].std() > 0.1
    with pytest.raises(ValueError, match="unknown size"):
        BoxModel(np.ones(4), None, size="shrinking")


def test_bis_pf_tracks_the_balls_with_boxes_of_their_size():
    """Issue 30: the boxes of every filter on bis_pf's ball scenes stay 20x20 (they drifted to 57 px^2)."""
    from hydra import compose, initialize_config_dir

    from replication.paths import CONF_DIR
    from replication.runner.config import expand
    from replication.tasks import TASKS

    with initialize_config_dir(config_dir=str(CONF_DIR), version_base="1.3"):
        cfg = compose("config", overrides=["experiment=bis_pf", "scale=quick",
                                           "experiment.scenes.exp2_16_targets.frames.quick=30"])
    runs = expand(cfg)
    assert {r.model["motion"]["size"] for r in runs} == {"fixed"}
    run = next(r for r in runs if r.method == "BIS-PF" and r.condition.get("scene") == "exp2_16_targets")
    boxes = np.asarray(TASKS[run.task].run(run)["per_frame"]["box"], dtype=float)
    assert boxes.shape[1] == 16 and (boxes[..., 2:4] == 20.0).all()


@pytest.mark.parametrize("kind", ["random_walk", "constant_velocity"])
@pytest.mark.parametrize("noise_on", ["velocity", "position"])
@pytest.mark.parametrize("size", ["drifting", "fixed"])
def test_the_compiled_box_motion_is_the_matrix_form_to_the_bit(kind, noise_on, size):
    """propagate = constrain(f(x) + e @ W.T) with e the same normals (a constant-velocity model's two (N, 2)
    blocks drawn as one (2, N, 2) call), bit for bit: each row of W has one non-zero entry."""
    from replication.models.box import BoxModel

    model = BoxModel(np.array([50.0, 40.0, 20.0, 16.0]), None, kind=kind, noise_on=noise_on, size=size, accel_sd=0.63,
                     period=1.5, step_sd=(4.0, 3.0, 0.5, 0.1), min_size=15.0)
    rng = np.random.default_rng(1)
    particles = model.sample_initial(300, rng)
    particles[::7, 2:4] = 15.0  # sizes at the clamp
    for t in range(1, 30):
        replay = np.random.default_rng(t)
        blocks = [replay.standard_normal((300, 4))] if kind == "random_walk" else [
            replay.standard_normal((300, 2)), replay.standard_normal((300, 2))]
        expected = model.constrain(model.f(particles, t) + np.hstack(blocks) @ model.noise_factor.T)
        moved = model.propagate(particles[::-1][::-1], t, np.random.default_rng(t))  # any layout
        assert moved.tobytes() == expected.tobytes()
        particles = moved
