"""Mean shift (MS, Comaniciu, Ramesh and Meer 2003) and the mean-shift particle filter (MSPF, Shan, Tan
and Wei 2007), the hspf paper's MS and MSPF baselines (``baselines.md`` §5).

One mean-shift iteration moves a box of fixed size from y0 to

    y1 = sum_i x_i w_i g_i / sum_i w_i g_i,   w_i = sqrt(q_u / p_u(y0)) at u = b(x_i),

over the box's sample points x_i (``baselines.md`` §5).  With the Epanechnikov profile g = -k' is
constant inside the kernel, so y1 is the w-weighted mean of the points.  The
points are the model's :class:`ColourHistogram` pattern (a grid of one point
per pixel of the reference box gives "all pixels", as hspf uses for MS and
MSPF: ``observation: {samples: null}``), so p_u is the kernel histogram that
the likelihood scores.  A box stops when its shift is below ``eps`` px or
after ``max_iter`` iterations; CRM03's optional halving step (when rho
drops) is left out, as its authors do in practice.  The MS tracker (:func:`ms`) starts, like HS, from a
draw of the model's initial distribution.  Sizes are not adapted.

MSPF: prior prediction, mean shift of every particle, then weights
lambda p(z | x) with lambda the same mixture compensation as HSPF
(:func:`replication.filters.harmony.log_compensation`, same readings and
default); Shan et al. leave the compensation open (``baselines.md`` §5 [U]).
"""

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from replication.filters.harmony import COMPENSATIONS, hold, log_compensation
from replication.filters.registry import drawn
from replication.smc.loop import ParticleFilter, ResamplingPolicy


def mean_shift(
    boxes: np.ndarray,
    bin_image: np.ndarray,
    histogram,
    reference: np.ndarray,
    max_iter: int = 20,
    eps: float = 0.5,
) -> tuple[np.ndarray, np.ndarray]:
    """Mean-shift every box (N, >= 4; cx, cy, w, h, ...) towards the reference histogram q; return the moved
    boxes (sizes unchanged) and the iterations each ran.

    Per iteration one :meth:`ColourHistogram.gather` reads the bins of all unconverged boxes'
    sample points and :meth:`ColourHistogram.tally` gives their kernel histograms.  The
    normalisation of p_u is a per-box factor that cancels in y1, so the raw
    kernel-weighted counts stand in for p_u.
    """
    if histogram.kernel != "epanechnikov":
        raise ValueError(f"mean shift needs the epanechnikov kernel (g constant), got {histogram.kernel!r}")
    boxes = np.array(boxes, dtype=float)
    root_q = np.append(np.sqrt(reference), 0.0)  # the spare bin (points outside the image): w = 0
    u, v = histogram.points[:, 0], histogram.points[:, 1]
    iterations = np.zeros(len(boxes), dtype=int)
    active = np.flatnonzero((boxes[:, 2] > 0) & (boxes[:, 3] > 0))
    for _ in range(max_iter):
        if active.size == 0:
            break
        n = active.size
        half = boxes[active, 2:4] / 2.0
        bins, kernel = histogram.gather(bin_image, boxes[active])
        counts = histogram.tally(bins, kernel)
        ratio = np.divide(root_q, np.sqrt(counts), out=np.zeros_like(counts), where=counts > 0)
        w = np.take_along_axis(ratio, bins, axis=1)
        total = w.sum(axis=1)
        moving = total > 0
        shift = np.zeros((n, 2))
        shift[moving] = np.stack([w[moving] @ u, w[moving] @ v], axis=1) / total[moving, None] * half[moving]
        boxes[active, :2] += shift
        iterations[active] += 1
        active = active[moving & (np.linalg.norm(shift, axis=1) >= eps)]
    return boxes, iterations


@dataclass
class MeanShiftMove:
    """Move every particle by :func:`mean_shift` on the tracked model's frame; return log lambda (hspf
    eqs 2-5, ``compensation`` as in :func:`log_compensation`).  :class:`MeanShiftFilter` binds ``model``."""

    max_iter: int = 20  # CRM03's N_max
    eps: float = 0.5  # px: y0 and y1 in the same pixel
    compensation: str = "printed"
    model: Any = field(default=None, repr=False)

    def __post_init__(self):
        if int(self.max_iter) != self.max_iter or self.max_iter < 0:
            raise ValueError(f"max_iter must be a non-negative integer, got {self.max_iter}")
        if self.eps < 0:
            raise ValueError(f"eps must be non-negative, got {self.eps}")
        if self.compensation not in COMPENSATIONS:
            raise ValueError(f"unknown compensation {self.compensation!r}; choose one of {COMPENSATIONS}")

    def __call__(self, particles, log_likelihood, rng):
        if self.model is None:
            raise ValueError("MeanShiftMove needs the tracked BoxModel: run it inside a MeanShiftFilter")
        log_likelihood(particles[:1])  # makes the model cache this frame's bin image
        likelihood = self.model.likelihood
        bin_image = self.model.cache["prepared"]
        moved, iterations = mean_shift(
            particles, bin_image, likelihood.histogram, likelihood.reference, self.max_iter, self.eps
        )
        self.model.spend(int(iterations.sum()), self.model.cache["t"])  # a histogram per box per iteration
        return moved, log_compensation(particles, moved, self.compensation)


@dataclass
class MeanShiftFilter(ParticleFilter):
    """A :class:`ParticleFilter` whose :class:`MeanShiftMove` reads the bin image, histogram pattern and
    reference q of the model of the state being stepped (the Move protocol passes only log p(z | x))."""

    def step(self, state, z) -> None:
        self.move.model = state.model
        super().step(state, z)


@drawn("sky", "--", ">")
def mspf(
    n_particles: int, resampling: str = "multinomial", ess_threshold: float = 1.0, **mean_shift_params
) -> MeanShiftFilter:
    """MSPF: prior prediction, mean-shift move, weights lambda p(z | x), resampling every step by default;
    ``mean_shift_params`` are :class:`MeanShiftMove` fields."""
    policy = ResamplingPolicy(resampling, ess_threshold)
    return MeanShiftFilter(n_particles, policy, move=MeanShiftMove(**mean_shift_params))


@drawn("orange", "-", "<")
def ms(**mean_shift_params) -> MeanShiftFilter:
    """The MS tracker: one box, no motion model (it starts from the previous estimate, as HS does),
    moved by mean shift; no weights and no resampling."""
    move = MeanShiftMove(compensation="none", **mean_shift_params)
    return MeanShiftFilter(1, ResamplingPolicy("systematic", 0.0), proposal=hold, move=move)
