"""Aggregation, verdicts and the join with the published values."""

import numpy as np
import pandas as pd
import pytest
from scipy import stats

from conftest import typed

from replication.evidence.aggregate import summarise
from replication.evidence.quantities import quantity
from replication.evidence.statistics import estimate, mean, median, paired_difference, proportion, stratified_mean
from replication.errors import ConfigError
from replication.evidence.verdict import BAYES_FLOOR, Outcome, Verdict, judge_band, judge_value, stability_bands
from replication.evidence.published import load_published
from replication.evidence.schema import dump, load
from replication.evidence.tables.comparison import Comparison

EXPERIMENT = {
    "paper": "gps_qmcpf",
    "methods": {"PF": {"filter": "bootstrap", "label": "PF"}, "grid": {"filter": "point_mass", "label": "grid"}},
}


def test_clopper_pearson_interval_is_scipys_exact_one():
    found = proportion(3, 10)
    scipy_ci = stats.binomtest(3, 10).proportion_ci(method="exact")
    assert found.value == 0.3 and found.method == "Clopper-Pearson"
    assert (found.low, found.high) == pytest.approx((scipy_ci.low, scipy_ci.high), rel=1e-12)
    none = proportion(0, 5)  # 0 of 5: [0, 1 - 0.025^(1/5)], not the zero-width [0, 0] of a t-interval
    assert none.low == 0.0 and none.high == pytest.approx(1 - 0.025 ** (1 / 5))
    assert proportion(10, 10).high == 1.0 and proportion(10, 10).low < 1.0


def test_mean_is_the_t_interval_and_stays_in_range():
    values = np.array([0.0, 0.0, 0.0, 0.1, 0.9, 1.0, 1.0, 1.0, 1.0, 1.0])
    found = mean(values, 0.0, 1.0)
    reference = stats.ttest_1samp(values, 0.0).confidence_interval(0.95)
    assert found.value == pytest.approx(0.6)
    assert (found.low, found.high) == pytest.approx((reference.low, reference.high))
    near_top = mean(np.r_[np.ones(4), 0.2], 0.0, 1.0)  # t's upper end, 1.2, clipped to the share's range
    assert near_top.high == 1.0 and 0.0 <= near_top.low
    assert np.isnan(mean([2.0, 2.0, 2.0]).low)  # every run equal: no zero-width interval
    assert np.isnan(mean([5.0]).low) and np.isnan(mean([]).value)


def test_a_stratified_mean_of_runs_all_equal_has_no_interval_though_their_variance_rounds_above_zero():
    groups = [np.full(5, 0.4123204837490552), np.full(5, 0.10880952380952381)]  # a deterministic tracker's runs
    assert groups[0].var(ddof=1) > 0  # rounding: the mean of five copies is not the copy
    shown = stratified_mean(groups, 0.0, 1.0)
    assert np.isnan(shown.low) and np.isnan(shown.high) and shown.method == "stratified t (every run equal)"
    assert shown.value == pytest.approx((0.4123204837490552 + 0.10880952380952381) / 2)
    varied = stratified_mean([np.array([0.1, 0.2, 0.3]), np.array([0.5, 0.5, 0.5])])
    assert varied.low < varied.value < varied.high


def test_t_interval_covers_the_true_mean_about_95_percent_of_the_time_at_5_runs():
    rng = np.random.default_rng(0)
    covered = sum(mean(rng.normal(1.0, 1.0, size=5)).contains(1.0) for _ in range(2000))
    assert 0.935 < covered / 2000 < 0.965


def test_median_interval_uses_binomial_order_statistics():
    values = np.arange(1.0, 11.0)  # n = 10: ranks 2 and 9 (P(2 <= B <= 8) >= 0.95 for B ~ Bin(10, 1/2))
    found = median(values[::-1])
    assert found.value == 5.5 and (found.low, found.high) == (2.0, 9.0)
    assert np.isnan(median([1.0, 2.0, 3.0]).low)  # too few runs for a 95% order-statistic interval


def test_estimate_fits_its_quantity():
    assert estimate(np.array([0.0, 1.0, 1.0, 0.0, 1.0]), quantity("failed")).method == "Clopper-Pearson"
    percent = estimate(np.array([0, 100, 100, 0, 100.0]), quantity("tracked_to_end[cle<=20]").scaled(100))
    assert percent.value == 60.0 and percent.high <= 100.0 and percent.low >= 0.0
    assert estimate(np.array([1.0, 2.0, 3.0]), quantity("rmse")).method == "t"
    assert quantity("correct_frames[iou>=0.5]").high == 1.0 and quantity("mota").high == 1.0
    assert quantity("ms_per_frame").machine_dependent
    with pytest.raises(ConfigError, match="unknown metric 'ess_min'"):  # no direction guessed for a claim
        quantity("ess_min")


def test_paired_difference_is_the_t_interval_of_per_run_differences():
    ours, theirs = np.array([1.0, 2.0, 3.0, 4.0, 5.5]), np.array([1.5, 2.4, 3.1, 4.6, 5.7])
    found = paired_difference(ours, theirs)
    reference = stats.ttest_rel(ours, theirs).confidence_interval(0.95)
    assert found.value == pytest.approx(np.mean(ours - theirs))
    assert (found.low, found.high) == pytest.approx((reference.low, reference.high))


def test_cell_verdicts_need_equivalence_to_be_reproduced():
    rmse = quantity("rmse")
    rng = np.random.default_rng(3)
    tight = 1.0 + rng.normal(0, 0.02, 20)  # mean about 1, its 90% interval well inside +-10% of 1.02
    assert judge_value(np.nan, tight, rmse) is None  # a row of ours with no published number
    assert judge_value(tight.mean() + 0.02, tight, rmse).outcome is Outcome.REPRODUCED
    far = judge_value(2.0, tight, rmse)
    assert far.outcome is Outcome.NOT_REPRODUCED and far.why.startswith("-50%") and far.p_against < 1e-4
    wide = 1.0 + rng.normal(0, 0.5, 20)  # consistent with 1.05 but not shown within +-10%
    verdict = judge_value(wide.mean() + 0.05, wide, rmse)
    assert verdict.outcome is Outcome.INCONCLUSIVE and "neither shown within" in verdict.why
    # the paper's own Monte Carlo noise widens the test: 20 % below a fixed value is outside its band, not
    # below a published mean over 2 runs
    spread = 1.0 + rng.normal(0, 0.1, 20)
    assert judge_value(1.25 * spread.mean(), spread, rmse).outcome is Outcome.NOT_REPRODUCED
    assert judge_value(1.25 * spread.mean(), spread, rmse, paper_runs=2).outcome is Outcome.INCONCLUSIVE
    floor = np.full(20, 0.8) + rng.normal(0, 0.01, 20)
    below = judge_value(0.5, tight, rmse, floor=floor)
    assert below.outcome is Outcome.NOT_REPRODUCED and below.tag == BAYES_FLOOR
    assert judge_value(10.0, np.full(20, 0.5), quantity("ms_per_frame")).outcome is Outcome.NOT_TESTABLE
    assert judge_value(1.05, tight[:4], rmse) == Verdict(Outcome.NOT_TESTABLE, "too few runs (4)")
    assert judge_value(1.0, np.full(10, 1.0), rmse).outcome is Outcome.NOT_TESTABLE  # every run equal
    percent = quantity("tracked_to_end[cle<=20]").scaled(100)
    runs = np.r_[np.full(3, 100.0), np.zeros(17)]
    rate = judge_value(39.3, runs, percent, paper_runs=100)  # 3 of 20 against 39 of 100: Fisher's exact test
    assert rate.p_against == pytest.approx(stats.fisher_exact([[3, 17], [39, 61]]).pvalue)
    assert str(Verdict(Outcome.NOT_REPRODUCED, "-50%")) == "not reproduced (-50%)"
    assert load(Verdict, dump(Verdict(Outcome.INCONCLUSIVE, "x", 0.2, 0.3))) == \
        Verdict(Outcome.INCONCLUSIVE, "x", 0.2, 0.3)


def test_band_verdicts_for_ratings_use_the_exact_interval():
    bands = stability_bands()
    assert judge_band("good", 0, 10, bands).outcome is Outcome.INCONCLUSIVE  # [0, 0.31]: good or medium
    assert judge_band("good", 0, 40, bands).outcome is Outcome.REPRODUCED  # [0, 0.088]
    assert judge_band("good", 8, 10, bands).outcome is Outcome.NOT_REPRODUCED
    assert judge_band("poor", 3, 4, bands).outcome is Outcome.NOT_TESTABLE  # 4 runs
    # bis_pf's 3123 modes: 0 of 5 runs keep both; Clopper-Pearson [0, 0.52] meets 'success' (>= 0.5)
    modes = {"success": (0.5, 1.0), "failure": (0.0, 0.5)}
    assert judge_band("success", 0, 5, modes).outcome is Outcome.INCONCLUSIVE
    assert judge_band("success", 0, 10, modes).outcome is Outcome.NOT_REPRODUCED


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
    assert np.isnan(summary.loc[("PF", "N=20"), "ci_low"])  # both runs 2.0: no interval
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
    return typed(pd.DataFrame(rows))


def test_table_joins_paper_values_and_judges_against_the_floor(published):
    spec = {"name": "t", "title": "t", "paper_table": "1", "metric": "rmse"}
    table = Comparison(Comparison.Spec.of(spec, "t"), EXPERIMENT, published).build(records())
    rows = table.frame.set_index("condition")
    assert rows.loc["N=10", "paper"] == 1.5 and rows.loc["N=10", "verdict"].outcome is Outcome.REPRODUCED
    assert rows.loc["N=20", "verdict"].why.startswith("below the Bayes floor")
    assert rows.loc["-", "verdict"] is None  # the floor: a row of ours with no published counterpart
    # the paired excess over the floor is exact here: each run is floor + a constant
    assert rows.loc["N=10", "excess over the floor (paired, 95% CI)"] == "0.5 [0.5, 0.5]"
    assert {e.published_index for e in table.cells} == {0, 1}  # the QPF cell stays unmatched
    shown = table.shown()
    assert {"ours (95% CI)", "paper", "verdict"} <= set(shown.columns) and "estimate" not in shown
    written = table.written()
    assert set(written["outcome"]) == {"reproduced", "not reproduced", ""}
    assert (table.read(written).shown() == shown).all().all()  # the PDF draws the CSV as the page shows it


def test_unstated_paper_condition_is_mapped(published):
    frame = records().assign(mean_ess=lambda f: np.where(f["condition"] == "N=10", 7.0, np.nan))
    frame.loc[frame["condition"] == "N=10", "mean_ess"] += np.linspace(-0.5, 0.5, 10)
    spec = {"name": "e", "title": "e", "paper_table": "2", "metric": "mean_ess", "paper_condition": "N=10"}
    table = Comparison(Comparison.Spec.of(spec, "t"), EXPERIMENT, published).build(frame).frame
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
    from replication.evidence.tables.modes import two_mode_share

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
    from replication.report.pages.scale import scale_note
    from replication.scales import at_scale, scale_changes

    config = {"quick_frames": {"paper": None, "quick": 100},  # a YAML anchor, not a setting
              "runs": {"paper": 100, "quick": 10},
              "scenes": {"Girl": {"last": {"paper": None, "quick": 100}}, "b": {"frames": {"paper": 5, "quick": 5}}},
              "methods": {"PF": {"n_particles": 10, "sweep": {"N": {"paper": [10, 100], "quick": [10, 50]}}}}}
    assert scale_changes(at_scale(config, "paper"), at_scale(config, "quick")) == [
        "runs: 100 -> 10", "scene Girl last frame: all -> 100", "methods PF sweep N: [10, 100] -> [10, 50]"]
    assert scale_note("paper") is None
    assert "(runs: 100 -> 10)" in scale_note("quick", ["runs: 100 -> 10"])


def test_the_quick_banner_of_a_users_own_sequences_lists_them_not_the_shipped_ones(make_cfg, tmp_path):
    """hspf on a sequence of one's own (a copy of Girl named MyClip): its page's banner names MyClip's frames,
    not the six shipped sequences it replaced."""
    from conftest import PROJECT_ROOT

    from replication.runner.results import Results
    from replication.runner.store import Store
    from replication.scales import scale_changes
    from replication.scenes.otb import OTB_ROOT

    girl = PROJECT_ROOT / OTB_ROOT / "Girl"
    if not girl.is_dir():
        pytest.skip(f"OTB data not at {girl}")
    (tmp_path / "otb").mkdir()
    (tmp_path / "otb" / "MyClip").symlink_to(girl.resolve())
    cfg = make_cfg("hspf", "scale=quick", f"data.otb={tmp_path / 'otb'}", "sequences=[MyClip]")
    results = Results.of(cfg, [], Store(tmp_path / "experiments", "hspf"))
    changes = scale_changes(results.at_paper_scale, results.experiment)
    assert [change for change in changes if change.startswith("scene")] == ["scene MyClip last frame: all -> 100"]
    assert any(change.startswith("runs: ") for change in changes)


def test_every_template_escapes_what_a_config_puts_in_a_page():
    """A title, label or note from a config is text: a <script> in it must not reach the page as markup."""
    from replication.report.pages.render import ENVIRONMENT, render

    assert all(ENVIRONMENT.autoescape(name) for name in ENVIRONMENT.list_templates())
    page = render("base.html.j2", title="<script>alert(1)</script>")
    assert "<script>alert(1)" not in page and "&lt;script&gt;alert(1)" in page


def test_a_summary_table_is_written_as_numbers_and_read_back_to_the_same_page():
    """summary tables (issue 19): the CSV has each metric's mean, low and high as numbers; the page and
    the PDF (drawn from the CSV) show 'mean [low, high]'."""
    import io

    from replication.evidence.tables import Table, TableKind

    records = pd.DataFrame({"method": ["A"] * 6 + ["B"] * 6, "condition": [""] * 12,
                            "mota": [0.5, 0.6, 0.55, 0.52, 0.58, 0.61, 0.1, 0.2, 0.15, 0.12, 0.18, 0.11]})
    table = TableKind.of({"name": "s", "metrics": ["mota"]}, {"methods": {}}, pd.DataFrame()).build(records)
    written = table.written()
    assert list(written.columns) == ["method", "condition", "runs", "mota", "mota_low", "mota_high"]
    assert pd.api.types.is_float_dtype(written["mota"]) and (written["mota_low"] <= written["mota"]).all()
    assert written.loc[0, "mota"] == pytest.approx(np.mean([0.5, 0.6, 0.55, 0.52, 0.58, 0.61]))
    back = Table.read(pd.read_csv(io.StringIO(written.to_csv(index=False))))
    assert back.shown().equals(table.shown())


def test_a_tuning_table_picks_the_best_mean_objective_among_the_settings_that_meet_the_constraint():
    """The rule of bis_pf_pets_tuning, by hand: 'a' has the best MOTA but starts too many tracks per person;
    'b' is the best of those below 1.5; 'c' is worse; rows come best MOTA first."""
    from replication.evidence.tables import TableKind

    rows = [(c, m, t) for c, ms, ts in (("a", [0.6, 0.62, 0.61], [2.0, 2.1, 1.9]), ("b", [0.5, 0.52, 0.49], [1.2, 1.3, 1.1]),
                                         ("c", [0.3, 0.35, 0.31], [1.0, 1.0, 1.2])) for m, t in zip(ms, ts)]
    records = pd.DataFrame([{"method": "MIPF", "condition": c, "mota": m, "tracks_per_person": t} for c, m, t in rows])
    spec = {"name": "tuning", "kind": "tuning", "objective": "mota",
            "constraint": {"metric": "tracks_per_person", "below": 1.5}}
    table = TableKind.of(spec, {"methods": {}}, pd.DataFrame()).build(records)
    assert table.frame["condition"].tolist() == ["a", "b", "c"]
    assert table.frame["picked"].tolist() == ["", "picked", ""]
    assert table.frame["tracks_per_person < 1.5"].tolist() == ["no", "yes", "yes"]
    assert table.note.endswith(": b.")
    strict = {**spec, "constraint": {"metric": "tracks_per_person", "below": 1.0}}
    none = TableKind.of(strict, {"methods": {}}, pd.DataFrame()).build(records)
    assert none.frame["picked"].tolist() == ["", "", ""] and none.note.startswith("No setting meets the rule")
