"""A ranking over a few sequences with its stability (two-level bootstrap), on hand cases, and the claim it
decides."""

import numpy as np
import pandas as pd
import pytest

from conftest import typed

from replication.evidence.verdict import Outcome
from replication.report import figures
from replication.report.figures import ranking as ranking_figures
from replication.evidence.checks import Result
from replication.evidence.claim_tests import ClaimTest
from replication.evidence.ranking import held_out, rank, rankings
from replication.evidence.tables import Table, TableKind
from replication.runner.footage import SceneFootage

FOOTAGE = SceneFootage()  # the video the runs saw, as the pages are given it
SEQUENCES = [f"s{i}" for i in range(6)]


def _records(scores: np.ndarray, methods: list[str], metric: str = "precision20", **condition):
    """Run records from sequences x runs x methods scores: run r of every method on a sequence shares its
    data (``data_condition``, ``repetition``)."""
    rest = "".join(f";{k}={v}" for k, v in condition.items())
    return typed(pd.DataFrame([{"method": m, "condition": f"scene={s}{rest}", "data_condition": f"scene={s}",
                                "repetition": r, metric: scores[i, r, j]}
                               for i, s in enumerate(SEQUENCES[:scores.shape[0]]) for r in range(scores.shape[1])
                               for j, m in enumerate(methods)]))


def test_a_method_ahead_on_every_sequence_and_run_is_first_with_probability_one():
    rng = np.random.default_rng(3)
    scores = rng.uniform(0.2, 0.6, (6, 5, 4))
    scores[:, :, 2] = scores.max(axis=2) + 0.01  # C: ahead of every other method in every run
    ranked = rank(scores, list("ABCD"), SEQUENCES, lower_is_better=False)
    assert ranked.methods[0] == "C" and ranked.p_best[0] == 1.0 and ranked.p_best.sum() == pytest.approx(1.0)
    first = ranked.rank(0)
    assert (first.value, first.low, first.high) == (1.0, 1, 1)
    assert np.all(ranked.beats[0, 1:] == 1.0) and np.all(ranked.beats[1:, 0] == 0.0)
    assert ranked.wins(0, 1) == 6 and ranked.difference(0, 1).low > 0
    # the same when lower is better (an error): the lowest is first
    errors = rank(-scores, list("ABCD"), SEQUENCES, lower_is_better=True)
    assert errors.methods[0] == "C" and errors.p_best[0] == 1.0
    # every rank distribution sums to one; a method's rank interval holds its mean rank
    assert np.allclose(ranked.rank_probability.sum(axis=1), 1.0)
    assert np.allclose(ranked.rank_probability.sum(axis=0), 1.0)
    assert all(ranked.rank(i).low <= ranked.rank(i).value <= ranked.rank(i).high for i in range(4))


def test_two_methods_with_identical_scores_share_first_place_exactly():
    rng = np.random.default_rng(4)
    a = rng.uniform(0.5, 0.9, (6, 5, 1))
    scores = np.concatenate([a, a, a - 0.3 - rng.uniform(0, 0.05, a.shape)], axis=2)  # B is A; C is behind
    ranked = rank(scores, ["A", "B", "C"], SEQUENCES, lower_is_better=False)
    i, j = ranked.index("A"), ranked.index("B")
    assert ranked.beats[i, j] == ranked.beats[j, i] == 0.5  # a tie is half a win, never the first listed's
    assert ranked.p_best[i] == ranked.p_best[j] == 0.5
    assert (ranked.rank(i).low, ranked.rank(i).high) == (1, 2)
    off = ~np.eye(3, dtype=bool)
    assert np.allclose((ranked.beats + ranked.beats.T)[off], 1.0)


def test_mirrored_methods_beat_each_other_about_half_the_time():
    """A ahead by 0.2 on half the sequences, B by 0.2 on the others: neither ranking is supported."""
    rng = np.random.default_rng(5)
    base = rng.uniform(0.3, 0.6, (6, 5, 1))
    lead = np.array([0.2, 0.2, 0.2, 0.0, 0.0, 0.0])[:, None, None]
    ranked = rank(np.concatenate([base + lead, base + 0.2 - lead], axis=2), ["A", "B"], SEQUENCES, False)
    assert 0.4 < ranked.beats[0, 1] < 0.6 and 0.4 < ranked.p_best[0] < 0.6
    assert ranked.beats[0, 1] + ranked.beats[1, 0] == pytest.approx(1.0)
    assert ranked.difference(0, 1).contains(0.0)


def test_runs_are_resampled_together_common_random_numbers():
    """A run's luck (sd 0.3) is shared by both methods and dwarfs A's lead (0.01) on one sequence:
    resampled together, A beats B in every resample; resampled apart, it would not."""
    luck = np.random.default_rng(6).normal(0.0, 0.3, (1, 5, 1))
    scores = 0.5 + np.concatenate([luck + 0.01, luck], axis=2)
    ranked = rank(scores, ["A", "B"], ["s0"], lower_is_better=False)
    assert ranked.beats[0, 1] == 1.0


def test_rankings_from_records_pair_runs_and_split_by_a_variable():
    rng = np.random.default_rng(7)
    scores = rng.uniform(0.2, 0.8, (6, 5, 2))
    records = pd.concat([_records(scores, ["PF", "ISM-PF"], N=10),
                         _records(scores[:, :, ::-1], ["PF", "ISM-PF"], N=50)])  # the other way round
    split = rankings(records, "precision20", by="N")
    assert set(split) == {"N=10", "N=50"}
    ten, fifty = split["N=10"], split["N=50"]
    assert ten.p_best[ten.index("PF")] == fifty.p_best[fifty.index("ISM-PF")]
    together = rankings(records, "precision20")
    assert set(together) == {""} and set(together[""].methods) == {"PF (N=10)", "ISM-PF (N=10)", "PF (N=50)",
                                                                  "ISM-PF (N=50)"}
    unpaired = records[~((records["method"] == "PF") & (records["repetition"] == 4))]  # a run PF lacks
    assert rankings(unpaired, "precision20", by="N")["N=10"].runs == 4


EXPERIMENT = {"methods": {"A": {}, "B": {}, "C": {}}}


def _best(method: str, records: pd.DataFrame, experiment: dict = EXPERIMENT):
    return Result.of(ClaimTest.of({"test": "best", "metric": "precision20", "method": method}, experiment)
                     .checks(records, {})).verdict


def test_the_best_claim_is_decided_by_paired_tests_against_each_competitor_over_the_sequences():
    rng = np.random.default_rng(8)
    scores = rng.uniform(0.3, 0.5, (6, 5, 3))
    scores[:, :, 0] = scores.max(axis=2) + 0.05  # A first everywhere
    dominated = _records(scores, list("ABC"))
    assert _best("A", dominated).outcome is Outcome.REPRODUCED
    beaten = _best("B", dominated)
    assert beaten.outcome is Outcome.NOT_REPRODUCED and "A is better" in beaten.why
    assert "P(best) = 0.00" in beaten.why and "description only" in beaten.why
    # B has the higher mean (one sequence by far) but is ahead on only 3 of 6 sequences: no verdict either way
    close = scores.copy()
    close[:, :, 1] = close[:, :, 0] + np.array([0.5, 0.05, 0.05, -0.05, -0.05, -0.05])[:, None]
    assert close[:, :, 1].mean() > close[:, :, 0].mean()
    assert _best("B", _records(close, list("ABC"))).outcome is Outcome.INCONCLUSIVE
    # not reliable: no verdict from fewer than 5 runs, 5 sequences, or sequences cut short
    one_run = _best("A", _records(scores[:, :1], list("ABC")))
    assert one_run.outcome is Outcome.NOT_TESTABLE and "1 run per sequence" in one_run.why
    assert "P(best) = 1.00" in one_run.why
    assert _best("A", _records(scores[:4], list("ABC"))).outcome is Outcome.NOT_TESTABLE
    cut = {**EXPERIMENT, "scenes": {s: {"kind": "otb", "name": s, "last": 100} for s in SEQUENCES}}
    short = _best("A", dominated, cut)
    assert short.outcome is Outcome.NOT_TESTABLE and "cut to frames 1-100" in short.why


def test_ranking_and_pairwise_tables_and_the_figure(tmp_path, keep_figures):
    rng = np.random.default_rng(9)
    records = _records(rng.uniform(0.2, 0.8, (6, 1, 3)), list("ABC"))
    experiment = {"methods": {"A": {"label": "A (N = 5)"}, "B": {}, "C": {}}}
    spec = {"name": "r", "kind": "ranking", "metric": "precision20"}
    table = TableKind.of(spec, experiment, pd.DataFrame()).build(records)
    assert table.note.startswith("Not reliable: 1 run per sequence")
    assert "A (N = 5)" in set(table.frame["method"])  # the config's label
    assert table.frame["P(best)"].sum() == pytest.approx(1.0, abs=0.002)
    back = Table.read(table.written())  # the PDF's round trip through the CSV
    assert list(back.shown()["rank"]) == list(table.shown()["rank"])
    pairs = TableKind.of({**spec, "kind": "pairwise"}, experiment, pd.DataFrame()).build(records)
    order = list(table.frame["method"])  # best first: each pair names the better-ranked first
    assert [(order.index(a), order.index(b)) for a, b in zip(pairs.frame["A"], pairs.frame["B"])] == \
        [(0, 1), (0, 2), (1, 2)]
    drawn = keep_figures(ranking_figures)
    figures.draw(records, {**spec, "title": "t"}, experiment, tmp_path / "r.png", footage=FOOTAGE)
    title = drawn[0].axes[0].get_title(loc="left")
    assert "not reliable" in title and "6 sequences x 1 run(s)" in title


def test_leaving_one_sequence_out_counts_the_shown_orders_that_hold_on_it():
    # method 0 far ahead of 1 and 2 on every sequence (by 1.0, spread 0.1): with any 5 of 6 sequences the
    # paired t shows both orders, from 0's family and from each loser's; 1 and 2 are level (no order shown)
    rng = np.random.default_rng(3)
    per_sequence = np.array([[2.0, 1.0, 1.0]]) + 0.1 * rng.standard_normal((6, 3))
    held, shown = held_out(per_sequence, lower_is_better=False)
    assert shown == 6 * 4 and held == shown  # 0 > 1 and 0 > 2, each seen from both sides, in 6 folds
    # a sequence on which the order reverses: the orders shown without it fail on it
    reversed_last = per_sequence.copy()
    reversed_last[-1] = [0.0, 1.0, 1.0]
    held, shown = held_out(reversed_last, lower_is_better=False)
    assert shown >= 4 and held == shown - 4  # the fold leaving out the reversed sequence: its 4 orders fail
