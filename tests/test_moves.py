"""The PSO and ISM move steps: hand-computed updates, the personal-best window, the loop hook."""

import numpy as np
import pytest

from replication.filters import FILTERS
from replication.filters.ism import ISMMove
from replication.filters.pso import PSOMove
from replication.models import LinearGaussian


class Stub:
    """A generator that returns prescribed numbers, so an update can be computed by hand."""

    def __init__(self, uniforms, normals):
        self.uniforms, self.normals = np.asarray(uniforms, float), np.asarray(normals, float)

    def random(self, shape):
        assert np.shape(self.uniforms) == tuple(shape)
        return self.uniforms

    def standard_normal(self, shape):
        assert np.shape(self.normals) == tuple(shape)
        return self.normals


def likelihood_table(x):
    return np.log(np.where(x[:, 0] == 1.0, 0.5, 0.2))  # F = 0.5 at x = 1, 0.2 elsewhere


@pytest.mark.parametrize("update, expected", [("additive", [4.4, -1.3314286]), ("replace", [3.4, -4.3314286])])
def test_ism_equations_10_to_16_by_hand(update, expected):
    particles = np.array([[1.0], [3.0]])
    rng = Stub(uniforms=[[0.5, 0.25], [1.0, 0.5]], normals=[[1, 2], [3, 4], [0.5, 1], [1, 0.5], [2, 2], [1, 1]])
    move = ISMMove(c1=0.8, c2=0.2, tau1=0.1, update=update)
    moved, correction = move(particles, likelihood_table, rng)
    # eq (10): u1 = u1 + randn (F(x) - F(p_g)), F(p_g) = 0.5: [0.5, 0.25 + 2 (0.2 - 0.5)]
    np.testing.assert_allclose(move.u[0], [0.5, -0.35])
    np.testing.assert_allclose(move.u[1], [1.0, 0.5])  # eq (11): each particle is its own best so far
    np.testing.assert_allclose(move.v[0, :, 0], [0.0, -0.2])  # eq (12): 0.1 * 1 * (1 - 3)
    np.testing.assert_allclose(move.v[1, :, 0], [0.0, 0.0])  # eq (13)
    # eqs (14)-(16): t1 = [2/0.5, 2/-0.35 - 0.2], t2 = [1/1, 1/0.5]; step = 0.8 t1 + 0.2 t2
    np.testing.assert_allclose(moved[:, 0], expected, rtol=1e-6)
    np.testing.assert_array_equal(correction, 0.0)


def test_personal_bests_only_look_back_over_the_window():
    move = ISMMove(window=3)
    rng = np.random.default_rng(0)
    best_first = [0.9, 0.5, 0.4, 0.3, 0.2]  # particle 0 was best at frame 0, worse every frame after
    for k, value in enumerate(best_first):
        positions = np.array([[float(k)], [100.0]])
        move(positions, lambda x, v=value: np.log(np.array([v, 0.1])), rng)
    personal, personal_value, leader, leader_value = move.bests()
    assert len(move.history) == 3
    assert personal_value[0] == 0.4 and personal[0, 0] == 2.0  # frames 2..4 only: frame 0's 0.9 is forgotten
    assert leader_value == 0.4 and leader[0] == 2.0


def test_ism_settings_are_checked():
    with pytest.raises(ValueError, match="c1 \\+ c2 = 1"):
        ISMMove(c1=0.8, c2=0.8)
    with pytest.raises(ValueError, match="unknown ISM update"):
        ISMMove(update="sideways")


def test_pso_climbs_towards_the_likelihood_peak_within_the_velocity_clamp():
    def log_likelihood(x):
        return -0.5 * ((x[:, 0] - 5.0) ** 2)

    particles = np.random.default_rng(1).normal(0.0, 1.0, (30, 1))
    move = PSOMove(iterations=20, max_velocity=(0.5,))
    moved, correction = move(particles, log_likelihood, np.random.default_rng(2))
    assert np.abs(moved[:, 0] - 5).mean() < np.abs(particles[:, 0] - 5).mean() / 2
    assert np.all(np.abs(moved - particles) <= 20 * 0.5 + 1e-9)
    np.testing.assert_array_equal(correction, 0.0)
    unmoved, _ = PSOMove(iterations=0, max_velocity=(0.5,))(particles, log_likelihood, np.random.default_rng(2))
    np.testing.assert_array_equal(unmoved, particles)


def test_pso_stops_once_the_global_best_is_good_enough():
    calls = []

    def log_likelihood(x):
        calls.append(1)
        return np.zeros(len(x))

    PSOMove(iterations=10, max_velocity=(1.0,), stop_log_likelihood=-1.0)(np.zeros((5, 1)), log_likelihood, None)
    assert len(calls) == 1  # the first evaluation already reaches the threshold
    with pytest.raises(ValueError, match="max_velocity has 4 entries"):
        PSOMove()(np.zeros((5, 1)), log_likelihood, np.random.default_rng(0))


@pytest.mark.parametrize("name, extra", [("pso", {"max_velocity": [1.0]}), ("ism", {})])
def test_moves_plug_into_the_one_loop(name, extra):
    model = LinearGaussian(steps=15)
    observations = model.simulate(np.random.default_rng(0))[1]
    output = FILTERS[name](n_particles=50, **extra).run(_Column(model), observations, np.random.default_rng(1))
    assert np.all(np.isfinite(output.means)) and output.resample_count == 15


class _Column:
    """A scalar model with (N, 1) particles, the shape the image moves work in."""

    def __init__(self, model):
        self.model = model

    def sample_initial(self, n, rng):
        return self.model.sample_initial(n, rng)[:, None]

    def propagate(self, particles, t, rng):
        return self.model.propagate(particles[:, 0], t, rng)[:, None]

    def log_likelihood(self, particles, z, t):
        return self.model.log_likelihood(particles[:, 0], z, t)
