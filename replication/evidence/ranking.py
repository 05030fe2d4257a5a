"""How stable a ranking of methods over a few sequences is: a two-level bootstrap.

A table that ranks methods by their mean score over a handful of sequences
(hspf's seven trackers on six OTB sequences) says little until it says how
the order would move with other sequences and other runs.  Each bootstrap
resample draws the sequences with replacement and, within each drawn
sequence, its runs with replacement -- the same runs for every method, since
the methods at a repetition filter the same data from the same seed (common
random numbers) -- and ranks the methods by their mean over the resample.
Over the resamples (seeded: a report is a pure function of the records):

* ``P(best)``: the share of resamples in which a method ranks first;
* ``P(rank = k)`` and the mean rank (the rank's interval is :func:`rank_set`'s, from paired tests over
  the sequences: percentiles of a bootstrap over six sequences are too narrow, and missed 2 of 7 ranks
  on five sequences the project had not seen), checked by leaving one sequence out (:func:`held_out`);
* ``P(A beats B)``: the share in which A's mean is better than B's;
* each method's mean over the sequences with its percentile interval (inside
  the metric's range, as every resampled mean is).

The paired difference A - B of two methods is the mean over the sequences of
their per-sequence difference (each sequence's mean over its runs), with the
t interval over the sequences
(:func:`~replication.evidence.statistics.paired_difference`).

Ties (equal means in a resample: two trackers that lose the target alike)
are split evenly: tied methods share their ranks with equal probability and a
tie is half a win each, so two methods with identical scores beat each other
with probability 0.5 exactly.
"""

from dataclasses import dataclass

import numpy as np
import pandas as pd

from replication.evidence.quantities import quantity
from replication.evidence.comparisons import best_test
from replication.evidence.inference import holm
from replication.evidence.settings import INFERENCE
from replication.evidence.statistics import Estimate, paired_difference
from replication.condition import label_of, values_of

TIE = 1e-12  # means closer than this (relative to the largest score) are level: summation order, not skill


@dataclass(frozen=True)
class Ranking:
    """Methods ranked over sequences, best first (by mean rank over the resamples), with their stability.

    ``scores`` is sequences x runs x methods as measured; ``rank_probability``
    methods x ranks, P(rank = k + 1); ``beats`` methods x methods, P(row beats
    column) (NaN on the diagonal); ``means`` the resampled means, resamples x
    methods.
    """

    methods: tuple[str, ...]
    sequences: tuple[str, ...]
    scores: np.ndarray
    lower_is_better: bool
    rank_probability: np.ndarray
    beats: np.ndarray
    means: np.ndarray

    @property
    def runs(self) -> int:
        """Runs per sequence and method (the repetitions every method ran on every sequence)."""
        return self.scores.shape[1]

    @property
    def p_best(self) -> np.ndarray:
        return self.rank_probability[:, 0]

    @property
    def mean_rank(self) -> np.ndarray:
        return self.rank_probability @ np.arange(1, len(self.methods) + 1)

    def index(self, method: str) -> int:
        return self.methods.index(method)

    def rank(self, i: int) -> Estimate:
        """Method ``i``'s mean rank over the bootstrap resamples (description) and its 95% rank set
        (:func:`rank_set`: what the sequences show, not what the resamples of a few of them suggest)."""
        low, high = rank_set(self.per_sequence_means, i, self.lower_is_better)
        mean = round(float(self.mean_rank[i]), 2)
        return Estimate(mean, float(low), float(high), len(self.sequences), "rank set, paired t over sequences")

    def score(self, i: int) -> Estimate:
        """Method ``i``'s mean over the sequences (of its mean over runs) and the percentile interval of
        its resampled means."""
        value = float(self.scores[:, :, i].mean())
        low, high = np.quantile(self.means[:, i], [(1 - INFERENCE.level) / 2, (1 + INFERENCE.level) / 2])
        return Estimate(value, float(low), float(high), self.runs, "two-level bootstrap, percentile")

    @property
    def out_of_sample(self) -> tuple[int, int]:
        """(held, shown): :func:`held_out` on this ranking's sequences."""
        return held_out(self.per_sequence_means, self.lower_is_better)

    @property
    def per_sequence_means(self) -> np.ndarray:
        """Sequences x methods: each method's mean over its runs on each sequence."""
        return self.scores.mean(axis=1)

    def per_sequence(self, i: int) -> np.ndarray:
        return self.per_sequence_means[:, i]

    def difference(self, a: int, b: int) -> Estimate:
        """Mean over the sequences of the per-sequence difference a - b, t interval over the sequences."""
        return paired_difference(self.per_sequence(a), self.per_sequence(b))

    def wins(self, a: int, b: int) -> int:
        """On how many sequences a's mean over runs is better than b's."""
        ahead = self.per_sequence(a) - self.per_sequence(b)
        return int(((-ahead if self.lower_is_better else ahead) > 0).sum())


def rank_set(per_sequence, i: int, lower_is_better: bool) -> tuple[np.ndarray, np.ndarray]:
    """The 95% confidence set of method ``i``'s rank (1 = best) from ``per_sequence`` (sequences x methods,
    leading batch axes allowed): one more than the methods shown better than it, to the count of methods
    less those shown worse (:func:`shown_orders`; Mogstad, Romano, Shaikh and Wilhelm's marginal rank set).
    The sequences are the sample: a set that holds for sequences like these, not only for resamples of the
    few at hand."""
    ahead, behind = shown_orders(per_sequence, i, lower_is_better)
    m = np.shape(per_sequence)[-1]
    return 1 + behind.sum(axis=-1), m - ahead.sum(axis=-1)


def shown_orders(per_sequence, i: int, lower_is_better: bool) -> tuple[np.ndarray, np.ndarray]:
    """Which competitors (last axis, the methods' order without ``i``) method ``i`` is shown ahead of, and
    which are shown ahead of it: the paired t-test over the sequences, Holm across the 2 (M - 1)
    one-sided tests."""
    tested = best_test(per_sequence, i, lower_is_better)
    m = np.shape(per_sequence)[-1]
    adjusted = holm(np.concatenate([tested.p_for, tested.p_against], axis=-1))
    shown = np.nan_to_num(adjusted, nan=1.0) < INFERENCE.alpha
    return shown[..., : m - 1], shown[..., m - 1:]


def held_out(per_sequence, lower_is_better: bool) -> tuple[int, int]:
    """Leave one sequence out: the orders between two methods that the other sequences show (each
    method's :func:`shown_orders`), and how many of them hold on the sequence left out.  Returns (held,
    shown) over every fold: whether what a rank set rests on predicts a sequence it has not seen."""
    per_sequence = np.asarray(per_sequence, dtype=float)
    n, m = per_sequence.shape
    sign = -1.0 if lower_is_better else 1.0
    held = shown = 0
    for left in range(n):
        rest, new = np.delete(per_sequence, left, axis=0), per_sequence[left]
        for i in range(m):
            ahead, behind = shown_orders(rest, i, lower_is_better)
            lead = np.delete(sign * (new[i] - new), i)  # i's lead over each competitor on the new sequence
            shown += int(ahead.sum() + behind.sum())
            held += int((lead[ahead] > 0).sum() + (lead[behind] < 0).sum())
    return held, shown


def rank(scores: np.ndarray, methods, sequences, lower_is_better: bool) -> Ranking:
    """The two-level bootstrap of a ranking: ``scores`` is sequences x runs x methods, run r of every
    method on a sequence sharing its data and seed (the runs are resampled together)."""
    scores = np.asarray(scores, dtype=float)
    n_sequences, n_runs, n_methods = scores.shape
    rng = np.random.default_rng(INFERENCE.bootstrap_seed)
    drawn = rng.integers(0, n_sequences, size=(INFERENCE.bootstrap_resamples, n_sequences, 1))
    runs = rng.integers(0, n_runs, size=(INFERENCE.bootstrap_resamples, n_sequences, n_runs))
    means = scores[drawn, runs].mean(axis=(1, 2))  # resamples x methods
    sign = -1.0 if lower_is_better else 1.0
    lead = sign * (means[:, :, None] - means[:, None, :])  # [b, i, j]: how far i is ahead of j
    level = np.abs(lead) <= TIE * max(1.0, float(np.abs(scores).max()))  # equal but for rounding
    ahead = ((lead < 0) & ~level).sum(axis=2)  # [b, i]: the methods ahead of i
    tied = level.sum(axis=2)  # [b, i]: i and the methods level with it
    k = np.arange(1, n_methods + 1)
    shares = (k > ahead[..., None]) & (k <= (ahead + tied)[..., None])  # i takes ranks ahead+1 .. ahead+tied
    rank_probability = (shares / tied[..., None]).mean(axis=0)
    beats = (((lead > 0) & ~level) + 0.5 * level).mean(axis=0)
    np.fill_diagonal(beats, np.nan)
    order = np.lexsort((-sign * scores.mean(axis=(0, 1)), rank_probability @ k))  # by mean rank, then mean
    return Ranking(tuple(methods[i] for i in order), tuple(sequences), scores[:, :, order], lower_is_better,
                   rank_probability[order], beats[np.ix_(order, order)], means[:, order])


def rankings(records: pd.DataFrame, metric: str, over: str = "scene", by: str | None = None) -> dict[str, Ranking]:
    """The rankings a table, figure or claim asks for: the methods in ``records`` by mean ``metric`` over the
    values of the condition variable ``over`` (the sequences), one ranking per value of the variable ``by`` if
    given (keyed 'N=10'; '' without ``by``).

    A method run at several values of another variable is one entry per value ('PF (N=300)').  Only
    repetitions every entry ran on every sequence are kept (the pairing); a metric an entry does not
    have leaves it out; a group of fewer than two entries is no ranking.
    """
    rest = label_of(records, without=(over, by))
    frame = pd.DataFrame({
        "group": [f"{by}={value}" if value is not None else "" for value in values_of(records, by)],
        "sequence": values_of(records, over),
        "repetition": records["repetition"],
        "entry": [m if not r else f"{m} ({r})" for m, r in zip(records["method"], rest)],
        "value": records[metric].astype(float),
    }).dropna(subset=["sequence"])
    found = {}
    for group, rows in frame.groupby("group", sort=False):
        table = rows.pivot_table(index=["sequence", "repetition"], columns="entry", values="value",
                                 sort=False)
        table = table.dropna(axis=1, how="all").dropna()
        kept = table.index.to_frame(index=False)
        counts = kept.groupby("repetition", sort=False)["sequence"].nunique()
        common = counts.index[counts == kept["sequence"].nunique()]
        table = table[table.index.get_level_values("repetition").isin(common)]
        if table.shape[1] < 2 or table.empty:
            continue
        sequences = list(dict.fromkeys(table.index.get_level_values("sequence")))
        cube = np.stack([table.xs(s, level="sequence").sort_index().to_numpy() for s in sequences])
        found[group] = rank(cube, list(table.columns), sequences, quantity(metric).lower_is_better)
    return found


def unreliable(ranking: Ranking, experiment: dict) -> str:
    """Why a ranking is not reliable ('' when it is): fewer than :data:`INFERENCE.min_runs` runs per sequence,
    fewer than :data:`INFERENCE.min_sequences` sequences, or sequences cut short (a scene's ``first`` or ``last``
    frame set, as at the quick scale: a ranking of the first 100 frames is not one of the sequences)."""
    found = []
    if ranking.runs < INFERENCE.min_runs:
        runs = f"{ranking.runs} run{'s' if ranking.runs > 1 else ''}"
        found.append(f"{runs} per sequence (fewer than {INFERENCE.min_runs})")
    if len(ranking.sequences) < INFERENCE.min_sequences:
        found.append(f"{len(ranking.sequences)} sequences (fewer than {INFERENCE.min_sequences})")
    scenes = experiment.get("scenes", {})
    cut = {s: (scenes[s].get("first") or 0, scenes[s].get("last")) for s in ranking.sequences
           if s in scenes and (scenes[s].get("first") or scenes[s].get("last"))}
    if cut:
        spans = {f"frames {first + 1}-{last or 'end'}" for first, last in cut.values()}
        which = "sequences" if len(cut) == len(ranking.sequences) else f"{len(cut)} of the sequences"
        found.append(f"{which} cut to {' or '.join(sorted(spans))}")
    return f"not reliable: {'; '.join(found)}" if found else ""
