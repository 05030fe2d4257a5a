"""HSPF: IHS schedules, each stop rule, the search and its window, weight compensation (eqs 2-5), filters."""

import numpy as np
import pytest

from replication.filters.harmony import (
    HarmonyMove,
    bandwidth,
    hs,
    hspf,
    improvise,
    log_compensation,
    pitch_adjust_rate,
)
from replication.metrics.scalar import rmse
from replication.models.ungm import UNGM

OFF = dict(idle=None, precision=None, quality=None)  # only the NI rule


class Constant:
    """A generator whose uniforms are all ``u`` and whose integers are all ``k``."""

    def __init__(self, u, k):
        self.u, self.k = u, k

    def random(self, size):
        return np.full(size, self.u)

    def integers(self, high, size):
        return np.full(size, self.k)


class Rising:
    """A fitness that is the same for every harmony of one call and rises by one per call, capped at ``cap``:
    call 0 scores the initial memory, call gn the harmonies improvised at iteration gn."""

    def __init__(self, cap=np.inf):
        self.calls, self.cap = 0, cap

    def __call__(self, x):
        value = min(self.calls, self.cap)
        self.calls += 1
        return np.full(len(x), float(value))


def test_pitch_adjust_rate_rises_linearly_from_min_to_max():
    rates = pitch_adjust_rate(np.arange(11), 10, par_min=0.4, par_max=0.9)
    np.testing.assert_allclose(rates, np.linspace(0.4, 0.9, 11))


def test_bandwidth_decays_exponentially_from_max_to_min():
    widths = bandwidth(np.arange(11), 10, bw_min=1e-4, bw_max=1.0)
    assert widths[0] == 1.0
    assert widths[-1] == pytest.approx(1e-4)
    assert np.all(np.diff(widths) < 0)
    np.testing.assert_allclose(widths[1:] / widths[:-1], 1e-4**0.1)  # c = ln(bw_min / bw_max) / NI


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda: bandwidth(1, 0), "NI must be a positive integer"),
        (lambda: bandwidth(11, 10), "must lie in \\[0, NI"),
        (lambda: bandwidth(1, 10, bw_min=2.0, bw_max=1.0), "bw_min <= bw_max"),
        (lambda: pitch_adjust_rate(1, 10, par_min=0.9, par_max=0.4), "PAR_min <= PAR_max"),
        (lambda: HarmonyMove(ni=-1), "NI must be a non-negative"),
        (lambda: HarmonyMove(hms=0), "HMS must be a positive"),
        (lambda: HarmonyMove(hmcr=1.5), "HMCR must lie in"),
        (lambda: HarmonyMove(radius=(1.0, -1.0)), "radius must be a positive"),
        (lambda: HarmonyMove(idle=0), "idle \\(ider\\)"),
        (lambda: HarmonyMove(precision=0.0), "precision \\(Tprecision\\)"),
        (lambda: HarmonyMove(quality=-0.7), "quality \\(Tquality\\) is a likelihood"),
        (lambda: HarmonyMove(quality_units="ncc"), "unknown quality_units 'ncc'; choose one of"),
        (lambda: HarmonyMove(quality=1.5, quality_units="rho"), "in rho units must lie in \\[0, 1\\]"),
        (lambda: HarmonyMove(likelihood_sigma=0.0), "likelihood_sigma must be positive"),
        (lambda: HarmonyMove(compensation="magic"), "unknown compensation"),
        (lambda: log_compensation(np.zeros(2), np.zeros(2), "magic"), "unknown compensation"),
    ],
)
def test_bad_settings_are_refused(call, message):
    with pytest.raises(ValueError, match=message):
        call()


def test_radius_must_match_the_state():
    move = HarmonyMove(radius=(8.0, 8.0, 1.0, 1.0))
    with pytest.raises(ValueError, match="radius has 4 entries for a state of 1"):
        move(np.zeros(5), lambda x: -(x**2), np.random.default_rng(0))


def particles_and_rng():
    return np.linspace(-3.0, 3.0, 20), np.random.default_rng(7)


def test_ni_stops_the_search():
    particles, rng = particles_and_rng()
    result = HarmonyMove(ni=7, radius=1.0, **OFF).search(particles, lambda x: np.zeros(len(x)), rng)
    np.testing.assert_array_equal(result.iterations, 7)


@pytest.mark.parametrize("fitness, expected", [(lambda x: np.zeros(len(x)), 3), (Rising(cap=2), 2 + 3)])
def test_idle_iterations_stop_the_search(fitness, expected):
    # flat fitness: never a better best, so ider = 3 idle iterations; rising to 2: improves twice, then 3 idle
    particles, rng = particles_and_rng()
    move = HarmonyMove(ni=10, radius=1.0, idle=3, precision=None, quality=None)
    np.testing.assert_array_equal(move.search(particles, fitness, rng).iterations, expected)


def test_quality_stops_the_search_in_likelihood_units():
    particles, rng = particles_and_rng()
    move = HarmonyMove(ni=10, radius=1.0, idle=None, precision=None, quality=np.exp(4.0))
    rising = move.search(particles, Rising(), rng)
    np.testing.assert_array_equal(rising.iterations, 4)  # log f reaches 4 at gn = 4
    flat = HarmonyMove(ni=10, radius=1.0, idle=None, precision=None, quality=0.7)
    at_start = flat.search(particles, lambda x: np.full(len(x), np.log(0.8)), rng)  # f = 0.8 >= 0.7 already
    np.testing.assert_array_equal(at_start.iterations, 0)


def test_quality_in_rho_units_is_a_bhattacharyya_threshold():
    # rho >= 0.7 with sigma = 0.1: log p >= -0.3 / 0.02 - log(sqrt(2 pi) 0.1) = -15 + 1.383647 = -13.616353
    move = HarmonyMove(ni=10, radius=1.0, idle=None, precision=None, quality=0.7, quality_units="rho")
    assert move.log_quality == pytest.approx(-13.616353, abs=1e-6)
    particles, rng = particles_and_rng()

    def at_rho(rho):  # the colour likelihood of a box whose Bhattacharyya coefficient is rho, everywhere
        return lambda x: np.full(len(x), -(1.0 - rho) / (2.0 * 0.1**2) - np.log(np.sqrt(2.0 * np.pi) * 0.1))

    np.testing.assert_array_equal(move.search(particles, at_rho(0.75), rng).iterations, 0)
    np.testing.assert_array_equal(move.search(particles, at_rho(0.65), rng).iterations, 10)
    in_likelihood = HarmonyMove(ni=10, radius=1.0, idle=None, precision=None, quality=0.7)
    np.testing.assert_array_equal(in_likelihood.search(particles, at_rho(0.75), rng).iterations, 10)
    np.testing.assert_array_equal(in_likelihood.search(particles, at_rho(0.97), rng).iterations, 0)


def test_precision_stops_the_search_once_worst_and_best_meet():
    # fitness x; every uniform is 0.75, so the initial draw is x + 0.5 (the best), and with HMCR = 1 and
    # PAR = 0 the harmony at gn = 1 copies the draw (index 1), replaces the worst and the memory collapses
    particles = np.array([[0.0], [10.0]])
    settings = dict(ni=10, radius=1.0, hmcr=1.0, par_min=0.0, par_max=0.0, idle=None, quality=None)
    run = lambda precision: HarmonyMove(precision=precision, **settings).search(  # noqa: E731
        particles, lambda x: x[:, 0], Constant(u=0.75, k=1)
    )
    np.testing.assert_array_equal(run(0.6).iterations, 0)  # initial spread 0.5 < 0.6
    np.testing.assert_array_equal(run(0.1).iterations, 1)
    np.testing.assert_array_equal(run(0.1).harmony_memory[:, :, 0], [[0.5, 0.5], [10.5, 10.5]])
    np.testing.assert_array_equal(run(None).iterations, 10)


def test_stopped_particles_keep_their_best_while_others_search_on():
    particles = np.array([0.0, 5.0])
    # particle 0 sits where f = 1 >= quality and stops at once; particle 1 (f tiny) searches all NI iterations
    log_likelihood = lambda x: np.where(np.abs(x) < 1.0, 0.0, -50.0 - np.abs(x - 5.0))  # noqa: E731
    move = HarmonyMove(ni=6, radius=1.0, idle=None, precision=None, quality=0.5)
    result = move.search(particles, log_likelihood, np.random.default_rng(3))
    np.testing.assert_array_equal(result.iterations, [0, 6])
    assert result.best[0, 0] == 0.0


def test_ihs_climbs_a_quadratic_and_never_ends_worse_than_it_started():
    target = np.array([1.0, -1.0])

    def log_fitness(x):
        return -0.5 * np.sum((x - target) ** 2, axis=1)

    particles = np.random.default_rng(1).normal(0.0, 1.0, (200, 2))
    move = HarmonyMove(ni=200, hms=5, radius=3.0, **OFF)
    result = move.search(particles, log_fitness, np.random.default_rng(2))
    assert np.all(log_fitness(result.best) >= log_fitness(particles))
    before = np.linalg.norm(particles - target, axis=1).mean()
    after = np.linalg.norm(result.best - target, axis=1).mean()
    assert after < 0.05 * before


def test_new_harmonies_stay_inside_the_window():
    rng = np.random.default_rng(4)
    lower = rng.normal(0.0, 1.0, (500, 4))
    upper = lower + rng.uniform(0.1, 2.0, (500, 4))
    memory = lower[:, None] + rng.random((500, 3, 4)) * (upper - lower)[:, None]
    for par, bw in [(1.0, 1.0), (0.5, 0.3), (0.0, 1.0)]:
        for hmcr in (0.0, 0.5, 1.0):
            new = improvise(memory, lower, upper, hmcr, par, bw, rng)
            assert np.all((new >= lower) & (new <= upper))
    considered = improvise(memory, lower, upper, hmcr=1.0, par=0.0, bw=1.0, rng=rng)
    assert np.all(np.any(considered[:, None] == memory, axis=1))  # memory consideration alone copies values
    particles = rng.normal(0.0, 5.0, (300, 4))
    noise = np.random.default_rng(5)  # a rough fitness, so harmonies replace each other often
    result = HarmonyMove(ni=20, hms=4, radius=(8.0, 8.0, 1.0, 1.0), **OFF).search(
        particles, lambda x: noise.normal(size=len(x)), rng
    )
    offset = np.abs(result.harmony_memory - particles[:, None])
    assert np.all(offset <= np.array([8.0, 8.0, 1.0, 1.0]))


@pytest.mark.parametrize("reading", ["printed", "importance"])
def test_compensation_is_exactly_one_for_the_identity_move(reading):
    particles = np.random.default_rng(5).normal(0.0, 3.0, 50)
    unmoved, correction = HarmonyMove(ni=0, radius=1.0, compensation=reading)(
        particles, lambda x: -(x**2), np.random.default_rng(0)
    )
    np.testing.assert_array_equal(unmoved, particles)
    np.testing.assert_array_equal(correction, 0.0)
    # every improvised harmony is rejected: each particle sits on the peak of its window
    on_peaks = np.arange(-25.0, 25.0)
    rejected, correction = HarmonyMove(ni=10, radius=0.4, compensation=reading, **OFF)(
        on_peaks, lambda x: -((x - np.round(x)) ** 2), np.random.default_rng(0)
    )
    np.testing.assert_array_equal(rejected, on_peaks)
    np.testing.assert_array_equal(correction, 0.0)


def kernel(d2):
    """exp(-d^2 / (2 v)) with v = 14/9, the variance of both sets below."""
    return np.exp(-d2 * 9.0 / 28.0)


def test_compensation_by_hand():
    predicted, moved = np.array([0.0, 1.0, 3.0]), np.array([0.0, 2.0, 3.0])  # both sets have variance 14/9
    # printed eqs (2)-(3): sum_j G(X^j)(X^i) / sum_j G(X~^j)(X~^i), squared distances within each set
    printed = [
        (1 + kernel(4) + kernel(9)) / (1 + kernel(1) + kernel(9)),
        (kernel(4) + 1 + kernel(1)) / (kernel(1) + 1 + kernel(4)),
        (kernel(9) + kernel(1) + 1) / (kernel(9) + kernel(4) + 1),
    ]
    np.testing.assert_allclose(log_compensation(predicted, moved, "printed"), np.log(printed))
    assert np.log(printed[0]) == pytest.approx(-0.290327, abs=1e-6)
    # importance: sum_j G(X~^j)(X^i) / sum_j G(X^j)(X^i), squared distances from the moved particle
    importance = [
        (1 + kernel(1) + kernel(9)) / (1 + kernel(4) + kernel(9)),
        (kernel(4) + 2 * kernel(1)) / (kernel(4) + 1 + kernel(1)),
        (kernel(9) + kernel(4) + 1) / (kernel(9) + kernel(1) + 1),
    ]
    np.testing.assert_allclose(log_compensation(predicted, moved, "importance"), np.log(importance))
    # unequal spreads: X~ = (0, 2) has variance 1, X = (1, 2) variance 1/4; the Gaussians' normalising
    # constants 1 / sqrt(2 pi Sigma) then make lambda = sqrt(1 / (1/4)) = 2 (the exponentials cancel)
    np.testing.assert_allclose(log_compensation(np.array([0.0, 2.0]), np.array([1.0, 2.0])), np.log(2.0))
    np.testing.assert_array_equal(log_compensation(predicted, moved, "none"), 0.0)


def test_compensation_works_on_box_states():
    rng = np.random.default_rng(6)
    predicted = rng.normal(50.0, 5.0, (40, 4))
    target = np.array([55.0, 45.0, 20.0, 30.0])
    move = HarmonyMove(radius=(8.0, 8.0, 1.0, 1.0), compensation="importance")
    moved, correction = move(predicted, lambda x: -0.5 * np.sum((x - target) ** 2, axis=1), rng)
    assert moved.shape == predicted.shape and correction.shape == (40,)
    assert np.all(np.isfinite(correction)) and np.any(correction != 0.0)


def ungm_run(seed, **harmony):
    model = UNGM(Q=10.0, R=1.0, x0=1.0, P0=0.0, steps=60)
    states, observations = model.simulate(np.random.default_rng([seed, 0]))
    settings = dict(ni=10, hms=2, radius=np.sqrt(10.0), precision=None) | harmony
    output = hspf(100, "multinomial", **settings).run(model, observations, np.random.default_rng([seed, 1]))
    return output, states


def test_hspf_filters_the_ungm_deterministically():
    output, states = ungm_run(0)
    error = rmse(output.means, states)
    assert np.isfinite(error) and error < 15.0
    assert output.resampled.all() and not output.degenerate.any()
    again, _ = ungm_run(0)
    np.testing.assert_array_equal(again.means, output.means)
    other, _ = ungm_run(0, compensation="importance")
    assert np.isfinite(rmse(other.means, states))


class StillTarget:
    """A box that stands still at ``target``; the tracker starts at the origin."""

    target = np.array([12.0, -9.0, 20.0, 30.0])

    def sample_initial(self, n, rng):
        return np.tile([0.0, 0.0, 20.0, 30.0], (n, 1))

    def propagate(self, particles, t, rng):
        raise AssertionError("HS has no motion model")

    def log_likelihood(self, particles, observation, t):
        return -0.5 * np.sum((particles - self.target) ** 2, axis=1)


def test_hs_tracker_walks_its_window_towards_the_target():
    model = StillTarget()
    tracker = hs(ni=30, hms=4, radius=(4.0, 4.0, 1.0, 1.0), **OFF)
    output = tracker.run(model, range(12), np.random.default_rng(8))
    error = np.linalg.norm(output.means - model.target, axis=1)
    assert np.all(np.diff(error) <= 1e-12) and error[-1] < 1.0
    np.testing.assert_array_equal(output.ess, 1.0)
    assert not output.resampled.any()
