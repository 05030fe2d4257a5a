"""Aggregation, verdicts and the join with the published values."""

import numpy as np
import pandas as pd
import pytest

from scipy import stats

from replication.report.aggregate import summarise
from replication.report.published import load_published
from replication.report.quantities import quantity
from replication.report.statistics import (
    RESAMPLES, SEED, Estimate, bootstrap_mean, estimate, median, paired_difference, proportion, rate_test,
)
from replication.report.tables import Comparison, stability_bands
from replication.report.verdict import Outcome, Verdict, judge_band, judge_value

EXPERIMENT = {
    "paper": "gps_qmcpf",
    "methods": {"PF": {"filter": "bootstrap", "label": "PF"}, "grid": {"filter": "point_mass", "label": "grid"}},
}


def test_wilson_interval_hand_case_and_scipy():
    # 3 of 10: Wilson's score interval, p +- z sqrt(p(1-p)/n + z^2/4n^2) / (1 + z^2/n) around the shrunk centre
    z = stats.norm.ppf(0.975)
    centre = (0.3 + z**2 / 20) / (1 + z**2 / 10)
    half = z * np.sqrt(0.3 * 0.7 / 10 + z**2 / 400) / (1 + z**2 / 10)
    found = proportion(3, 10)
    assert found.value == 0.3 and found.method == "Wilson"
    assert (found.low, found.high) == pytest.approx((centre - half, centre + half), rel=1e-9)
    scipy_ci = stats.binomtest(3, 10).proportion_ci(method="wilson")
    assert (found.low, found.high) == pytest.approx((scipy_ci.low, scipy_ci.high), rel=1e-12)
    none = proportion(0, 10)  # 0 of 10: not the zero-width [0, 0] of a t-interval
    assert none.low == 0.0 and none.high == pytest.approx(0.2775, abs=1e-4)
    assert proportion(10, 10).high == 1.0 and proportion(10, 10).low < 1.0


def test_bootstrap_mean_is_scipys_bca_and_stays_in_range():
    values = np.array([0.0, 0.0, 0.0, 0.1, 0.9, 1.0, 1.0, 1.0, 1.0, 1.0])
    found = bootstrap_mean(values, 0.0, 1.0)
    reference = stats.bootstrap((values,), np.mean, method="BCa", n_resamples=RESAMPLES,
                                random_state=np.random.default_rng(SEED)).confidence_interval
    assert found.value == pytest.approx(0.6)
    assert (found.low, found.high) == pytest.approx((reference.low, reference.high))
    near_top = bootstrap_mean(np.r_[np.ones(19), 0.2], 0.0, 1.0)  # a share near its bound
    assert 0.0 <= near_top.low <= near_top.value <= near_top.high <= 1.0
    assert bootstrap_mean([2.0, 2.0, 2.0]).low == 2.0  # nothing to resample
    assert np.isnan(bootstrap_mean([5.0]).low) and np.isnan(bootstrap_mean([]).value)


def test_bootstrap_interval_covers_the_true_mean_about_95_percent_of_the_time():
    rng = np.random.default_rng(0)
    covered = sum(bootstrap_mean(rng.exponential(1.0, size=30)).contains(1.0) for _ in range(300))
    assert 0.88 < covered / 300 < 0.99


def test_median_interval_uses_binomial_order_statistics():
    values = np.arange(1.0, 11.0)  # n = 10: ranks 2 and 9 (P(2 <= B <= 8) >= 0.95 for B ~ Bin(10, 1/2))
    found = median(values[::-1])
    assert found.value == 5.5 and (found.low, found.high) == (2.0, 9.0)
    assert np.isnan(median([1.0, 2.0, 3.0]).low)  # too few runs for a 95% order-statistic interval


def test_estimate_fits_its_quantity():
    assert estimate(np.array([0.0, 1.0, 1.0, 0.0, 1.0]), quantity("failed")).method == "Wilson"
    percent = estimate(np.array([0, 100, 100, 0, 100.0]), quantity("tracked_to_end[cle<=20]").scaled(100))
    assert percent.value == 60.0 and percent.high <= 100.0 and percent.low >= 0.0
    assert estimate(np.array([1.0, 2.0, 3.0]), quantity("rmse")).method == "BCa bootstrap"
    assert quantity("correct_frames[iou>=0.5]").high == 1.0 and quantity("mota").high == 1.0
    assert quantity("ms_per_frame").machine_dependent


def test_paired_difference_is_the_bootstrap_of_per_run_differences():
    ours, theirs = np.array([1.0, 2.0, 3.0, 4.0, 5.5]), np.array([1.5, 2.4, 3.1, 4.6, 5.7])
    found = paired_difference(ours, theirs)
    assert found.value == pytest.approx(np.mean(ours - theirs))
    assert (found.low, found.high) == pytest.approx(
        (bootstrap_mean(ours - theirs).low, bootstrap_mean(ours - theirs).high))


def test_fisher_exact_rate_test_matches_scipy():
    # ours 3 of 20 against the paper's 39.3 % of 100 runs (39 of 100)
    assert rate_test(3, 20, 0.393, 100) == pytest.approx(stats.fisher_exact([[3, 17], [39, 61]]).pvalue)


def test_cell_verdicts():
    rmse = quantity("rmse")
    ours = Estimate(1.0, 0.9, 1.1, 20, "BCa bootstrap")
    assert judge_value(np.nan, ours, rmse) is None  # a row of ours with no published number
    assert judge_value(1.05, ours, rmse) == Verdict(Outcome.REPRODUCED)
    assert judge_value(2.0, ours, rmse) == Verdict(Outcome.NOT_REPRODUCED, "-50%")
    assert judge_value(1.13, ours, rmse).outcome is Outcome.NOT_REPRODUCED
    assert judge_value(1.13, ours, rmse, paper_runs=20).outcome is Outcome.REPRODUCED  # widened by sqrt(2)
    assert judge_value(0.5, ours, rmse, floor_low=0.8) == Verdict(Outcome.NOT_REPRODUCED, "below the Bayes floor 0.8")
    assert judge_value(10.0, Estimate(0.5, 0.4, 0.6, 20, ""), quantity("ms_per_frame")).outcome \
        is Outcome.NOT_TESTABLE
    assert judge_value(1.05, Estimate(1.0, 0.9, 1.1, 4, ""), rmse) == Verdict(Outcome.NOT_TESTABLE, "too few runs (4)")
    percent = quantity("tracked_to_end[cle<=20]").scaled(100)
    assert judge_value(39.3, Estimate(15.0, 5.0, 36.0, 20, "Wilson"), percent, paper_runs=100).why.startswith(
        "Fisher's exact test p = ")
    assert str(Verdict(Outcome.NOT_REPRODUCED, "-50%")) == "not reproduced (-50%)"
    assert Verdict.from_dict(Verdict(Outcome.INCONCLUSIVE, "x").as_dict()) == Verdict(Outcome.INCONCLUSIVE, "x")


def test_band_verdicts_for_ratings():
    bands = stability_bands()
    assert judge_band("good", proportion(0, 10), bands).outcome is Outcome.INCONCLUSIVE  # [0, 0.28]: good or medium
    assert judge_band("good", proportion(0, 40), bands).outcome is Outcome.REPRODUCED  # [0, 0.088]
    assert judge_band("good", proportion(8, 10), bands) == Verdict(Outcome.NOT_REPRODUCED, "ours: poor")
    assert judge_band("poor", proportion(3, 4), bands).outcome is Outcome.NOT_TESTABLE  # 4 runs


def test_summarise_groups_by_method_and_condition():
    records = pd.DataFrame(
        {
            "method": ["PF"] * 4 + ["grid"] * 2,
            "condition": ["N=10", "N=10", "N=20", "N=20", "", ""],
            "rmse": [1.0, 3.0, 2.0, 2.0, 1.0, 1.0],
        }
    )
    summary = summarise(records, "rmse").set_index(["method", "condition"])
    assert summary.loc[("PF", "N=10"), "mean"] == 2.0
    assert summary.loc[("PF", "N=10"), "variance"] == 2.0
    assert summary.loc[("PF", "N=20"), "ci_low"] == summary.loc[("PF", "N=20"), "ci_high"] == 2.0
    assert summary.loc[("grid", ""), "runs"] == 2


@pytest.fixture
def published(tmp_path):
    path = tmp_path / "published.csv"
    path.write_text(
        "paper,table,experiment,method,metric,condition,value,unit,note\n"
        "gps_qmcpf,1,ungm,PF,rmse,N=10,1.5,,\n"
        "gps_qmcpf,1,ungm,PF,rmse,N=20,0.2,,\n"
        "gps_qmcpf,1,ungm,QPF,rmse,N=10,1.0,,not ours yet\n"
        "gps_qmcpf,2,ungm,PF,mean_ess,,7.0,particles,N not stated\n"
    )
    return load_published(str(path))


def records():
    rng = np.random.default_rng(0)
    rows = []
    for rep in range(10):
        floor = 1.0 + 0.1 * rng.standard_normal()
        rows.append({"method": "grid", "condition": "", "data_condition": "", "repetition": rep, "rmse": floor})
        for n, excess in (("N=10", 0.5), ("N=20", 0.1)):
            rows.append(
                {"method": "PF", "condition": n, "data_condition": "", "repetition": rep, "rmse": floor + excess}
            )
    return pd.DataFrame(rows)


def test_table_joins_paper_values_and_judges_against_the_floor(published):
    spec = {"name": "t", "title": "t", "paper_table": "1", "metric": "rmse"}
    table = Comparison(spec, EXPERIMENT, published).build(records())
    rows = table.frame.set_index("condition")
    assert rows.loc["N=10", "paper"] == 1.5 and rows.loc["N=10", "verdict"].outcome is Outcome.REPRODUCED
    assert rows.loc["N=20", "verdict"].why.startswith("below the Bayes floor")
    assert rows.loc["-", "verdict"] is None  # the floor: a row of ours with no published counterpart
    # the paired excess over the floor is exact here: each run is floor + a constant
    assert rows.loc["N=10", "excess over the floor (paired, 95% CI)"] == "0.5 [0.5, 0.5]"
    assert {e["published_index"] for e in table.cells} == {0, 1}  # the QPF cell stays unmatched
    shown = table.shown()
    assert {"ours (95% CI)", "paper", "verdict"} <= set(shown.columns) and "estimate" not in shown
    written = table.written()
    assert set(written["outcome"]) == {"reproduced", "not reproduced", ""}
    assert (table.read(written).shown() == shown).all().all()  # the PDF draws the CSV as the page shows it


def test_unstated_paper_condition_is_mapped(published):
    frame = records().assign(mean_ess=lambda f: np.where(f["condition"] == "N=10", 7.0, np.nan))
    frame.loc[frame["condition"] == "N=10", "mean_ess"] += np.linspace(-0.5, 0.5, 10)
    spec = {"name": "e", "title": "e", "paper_table": "2", "metric": "mean_ess", "paper_condition": "N=10"}
    table = Comparison(spec, EXPERIMENT, published).build(frame).frame
    assert list(table["condition"]) == ["N=10"]  # rows with no finite value are dropped
    assert table["paper"].iloc[0] == 7.0 and table["verdict"].iloc[0].outcome is Outcome.REPRODUCED


def test_published_values_file_has_every_ungm_cell_we_report():
    from replication.paths import resolve

    path = resolve("../shared/reference/published_values.csv")
    if not path.exists():
        pytest.skip("../shared is not beside the project")
    table = load_published(str(path))
    pf = table[(table["paper"] == "gps_qmcpf") & (table["method"] == "PF") & (table["metric"] == "rmse")]
    assert sorted(pf["condition"]) == ["N=100", "N=200", "N=500"]


def test_two_mode_share_counts_frames_with_mass_near_both_hypotheses():
    from replication.report.modes import two_mode_share

    density = np.zeros((4, 10))  # 10 bins over [0, 100): bin centres 5, 15, ..., 95
    density[0, [2, 7]] = 0.5  # mass at 25 and 75: both hypotheses held
    density[1, 2] = 1.0  # only the first
    density[2, [2, 7]] = [0.95, 0.05]  # the second under the 10% bar
    density[3, 5] = 1.0  # hypotheses 1 px apart: one mode, frame left out
    hypotheses = np.array([[25.0, 75.0], [25.0, 75.0], [25.0, 75.0], [55.0, 56.0]])
    assert two_mode_share(density, hypotheses, 100.0, width=5.0, mass=0.1) == pytest.approx(1 / 3)
    with pytest.raises(ValueError, match="never separate"):
        two_mode_share(density[3:], hypotheses[3:], 100.0, width=5.0, mass=0.1)


def test_scale_changes_lists_what_quick_changes_from_the_config():
    from replication.report.scale import scale_changes, scale_note

    config = {"quick_frames": {"paper": None, "quick": 100},  # a YAML anchor, not a setting
              "runs": {"paper": 100, "quick": 10},
              "scenes": {"Girl": {"last": {"paper": None, "quick": 100}}, "b": {"frames": {"paper": 5, "quick": 5}}},
              "methods": {"PF": {"n_particles": 10}}}
    assert scale_changes(config) == ["runs: 100 -> 10", "scene Girl last frame: all -> 100"]
    assert scale_note("paper") is None
    assert "(runs: 100 -> 10)" in scale_note("quick", ["runs: 100 -> 10"])


def test_every_template_escapes_what_a_config_puts_in_a_page():
    """A title, label or note from a config is text: a <script> in it must not reach the page as markup."""
    from replication.report.render import ENVIRONMENT, render

    assert all(ENVIRONMENT.autoescape(name) for name in ENVIRONMENT.list_templates())
    page = render("base.html.j2", title="<script>alert(1)</script>")
    assert "<script>alert(1)" not in page and "&lt;script&gt;alert(1)" in page


def test_a_summary_table_is_written_as_numbers_and_read_back_to_the_same_page():
    """summary tables (issue 19): the CSV has each metric's mean, low and high as numbers; the page and
    the PDF (drawn from the CSV) show 'mean [low, high]'."""
    import io

    from replication.report.tables import Table, TableKind

    records = pd.DataFrame({"method": ["A"] * 6 + ["B"] * 6, "condition": [""] * 12,
                            "mota": [0.5, 0.6, 0.55, 0.52, 0.58, 0.61, 0.1, 0.2, 0.15, 0.12, 0.18, 0.11]})
    table = TableKind.of({"name": "s", "metrics": ["mota"]}, {"methods": {}}, pd.DataFrame()).build(records)
    written = table.written()
    assert list(written.columns) == ["method", "condition", "runs", "mota", "mota_low", "mota_high"]
    assert pd.api.types.is_float_dtype(written["mota"]) and (written["mota_low"] <= written["mota"]).all()
    assert written.loc[0, "mota"] == pytest.approx(np.mean([0.5, 0.6, 0.55, 0.52, 0.58, 0.61]))
    back = Table.read(pd.read_csv(io.StringIO(written.to_csv(index=False))))
    assert back.shown().equals(table.shown())
