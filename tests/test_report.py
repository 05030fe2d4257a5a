"""Aggregation, verdicts and the join with the published values."""

import numpy as np
import pandas as pd
import pytest

from replication.report.aggregate import comparison_interval, mean_interval, summarise
from replication.report.published import load_published
from replication.report.tables import build_table, format_table
from replication.report.verdict import verdict

EXPERIMENT = {
    "paper": "gps_qmcpf",
    "methods": {"PF": {"filter": "bootstrap", "label": "PF"}, "grid": {"filter": "point_mass", "label": "grid"}},
}


def test_mean_interval_hand_computed():
    # mean 2, sd 1, n = 3: t_{0.975, 2} = 4.302653; half-width = 4.302653 / sqrt(3)
    mean, low, high = mean_interval([1.0, 2.0, 3.0])
    assert mean == 2.0
    assert high - mean == pytest.approx(4.302653 / np.sqrt(3), rel=1e-6)
    assert mean - low == pytest.approx(high - mean)
    assert np.isnan(mean_interval([5.0])[1])
    assert np.isnan(mean_interval([])[0])


def test_comparison_interval_widens_for_the_papers_own_noise():
    # sd 2, 25 runs of ours, 100 of theirs: half-width t_{0.975,24} * 2 * sqrt(1/25 + 1/100)
    low, high = comparison_interval(10.0, 2.0, 25, 100)
    assert high - 10.0 == pytest.approx(2.063899 * 2.0 * np.sqrt(0.05), rel=1e-5)
    assert 10.0 - low == pytest.approx(high - 10.0)
    own = comparison_interval(10.0, 2.0, 25, None)
    assert own[1] - 10.0 == pytest.approx(2.063899 * 2.0 / 5.0, rel=1e-5)  # our own 95% interval
    assert np.isnan(comparison_interval(1.0, np.nan, 1, 100)[0])


def test_interval_covers_the_true_mean_about_95_percent_of_the_time():
    rng = np.random.default_rng(0)
    covered = 0
    for _ in range(2000):
        _, low, high = mean_interval(rng.exponential(1.0, size=30))
        covered += low <= 1.0 <= high
    assert 0.91 < covered / 2000 < 0.97  # skewed data: t-intervals undercover a little


def test_verdict_rules():
    assert verdict(np.nan, 1.0, 0.9, 1.1, "rmse") == "reference"
    assert verdict(1.05, 1.0, 0.9, 1.1, "rmse") == "agrees"
    assert verdict(2.0, 1.0, 0.9, 1.1, "rmse") == "differs (-50%)"
    assert verdict(0.5, 1.0, 0.9, 1.1, "rmse") == "differs (+100%)"
    assert verdict(1.6, 4.5, 4.0, 5.0, "rmse", floor_low=4.1) == "below the Bayes floor (4.1)"
    assert verdict(10.0, 0.5, 0.4, 0.6, "time").startswith("machine-dependent (ours/theirs = 0.05")


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
    table, matched = build_table(records(), spec, EXPERIMENT, published)
    rows = table.set_index("condition")
    assert rows.loc["N=10", "paper"] == 1.5 and rows.loc["N=10", "verdict"] == "agrees"
    assert rows.loc["N=20", "verdict"].startswith("below the Bayes floor")
    assert rows.loc["-", "verdict"] == "reference"
    # the paired excess over the floor is exact here: each run is floor + a constant
    assert rows.loc["N=10", "excess_over_floor"] == pytest.approx(0.5)
    assert rows.loc["N=10", "excess_ci_high"] - rows.loc["N=10", "excess_ci_low"] == pytest.approx(0.0, abs=1e-12)
    assert len(matched) == 2  # the QPF cell stays unmatched
    text = format_table(table)
    assert "paper" in text.columns and "excess over the floor (paired, 95% CI)" in text.columns


def test_unstated_paper_condition_is_mapped(published):
    frame = records().assign(mean_ess=lambda f: np.where(f["condition"] == "N=10", 7.0, np.nan))
    frame.loc[frame["condition"] == "N=10", "mean_ess"] += np.linspace(-0.5, 0.5, 10)
    spec = {"name": "e", "title": "e", "paper_table": "2", "metric": "mean_ess", "paper_condition": "N=10"}
    table, matched = build_table(frame, spec, EXPERIMENT, published)
    assert list(table["condition"]) == ["N=10"]  # rows with no finite value are dropped
    assert table["paper"].iloc[0] == 7.0 and table["verdict"].iloc[0] == "agrees"


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
