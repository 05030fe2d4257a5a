"""Point sets of gps_qmcpf and its quasi-Monte-Carlo filters against exact answers."""

import numpy as np
import pytest
from scipy.special import ndtri
from scipy.stats import qmc as scipy_qmc

from replication.filters.qmc import (
    NQMCProposal,
    SQMCProposal,
    SupportBoxProposal,
    gps_qmcpf,
    nqmcpf,
    tr_sqmc,
)
from replication.models import LinearGaussian, kalman_filter
from replication.qmc import (
    discrepancy,
    discrepancy_table,
    good_point,
    good_point_set,
    halton,
    point_set,
    random_shift,
)

MODEL = LinearGaussian(a=0.9, c=1.0, Q=1.0, R=0.5, x0=0.0, P0=1.0, steps=25)
BUILDERS = {"nqmcpf": nqmcpf, "gps_qmcpf": gps_qmcpf, "tr_sqmc": tr_sqmc}


# --- point sets ---------------------------------------------------------------------------


def test_good_point_for_s2_uses_p7():
    """(p - 3)/2 >= 2 first holds at p = 7: r = ({2 cos(2 pi/7)}, {2 cos(4 pi/7)})."""
    r = good_point(2)
    assert 2 * np.cos(2 * np.pi / 7) == pytest.approx(1.2469796)  # {.} drops 1
    assert 2 * np.cos(4 * np.pi / 7) == pytest.approx(-0.4450419)  # {.} = x - floor(x) adds 1
    np.testing.assert_allclose(r, [0.2469796, 0.5549581], atol=1e-7)


@pytest.mark.parametrize(
    ("s", "expected"),
    [
        (1, [0.618034]),  # p = 5: {2 cos(2 pi / 5)}, the golden ratio
        (3, [0.682507, 0.830830, 0.715370]),  # p = 11
        (6, [0.864944, 0.478018, 0.891477, 0.184537, 0.452674, 0.794731]),  # p = 17
    ],
)
def test_good_point_matches_the_table_of_baselines(s, expected):
    np.testing.assert_allclose(good_point(s), expected, atol=1e-6)


def test_exp_good_point_is_the_fractional_part_of_e_to_the_i():
    np.testing.assert_allclose(good_point(2, "exp"), [np.e - 2, np.e**2 - 7])


def test_good_point_set_is_k_times_r_modulo_one():
    points = good_point_set(400, 2)
    assert points.shape == (400, 2)
    assert np.all((points >= 0) & (points < 1))
    np.testing.assert_allclose(
        points[:3], [[0.2469796, 0.5549581], [0.4939592, 0.1099163], [0.7409388, 0.6648744]], atol=1e-7
    )
    k = np.arange(1, 401)[:, None]
    np.testing.assert_allclose(points, (k * good_point(2)) % 1.0, atol=1e-9)
    np.testing.assert_array_equal(good_point_set(400, 2), points)  # deterministic


def test_good_point_set_beats_random_points_in_discrepancy():
    """gps_qmcpf figs 1 and 3, n = 400 in 2-D: about 10 times lower than random points on average."""
    good = good_point_set(400, 2)
    for method in ("CD", "L2-star"):
        randoms = [discrepancy(np.random.default_rng(seed).random((400, 2)), method) for seed in range(10)]
        assert discrepancy(good, method) < min(randoms)
        assert discrepancy(good, method) < 0.6 * np.mean(randoms)


def test_halton_is_scipys_sequence_without_the_origin():
    points = halton(5, 2)
    np.testing.assert_allclose(points[:3], [[0.5, 1 / 3], [0.25, 2 / 3], [0.75, 1 / 9]])
    np.testing.assert_array_equal(points, scipy_qmc.Halton(2, scramble=False).random(6)[1:])
    assert np.all(points > 0)
    scrambled = [halton(5, 2, np.random.default_rng(3), scramble=True) for _ in range(2)]
    np.testing.assert_array_equal(*scrambled)
    assert not np.allclose(scrambled[0], points)


def test_random_shift_is_a_rotation_modulo_one():
    points = good_point_set(50, 3)
    shifted = random_shift(points, np.random.default_rng(0))
    assert np.all((shifted >= 0) & (shifted < 1))
    offset = (shifted - points) % 1.0
    np.testing.assert_allclose(offset, np.broadcast_to(offset[0], offset.shape), atol=1e-12)
    np.testing.assert_array_equal(shifted, random_shift(points, np.random.default_rng(0)))
    assert not np.allclose(shifted, random_shift(points, np.random.default_rng(1)))


def test_discrepancy_table_compares_the_three_point_sets():
    table = discrepancy_table(n=100, dims=(2, 3), seeds=3)
    assert list(table.columns) == ["s", "n", "random", "halton", "good_cos", "good_exp"]
    assert list(table["s"]) == [2, 3]
    assert np.all(table[["halton", "good_cos", "good_exp"]].to_numpy() < table[["random"]].to_numpy())


def test_bad_point_set_arguments_are_refused():
    for n, s in ((0, 2), (10, 0), (2.5, 2)):
        with pytest.raises(ValueError, match="positive integer"):
            good_point_set(n, s)
    with pytest.raises(ValueError, match="good point kind"):
        good_point(2, "sqrt")
    with pytest.raises(ValueError, match="needs an rng"):
        halton(10, 2, scramble=True)
    with pytest.raises(ValueError, match="discrepancy"):
        discrepancy(good_point_set(10, 2), "star")
    with pytest.raises(ValueError, match="point set"):
        point_set("sobol", 10, 2)
    with pytest.raises(ValueError, match=r"\(n, s\)"):
        random_shift(np.zeros(5), np.random.default_rng(0))


# --- proposals -----------------------------------------------------------------------------


def test_nqmcpf_draws_the_prior_through_the_inverse_normal_cdf():
    particles, log_weights = np.linspace(-1, 1, 8), np.log(np.full(8, 1 / 8))
    x, lw = NQMCProposal(randomise=False)(MODEL, particles, log_weights, 1, np.random.default_rng(0))
    np.testing.assert_allclose(x, MODEL.a * particles + np.sqrt(MODEL.Q) * ndtri(halton(8, 1)[:, 0]))
    np.testing.assert_array_equal(lw, log_weights)
    assert isinstance(nqmcpf(8).proposal, NQMCProposal)  # the default reading: prior-driven


@pytest.mark.parametrize(
    "proposal",
    [
        gps_qmcpf(20, randomise=False, width=2.0).proposal,  # GPS-QMCPF: the good points
        nqmcpf(20, randomise=False, proposal="support_box", width=2.0).proposal,  # §1.2: Halton points
    ],
    ids=["good_cos", "halton"],
)
def test_support_box_maps_the_points_into_the_box_and_weights_by_the_mixture(proposal):
    rng = np.random.default_rng(0)
    particles, log_weights = rng.standard_normal(20), np.log(rng.dirichlet(np.ones(20)))
    assert isinstance(proposal, SupportBoxProposal)
    x, lw = proposal(MODEL, particles, log_weights, 1, rng)
    w = np.exp(log_weights)
    means = MODEL.a * particles
    m, sd = w @ means, np.sqrt(w @ (means - w @ means) ** 2 + MODEL.Q)
    a, b = m - 2.0 * sd, m + 2.0 * sd
    np.testing.assert_allclose(x, a + (b - a) * point_set(proposal.points, 20, 1)[:, 0])  # eq (6)
    mixture = np.exp(MODEL.transition_log_density(x[:, None], particles[None, :], 1)) @ w  # eq (7)
    np.testing.assert_allclose(np.exp(lw), mixture * (b - a) / 20)  # eq (8) before the likelihood, / N


def test_sqmc_resamples_sorted_particles_with_the_first_coordinate():
    """All weight on the largest particle: every ancestor is that particle."""
    particles = np.array([3.0, -1.0, 7.0, 0.5])
    log_weights = np.array([-np.inf, -np.inf, 0.0, -np.inf])
    x, lw = SQMCProposal(randomise=False)(MODEL, particles, log_weights, 1, np.random.default_rng(0))
    u = halton(4, 2)
    u = u[np.argsort(u[:, 0])]
    np.testing.assert_allclose(x, MODEL.a * 7.0 + ndtri(u[:, 1]))
    np.testing.assert_allclose(lw, np.full(4, -np.log(4)))


# --- filters -------------------------------------------------------------------------------


def rms_gap_to_kalman(build, n, repeats=8):
    """RMS over steps and repeats of (filter mean - Kalman mean) on fixed data."""
    observations = MODEL.simulate(np.random.default_rng(123))[1]
    kalman_means, _, _ = kalman_filter(MODEL, observations)
    seeds = np.random.SeedSequence(0).spawn(repeats)
    gaps = [build(n).run(MODEL, observations, np.random.default_rng(s)).means - kalman_means for s in seeds]
    return float(np.sqrt(np.mean(np.square(gaps))))


SUPPORT_BOX = {"nqmcpf_support_box": lambda n: nqmcpf(n, ess_threshold=0.0, proposal="support_box")}


@pytest.mark.parametrize(
    ("name", "tolerance"),
    [("nqmcpf", 0.05), ("gps_qmcpf", 0.01), ("tr_sqmc", 0.04), ("nqmcpf_support_box", 0.01)],
)
def test_qmc_filters_converge_to_the_kalman_filter(name, tolerance):
    """Posterior sd is about 0.6; bootstrap PF's gap at N = 400 is about 0.045."""
    small, large = (rms_gap_to_kalman((BUILDERS | SUPPORT_BOX)[name], n) for n in (50, 400))
    assert large < tolerance, (small, large)
    assert large < 0.6 * small, (small, large)


def test_gps_qmcpf_log_evidence_matches_kalman_marginal_likelihood():
    observations = MODEL.simulate(np.random.default_rng(4))[1]
    _, _, exact = kalman_filter(MODEL, observations)
    estimate = gps_qmcpf(400).run(MODEL, observations, np.random.default_rng(2))
    assert estimate.log_evidence == pytest.approx(exact, abs=0.15)


@pytest.mark.parametrize("name", sorted(BUILDERS))
def test_randomised_filters_are_reproducible_per_seed_and_differ_between_seeds(name):
    observations = MODEL.simulate(np.random.default_rng(5))[1]
    first, again, other = (
        BUILDERS[name](100).run(MODEL, observations, np.random.default_rng(seed)).means for seed in (1, 1, 2)
    )
    np.testing.assert_array_equal(first, again)
    assert not np.allclose(first, other)


@pytest.mark.parametrize(
    "build",
    [
        lambda: nqmcpf(100, ess_threshold=0.0, randomise=False),
        lambda: gps_qmcpf(100, randomise=False),
        lambda: tr_sqmc(100, randomise=False),
    ],
    ids=sorted(BUILDERS),
)
def test_non_randomised_filters_ignore_the_seed(build):
    observations = MODEL.simulate(np.random.default_rng(5))[1]
    runs = [build().run(MODEL, observations, np.random.default_rng(seed)) for seed in (1, 2)]
    np.testing.assert_array_equal(runs[0].means, runs[1].means)
    np.testing.assert_array_equal(runs[0].ess, runs[1].ess)


def test_bad_filter_arguments_are_refused():
    with pytest.raises(ValueError, match="point set"):
        nqmcpf(100, points="sobol")
    with pytest.raises(
        ValueError, match=r"NQMCPF proposal 'mixture'; choose one of \('prior', 'support_box'\)"
    ):
        nqmcpf(100, proposal="mixture")
    with pytest.raises(ValueError, match="width"):
        nqmcpf(100, proposal="support_box", width=-1.0)
    with pytest.raises(ValueError, match="width"):
        gps_qmcpf(100, width=0.0)
    with pytest.raises(ValueError, match="resampling scheme"):
        gps_qmcpf(100, resampling="bogus")
    with pytest.raises(ValueError, match="P0 > 0"):
        gps_qmcpf(10).start(LinearGaussian(P0=0.0), np.random.default_rng(0))
    with pytest.raises(ValueError, match="scalar states"):
        SQMCProposal()(MODEL, np.zeros((4, 2)), np.zeros(4), 1, np.random.default_rng(0))


def test_randomised_points_are_dealt_afresh_each_step():
    """Consecutive draws give a particle unrelated points: no persistent noise direction per particle."""
    source = NQMCProposal(randomise=True, points="halton")
    rng = np.random.default_rng(5)
    draws = np.array([source.draw(500, 1, rng)[:, 0] for _ in range(40)])  # (steps, particles)
    lag_one = [np.corrcoef(draws[t], draws[t + 1])[0, 1] for t in range(39)]
    assert abs(np.mean(lag_one)) < 0.02
    u = np.sort(draws[0])  # still a shifted Halton set: its empirical CDF hugs the uniform one
    assert np.max(np.abs(np.arange(1, 501) / 500 - u)) < 0.01
