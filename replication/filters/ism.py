"""ISM-PF: the particle filter with an information-sharing mechanism (ism_pf, section 3).

Each frame, after prediction, with F the likelihood (eq 30) and N particles:

* personal best p_j: particle j's best position over the last ``window`` frames
  (30 in the paper), global best p_g: the best of the personal bests;
* environment matrix u (2 x N), eqs (10)-(11):
  u1_j += randn (F(x_j) - F(p_g)),  u2_j += randn (F(x_j) - F(p_j));
* position matrix v (2 x N x d), eqs (12)-(13):
  v1_j += tau1 randn (p_g - x_j),   v2_j += tau1 randn (p_j - x_j);
* fusion, eqs (14)-(16): t1 = randn / u1 + v1, t2 = randn / u2 + v2, and
  x_j = c1 t1 + c2 t2.

Each randn is one standard normal per particle and equation (``randn(1)``),
shared by the state's coordinates.  u starts uniform in [0, 1], v at zero,
and both persist across frames per particle index, as do the personal-best
histories (resampling re-labels particles but not the matrices: the paper
says nothing of carrying them along ancestry).

Eq (16) read literally *replaces* the particle by a combination of offsets,
which puts every particle near the image origin.  We read t as a displacement
of the predicted particle, x_j <- x_j + c1 t1 + c2 t2, like the PSO position
update x <- x + v that eqs (12)-(13) imitate (``update: additive``, the
default); ``update: replace`` is the literal reading.  The move returns no
weight correction: particles are weighted by the likelihood where they land
(eq 29).

Three further choices the paper leaves open are named options:

* ``bests``: ``stored`` compares the positions of the window by the F each
  had on its own frame; ``rescored`` re-scores them on the current frame
  before picking p_j and p_g (section 5.2 puts ISM-PF's cost in computing the
  personal bests over "the last 30 historical moments", which only costs
  anything if old positions are re-evaluated).
* ``v_memory``: ``carried`` lets v_{1,k}, v_{2,k} of eqs (12)-(13) start from
  the previous frame's v (v is zeroed only at Step 0); ``reset`` starts them
  at zero every frame.
* ``moves``: ``box`` applies the ISM step to every coordinate of (x, y, w, h);
  ``position`` to (x, y) only, leaving w, h to the motion model (eq 28).
"""

from dataclasses import dataclass, field

import numpy as np

from replication.filters.registry import drawn
from replication.smc.loop import ParticleFilter, ResamplingPolicy

UPDATES = ("additive", "replace")
BESTS = ("stored", "rescored")
V_MEMORY = ("carried", "reset")
MOVES = ("box", "position")


@dataclass
class ISMMove:
    c1: float = 0.8
    c2: float = 0.2
    tau1: float = 0.1
    window: int = 30
    update: str = "additive"
    bests: str = "stored"
    v_memory: str = "carried"
    moves: str = "box"
    u: np.ndarray | None = field(default=None, repr=False)
    v: np.ndarray | None = field(default=None, repr=False)
    history: list = field(default_factory=list, repr=False)

    def __post_init__(self):
        for option, allowed in (("update", UPDATES), ("bests", BESTS), ("v_memory", V_MEMORY), ("moves", MOVES)):
            if getattr(self, option) not in allowed:
                raise ValueError(f"unknown ISM {option} {getattr(self, option)!r}; choose one of {allowed}")
        if self.window < 1:
            raise ValueError(f"the personal-best window must be at least 1 frame, got {self.window}")
        if not np.isclose(self.c1 + self.c2, 1.0):
            raise ValueError(f"ism_pf requires c1 + c2 = 1, got {self.c1} + {self.c2}")

    def scores(self, log_likelihood) -> np.ndarray:
        """F of every position in the window, (frames, N): as stored on its own frame, or re-scored
        on the current frame's likelihood (``bests: rescored``) in one call over all earlier frames."""
        stored = np.stack([h[1] for h in self.history])
        if self.bests == "stored" or len(self.history) == 1:
            return stored
        earlier = np.stack([h[0] for h in self.history[:-1]])  # (frames - 1, N, d)
        rescored = np.exp(log_likelihood(earlier.reshape(-1, earlier.shape[-1]))).reshape(earlier.shape[:2])
        return np.vstack([rescored, stored[-1:]])

    def best_positions(self, values: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
        """Personal bests p_j and F(p_j) over the window scored by ``values``, and the global best p_g and F(p_g)."""
        positions = np.stack([h[0] for h in self.history])  # (frames, N, d)
        frame = np.argmax(values, axis=0)
        columns = np.arange(values.shape[1])
        personal, personal_value = positions[frame, columns], values[frame, columns]
        leader = np.argmax(personal_value)
        return personal, personal_value, personal[leader], personal_value[leader]

    def __call__(self, particles, log_likelihood, rng):
        n = len(particles)
        if self.u is None:
            self.u = rng.random((2, n))
        if self.v is None or self.v_memory == "reset":
            self.v = np.zeros((2, *particles.shape))
        fitness = np.exp(log_likelihood(particles))  # F, the likelihood itself (eq 30)
        self.history = (self.history + [(particles.copy(), fitness)])[-self.window :]
        personal, personal_value, leader, leader_value = self.best_positions(self.scores(log_likelihood))
        noise = rng.standard_normal((6, n))
        self.u[0] += noise[0] * (fitness - leader_value)  # eq (10)
        self.u[1] += noise[1] * (fitness - personal_value)  # eq (11)
        self.v[0] += self.tau1 * noise[2][:, None] * (leader - particles)  # eq (12)
        self.v[1] += self.tau1 * noise[3][:, None] * (personal - particles)  # eq (13)
        with np.errstate(divide="ignore"):
            t1 = (noise[4] / self.u[0])[:, None] + self.v[0]  # eq (14)
            t2 = (noise[5] / self.u[1])[:, None] + self.v[1]  # eq (15)
        step = self.c1 * t1 + self.c2 * t2  # eq (16)
        axes = slice(None) if self.moves == "box" else slice(0, 2)  # (x, y, w, h) or (x, y)
        moved = particles.copy()
        moved[:, axes] = (particles[:, axes] if self.update == "additive" else 0.0) + step[:, axes]
        return np.where(np.isfinite(moved), moved, particles), np.zeros(n)


@drawn("vermillion", "-", "^")
def ism(n_particles: int, resampling: str = "systematic", ess_threshold: float = 1.0, **sharing) -> ParticleFilter:
    """ISM-PF: the SMC loop with the information-sharing move; ``sharing`` are :class:`ISMMove` fields."""
    return ParticleFilter(n_particles, ResamplingPolicy(resampling, ess_threshold), move=ISMMove(**sharing))
