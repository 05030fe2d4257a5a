"""State-space models of one target's box in an image sequence.

State columns: centre x, centre y, width, height, then (constant velocity)
the velocities vx, vy.  Motions:

* ``random_walk``: every component takes a Gaussian step of its own sd
  (the Brownian motion of ism_pf and hspf);
* ``constant_velocity``: gps_qmcpf eq (14) with period T: the centre moves by
  v T + a T^2 / 2 and the velocity by a T, a ~ N(0, accel_sd^2); the size takes
  a random perturbation (fusion_pf's "first-order dynamics for the centre").
  With ``noise_on: position`` the disturbance enters the centre instead: it
  moves by v T + accel_sd e and v stays (bis_pf section 3.2, "constant
  velocity disturbed by Gaussian noise ... a random walk", read as noise on
  position); v starts at 0, so the centre then takes a random walk.

Sizes take a random walk (``size: drifting``) and are kept at least
``min_size`` px, or keep the first box's (``size: fixed``: no size noise,
whatever ``step_sd`` and ``initial_sd`` give the size; bis_pf's 20x20 balls).
The observation is an image; the
likelihood is a :class:`replication.vision.ColourLikelihood` (or any object
with ``prepare(frame)`` and ``log_likelihood(boxes, prepared)``).
"""

from dataclasses import dataclass, field
from typing import Any, NamedTuple

import numpy as np
from numba import njit

MOTIONS = ("random_walk", "constant_velocity")
NOISE_ON = ("velocity", "position")  # where a constant-velocity model's disturbance enters
SIZES = ("drifting", "fixed")  # whether the box's width and height move


@dataclass
class BoxModel:
    """A target's box moving as ``kind``, observed through ``likelihood``, starting from ``initial_box``."""

    initial_box: np.ndarray  # (cx, cy, w, h)
    likelihood: Any
    kind: str = "random_walk"
    step_sd: tuple[float, float, float, float] = (4.0, 4.0, 0.5, 0.5)  # cx, cy, w, h (random walk)
    accel_sd: float = 1.0  # constant velocity: sd of the acceleration, px / frame^2
    period: float = 1.0  # T of gps_qmcpf eq (14)
    noise_on: str = "velocity"  # constant velocity: the disturbance accelerates (eq 14) or displaces the centre
    size: str = "drifting"  # fixed: the first box's width and height throughout
    initial_sd: tuple[float, float, float, float] = (2.0, 2.0, 0.5, 0.5)
    min_size: float = 2.0
    cache: dict = field(default_factory=dict, repr=False)  # frame features; shared by a run's targets
    first_frame: np.ndarray | None = field(default=None, repr=False)  # the frame of initial_box (MIL, DFT learn on it)

    def __post_init__(self):
        if self.kind not in MOTIONS:
            raise ValueError(f"unknown motion {self.kind!r}; choose one of {MOTIONS}")
        if self.noise_on not in NOISE_ON:
            raise ValueError(f"unknown noise_on {self.noise_on!r}; choose one of {NOISE_ON}")
        self.initial_box = np.asarray(self.initial_box, dtype=float)
        self.step_sd = np.array(self.step_sd, dtype=float)  # copies: a fixed size zeroes their size entries
        self.initial_sd = np.array(self.initial_sd, dtype=float)
        if self.size not in SIZES:
            raise ValueError(f"unknown size {self.size!r}; choose one of {SIZES}")
        if self.size == "fixed":
            self.step_sd[2:4] = self.initial_sd[2:4] = 0.0
        if (self.step_sd < 0).any() or (self.initial_sd < 0).any() or self.accel_sd < 0:
            raise ValueError("noise standard deviations must be non-negative")
        self.dim = 4 if self.kind == "random_walk" else 6
        self.noise_factor = self._noise_factor()  # W, fixed by the settings: built once
        self._sources = NoiseSources.of(self.noise_factor, 4 if self.kind == "random_walk" else 2)

    @property
    def x0(self) -> np.ndarray:
        """Mean of the initial state: the first box, at rest."""
        return np.concatenate([self.initial_box, np.zeros(self.dim - 4)])

    @property
    def P0(self) -> np.ndarray:
        """Per-coordinate variances of the initial state (velocities start at exactly 0)."""
        return np.concatenate([self.initial_sd**2, np.zeros(self.dim - 4)])

    def f(self, particles: np.ndarray, t: int) -> np.ndarray:
        """The deterministic part A x of the motion (gps_qmcpf eq 14 for constant velocity)."""
        if self.kind == "random_walk":
            return particles.copy()
        moved = particles.copy()
        moved[:, :2] += particles[:, 4:6] * self.period
        return moved

    def _noise_factor(self) -> np.ndarray:
        """W of x_t = A x_{t-1} + W e, e ~ N(0, I): (d, 4) (eq 14: accelerations of x and y, size steps;
        with noise on position, steps of the centre that leave v alone)."""
        if self.kind == "random_walk":
            return np.diag(self.step_sd)
        w = np.zeros((6, 4))
        if self.noise_on == "position":
            w[[0, 1], [0, 1]] = self.accel_sd
        else:
            w[[0, 1], [0, 1]] = self.accel_sd * self.period**2 / 2
            w[[4, 5], [0, 1]] = self.accel_sd * self.period
        w[[2, 3], [2, 3]] = self.step_sd[2:4]
        return w

    def constrain(self, particles: np.ndarray) -> np.ndarray:
        """Sizes are kept at least ``min_size`` px."""
        particles[:, 2:4] = np.maximum(particles[:, 2:4], self.min_size)
        return particles

    def sample_initial(self, n: int, rng: np.random.Generator) -> np.ndarray:
        particles = np.zeros((n, self.dim))
        particles[:, :4] = self.initial_box + self.initial_sd * rng.standard_normal((n, 4))
        return self.constrain(particles)

    def propagate(self, particles: np.ndarray, t: int, rng: np.random.Generator) -> np.ndarray:
        """x_t = A x_{t-1} + W e, sizes kept at least ``min_size``; a constant-velocity model draws the
        accelerations (N, 2), then the size steps (N, 2), in one call as one (2, N, 2) block: the same
        numbers in the same order.  One compiled pass (:func:`_moved`) gives ``constrain(f(x) + e @ W.T)``
        to the bit."""
        sources = self._sources
        draws = rng.standard_normal(sources.blocks * len(particles) * sources.width)  # C order: (blocks, N, width)
        return self.moved(particles, draws, np.array([0, len(particles)]))

    def moved(self, particles: np.ndarray, draws: np.ndarray, offsets: np.ndarray) -> np.ndarray:
        """:meth:`propagate` of the rows of targets of this motion (target t's ``offsets[t]:offsets[t + 1]``)
        with their normals ``draws``, each target's (blocks, n_t, width) after the one before (:func:`_moved`)."""
        sources = self._sources
        return _moved(particles, draws, np.asarray(offsets, dtype=np.int64), sources.blocks, sources.width, sources.block,
                      sources.column, sources.scale, self.kind == "constant_velocity", float(self.period),
                      float(self.min_size))

    def propose(self, particles: np.ndarray, t: int, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray | float]:
        """Draw x_t from the proposal given x_{t-1} = ``particles``, with log p(x_t | x_{t-1}) / q(x_t | ...),
        the term an importance weight adds to the log-likelihood.  Here the proposal is the motion
        prior (the bootstrap filter), so the term is 0."""
        return self.propagate(particles, t, rng), 0.0

    def log_likelihood(self, particles: np.ndarray, frame: np.ndarray, t: int) -> np.ndarray:
        """N log-likelihoods; the frame's features are computed once per frame and reused by moves
        and by the other targets' models that share ``cache``."""
        return self.likelihood.log_likelihood(particles[:, :4], self.prepared(frame, t))

    def spend(self, evaluations: int, t: int) -> None:
        """Work a method does on this model's observation outside :meth:`log_likelihood` (a mean-shift
        iteration computes a box's histogram, as a likelihood evaluation does); counted by
        :class:`replication.smc.work.Counted`, nothing to do here."""

    def similarity(self, states: np.ndarray, frame: np.ndarray, t: int) -> np.ndarray:
        """The Bhattacharyya coefficient rho of each state's box against the reference (the frame's
        features shared with :meth:`log_likelihood` through ``cache``)."""
        return self.likelihood.similarity(states[:, :4], self.prepared(frame, t))[0]

    def prepared(self, frame: np.ndarray, t: int):
        """The likelihood's features of ``frame`` (step ``t``), computed once per step for every model sharing ``cache``."""
        if self.cache.get("t") != t:
            self.cache.update(t=t, prepared=self.likelihood.prepare(frame))
        return self.cache["prepared"]

    def adapt(self, estimate: np.ndarray, t: int) -> None:
        """Let an adaptive likelihood (fusion_pf eqs 6-7) update itself at the frame's estimated state."""
        if hasattr(self.likelihood, "adapt") and self.cache.get("t") == t:
            self.likelihood.adapt(estimate[:4], self.cache["prepared"])


class NoiseSources(NamedTuple):
    """W (d, k) as one noise term per coordinate, for :func:`_moved`: the k normals are drawn as ``blocks``
    blocks of (N, ``width``) (e_i is a particle's rows of the blocks side by side, as ``np.hstack`` joins
    them), and coordinate j takes the normal in ``block[j]``, ``column[j]`` times ``scale[j]`` (its one
    non-zero entry of W, or 0 for a coordinate without noise: a fixed size)."""

    blocks: int
    width: int
    block: np.ndarray
    column: np.ndarray
    scale: np.ndarray

    @classmethod
    def of(cls, factor: np.ndarray, width: int) -> "NoiseSources":
        if ((factor != 0).sum(axis=1) > 1).any():
            raise AssertionError("a coordinate takes more than one noise term")  # cannot happen: eq 14, the random walk
        source = np.argmax(factor != 0, axis=1)
        return cls(factor.shape[1] // width, width, (source // width).astype(np.int64),
                   (source % width).astype(np.int64), factor[np.arange(len(factor)), source].astype(float))


@njit(cache=True, error_model="numpy")
def _moved(particles, draws, offsets, blocks, width, block, column, scale, constant_velocity, period, min_size):
    """``constrain(f(x) + e @ W.T)`` in one pass: coordinate j of a particle is f_j(x) (x_j, plus v_j T for a
    constant-velocity centre) plus W_js e_s, its one noise term, and a size below ``min_size`` is raised to it.
    The rows of one or more targets of one motion: target t's rows ``offsets[t]:offsets[t + 1]`` take its
    normals, the next ``blocks`` x n_t x ``width`` of ``draws`` as one (blocks, n_t, width) block.

    Bit for bit the matrix form: each row of W has one non-zero entry, so (e W^T)_j is the rounded product
    W_js e_s whatever the order of the dot product (the other terms add exact zeros), added to f_j(x) as numpy
    adds it; the clamp keeps NaN, as ``np.maximum`` does."""
    out = np.empty(particles.shape)
    for t in range(offsets.size - 1):
        first, rows = offsets[t], offsets[t + 1] - offsets[t]
        for j in range(particles.shape[1]):  # a coordinate at a time: its noise term is one column of a block
            noise = first * blocks * width + block[j] * rows * width + column[j]
            for i in range(first, first + rows):
                x = particles[i, j]
                if constant_velocity and j < 2:
                    x = x + particles[i, j + 4] * period
                x = x + draws[noise + (i - first) * width] * scale[j]
                if (j == 2 or j == 3) and x < min_size:
                    x = min_size
                out[i, j] = x
    return out
