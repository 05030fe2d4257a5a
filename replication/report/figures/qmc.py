"""gps_qmcpf Figures 1-3 and their discrepancies: random, Halton and good point sets side by side."""

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from replication import atomic
from replication.qmc import discrepancy, point_set
from replication.evidence.figures import PointSets
from replication.report.figures.base import draws

PANELS = (("random", "random (uniform)"), ("halton", "Halton"), ("good_cos", "good point set, r = 2cos(2 pi i / p)"),
          ("good_exp", "good point set, r = exp(i)"))


@draws(PointSets)
def point_sets(records: pd.DataFrame, spec: PointSets, experiment: dict, path: Path) -> Path:
    """``spec.n`` points in [0, 1)^2 of each set, with the centred L2 discrepancy in the title."""
    n = spec.n
    fig, axes = plt.subplots(1, len(PANELS), figsize=(3.2 * len(PANELS), 3.4))
    for ax, (name, title) in zip(axes, PANELS):
        points = np.random.default_rng(0).random((n, 2)) if name == "random" else point_set(name, n, 2)
        ax.scatter(points[:, 0], points[:, 1], s=3)
        ax.set_title(f"{title}\nCD = {discrepancy(points, 'CD'):.2e}", fontsize=8)
        ax.set_aspect("equal")
        ax.set_xlim(0, 1)
        ax.set_ylim(0, 1)
    fig.tight_layout()
    atomic.save_figure(fig, path, dpi=110)
    plt.close(fig)
    return path
