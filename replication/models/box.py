"""State-space models of one target's box in an image sequence.

State columns: centre x, centre y, width, height, then (constant velocity)
the velocities vx, vy.  Motions:

* ``random_walk``: every component takes a Gaussian step of its own sd
  (the Brownian motion of ism_pf and hspf);
* ``constant_velocity``: gps_qmcpf eq (14) with period T: the centre moves by
  v T + a T^2 / 2 and the velocity by a T, a ~ N(0, accel_sd^2); the size takes
  a random perturbation (fusion_pf's "first-order dynamics for the centre").

Sizes are kept at least ``min_size`` px.  The observation is an image; the
likelihood is a :class:`replication.vision.ColourLikelihood` (or any object
with ``prepare(frame)`` and ``log_likelihood(boxes, prepared)``).
"""

from dataclasses import dataclass, field
from typing import Any

import numpy as np

MOTIONS = ("random_walk", "constant_velocity")


@dataclass
class BoxModel:
    """A target's box moving as ``kind``, observed through ``likelihood``, starting from ``initial_box``."""

    initial_box: np.ndarray  # (cx, cy, w, h)
    likelihood: Any
    kind: str = "random_walk"
    step_sd: tuple[float, float, float, float] = (4.0, 4.0, 0.5, 0.5)  # cx, cy, w, h (random walk)
    accel_sd: float = 1.0  # constant velocity: sd of the acceleration, px / frame^2
    period: float = 1.0  # T of gps_qmcpf eq (14)
    initial_sd: tuple[float, float, float, float] = (2.0, 2.0, 0.5, 0.5)
    min_size: float = 2.0
    cache: dict = field(default_factory=dict, repr=False)  # frame features; shared by a run's targets

    def __post_init__(self):
        if self.kind not in MOTIONS:
            raise ValueError(f"unknown motion {self.kind!r}; choose one of {MOTIONS}")
        self.initial_box = np.asarray(self.initial_box, dtype=float)
        self.step_sd = np.asarray(self.step_sd, dtype=float)
        self.initial_sd = np.asarray(self.initial_sd, dtype=float)
        if (self.step_sd < 0).any() or (self.initial_sd < 0).any() or self.accel_sd < 0:
            raise ValueError("noise standard deviations must be non-negative")
        self.dim = 4 if self.kind == "random_walk" else 6

    def sample_initial(self, n: int, rng: np.random.Generator) -> np.ndarray:
        particles = np.zeros((n, self.dim))
        particles[:, :4] = self.initial_box + self.initial_sd * rng.standard_normal((n, 4))
        particles[:, 2:4] = np.maximum(particles[:, 2:4], self.min_size)
        return particles

    def propagate(self, particles: np.ndarray, t: int, rng: np.random.Generator) -> np.ndarray:
        moved = particles.copy()
        if self.kind == "random_walk":
            moved += self.step_sd * rng.standard_normal(particles.shape)
        else:
            accel = self.accel_sd * rng.standard_normal((len(particles), 2))
            moved[:, :2] += particles[:, 4:6] * self.period + accel * self.period**2 / 2
            moved[:, 4:6] += accel * self.period
            moved[:, 2:4] += self.step_sd[2:4] * rng.standard_normal((len(particles), 2))
        moved[:, 2:4] = np.maximum(moved[:, 2:4], self.min_size)
        return moved

    def log_likelihood(self, particles: np.ndarray, frame: np.ndarray, t: int) -> np.ndarray:
        """N log-likelihoods; the frame's features are computed once per frame and reused by moves
        and by the other targets' models that share ``cache``."""
        if self.cache.get("t") != t:
            self.cache.update(t=t, prepared=self.likelihood.prepare(frame))
        return self.likelihood.log_likelihood(particles[:, :4], self.cache["prepared"])

    def adapt(self, estimate: np.ndarray, t: int) -> None:
        """Let an adaptive likelihood (fusion_pf eqs 6-7) update itself at the frame's estimated state."""
        if hasattr(self.likelihood, "adapt") and self.cache.get("t") == t:
            self.likelihood.adapt(estimate[:4], self.cache["prepared"])

    @staticmethod
    def boxes(states: np.ndarray) -> np.ndarray:
        """(x, y, w, h) boxes of states (..., >= 4) given as (cx, cy, w, h, ...)."""
        states = np.asarray(states)
        return np.concatenate([states[..., :2] - states[..., 2:4] / 2.0, states[..., 2:4]], axis=-1)
