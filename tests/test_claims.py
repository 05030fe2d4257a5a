"""The papers' claims as data, and the tests that judge them, on hand cases."""

import numpy as np
import pandas as pd
import pytest
from hydra import compose, initialize_config_dir
from omegaconf import OmegaConf
from scipy import stats

from conftest import PROJECT_ROOT, typed

from replication.evidence.statistics import Estimate
from replication.evidence.verdict import Outcome, Verdict
from replication.paths import CONF_DIR, resolve
from replication.evidence.checks import Check, Result
from replication.evidence.claim_tests import ClaimTest, claim_spec
from replication.evidence.claims import Reading, load_papers
from replication.evidence.published import load_published
from replication.evidence.settings import INFERENCE

PUBLISHED = resolve("../shared/reference/published_values.csv")
PAPERS = load_papers()


def test_every_published_cell_belongs_to_exactly_one_claim():
    if not PUBLISHED.exists():
        pytest.skip("../shared is not beside the project")
    published = load_published(str(PUBLISHED))
    claims = [c for p in PAPERS for c in p.claims]
    for _, cell in published.iterrows():
        owners = [c.id for c in claims if c.owns(cell)]
        assert len(owners) == 1, (dict(cell[["paper", "table", "experiment", "method", "metric"]]), owners)


def test_every_reading_names_a_real_experiment_methods_and_tables():
    assert {p.key for p in PAPERS} == {"ism_pf", "gps_qmcpf", "bis_pf", "fusion_pf", "hspf"}
    assert len({c.id for p in PAPERS for c in p.claims}) == sum(len(p.claims) for p in PAPERS)
    with initialize_config_dir(config_dir=str(CONF_DIR), version_base="1.3"):
        for paper in PAPERS:
            for claim in paper.claims:
                assert claim.id.startswith(f"{paper.key}.") and claim.readings, claim.id
                for reading in claim.readings:
                    experiment = OmegaConf.to_container(
                        compose("config", overrides=[f"experiment={reading.experiment}"]).experiment)
                    assert experiment["paper"] == paper.key, claim.id
                    test = reading.test
                    ClaimTest.of(test, experiment)  # a known test
                    named = [m for g in getattr(test, "order", []) for m in ([g] if isinstance(g, str) else g)]
                    named += [m for k in ("method", "baseline") if test.test != "uniformity" and getattr(test, k, None)
                              for m in ([getattr(test, k)] if isinstance(getattr(test, k), str) else getattr(test, k))]
                    assert set(named) <= set(experiment["methods"]), (claim.id, reading.name)
                    tables = {t["name"] for t in experiment["report"]["tables"]}
                    assert set(getattr(test, "tables", [])) <= tables, (claim.id, reading.name)


EXPERIMENT = {"methods": {"A": {}, "B": {}, "C": {}}}


def _records(effects: dict[str, float], runs: int = 20, metric: str = "rmse", noise: float = 0.1) -> pd.DataFrame:
    """Three methods on common data: run r of every method shares a base value, plus the method's effect."""
    rng = np.random.default_rng(1)
    base = rng.normal(5.0, 1.0, runs)
    return typed(pd.DataFrame([{"method": m, "condition": "N=1", "data_condition": "", "repetition": r,
                                metric: base[r] + effect + noise * rng.standard_normal()}
                               for m, effect in effects.items() for r in range(runs)]))


def _verdict(spec: dict, records: pd.DataFrame) -> Verdict:
    return Result.of(ClaimTest.of(spec, EXPERIMENT).checks(records, {})).verdict


def test_order_uses_paired_differences():
    # the run-to-run spread (sd 1) dwarfs the effects (0.2): only pairing by run can resolve them
    records = _records({"A": 0.0, "B": 0.2, "C": 0.4})
    assert _verdict({"test": "order", "metric": "rmse", "order": ["A", "B", "C"]}, records).outcome \
        is Outcome.REPRODUCED
    backwards = _verdict({"test": "order", "metric": "rmse", "order": ["C", "A"]}, records)
    assert backwards.outcome is Outcome.NOT_REPRODUCED and "C - A at N=1" in backwards.why
    assert "the other way round" in backwards.why and backwards.p_against < 0.05
    tied = _records({"A": 0.0, "B": 0.0})
    assert _verdict({"test": "order", "metric": "rmse", "order": ["A", "B"]}, tied).outcome is Outcome.INCONCLUSIVE
    # "no slower than by more than 10 %": B is 4 % worse than A
    assert _verdict({"test": "order", "metric": "rmse", "order": ["B", "A"], "tolerance": 0.1}, records).outcome \
        is Outcome.REPRODUCED
    higher = _records({"A": 1.0, "B": 0.0}, metric="mean_ess")  # higher is better for ESS
    assert _verdict({"test": "order", "metric": "mean_ess", "order": ["A", "B"]}, higher).outcome \
        is Outcome.REPRODUCED
    few = _records({"A": 0.0, "B": 1.0}, runs=4)
    assert _verdict({"test": "order", "metric": "rmse", "order": ["A", "B"]}, few) == \
        Verdict(Outcome.NOT_TESTABLE, "too few runs (4)")


def test_equal_cost_pairs_the_method_with_the_cheapest_baseline_condition_that_reaches_its_budget():
    """HSPF-like M spends 1100 evaluations per step at N = 100; the baseline B is swept over N, spending N:
    the check pairs M with B at N = 1400 (the cheapest reaching 1100), run by run on the same data."""
    rng = np.random.default_rng(2)
    base = rng.normal(5.0, 1.0, 20)
    rows = [{"method": "M", "condition": "N=100", "evaluations_per_step": 1100.0, "rmse": base[r] + 0.3}
            for r in range(20)]
    rows += [{"method": "B", "condition": f"N={n}", "evaluations_per_step": float(n),
              "rmse": base[r] + 1.0 / np.sqrt(n) + 0.01 * rng.standard_normal()}
             for n in (250, 500, 1000, 1400, 2000, 4000) for r in range(20)]
    records = typed(pd.DataFrame([{**row, "data_condition": "", "repetition": i % 20} for i, row in enumerate(rows)]))
    spec = {"test": "equal_cost", "metric": "rmse", "method": "M", "baseline": "B", "cost": "evaluations_per_step"}
    (check,) = ClaimTest.of(spec, EXPERIMENT).checks(records, {})
    assert check.detail == "budget 1100; B at N=1400 spends 1400"
    assert check.what == "M at N=100 - B at equal likelihood evaluations per step"  # its identity, free of budgets
    assert check.estimate.value == pytest.approx(0.3 - 1.0 / np.sqrt(1400), abs=0.01)  # M worse, paired
    assert check.verdict.outcome is Outcome.NOT_REPRODUCED
    elsewhere = records.assign(data_condition=np.where(records["condition"] == "N=1400", "scene=b", ""))
    (check,) = ClaimTest.of(spec, EXPERIMENT).checks(elsewhere, {})
    assert check.detail.endswith("B at N=2000 spends 2000")  # an N run on other data (another scene) is not a budget
    # several methods and baselines: each method against each baseline, a check each (Holm across them)
    twice = pd.concat([records, records.assign(method=records["method"].map({"M": "M2", "B": "B2"}))])
    listed = {**spec, "method": ["M", "M2"], "baseline": ["B", "B2"]}
    checks = ClaimTest.of(listed, EXPERIMENT).checks(typed(twice.reset_index(drop=True)), {})
    assert [c.what.split(" - ")[0] + " / " + c.what.split(" - ")[1].split(" at ")[0] for c in checks] == [
        "M at N=100 / B", "M at N=100 / B2", "M2 at N=100 / B", "M2 at N=100 / B2"]
    assert {c.estimate.value for c in checks} == {checks[0].estimate.value}  # the same runs under each name
    assert Reading("r", "e", claim_spec(spec)).basis == "likelihood evaluations per step"
    assert Reading("r", "e", claim_spec({"test": "order", "metric": "rmse", "order": ["M", "B"]})).basis == ""  # the paper's: equal N
    poor = records[~records["condition"].isin(["N=1400", "N=2000", "N=4000"])]  # no B condition reaches 1100
    (untestable,) = ClaimTest.of(spec, EXPERIMENT).checks(poor, {})
    assert untestable.verdict.outcome is Outcome.NOT_TESTABLE and "at most 1000" in untestable.verdict.why


def test_a_comparison_of_times_shows_the_work_of_each_side():
    """A cost claim's check (a time) carries each method's likelihood evaluations per step beside it, so a
    slower code can be told from more work; a comparison of accuracy does not."""
    records = _records({"A": 0.0, "B": 0.2}, metric="ms_per_step")
    records["evaluations_per_step"] = np.where(records["method"] == "A", 100.0, 1100.0)
    (check,) = ClaimTest.of({"test": "order", "metric": "ms_per_step", "order": ["A", "B"]}, EXPERIMENT) \
        .checks(records, {})
    assert check.detail == "likelihood evaluations per step: A 100, B 1100"
    assert check.shown == f"{check.what} ({check.detail})"
    accuracy = _records({"A": 0.0, "B": 0.2}).assign(evaluations_per_step=100.0)
    (check,) = ClaimTest.of({"test": "order", "metric": "rmse", "order": ["A", "B"]}, EXPERIMENT) \
        .checks(accuracy, {})
    assert check.detail == "" and check.shown == check.what


def test_inconclusive_says_what_the_runs_could_detect():
    tied = _records({"A": 0.0, "B": 0.0}, runs=5)
    verdict = _verdict({"test": "order", "metric": "rmse", "order": ["A", "B"]}, tied)
    assert verdict.outcome is Outcome.INCONCLUSIVE and "5 runs detect" in verdict.why


def test_holm_keeps_nine_checks_from_calling_a_claim_wrong_on_one_unlucky_check():
    # nine pairs, one of them a little the other way round (t = 2.68, p = 0.007 alone): not past Holm
    z = np.random.default_rng(5).standard_normal(20)
    z = (z - z.mean()) / z.std(ddof=1)  # mean 0, sd 1 exactly
    rows = []
    for condition in range(9):
        for r in range(20):
            shift = (0.06 if condition == 0 else 0.0) + 0.1 * z[r]
            rows += [{"method": "A", "condition": f"N={condition}", "data_condition": "", "repetition": r,
                      "rmse": 5.0 + shift}, {"method": "B", "condition": f"N={condition}", "data_condition": "",
                                            "repetition": r, "rmse": 5.0}]
    records = typed(pd.DataFrame(rows))
    checks = ClaimTest.of({"test": "order", "metric": "rmse", "order": ["A", "B"]}, EXPERIMENT).checks(records, {})
    first = checks[0].verdict
    assert first.outcome is Outcome.NOT_REPRODUCED and 9 * first.p_against > 0.05
    result = Result.of(checks)
    assert result.verdict.outcome is not Outcome.NOT_REPRODUCED
    assert "not significant after Holm across 9 checks" in result.checks[0].verdict.why


def test_identical_outcomes_decide_nothing_even_against_the_papers_size():
    """Every run of both methods at the floor: the paper's 95 % against 55 % (its own noise alone would call
    a gap of 0 short of 40 pp) is not tested: the scene decides nothing about the paper."""
    metric = "tracked_to_end[cle<=20]"
    both_fail = _records({"A": 0.0, "B": 0.0}, metric=metric, noise=0.0)
    both_fail[metric] = 0.0
    for size in ({}, {"size": {"quoted": {"A": 95, "B": 55}}, "scale": 100}):
        verdict = _verdict({"test": "order", "metric": metric, "order": ["A", "B"], **size}, both_fail)
        assert verdict.outcome is Outcome.NOT_TESTABLE
        assert "every run of both methods at the floor (0 of 20): the scene decides nothing" in verdict.why
    both_fail[metric] = 1.0
    assert "at the ceiling (20 of 20)" in _verdict({"test": "order", "metric": metric, "order": ["A", "B"]},
                                                    both_fail).why


def test_a_quoted_size_is_tested_against_ours():
    published = pd.DataFrame({"paper": "p", "table": "1", "experiment": "", "method": ["A", "B"],
                              "metric": "rmse", "condition": "N=1", "value": ["1.6", "4.2"], "unit": "",
                              "note": "", "number": [1.6, 4.2]})
    experiment = {"paper": "p", "methods": EXPERIMENT["methods"],
                  "report": {"tables": [{"name": "t1", "paper_table": "1", "metric": "rmse"}]}}
    records = _records({"A": 0.0, "B": 0.2})  # A better by 0.2, the paper's A better by 2.6
    spec = {"test": "order", "metric": "rmse", "order": ["A", "B"], "size": {"table": "t1"}}
    verdict = Result.of(ClaimTest.of(spec, experiment, published).checks(records, {})).verdict
    assert verdict.outcome is Outcome.NOT_REPRODUCED and "the sign agrees, the size does not" in verdict.why
    ratio = {**spec, "size": {"table": "t1", "kind": "ratio"}}
    verdict = Result.of(ClaimTest.of(ratio, experiment, published).checks(records, {})).verdict
    assert "ratio 0.381" in verdict.why


def test_a_share_printed_in_percent_is_sized_in_percent():
    """A share of frames (0..1 per run) shown in percentage points (scale 100) against a paper's 92.3 % and
    77.3 %: a gap of 15 pp in ours is the paper's size, one of 8 pp falls short.  (The paper's numbers were
    once tested against the runs' shares unscaled, so a gap equal to the paper's read as "size absent".)"""
    metric = "correct_frames[iou>=0.5]"
    spec = {"test": "order", "metric": metric, "order": ["A", "B"], "scale": 100, "unit": " pp",
            "size": {"quoted": {"A": 92.3, "B": 77.3}}}
    rng = np.random.default_rng(2)
    for gap, outcome in ((0.15, Outcome.REPRODUCED), (0.08, Outcome.NOT_REPRODUCED)):
        records = typed(pd.DataFrame([{"method": m, "condition": "N=1", "data_condition": "", "repetition": r,
                                       metric: share + 0.01 * rng.standard_normal()}
                                      for r in range(30) for m, share in (("A", 0.7 + gap), ("B", 0.7))]))
        checks = ClaimTest.of(spec, EXPERIMENT).checks(records, {})
        assert Result.of(checks).verdict.outcome is outcome, gap
        assert checks[0].paper == pytest.approx(15.0)  # the paper's gap, in the units ours is shown in
        assert checks[0].estimate.value == pytest.approx(100 * gap, abs=1.0)


def test_a_users_claim_quotes_its_own_numbers_for_the_size():
    """No published table: the reading quotes the pair, and the size is tested as a paper's is."""
    records = _records({"A": 0.0, "B": 0.2})
    spec = {"test": "order", "metric": "rmse", "order": ["A", "B"], "size": {"quoted": {"A": 1.6, "B": 4.2}}}
    verdict = _verdict(spec, records)  # no published values at all
    assert verdict.outcome is Outcome.NOT_REPRODUCED and "the sign agrees, the size does not" in verdict.why
    agreeing = {**spec, "size": {"quoted": {"A": 4.8, "B": 5.0}}}  # a gap of 0.2, ours
    assert _verdict(agreeing, records).outcome is Outcome.REPRODUCED


def test_a_users_claims_files_are_read_as_the_papers_and_a_broken_one_is_one_line(tmp_path):
    from replication.errors import ConfigError
    from replication.evidence.claims import load_own_papers

    own = load_own_papers(PROJECT_ROOT / "examples" / "auxiliary_pf" / "conf" / "claims")
    assert [paper.key for paper in own] == ["apf"] and [c.id for c in own[0].claims] == ["apf.ungm"]
    with pytest.raises(ConfigError, match="no claims file"):
        load_own_papers(tmp_path)
    head = "paper: mine\norder: 7\ntitle: t\nauthors: a\nvenue: v\nclaims:\n  - id: mine.x\n"
    (tmp_path / "mine.yaml").write_text(head + "    readings: []\n")
    with pytest.raises(ConfigError, match=r"mine.yaml lacks the key 'claim'; see conf/claims/\*.yaml$"):
        load_own_papers(tmp_path)
    (tmp_path / "mine.yaml").write_text(head + "    claim: c\n    where: s\n    readings:\n"
                                        "      - {name: r, experiment: e, test: faster}\n")
    with pytest.raises(ConfigError, match=r"mine.yaml: claim mine.x, reading r: unknown claim test 'faster'; known claim tests: .*order"):
        load_own_papers(tmp_path)


def test_threshold():
    records = _records({"A": 0.0, "B": 1.0}, metric="fps")
    here = {"test": "threshold", "metric": "fps", "method": "A", "condition": {"N": 1}, "machine": "this"}
    assert _verdict({**here, "at_least": 2.0, "statistic": "median"}, records).outcome is Outcome.REPRODUCED
    assert _verdict({**here, "at_least": 50.0}, records).outcome is Outcome.NOT_REPRODUCED
    # 5 runs all above the bound: the exact sign test's floor, 1/32, decides (no order-statistic 95% interval)
    five = _records({"A": 20.0}, runs=5, metric="fps")
    verdict = _verdict({**here, "at_least": 5.52, "statistic": "median"}, five)
    assert verdict.outcome is Outcome.REPRODUCED and verdict.p_for == pytest.approx(1 / 32)


def test_a_time_measured_on_another_machine_is_not_testable_and_the_ratio_is_shown():
    five = _records({"A": 20.0}, runs=5, metric="fps")
    spec = {"test": "threshold", "metric": "fps", "method": "A", "condition": {"N": 1}, "at_least": 5.52}
    verdict = _verdict(spec, five)
    median = float(np.median(five.loc[five["method"] == "A", "fps"]))
    assert verdict.outcome is Outcome.NOT_TESTABLE
    assert f"ours / theirs = {median / 5.52:.3g}" in verdict.why


def test_result_combines_checks():
    def check(outcome):
        return Check("x", Verdict(outcome), Estimate(1.0, 0.5, 1.5, 10, ""))

    yes, no, maybe, untestable = (check(o) for o in (Outcome.REPRODUCED, Outcome.NOT_REPRODUCED,
                                                     Outcome.INCONCLUSIVE, Outcome.NOT_TESTABLE))  # no p-values
    assert Result.of([yes, yes, untestable]).verdict.outcome is Outcome.REPRODUCED
    assert Result.of([yes, maybe]).verdict.outcome is Outcome.INCONCLUSIVE
    assert Result.of([maybe, no, yes]).verdict.outcome is Outcome.NOT_REPRODUCED
    assert Result.of([maybe, no]).deciding is not None
    assert Result.of([untestable]).verdict.outcome is Outcome.NOT_TESTABLE
    assert Result.of([]).verdict.outcome is Outcome.NOT_TESTABLE


def test_cells_reads_a_rating_tables_verdicts_and_the_proportion_behind_them():
    from replication.evidence.tables.rating import Rating

    published = pd.DataFrame({"paper": ["p"], "table": ["3"], "experiment": ["s"], "method": ["A"],
                              "metric": ["stability"], "condition": [""], "value": ["good"], "unit": [""],
                              "note": [""], "number": [np.nan]})
    records = typed(pd.DataFrame({"method": "A", "condition": "scene=s", "failed": [0.0] * 28 + [1.0] * 12}))
    spec = {"name": "t3", "paper_table": "3", "metric": "failed", "paper_metric": "stability",
            "match": [{"ours": {"scene": "s"}, "paper": {"experiment": "s"}}]}
    table = Rating(Rating.Spec.of(spec, "t3"), {"paper": "p", "methods": {"A": {}}}, published).build(records)
    result = Result.of(ClaimTest.of({"test": "cells", "tables": ["t3"]}, EXPERIMENT).checks(records, {"t3": table}))
    assert result.verdict.outcome is Outcome.NOT_REPRODUCED  # 12 of 40 failed: [0.18, 0.45], medium, not good
    assert result.deciding.estimate.value == 0.3 and "(ours: medium)" in result.deciding.what


def test_the_deciding_check_is_the_strongest_evidence_however_small_its_p_value():
    def against(p: float, what: str) -> Check:
        return Check(what, Verdict(Outcome.NOT_REPRODUCED, "", 1.0, p), Estimate(1.0, 0.5, 1.5, 10, ""))

    assert Result.of([against(1e-20, "weaker"), against(1e-30, "stronger")]).deciding.what == "stronger"
    # Holm's running maximum ties the two (2 x 1e-3 and 1.2e-3 both become 2e-3): the smaller p-value decides
    assert Result.of([against(1.2e-3, "weaker"), against(1e-3, "stronger")]).deciding.what == "stronger"
    # on runs: A is worse than B by 1.5, B than C by 3 (p about 1e-23 and 1e-30, both 0 as 1 - p_above)
    records = _records({"A": 1.5, "B": 0.0, "C": -3.0})
    result = Result.of(ClaimTest.of({"test": "order", "metric": "rmse", "order": ["A", "B", "C"]}, EXPERIMENT)
                       .checks(records, {}))
    assert result.verdict.outcome is Outcome.NOT_REPRODUCED and result.deciding.what == "B - C at N=1"
    runs = records.pivot(index="repetition", columns="method", values="rmse")
    scipy = [stats.ttest_1samp(runs[b] - runs[w], 0.0, alternative="greater").pvalue for b, w in [("A", "B"), ("B", "C")]]
    assert 0 < scipy[1] < scipy[0] < 1e-16
    assert [c.verdict.p_against for c in result.checks] == pytest.approx(scipy, rel=1e-6)
    assert result.verdict.p_against == pytest.approx(2 * scipy[1], rel=1e-6)  # Holm across the two checks


def test_a_reading_names_the_checks_it_could_not_test():
    def check(what, outcome, why=""):
        return Check(what, Verdict(outcome, why), Estimate(1.0, 0.5, 1.5, 10, ""))

    yes = check("A - B", Outcome.REPRODUCED)
    result = Result.of([yes, yes, check("A - C", Outcome.NOT_TESTABLE, "too few runs (4)"),
                        check("A - D", Outcome.NOT_TESTABLE)])
    assert result.verdict.outcome is Outcome.REPRODUCED
    assert result.verdict.why.startswith("2 of 2 testable checks hold; 2 not testable: A - C (too few runs (4)), "
                                         "A - D; A - B: ")
    assert Result.of([yes, yes]).verdict.why.startswith("2 of 2 checks hold; A - B: ")  # all testable: said plainly


def test_a_check_with_an_allowance_shows_the_raw_difference_and_the_allowance_apart():
    """"B takes no more than 10 % longer than A": B is 5 % slower, 0.5 of A's 10; the test allows 1.0."""
    rng = np.random.default_rng(3)
    base = rng.normal(10.0, 1.0, 20)
    a, b = base, base + 0.5 + 0.1 * rng.standard_normal(20)
    records = typed(pd.DataFrame([{"method": m, "condition": "N=1", "data_condition": "", "repetition": r,
                                   "ms_per_step": v[r]} for m, v in (("A", a), ("B", b)) for r in range(20)]))
    spec = {"test": "order", "metric": "ms_per_step", "order": ["B", "A"], "tolerance": 0.1, "unit": " ms"}
    (check,) = ClaimTest.of(spec, EXPERIMENT).checks(records, {})
    interval = stats.ttest_1samp(b - a, 0.0).confidence_interval(1 - 2 * INFERENCE.alpha)
    assert check.estimate.value == pytest.approx(np.mean(b - a))  # the raw difference, not less the allowance
    assert (check.estimate.low, check.estimate.high) == pytest.approx((interval.low, interval.high))
    allowed = 0.1 * a.mean()
    assert check.reference == pytest.approx(allowed)  # the claim's line: slower by at most the allowance
    assert check.verdict.outcome is Outcome.REPRODUCED
    assert check.verdict.p_for == pytest.approx(stats.ttest_1samp(b - a, allowed, alternative="less").pvalue)
    raw = np.mean(b - a)
    assert check.verdict.why.startswith(f"{raw:+.3g} ms ({raw / a.mean():+.0%}), allowed +10% = {allowed:+.3g} ms: ")
    higher = records.assign(mean_ess=-records["ms_per_step"])  # higher is better: B may be lower by 10 %
    (check,) = ClaimTest.of({**spec, "metric": "mean_ess", "unit": ""}, EXPERIMENT).checks(higher, {})
    assert check.estimate.value == pytest.approx(-raw) and check.reference == pytest.approx(-allowed)
    assert f"allowed -10% = {-allowed:+.3g}: " in check.verdict.why


def test_each_check_shows_the_interval_of_the_level_it_names():
    """A check's interval is the 90 % interval of the one-sided tests that decided it; a published cell's, its
    table's 95 % interval (its two-sided test at 5 %): the number says which, and the interval is that."""
    from replication.evidence.tables.improvement import Improvement

    records = _records({"A": 0.0, "B": 0.2})
    runs = records.pivot(index="repetition", columns="method", values="rmse")
    (order,) = ClaimTest.of({"test": "order", "metric": "rmse", "order": ["A", "B"]}, EXPERIMENT).checks(records, {})
    ninety = stats.ttest_1samp(runs["A"] - runs["B"], 0.0).confidence_interval(0.90)
    assert (order.estimate.low, order.estimate.high) == pytest.approx((ninety.low, ninety.high))
    assert order.estimate.level == pytest.approx(0.90) and order.number.endswith(" (90% CI)")
    (bound,) = ClaimTest.of({"test": "threshold", "metric": "rmse", "method": "A", "condition": {"N": 1},
                             "at_most": 6.0}, EXPERIMENT).checks(records, {})
    ninety = stats.ttest_1samp(runs["A"], 6.0).confidence_interval(0.90)
    assert (bound.estimate.low, bound.estimate.high) == pytest.approx((ninety.low, ninety.high))
    assert bound.number.endswith(" (90% CI)")
    sizes = typed(records[["method", "data_condition", "repetition", "rmse"]].assign(  # a growth exponent's too
        condition=records["repetition"].map(lambda r: f"N={4 + r}")))
    (growth,) = ClaimTest.of({"test": "growth", "method": "A", "metric": "rmse", "x": "N", "at_most": 1.0},
                             EXPERIMENT).checks(sizes, {})
    a = sizes[sizes["method"] == "A"]
    fit = stats.linregress(np.log(4.0 + a["repetition"]), np.log(a["rmse"]))
    assert growth.estimate.high == pytest.approx(fit.slope + stats.t.ppf(1 - INFERENCE.growth_alpha, len(a) - 2) * fit.stderr)
    assert growth.number.endswith(" (92% CI)")  # each end the one-sided bound at growth_alpha
    published = pd.DataFrame({"paper": ["p"], "table": ["1"], "experiment": ["s"], "method": ["B vs A"],
                              "metric": ["rmse_improvement"], "condition": [""], "value": ["1.8"], "unit": ["%"],
                              "note": [""], "number": [1.8]})
    spec = {"name": "gain", "kind": "improvement", "paper_table": "1", "metric": "rmse",
            "paper_metric": "rmse_improvement", "baseline": "B", "method": "A", "tolerance_pp": 1.0}
    table = Improvement(Improvement.Spec.of(spec, "t"), {"paper": "p", "methods": {"A": {}, "B": {}}}, published).build(records)
    (cell,) = ClaimTest.of({"test": "cells", "tables": ["gain"]}, EXPERIMENT).checks(records, {"gain": table})
    gain = 100 * (runs["B"] - runs["A"]) / runs["B"].mean()
    ninety_five = stats.ttest_1samp(gain, 0.0).confidence_interval(INFERENCE.level)
    assert (cell.estimate.low, cell.estimate.high) == pytest.approx((ninety_five.low, ninety_five.high))
    assert cell.number.endswith(" (95% CI)")
    assert "(" not in Check("x", Verdict(Outcome.REPRODUCED), Estimate(1.0, np.nan, np.nan, 5, "")).number  # no interval
