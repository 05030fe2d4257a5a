"""The effect picture: every sized effect of the papers' claims, ours against the paper's, as the replication
projects draw theirs (Open Science Collaboration 2015, Fig. 3; Errington et al. 2021): the paper's effect
along x and ours up y in one unit, our per-run standard deviation, with the diagonal (ours as large as the
paper's), zero, each point's 95 % intervals, coloured by paper; its title the median share of the paper's
effect that survives over claims, with its bootstrap interval (:attr:`Scorecard.surviving`)."""

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from replication import atomic  # noqa: E402
from replication.evidence.scorecard import Scorecard  # noqa: E402

FIGURE = "effects.png"
ALT = ("Every claim's sized effect: ours against the paper's in standard deviations of a run, with the diagonal "
       "where ours is as large, zero, and each point's 95% intervals, coloured by paper")


def surviving_said(card: Scorecard) -> str:
    """'median 0.42 [0.2, 0.7] of the paper's effect survives, over 9 claims' (or why it cannot be said)."""
    median, low, high, claims = card.surviving
    if claims == 0:
        return "no claim quotes a size that was tested"
    interval = f" [{low:.2g}, {high:.2g}]" if np.isfinite(low) else ""
    return f"median {median:.2g}{interval} of the paper's effect survives, over {claims} claims"


def draw(card: Scorecard, path: Path) -> Path | None:
    """The picture of ``card``'s sized effects into ``path`` (None, and nothing written, where there are none)."""
    points = card.effects
    if points.empty:
        return None
    fig, ax = plt.subplots(figsize=(6.4, 5.2))
    colours = dict(zip(sorted(points["paper"].unique()), plt.cm.tab10.colors))
    for paper, rows in points.groupby("paper"):
        ax.errorbar(rows["original"], rows["replication"], xerr=rows["original_half"], yerr=rows["replication_half"],
                    fmt="o", ms=4, lw=0.7, alpha=0.8, color=colours[paper], label=paper)
    ends = _extent(points)
    ax.plot(ends, ends, color="0.4", ls="--", lw=0.9, label="ours as large as the paper's")
    ax.axhline(0, color="0.6", lw=0.8)
    ax.axvline(0, color="0.85", lw=0.8)
    ax.set_xlim(*ends)
    ax.set_ylim(*ends)
    ax.set_xlabel("the paper's effect (standard deviations of a run; 95% interval)")
    ax.set_ylabel("our effect (same unit; 95% interval)")
    ax.set_title(f"{len(points)} sized effects of {points['claim_id'].nunique()} claims: "
                 f"{surviving_said(card)}", fontsize=8, loc="left")
    ax.legend(fontsize=7, loc="upper left")
    fig.tight_layout()
    atomic.save_figure(fig, path, dpi=110)
    plt.close(fig)
    return path


def _extent(points: pd.DataFrame) -> tuple[float, float]:
    """One range for both axes holding every point and zero (intervals may run off it)."""
    values = np.concatenate([points["original"], points["replication"], [0.0]])
    low, high = float(np.min(values)), float(np.max(values))
    pad = 0.08 * (high - low or 1.0)
    return low - pad, high + pad
