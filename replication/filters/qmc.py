"""Quasi-Monte-Carlo particle filters of gps_qmcpf Table 1: NQMCPF, TR-SQMC and GPS-QMCPF.

Each is the one loop of :mod:`replication.smc.loop` with its own proposal;
the proposal also draws x_0 (gps_qmcpf §2.3 step 1) through :class:`QMCParticleFilter`.
They need a model with additive Gaussian noise (:class:`AdditiveGaussianModel`):
``f(x, t)``, ``Q``, ``x0``, ``P0``; the support-box proposal (GPS-QMCPF, NQMCPF's
``support_box``) also ``transition_log_density``.
States are scalars (particles of shape (N,)) or d-vectors (shape (N, d), with
Q and P0 scalars, per-coordinate variances or covariance matrices).

``randomise=True`` (the default) gives every step a fresh Cranley-Patterson
shift of the point set drawn from the filter's rng, so runs with different
seeds are independent (randomised QMC).  ``randomise=False`` uses the same
deterministic points at every step, as the paper presumably did (§2.2: for a
given number of points "the distribution is the same every time"); the filter
is then deterministic whenever the loop does not resample (``ess_threshold=0``;
TR-SQMC resamples with its own points).
"""

import math
from dataclasses import dataclass

import numpy as np
from scipy.special import ndtri

from replication.filters.registry import drawn
from replication.libm import exp, log
from replication.qmc import POINT_SETS, point_set, random_shift
from replication.smc.loop import FilterState, ParticleFilter, ResamplingPolicy
from replication.smc.resampling import inverse_cdf
from replication.smc.weights import logsumexp, moments

NQMCPF_PROPOSALS = ("prior", "support_box")


def _gaussian(mean, cov, u: np.ndarray) -> np.ndarray:
    """mean + chol(cov) Phi^-1(u), u of shape (N,) for scalar states or (N, d)."""
    z = ndtri(u)
    cov = np.asarray(cov, dtype=float)
    return mean + (z @ np.linalg.cholesky(cov).T if cov.ndim == 2 else np.sqrt(cov) * z)


def _gaussian_log_density(x: np.ndarray, mean, cov) -> np.ndarray:
    """log N(x; mean, cov) per particle, x of shape (N,) or (N, d) (cov scalar, per-coordinate or full)."""
    residual = x - mean
    if residual.ndim == 1:
        return -0.5 * (residual**2 / cov + log(2.0 * np.pi * cov))
    cov = np.asarray(cov, dtype=float)
    full = cov if cov.ndim == 2 else np.diag(np.broadcast_to(cov, residual.shape[1:]))
    solved = np.linalg.solve(full, residual.T).T
    return -0.5 * (np.sum(residual * solved, axis=1) + np.linalg.slogdet(2.0 * np.pi * full)[1])


def _variances(cov, shape: tuple) -> np.ndarray:
    """Per-coordinate variances, of the state's ``shape``, of a scalar, vector or matrix covariance."""
    cov = np.asarray(cov, dtype=float)
    return np.broadcast_to(np.diag(cov) if cov.ndim == 2 else cov, shape)


@dataclass(frozen=True)
class _PointSource:
    """The proposal's uniforms: the point set ``points``, randomly shifted at each call if ``randomise``."""

    randomise: bool = True
    points: str = "halton"

    def __post_init__(self):
        if self.points not in POINT_SETS:
            raise ValueError(f"unknown point set {self.points!r}; choose one of {sorted(POINT_SETS)}")

    def draw(self, n: int, s: int, rng: np.random.Generator) -> np.ndarray:
        """n points in [0, 1)^s; randomised: shifted, and dealt to the particles in a random order.

        A shift alone would give particle i the point (h_i + U_t) mod 1 at
        every step t: its noise would stay correlated over time (the same
        direction each step while it is not resampled), which biases the
        filter once resampling is not done every step.
        """
        points = point_set(self.points, n, s)
        return random_shift(points, rng)[rng.permutation(n)] if self.randomise else points

    def uniforms(self, n: int, shape: tuple, rng: np.random.Generator) -> np.ndarray:
        """n points for states of ``shape`` (() or (d,)): an array (n, *shape)."""
        return self.draw(n, shape[0] if shape else 1, rng).reshape(n, *shape)

    def initial(self, model, n: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
        """Step 1: x_0^i = x0 + chol(P0) Phi^-1(u_i), equally weighted."""
        u = self.uniforms(n, np.shape(model.x0), rng)
        return _gaussian(model.x0, model.P0, u), np.full(n, -math.log(n))


@dataclass(frozen=True)
class NQMCProposal(_PointSource):
    """NQMCPF: x_t^i = f(x_{t-1}^i, t) + chol(Q) Phi^-1(u_i) with QMC points u_i; weights carried over.

    A model with a ``noise_factor`` W (a box model: x = A x + W e with fewer
    noise terms than states) takes x = f(x) + W Phi^-1(u) and its ``constrain``.

    The paper's ref [11] (an improved QMCPF) is not available (baselines.md §6:
    "no sources found"); this is the QMC-PF of baselines.md §6 (Guo & Wang 2006;
    Ormoneit et al. 2001): the bootstrap filter with the normal draws of the
    prior replaced by Halton points through the inverse normal CDF.  The
    support-box QMCPF of gps_qmcpf §1.2 is ``nqmcpf(proposal="support_box")``.
    """

    def __call__(self, model, particles, log_weights, t, rng):
        factor = getattr(model, "noise_factor", None)
        if factor is not None:  # x = A x + W Phi^-1(u), u in [0, 1)^k: rank-deficient noise (gps_qmcpf eq 14)
            u = self.draw(len(particles), factor.shape[1], rng)
            return model.constrain(model.f(particles, t) + ndtri(u) @ factor.T), log_weights
        u = self.uniforms(len(particles), particles.shape[1:], rng)
        return _gaussian(model.f(particles, t), model.Q, u), log_weights


@dataclass(frozen=True)
class SupportBoxProposal(_PointSource):
    """The support-box QMCPF: gps_qmcpf §2.3 steps 2-3 with the good points (GPS-QMCPF), and §1.2's
    standard QMCPF with Halton points ("generate a support interval to map the low-discrepancy particle
    set at time k; then compute the weights at time k from the distribution of all particles at k-1").

    Support box [a_k, b_k] = m ± c s per coordinate, where m and s^2 are the
    mean and variance of the predictive mixture sum_j w_{k-1}^j N(f(x_{k-1}^j), Q)
    (s^2 = the weighted variance of f(x_{k-1}^j) plus Q) and c = ``width``;
    the paper does not say how it estimates the box.

    x_k^i = a_k + (b_k - a_k) u_i, eq (6); predictive density by the mixture
    p(x_k^i | z_{1:k-1}) ~ sum_j w_{k-1}^j p(x_k^i | x_{k-1}^j), eq (7), an N x N
    logsumexp (O(N^2) per step); log-weight log p(x | z_{1:k-1}) - log q(x) - log N
    with q uniform on the box: eq (8) as the gps_qmcpf README reads it, the
    weights w_{k-1} entering through the mixture.  The loop adds the
    likelihood, normalises (eq 9) and estimates (eq 10); the 1/N makes the sum
    of the weights estimate p(z_k | z_{1:k-1}), so ``log_evidence`` stays right.
    """

    points: str = "good_cos"
    width: float = 4.0

    def __post_init__(self):
        super().__post_init__()
        if not self.width > 0:
            raise ValueError(f"width (c of the support box m ± c s) must be positive, got {self.width}")

    def _box(self, n, mean, variances, log_target, rng) -> tuple[np.ndarray, np.ndarray]:
        """Eq (6) on mean ± c sqrt(variances); log-weights log_target(x) - log q(x) - log N."""
        half = self.width * np.sqrt(variances)
        x = (mean - half) + 2.0 * half * self.uniforms(n, np.shape(variances), rng)
        return x, log_target(x) + np.sum(log(2.0 * half)) - math.log(n)

    def initial(self, model, n, rng):
        """Step 1: the good points on x0 ± c sqrt(P0), weighted by p(x_0) / q(x_0)."""
        variances = _variances(model.P0, np.shape(model.x0))
        if np.any(variances <= 0):
            raise ValueError("GPS-QMCPF needs P0 > 0 for its initial support box")
        return self._box(n, model.x0, variances, lambda x: _gaussian_log_density(x, model.x0, model.P0), rng)

    def __call__(self, model, particles, log_weights, t, rng):
        log_w = log_weights - logsumexp(log_weights)
        means = model.f(particles, t)
        mean, spread, _ = moments(means, exp(log_w))  # numpy's pairwise sums: alike on every CPU
        variances = spread + _variances(model.Q, particles.shape[1:])

        def log_predictive(x):  # eq (7)
            return logsumexp(log_w + model.transition_log_density(x[:, None], particles[None, :], t), axis=1)

        return self._box(len(particles), mean, variances, log_predictive, rng)


@dataclass(frozen=True)
class SQMCProposal(_PointSource):
    """SQMC (Gerber & Chopin 2015, JRSS-B 77(3)) for scalar states, standing in for TR-SQMC.

    The paper's TR-SQMC (its ref [12]) could not be pinned down (baselines.md
    §6: "no sources found"); this is the closest documented sequential QMC
    filter.  Each step takes N points u in [0, 1)^2 sorted by u_0; the
    particles are Hilbert-sorted (in 1-D: sorted by value); the ancestor of
    point i is the inverse CDF of the sorted weights at u_0^i, and
    x_t^i = f(x_{t-1}^{a_i}, t) + sqrt(Q) Phi^-1(u_1^i).  The proposal thus
    resamples at every step with its own points; the loop never resamples.
    """

    def __call__(self, model, particles, log_weights, t, rng):
        if particles.ndim != 1:
            raise ValueError(f"SQMC orders scalar states only (1-D Hilbert sort), got {particles.shape}")
        n = len(particles)
        u = self.draw(n, 2, rng)
        u = u[np.argsort(u[:, 0])]
        order = np.argsort(particles)
        ancestors = order[inverse_cdf(exp(log_weights[order] - log_weights.max()), u[:, 0])]
        return _gaussian(model.f(particles[ancestors], t), model.Q, u[:, 1]), np.full(n, -math.log(n))


@dataclass
class QMCParticleFilter(ParticleFilter):
    """The loop of :class:`ParticleFilter` with x_0 from the proposal's point set (gps_qmcpf §2.3 step 1)."""

    def start(self, model, rng: np.random.Generator) -> FilterState:
        particles, log_weights = self.proposal.initial(model, self.n_particles, rng)
        return FilterState(model, rng, particles, log_weights)


@drawn("sky", "-", "s")
def nqmcpf(
    n_particles: int,
    resampling: str = "multinomial",
    ess_threshold: float = 1.0,
    randomise: bool = True,
    points: str = "halton",
    proposal: str = "prior",
    width: float = 4.0,
) -> QMCParticleFilter:
    """NQMCPF with one of NQMCPF_PROPOSALS: ``"prior"`` (:class:`NQMCProposal`), Halton points through
    Phi^-1 for the prior, resampling as bootstrap; ``"support_box"`` (:class:`SupportBoxProposal`), the
    standard QMCPF of gps_qmcpf §1.2: the points on the box m ± width s, weighted by the predictive
    mixture times the likelihood (``width`` is used by this one only)."""
    if proposal == "prior":
        source = NQMCProposal(randomise, points)
    elif proposal == "support_box":
        source = SupportBoxProposal(randomise, points, width)
    else:
        raise ValueError(f"unknown NQMCPF proposal {proposal!r}; choose one of {NQMCPF_PROPOSALS}")
    return QMCParticleFilter(n_particles, ResamplingPolicy(resampling, ess_threshold), proposal=source)


@drawn("vermillion", "-", "D")
def gps_qmcpf(
    n_particles: int,
    resampling: str = "multinomial",
    ess_threshold: float = 0.0,
    randomise: bool = True,
    points: str = "good_cos",
    width: float = 4.0,
) -> QMCParticleFilter:
    """GPS-QMCPF (:class:`SupportBoxProposal`): good points on the box m ± width s, mixture weights.

    The mixture of eq (7) carries the weights, so the filter needs no
    resampling (default ``ess_threshold=0``); resampling only adds noise to it.
    """
    return QMCParticleFilter(
        n_particles,
        ResamplingPolicy(resampling, ess_threshold),
        proposal=SupportBoxProposal(randomise, points, width),
    )


@drawn("green", "-", "v")
def tr_sqmc(n_particles: int, randomise: bool = True, points: str = "halton") -> QMCParticleFilter:
    """TR-SQMC, here Gerber & Chopin's SQMC (:class:`SQMCProposal`): QMC resampling inside the proposal."""
    return QMCParticleFilter(
        n_particles, ResamplingPolicy("systematic", 0.0), proposal=SQMCProposal(randomise, points)
    )
