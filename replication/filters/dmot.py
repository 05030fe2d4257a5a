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
between rounds (Jacobi).  The parameters are unsure in the sources: the
defaults below are our choice and live in the config.
"""

from dataclasses import dataclass

import numpy as np

from replication.filters.bis import DistributedFilter, neighbours
from replication.filters.joint import JointState


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
        linked = {i: [] for i in range(len(particles))}
        for i, j in neighbours(particles):
            linked[i].append(j)
            linked[j].append(i)
        inertia = [self.inertia(p, state.records[i].means) if linked[i] else 1.0 for i, p in enumerate(particles)]
        weights = list(pi)
        for _ in range(self.iterations):
            estimates = [w @ p[:, :2] for w, p in zip(weights, particles)]
            updated = []
            for i, p in enumerate(particles):
                w = pi[i] * inertia[i]
                for j in linked[i]:
                    d2 = ((p[:, :2] - estimates[j]) ** 2).sum(axis=1)
                    w = w * (1.0 - np.exp(-d2 / self.sigma1**2) / self.alpha1)
                updated.append(w / w.sum())
            weights = updated
        return weights

    def inertia(self, particles: np.ndarray, means: list) -> np.ndarray:
        """The inertia factor of each particle; 1 until two estimates give a reference motion."""
        if len(means) < 2:
            return np.ones(len(particles))
        last, reference = means[-1][:2], means[-1][:2] - means[-2][:2]
        motion = particles[:, :2] - last
        norms = np.linalg.norm(motion, axis=1) * np.linalg.norm(reference)
        cosine = np.divide(motion @ reference, norms, out=np.ones(len(particles)), where=norms > 0)
        theta = np.arccos(np.clip(cosine, -1.0, 1.0))
        speed = np.linalg.norm(motion, axis=1) - np.linalg.norm(reference)
        return 1.0 + np.exp(-(theta**2) / self.sigma_angle**2) * np.exp(-(speed**2) / self.sigma_speed**2) / self.alpha2
