"""The PSO and ISM move steps: hand-computed updates, the personal-best window, the loop hook."""

import numpy as np
import pytest

from replication.filters.registry import builder
from replication.filters.ism import ISMMove
from replication.filters.pso import PSOMove
from replication.models import LinearGaussian
from replication.vision.likelihood import gaussian_similarity_log_likelihood


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
    personal, personal_value, leader, leader_value = move.best_positions(move.scores(None))
    assert len(move.history) == 3
    assert personal_value[0] == 0.4 and personal[0, 0] == 2.0  # frames 2..4 only: frame 0's 0.9 is forgotten
    assert leader_value == 0.4 and leader[0] == 2.0


def test_ism_settings_are_checked():
    with pytest.raises(ValueError, match="c1 \\+ c2 = 1"):
        ISMMove(c1=0.8, c2=0.8)
    with pytest.raises(ValueError, match="unknown ISM update"):
        ISMMove(update="sideways")
    for option in ("bests", "v_memory", "moves"):
        with pytest.raises(ValueError, match=f"unknown ISM {option} 'sideways'; choose one of"):
            ISMMove(**{option: "sideways"})


def _table(values):
    """A likelihood that gives F = values[x] at the 1-D position x."""
    return lambda x: np.log([values[float(p)] for p in x[:, 0]])


@pytest.mark.parametrize("bests, leader, u1", [("stored", 0.0, [0.1, -0.8]), ("rescored", 2.0, [0.5, -0.4])])
def test_rescored_bests_pick_the_current_frames_best(bests, leader, u1):
    # frame 0: particle 0 at A = 0 scores 0.9; frame 1: it is at B = 2, which scores 0.5 now, while A scores 0.05 now
    # (particle 1: 5 scored 0.3 then, 0.01 now; 6 scores 0.2 now)
    move = ISMMove(window=30, bests=bests)
    rng = Stub(uniforms=[[0.5, 0.5], [0.5, 0.5]], normals=np.ones((6, 2)))
    move(np.array([[0.0], [5.0]]), _table({0.0: 0.9, 5.0: 0.3}), rng)
    evaluated = []
    frame1 = _table({0.0: 0.05, 2.0: 0.5, 5.0: 0.01, 6.0: 0.2})
    move(np.array([[2.0], [6.0]]), lambda x: evaluated.append(len(x)) or frame1(x), rng)
    personal, personal_value, best, best_value = move.best_positions(move.scores(frame1))
    assert best[0] == leader  # stored: A by its old 0.9; rescored: B, the best on the current frame
    assert personal[1, 0] == (5.0 if bests == "stored" else 6.0)
    # eq (10), randn = 1: frame 0 gives u1 = 0.5 + [0.9, 0.3] - 0.9; frame 1 adds [0.5, 0.2] - F(p_g),
    # F(p_g) = 0.9 stored (A's old score) or 0.5 rescored (B's)
    np.testing.assert_allclose(move.u[0], u1)
    # re-scoring is paid: the earlier frame's N positions are evaluated on the current frame in one call
    assert evaluated == ([2] if bests == "stored" else [2, 2])


@pytest.mark.parametrize("v_memory, carried", [("carried", -0.2), ("reset", 0.0)])
def test_v_reset_carries_no_velocity_from_the_previous_frame(v_memory, carried):
    move = ISMMove(v_memory=v_memory)
    rng = Stub(uniforms=[[0.5, 0.25], [1.0, 0.5]], normals=np.ones((6, 2)))
    move(np.array([[1.0], [3.0]]), likelihood_table, rng)  # eq (12): v1 = 0.1 * 1 * (1 - 3) for particle 1
    np.testing.assert_allclose(move.v[0, :, 0], [0.0, -0.2])
    # frame 1: both particles sit on the global and their personal best, so eqs (12)-(13) add nothing
    moved, _ = move(np.array([[1.0], [1.0]]), likelihood_table, rng)
    np.testing.assert_allclose(move.v[0, :, 0], [0.0, carried])
    np.testing.assert_allclose(move.v[1], 0.0)
    t1, t2 = 1 / move.u[0, 1] + carried, 1 / move.u[1, 1]  # eqs (14)-(15) with randn = 1
    np.testing.assert_allclose(moved[1, 0], 1.0 + 0.8 * t1 + 0.2 * t2)


@pytest.mark.parametrize("update", ["additive", "replace"])
def test_position_moves_leave_width_and_height_to_the_motion_model(update):
    particles = np.array([[10.0, 20.0, 30.0, 40.0], [12.0, 21.0, 28.0, 44.0]])

    def log_likelihood(x):
        return -0.5 * ((x[:, 0] - 11.0) ** 2 + (x[:, 2] - 29.0) ** 2)

    def moved(moves):
        rng = Stub(uniforms=[[0.5, 0.25], [1.0, 0.5]], normals=[[1, 2], [3, 4], [0.5, 1], [1, 0.5], [2, 2], [1, 1]])
        return ISMMove(update=update, moves=moves)(particles, log_likelihood, rng)[0]

    box, position = moved("box"), moved("position")
    np.testing.assert_array_equal(position[:, 2:], particles[:, 2:])  # w, h untouched
    np.testing.assert_array_equal(position[:, :2], box[:, :2])  # (x, y) take the same ISM step
    assert np.all(box[:, 2:] != particles[:, 2:])  # while box moves w, h with the same scalar


def test_eqs_10_11_leave_u_unchanged_when_f_is_as_small_as_sigma_c_003_makes_it():
    # sigma_c = 0.03 (eq 30): rho = 0.83 gives F = 1e-40, rho = 0.57 gives F = 1e-103, the range measured
    # on the office stand-in and Girl; u ~ U(0, 1) cannot register a change of 1e-40 in float64
    def small(x):
        return gaussian_similarity_log_likelihood(np.where(x[:, 0] == 1.0, 0.83, 0.57), 0.03)

    assert np.allclose(np.log10(np.exp(small(np.array([[1.0], [3.0]])))), [-40, -103], atol=1.5)
    uniforms = np.array([[0.5, 0.25], [1.0, 0.5]])
    rng = Stub(uniforms=uniforms.copy(), normals=[[1, 2], [3, 4], [0.5, 1], [1, 0.5], [2, 2], [1, 1]])
    move = ISMMove()
    move(np.array([[1.0], [3.0]]), small, rng)
    np.testing.assert_array_equal(move.u, uniforms)
    # at rho = 1 (F = 13.3, a perfect match) the same update does move u
    perfect = ISMMove()
    perfect(np.array([[1.0], [3.0]]), lambda x: gaussian_similarity_log_likelihood(np.where(x[:, 0] == 1.0, 1.0, 0.57), 0.03),
            Stub(uniforms=uniforms.copy(), normals=[[1, 2], [3, 4], [0.5, 1], [1, 0.5], [2, 2], [1, 1]]))
    assert perfect.u[0, 1] != uniforms[0, 1]


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


@pytest.mark.parametrize("personal_bests, expected", [("frame", [3.0, 9.0]), ("history", [3.0, 7.0])])
def test_pso_history_bests_are_kept_across_frames(personal_bests, expected):
    # c2 = 0 and r1 = 0.5: one iteration moves each particle half-way to its personal best
    move = PSOMove(iterations=1, c1=1.0, c2=0.0, max_velocity=(100.0,), personal_bests=personal_bests)
    rng = Stub(uniforms=[[0.5], [0.5]], normals=[])
    frame0, _ = move(np.array([[0.0], [5.0]]), lambda x: np.zeros(len(x)), rng)  # flat: nothing moves
    # frame 1 peaks at 5, where particle 1 was at frame 0: re-scored now, 5 beats its predicted 9 (0 > -16),
    # while particle 0's predicted 3 beats its old 0 (-4 > -25)
    moved, _ = move(np.array([[3.0], [9.0]]), lambda x: -((x[:, 0] - 5.0) ** 2), rng)
    np.testing.assert_allclose(moved[:, 0], expected)
    assert len(move.history) == (2 if personal_bests == "history" else 0)
    with pytest.raises(ValueError, match="unknown PSO personal_bests 'all'; choose one of"):
        PSOMove(personal_bests="all")


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
    output = builder(name)(n_particles=50, **extra).run(_Column(model), observations, np.random.default_rng(1))
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
