"""HSPF: the harmony search particle filter of Sun, Zhang, Hu and Mei (2018), and its HS tracker.

Each predicted particle x~^i seeds its own harmony memory inside the search
window [x~^i - radius, x~^i + radius]; improved harmony search (IHS, Mahdavi
et al. 2007; the paper's section 2.1, ``baselines.md`` §4) improvises one new
harmony per iteration and particle, all particles in parallel, and the
particle moves to its best harmony.  Its weight is then compensated by lambda
(eqs 1-5) before the loop multiplies in the likelihood.

What the paper leaves open, and our reading:

* fitness: log p(z | x), the log of the paper's objective f = p(Z | X); the
  log changes no comparison.  The units of ``quality`` (Tquality = 0.7) are
  not stated: ``quality_units="likelihood"`` (our default) stops a particle
  once its best harmony has p(z | x) >= quality; ``"rho"`` reads it as
  Fourie et al.'s Bhattacharyya threshold rho >= quality, i.e. p(z | x) >=
  exp(-(1 - rho_th) / (2 sigma^2)) / (sqrt(2 pi) sigma) for the colour
  likelihood with ``likelihood_sigma``.  With sigma = 0.1, 0.7 in likelihood
  units means rho >= 0.965; on the UNGM with R = 1 the likelihood never
  exceeds 0.399, so 0.7 never fires there.
* window: ``radius`` per coordinate (a scalar applies to all); the default
  (8, 8, 1, 1) px is twice the box random walk's ``step_sd``.
* initial memory (Step 2): the predicted particle plus HMS - 1 uniform draws
  in the window, so a particle never ends worse than it was predicted.
* bw_min, bw_max (baselines' 1e-4 and 1.0) are fractions of the radius: the
  first pitch adjustments span the whole window, the last are ~1e-4 of it.
* stop rules, per particle (a stopped particle keeps its best harmony):
  NI iterations; ``idle`` (ider) iterations in a row without a better best
  harmony; ``precision`` (Tprecision): Euclidean distance between the worst
  and the best harmony (px for boxes); ``quality`` (Tquality) as above.
  Precision and quality are also checked on the initial memory.  The paper's
  values 5 px and 0.7 are for tracking: on a scalar model pass
  ``precision=None`` (5 would stop at once with Q = 10).  NI = 0 turns the
  search off.
* compensation: eqs (2)-(3) read as printed (``"printed"``) give
  lambda^i = p(X^i) / q(X~^i), the mixture of the moved particles at the
  moved particle over the mixture of the predicted particles at the
  predicted particle.  ``"importance"`` is the correction eq (1) aims at
  ("so that the new particle set and the set before the move follow the
  same distribution"): X^i is a draw from the proposal q (prior
  prediction, then the HS move), whose density is intractable, and the
  target is p(z | x) pi(x) with pi the prior prediction, so the importance
  weight is pi(X^i) / q(X^i) p(z | X^i).  The mixtures of eqs (2)-(3) are
  kernel estimates of pi (centred on the predicted particles, draws from
  pi) and of q (centred on the moved ones, draws from q), both evaluated at
  the moved particle, as in MSEPF (Shan et al. 2007).  As printed, eq (1)
  puts the moved set's density on top and evaluates the predicted set's at
  the unmoved particle, which inverts the ratio.  A move that leaves every
  particle in place gives lambda = 1 under both.  Each mixture's Gaussians
  have the diagonal variance of the particle set they are centred on
  ("Sigma is the variance of the particle set").  ``"none"`` ignores the
  move (the HS tracker).
"""

from dataclasses import dataclass

import numpy as np

from replication.filters.registry import drawn
from replication.smc.loop import ParticleFilter, ResamplingPolicy
from replication.smc.weights import logsumexp
from replication.vision.likelihood import gaussian_similarity_log_likelihood

COMPENSATIONS = ("printed", "importance", "none")
QUALITY_UNITS = ("likelihood", "rho")
MIN_VARIANCE = 1e-12  # keeps G defined when a particle set has no spread in a coordinate


def _check_iteration(gn, ni: int) -> None:
    if int(ni) != ni or ni <= 0:
        raise ValueError(f"NI must be a positive integer, got {ni}")
    if np.any(np.asarray(gn) < 0) or np.any(np.asarray(gn) > ni):
        raise ValueError(f"the iteration gn must lie in [0, NI = {ni}], got {gn}")


def pitch_adjust_rate(gn, ni: int, par_min: float = 0.4, par_max: float = 0.9):
    """PAR(gn) = PAR_min + (PAR_max - PAR_min) gn / NI (section 2.1): linear from PAR_min to PAR_max."""
    _check_iteration(gn, ni)
    if not 0.0 <= par_min <= par_max <= 1.0:
        raise ValueError(f"need 0 <= PAR_min <= PAR_max <= 1, got {par_min}, {par_max}")
    return par_min + (par_max - par_min) * np.asarray(gn) / ni


def bandwidth(gn, ni: int, bw_min: float = 1e-4, bw_max: float = 1.0):
    """bw(gn) = bw_max exp(c gn), c = ln(bw_min / bw_max) / NI (section 2.1): bw_max at 0, bw_min at NI."""
    _check_iteration(gn, ni)
    if not 0.0 < bw_min <= bw_max:
        raise ValueError(f"need 0 < bw_min <= bw_max, got {bw_min}, {bw_max}")
    return bw_max * np.exp(np.log(bw_min / bw_max) / ni * np.asarray(gn))


def log_mixture_density(points: np.ndarray, centres: np.ndarray) -> np.ndarray:
    """log (1/N) sum_j G(centres^j, Sigma)(points^i) for each point (eqs 2-3);
    Sigma is the diagonal variance of the centres."""
    points, centres = points.reshape(len(points), -1), centres.reshape(len(centres), -1)
    variance = np.maximum(centres.var(axis=0), MIN_VARIANCE)
    distance = (((points[:, None, :] - centres[None, :, :]) ** 2) / variance).sum(axis=-1)
    norm = np.log(len(centres)) + 0.5 * np.log(2.0 * np.pi * variance).sum()
    return logsumexp(-0.5 * distance, axis=1) - norm


def log_compensation(predicted: np.ndarray, moved: np.ndarray, reading: str = "printed") -> np.ndarray:
    """log lambda^i of eq (5) for particles moved from ``predicted`` (X~) to ``moved`` (X);
    ``reading`` is one of COMPENSATIONS (see the module notes)."""
    if reading == "printed":
        return log_mixture_density(moved, moved) - log_mixture_density(predicted, predicted)
    if reading == "importance":
        return log_mixture_density(moved, predicted) - log_mixture_density(moved, moved)
    if reading == "none":
        return np.zeros(len(moved))
    raise ValueError(f"unknown compensation {reading!r}; choose one of {COMPENSATIONS}")


def improvise(harmony_memory, lower, upper, hmcr: float, par: float, bw: float, rng) -> np.ndarray:
    """One new harmony per memory (N, HMS, d) in its window [lower, upper] (Step 3 with IHS): per coordinate,
    with probability HMCR a random memory's value, then with probability PAR moved by +-U(0,1) bw half-widths
    unless that leaves the window; otherwise a uniform draw in the window."""
    n, hms, d = harmony_memory.shape
    pick = rng.integers(hms, size=(n, 1, d))
    considered = np.take_along_axis(harmony_memory, pick, axis=1)[:, 0]
    step = bw * (upper - lower) / 2.0 * rng.random((n, d))
    adjusted = considered + np.where(rng.random((n, d)) < 0.5, step, -step)
    adjust = (rng.random((n, d)) < par) & (adjusted >= lower) & (adjusted <= upper)
    considered = np.where(adjust, adjusted, considered)
    random = lower + rng.random((n, d)) * (upper - lower)
    return np.where(rng.random((n, d)) < hmcr, considered, random)


@dataclass
class HarmonySearch:
    """Each particle's final harmony memory (N, HMS, d), its fitness (N, HMS) and iterations run (N,)."""

    harmony_memory: np.ndarray
    fitness: np.ndarray
    iterations: np.ndarray

    @property
    def best(self) -> np.ndarray:
        return self.harmony_memory[np.arange(len(self.fitness)), self.fitness.argmax(axis=1)]


@dataclass
class HarmonyMove:
    """Move each predicted particle to the best harmony of its own IHS run; return log lambda (eqs 2-5)."""

    ni: int = 10
    hms: int = 2
    hmcr: float = 0.9
    par_min: float = 0.4
    par_max: float = 0.9
    bw_min: float = 1e-4  # fraction of the radius
    bw_max: float = 1.0  # fraction of the radius: a pitch adjustment first spans the window
    radius: float | tuple[float, ...] = (8.0, 8.0, 1.0, 1.0)
    idle: int | None = 5
    precision: float | None = 5.0
    quality: float | None = 0.7  # Tquality, in quality_units
    quality_units: str = "likelihood"  # or "rho": the Bhattacharyya coefficient (see the module notes)
    likelihood_sigma: float = 0.1  # the colour likelihood's sigma: turns a Tquality in rho into p(z | x)
    compensation: str = "printed"

    def __post_init__(self):
        if int(self.ni) != self.ni or self.ni < 0:
            raise ValueError(f"NI must be a non-negative integer, got {self.ni}")
        if int(self.hms) != self.hms or self.hms < 1:
            raise ValueError(f"HMS must be a positive integer, got {self.hms}")
        if not 0.0 <= self.hmcr <= 1.0:
            raise ValueError(f"HMCR must lie in [0, 1], got {self.hmcr}")
        if not 0.0 <= self.par_min <= self.par_max <= 1.0:
            raise ValueError(f"need 0 <= par_min <= par_max <= 1, got {self.par_min}, {self.par_max}")
        if not 0.0 < self.bw_min <= self.bw_max:
            raise ValueError(f"need 0 < bw_min <= bw_max, got {self.bw_min}, {self.bw_max}")
        self.radius = np.asarray(self.radius, dtype=float)
        if self.radius.ndim > 1 or np.any(self.radius <= 0):
            raise ValueError(f"radius must be a positive number or one per coordinate, got {self.radius}")
        if self.idle is not None and (int(self.idle) != self.idle or self.idle < 1):
            raise ValueError(f"idle (ider) must be a positive integer or None, got {self.idle}")
        if self.precision is not None and self.precision <= 0:
            raise ValueError(f"precision (Tprecision) must be positive or None, got {self.precision}")
        if self.quality_units not in QUALITY_UNITS:
            raise ValueError(f"unknown quality_units {self.quality_units!r}; choose one of {QUALITY_UNITS}")
        if self.quality is not None and self.quality_units == "likelihood" and self.quality <= 0:
            raise ValueError(
                f"quality (Tquality) is a likelihood and must be positive or None, got {self.quality}"
            )
        if self.quality is not None and self.quality_units == "rho" and not 0.0 <= self.quality <= 1.0:
            raise ValueError(
                f"quality (Tquality) in rho units must lie in [0, 1] or be None, got {self.quality}"
            )
        if not self.likelihood_sigma > 0:
            raise ValueError(f"likelihood_sigma must be positive, got {self.likelihood_sigma}")
        if self.compensation not in COMPENSATIONS:
            raise ValueError(f"unknown compensation {self.compensation!r}; choose one of {COMPENSATIONS}")

    def stopped(self, harmony_memory, fitness, idle) -> np.ndarray:
        """Which memories meet a stop rule other than NI: ider, Tprecision or Tquality (section 2.2.2)."""
        stop = np.zeros(len(fitness), dtype=bool)
        if self.idle is not None:
            stop |= idle >= self.idle
        if self.precision is not None:
            rows = np.arange(len(fitness))
            best = harmony_memory[rows, fitness.argmax(axis=1)]
            worst = harmony_memory[rows, fitness.argmin(axis=1)]
            stop |= np.linalg.norm(best - worst, axis=-1) < self.precision
        if self.quality is not None:
            stop |= fitness.max(axis=1) >= self.log_quality
        return stop

    @property
    def log_quality(self) -> float:
        """Tquality as a log-likelihood, the fitness's units."""
        if self.quality_units == "rho":
            return float(gaussian_similarity_log_likelihood(self.quality, self.likelihood_sigma))
        return float(np.log(self.quality))

    def search(self, particles, log_likelihood, rng) -> HarmonySearch:
        """Run IHS (Steps 2-5) from every particle at once, each in its window, each with its own stop."""
        start = particles.reshape(len(particles), -1)
        n, d = start.shape
        if self.radius.size not in (1, d):
            raise ValueError(f"radius has {self.radius.size} entries for a state of {d} coordinates")
        lower, upper = start - self.radius, start + self.radius
        evaluate = (lambda x: log_likelihood(x[:, 0])) if particles.ndim == 1 else log_likelihood
        draws = lower[:, None] + rng.random((n, self.hms - 1, d)) * (upper - lower)[:, None]
        harmony_memory = np.concatenate([start[:, None], draws], axis=1)
        fitness = evaluate(harmony_memory.reshape(-1, d)).reshape(n, self.hms)
        iterations, idle = np.zeros(n, dtype=int), np.zeros(n, dtype=int)
        active = ~self.stopped(harmony_memory, fitness, idle)
        schedule = np.arange(1, self.ni + 1)
        pars = pitch_adjust_rate(schedule, self.ni, self.par_min, self.par_max)
        bws = bandwidth(schedule, self.ni, self.bw_min, self.bw_max)
        for gn, par, bw in zip(schedule, pars, bws):
            rows = np.flatnonzero(active)
            if rows.size == 0:
                break
            new = improvise(harmony_memory[rows], lower[rows], upper[rows], self.hmcr, par, bw, rng)
            new_fitness = evaluate(new)
            worst = fitness[rows].argmin(axis=1)
            idle[rows] = np.where(new_fitness > fitness[rows].max(axis=1), 0, idle[rows] + 1)
            better = new_fitness > fitness[rows, worst]  # Step 4: replace the worst harmony
            harmony_memory[rows[better], worst[better]] = new[better]
            fitness[rows[better], worst[better]] = new_fitness[better]
            iterations[rows] = gn
            active[rows] = ~self.stopped(harmony_memory[rows], fitness[rows], idle[rows])
        return HarmonySearch(harmony_memory, fitness, iterations)

    def __call__(self, particles, log_likelihood, rng):
        if self.ni == 0:
            return particles.copy(), np.zeros(len(particles))
        moved = self.search(particles, log_likelihood, rng).best.reshape(particles.shape)
        return moved, log_compensation(particles, moved, self.compensation)


@drawn("vermillion", "-", "P")
def hspf(
    n_particles: int, resampling: str = "systematic", ess_threshold: float = 1.0, **harmony
) -> ParticleFilter:
    """HSPF (Algorithm 1): prior prediction, harmony-search move, weights lambda p(z | x) (eq 5), resample;
    ``harmony`` are :class:`HarmonyMove` fields.  Algorithm 1 resamples every step (ess_threshold 1)."""
    policy = ResamplingPolicy(resampling, ess_threshold)
    return ParticleFilter(n_particles, policy, move=HarmonyMove(**harmony))


def hold(model, particles, log_weights, t, rng):
    """HS's proposal: no motion model, the window is centred on the previous estimate (Fourie et al. 2010)."""
    return particles, log_weights


@drawn("green", "--", "^")
def hs(**harmony) -> ParticleFilter:
    """The paper's HS tracker: one harmony memory around the previous estimate, which moves to its best
    harmony; one particle, so no weights and no resampling."""
    move = HarmonyMove(compensation="none", **harmony)
    return ParticleFilter(1, ResamplingPolicy("systematic", 0.0), proposal=hold, move=move)
