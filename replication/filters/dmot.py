"""DMOT: distributed multi-object tracking with magnetic-inertia potentials (Qu, Schonfeld, Mohamed 2007).

As pinned in baselines.md §3: one bootstrap PF per target (the bis_pf step 1),
then ``iterations`` rounds in which every target interacting with others
re-weights its particles by

* magnetic repulsion from each neighbour j: 1 - (1/alpha1) exp(-d^2 / sigma1^2),
  d the distance from the particle's centre to j's current estimate (the
  original uses j's observation; its estimate is what a tracker has);
* inertia: 1 + (1/alpha2) exp(-theta^2 / sigma_angle^2) exp(-(|v| - |v_ref|)^2 / sigma_speed^2),
  theta the angle between the particle's motion from the last estimate and the
  reference motion (the last two estimates), |v| and |v_ref| their lengths;

the likelihood is the "gravitation" term.  Neighbours' estimates are updated
between rounds (Jacobi), all rounds in one compiled pass (:func:`_rounds`).
The parameters are unsure in the sources: the defaults below are our choice
and live in the config.
"""

from dataclasses import dataclass

import numpy as np
from numba import njit

from replication.compiled import matvec
from replication.filters.bis import DistributedFilter, neighbours
from replication.filters.joint import JointState
from replication.filters.registry import drawn


@drawn("sky", "-", ">")
@dataclass
class DMOT(DistributedFilter):
    n_particles: int = 400
    iterations: int = 6
    alpha1: float = 2.0
    sigma1: float = 20.0  # px: about one target
    alpha2: float = 2.0
    sigma_angle: float = 0.5  # rad
    sigma_speed: float = 1.0  # px / frame

    def __post_init__(self):
        if self.n_particles <= 0 or self.iterations < 0 or self.alpha1 <= 1 or self.alpha2 <= 0:
            raise ValueError(f"need N > 0, iterations >= 0, alpha1 > 1 (a positive repulsion), alpha2 > 0; got {self}")

    def interact(self, particles: list, pi: list, state: JointState) -> list:
        if not particles:
            return []
        linked = {i: [] for i in range(len(particles))}
        for i, j in neighbours(particles):
            linked[i].append(j)
            linked[j].append(i)
        inertia = [self.inertia(p, state.records[i].means) if linked[i] else np.ones(len(p)) for i, p in enumerate(particles)]
        offsets = np.cumsum([0] + [len(others) for others in linked.values()])
        others = np.array([j for i in linked for j in linked[i]], dtype=np.int64)
        weights = _rounds(np.stack([p[:, :2] for p in particles]), np.stack(pi), np.stack(inertia), offsets, others,
                          self.iterations, float(self.sigma1) ** 2, float(self.alpha1))
        return list(weights)

    def inertia(self, particles: np.ndarray, means: list) -> np.ndarray:
        """The inertia factor of each particle; 1 until two estimates give a reference motion."""
        if len(means) < 2:
            return np.ones(len(particles))
        return _inertia(np.ascontiguousarray(particles, dtype=float), means[-1][:2], means[-1][:2] - means[-2][:2],
                        self.sigma_angle**2, self.sigma_speed**2, float(self.alpha2))


@njit(cache=True)
def _inertia(particles, last, reference, angle_variance, speed_variance, alpha2):
    """1 + exp(-theta^2 / sigma_angle^2) exp(-(|v| - |v_ref|)^2 / sigma_speed^2) / alpha2 per particle, v its
    motion from ``last`` and theta its angle to ``reference`` (cos theta 1 where either has no length), in
    numpy's operations: |v_ref| and v . v_ref by BLAS (:func:`~replication.compiled.matvec`), as
    ``np.linalg.norm`` and ``@`` compute them, so the factors are the numpy form's to the bit."""
    n = particles.shape[0]
    motion = np.empty((n, 2))
    for r in range(n):
        motion[r, 0], motion[r, 1] = particles[r, 0] - last[0], particles[r, 1] - last[1]
    reference_length = np.sqrt(np.dot(reference, reference))
    along = matvec(motion, reference)
    out = np.empty(n)
    for r in range(n):
        length = np.sqrt(motion[r, 0] * motion[r, 0] + motion[r, 1] * motion[r, 1])
        norm = length * reference_length
        cosine = along[r] / norm if norm > 0 else 1.0
        if cosine < -1.0:
            cosine = -1.0
        elif cosine > 1.0:
            cosine = 1.0
        theta, speed = np.arccos(cosine), length - reference_length
        out[r] = 1.0 + np.exp(-(theta * theta) / angle_variance) * np.exp(-(speed * speed) / speed_variance) / alpha2
    return out


@njit(cache=True)
def _rounds(centres, pi, inertia, offsets, others, iterations, sigma1_squared, alpha1):
    """The ``iterations`` Jacobi rounds of :meth:`DMOT.interact` for M targets of N particles: ``centres``
    (M, N, 2), ``pi`` and ``inertia`` (M, N), target i's neighbours ``others[offsets[i]:offsets[i + 1]]``.
    Each round every target's weights become pi x inertia x the repulsions of its neighbours' estimates
    (the weighted means of their centres under the last round's weights), normalised.  The sums run in
    the particles' order, so the weights differ from the numpy form's (BLAS means, pairwise sums) by
    rounding only (relative 1e-15)."""
    m, n = pi.shape
    weights = pi.copy()
    estimates = np.empty((m, 2))
    for _ in range(iterations):
        for i in range(m):
            x = y = 0.0
            for k in range(n):
                x += weights[i, k] * centres[i, k, 0]
                y += weights[i, k] * centres[i, k, 1]
            estimates[i, 0], estimates[i, 1] = x, y
        updated = np.empty((m, n))
        for i in range(m):
            total = 0.0
            for k in range(n):
                w = pi[i, k] * inertia[i, k]
                for e in range(offsets[i], offsets[i + 1]):
                    j = others[e]
                    dx, dy = centres[i, k, 0] - estimates[j, 0], centres[i, k, 1] - estimates[j, 1]
                    w = w * (1.0 - np.exp(-(dx * dx + dy * dy) / sigma1_squared) / alpha1)
                updated[i, k] = w
                total += w
            for k in range(n):
                updated[i, k] /= total
        weights = updated
    return weights
