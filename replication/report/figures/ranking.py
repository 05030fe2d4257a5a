"""A ranking's stability drawn: each method's rank distribution and the pairwise P(A beats B) matrix."""

import textwrap
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from replication.evidence.ranking import rankings, unreliable
from replication.report.figures.style import OUTCOME_COLOURS, NothingToDraw, axis_label, save
from replication.evidence.figures import RankingFigure
from replication.report.figures.base import draws

LUMA = np.array([0.299, 0.587, 0.114])  # a colour's lightness: dark segments take white text


@draws(RankingFigure)
def ranking(records: pd.DataFrame, spec: RankingFigure, experiment: dict, path: Path) -> Path:
    """One row of two panels per ranking (:func:`~replication.evidence.ranking.rankings` of ``spec``):
    left, stacked bars of P(rank = k) per method, best first, with its P(best) and 95% rank interval;
    right, the matrix of P(row beats column).  A ranking that is not reliable says why above it."""
    found = rankings(records, spec.metric, spec.over, spec.by)
    if not found:
        raise NothingToDraw(f"figure {spec.name!r}: no two methods ran on the same sequences")
    heights = [max(2.4, 0.42 * len(r.methods) + 1.4) for r in found.values()]
    fig, axes = plt.subplots(len(found), 2, figsize=(12, sum(heights)), squeeze=False,
                             gridspec_kw={"height_ratios": heights, "width_ratios": [1.1, 1]})
    for (left, right), (group, ranked) in zip(axes, found.items()):
        methods = list(ranked.methods)
        n = len(methods)
        colours = plt.get_cmap("viridis")(np.linspace(0, 0.95, n))  # rank 1 darkest
        y = np.arange(n)
        start = np.zeros(n)
        for k in range(n):
            share = ranked.rank_probability[:, k]
            left.barh(y, share, left=start, color=colours[k], edgecolor="white", linewidth=0.5)
            for i in np.flatnonzero(share >= 0.06):  # the rank written in its segment where it fits
                left.text(start[i] + share[i] / 2, i, str(k + 1), ha="center", va="center", fontsize=7,
                          color="black" if colours[k][:3] @ LUMA > 0.5 else "white")
            start += share
        for i in range(n):
            rank = ranked.rank(i)
            left.text(1.02, i, f"P(best) {ranked.p_best[i]:.2f}, rank [{rank.low:.0f}, {rank.high:.0f}]",
                      va="center", fontsize=7)
        left.set_yticks(y, methods, fontsize=8)
        left.invert_yaxis()  # best on top
        left.set_xlim(0, 1)
        left.set_xlabel("P(rank = k), k written in its segment (1 = best)", fontsize=8)
        what = (f"{axis_label(spec.metric)}: mean over {len(ranked.sequences)} sequences x "
                f"{ranked.runs} run(s)")
        title = textwrap.fill(", ".join(filter(None, [group, what])), 75)
        caveat = unreliable(ranked, experiment)
        left.set_title(title + (f"\n{textwrap.fill(caveat, 75)}" if caveat else ""), fontsize=9,
                       loc="left", color=OUTCOME_COLOURS["inconclusive"] if caveat else "black")
        shown = np.where(np.isnan(ranked.beats), 0.5, ranked.beats)
        right.imshow(shown, cmap="RdBu", vmin=0, vmax=1)
        for i in range(n):
            for j in range(n):
                if i != j:
                    p = ranked.beats[i, j]
                    right.text(j, i, f"{p:.2f}", ha="center", va="center", fontsize=7,
                               color="white" if abs(p - 0.5) > 0.35 else "black")
        right.set_xticks(y, methods, rotation=40, ha="right", fontsize=8)
        right.set_yticks(y, methods, fontsize=8)
        right.set_title("P(row beats column)", fontsize=9)
    return save(fig, path)
