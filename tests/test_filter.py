"""The particle-filter loop against exact answers."""

import numpy as np
import pytest

from replication import bootstrap
from replication.models import UNGM, LinearGaussian, kalman_filter
from replication.smc import ParticleFilter, ResamplingPolicy

MODEL = LinearGaussian(a=0.9, c=1.0, Q=1.0, R=0.5, x0=0.0, P0=1.0, steps=25)


def rms_gap_to_kalman(n, repeats=24, seed=0):
    """RMS over steps and repeats of (PF posterior mean - Kalman posterior mean) on fixed data."""
    observations = MODEL.simulate(np.random.default_rng(123))[1]
    kalman_means, _, _ = kalman_filter(MODEL, observations)
    seeds = np.random.SeedSequence(seed).spawn(repeats)
    gaps = [
        bootstrap(n, "systematic", 0.5)
        .run(MODEL, observations, np.random.default_rng(s))
        .means
        - kalman_means
        for s in seeds
    ]
    return float(np.sqrt(np.mean(np.square(gaps))))


def test_bootstrap_pf_converges_to_kalman_at_root_n():
    sizes = np.array([100, 400, 1600, 6400])
    gaps = np.array([rms_gap_to_kalman(n) for n in sizes])
    slope = np.polyfit(np.log(sizes), np.log(gaps), 1)[0]
    assert np.all(np.diff(gaps) < 0), gaps
    assert -0.65 < slope < -0.35, (slope, gaps)  # Monte Carlo error ~ N^(-1/2)
    assert gaps[-1] < 0.02  # the posterior sd is about 0.6: 6400 particles are within 3% of it


def test_pf_variance_estimate_matches_kalman_variance():
    observations = MODEL.simulate(np.random.default_rng(9))[1]
    _, kalman_variances, _ = kalman_filter(MODEL, observations)
    output = bootstrap(20_000).run(MODEL, observations, np.random.default_rng(1))
    np.testing.assert_allclose(output.variances, kalman_variances, rtol=0.1)


def test_log_evidence_matches_kalman_marginal_likelihood():
    """The product of the normalising constants estimates p(z_1:T), known exactly for this model."""
    observations = MODEL.simulate(np.random.default_rng(4))[1]
    _, _, exact = kalman_filter(MODEL, observations)
    estimate = bootstrap(20_000, ess_threshold=1.0).run(MODEL, observations, np.random.default_rng(2))
    assert estimate.log_evidence == pytest.approx(exact, abs=0.1)


class Unexplainable(UNGM):
    """UNGM whose observation at step 3 no particle can explain (likelihood exactly zero)."""

    def log_likelihood(self, particles, observation, t):
        if t == 3:
            return np.full(particles.shape, -np.inf)
        return super().log_likelihood(particles, observation, t)


@pytest.mark.parametrize("scheme", ["multinomial", "systematic", "stratified", "residual"])
def test_a_frame_with_all_minus_infinity_is_recovered_not_nan(scheme):
    model = Unexplainable(steps=6)
    states, observations = model.simulate(np.random.default_rng(0))
    output = ParticleFilter(200, ResamplingPolicy(scheme, 0.5)).run(model, observations, np.random.default_rng(1))
    assert np.all(np.isfinite(output.means)) and np.all(np.isfinite(output.ess))
    np.testing.assert_array_equal(output.degenerate, [False, False, True, False, False, False])


def test_resampling_policy_threshold():
    rng = np.random.default_rng(0)
    model = UNGM(steps=40)
    observations = model.simulate(rng)[1]
    always = bootstrap(100, ess_threshold=1.0).run(model, observations, np.random.default_rng(1))
    never = bootstrap(100, ess_threshold=0.0).run(model, observations, np.random.default_rng(1))
    adaptive = bootstrap(100, ess_threshold=0.5).run(model, observations, np.random.default_rng(1))
    assert always.resample_count == 40 and never.resample_count == 0
    assert 0 < adaptive.resample_count < 40
    # adaptive resampling happens exactly at the steps whose ESS fell under N/2
    np.testing.assert_array_equal(adaptive.resampled, adaptive.ess < 50)


def test_identity_move_changes_nothing():
    """The move hook: an identity move with zero correction leaves the filter's output unchanged."""
    observations = MODEL.simulate(np.random.default_rng(5))[1]
    plain = bootstrap(300).run(MODEL, observations, np.random.default_rng(8))
    calls = []

    def identity(particles, log_likelihood, rng):
        calls.append(log_likelihood(particles).shape)
        return particles, np.zeros(len(particles))

    moved = ParticleFilter(300, ResamplingPolicy(), move=identity).run(MODEL, observations, np.random.default_rng(8))
    np.testing.assert_array_equal(plain.means, moved.means)
    assert calls == [(300,)] * MODEL.steps


def test_bad_arguments_are_refused():
    for n in (0, -5, 2.5):
        with pytest.raises(ValueError, match="n_particles"):
            ParticleFilter(n)
    with pytest.raises(ValueError, match="resampling scheme"):
        ResamplingPolicy("bogus")
    with pytest.raises(ValueError, match="ess_threshold"):
        ResamplingPolicy("systematic", 1.5)


def test_no_global_random_state_is_touched():
    before = np.random.get_state()[1].copy()
    model = UNGM(steps=10)
    observations = model.simulate(np.random.default_rng(0))[1]
    for scheme in ("multinomial", "systematic", "stratified", "residual"):
        bootstrap(50, scheme, 1.0).run(model, observations, np.random.default_rng(1))
    np.testing.assert_array_equal(np.random.get_state()[1], before)


def test_package_source_never_calls_legacy_global_random():
    from pathlib import Path

    import replication

    allowed = ("np.random.Generator", "np.random.default_rng", "np.random.SeedSequence")
    for path in Path(replication.__file__).parent.rglob("*.py"):
        for line in path.read_text().splitlines():
            if "np.random." in line:
                assert any(a in line for a in allowed) and "np.random.seed" not in line, f"{path}: {line}"


def test_buffers_kept_across_steps_never_overwrite_what_a_step_handed_out():
    """The loop reuses its log-weight and weight arrays from step to step; the log-weights and particles
    a step leaves in the state stay as they were after later steps (a step without resampling hands on
    log W = lw - logsumexp(lw), a new array; one with resampling the equal log-weights, never written)."""
    model = UNGM(steps=30)
    observations = model.simulate(np.random.default_rng(0))[1]
    pf = bootstrap(500, "systematic", 0.5)
    state = pf.start(model, np.random.default_rng(1))
    kept = []
    for z in observations:
        pf.step(state, z)
        kept.append((state.particles, state.log_weights, state.particles.copy(), state.log_weights.copy()))
    for particles, log_weights, particles_then, log_weights_then in kept:
        np.testing.assert_array_equal(particles, particles_then)
        np.testing.assert_array_equal(log_weights, log_weights_then)
    again = pf.run(model, observations, np.random.default_rng(1))
    np.testing.assert_array_equal(state.output().means, again.means)
    assert 0 < again.resample_count < len(observations)
