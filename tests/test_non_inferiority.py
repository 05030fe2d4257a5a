"""The bar of issue 61: at least a reference's score within a margin, at most a bound, on every sequence."""

import numpy as np
import pandas as pd
from scipy import stats

from replication.evidence.tables.table import TableKind

SPEC = {"name": "bar", "kind": "non_inferiority", "reference": "SORT", "metrics": ["mota"], "margin": 0.01,
        "most": {"tracks_per_person": 1.5}, "others": ["Detections"]}


def _records(mipf_mota, mipf_tracks, sort_mota=0.5):
    rows = []
    for r, (m, t) in enumerate(zip(mipf_mota, mipf_tracks)):
        rows.append({"method": "MIPF", "condition.scene": "pets", "repetition": r, "mota": m, "tracks_per_person": t})
        rows.append({"method": "SORT", "condition.scene": "pets", "repetition": r, "mota": sort_mota,
                     "tracks_per_person": 3.0})
        rows.append({"method": "Detections", "condition.scene": "pets", "repetition": r, "mota": 0.1,
                     "tracks_per_person": 9.0})
    return pd.DataFrame(rows)


def _build(records):
    return TableKind.of(SPEC, {"paper": "bis_pf", "methods": {}}, pd.DataFrame()).build(records)


def test_each_bar_is_the_exact_sign_test_of_the_median_run_against_scipys_binomial_test():
    """Every MIPF run meets the bar (MOTA at least SORT's 0.5 less 0.01; at most 1.5 tracks per person): the
    p of 5 of 5 runs meeting it when each meets it with probability 1/2, scipy's exact binomial test."""
    mota = np.array([0.491, 0.50, 0.51, 0.495, 0.505])  # the lowest just above the bar, 0.49
    tracks = [1.2, 1.3, 1.25, 1.3, 1.2]
    table = _build(_records(mota, tracks))
    expected = stats.binomtest(5, 5, 0.5, alternative="greater").pvalue  # 1/32
    for metric, values in (("mota", mota), ("tracks_per_person", tracks)):
        row = table.frame[table.frame["metric"] == metric].iloc[0]
        assert np.isclose(row["p"], expected, rtol=1e-12) and row["cleared"] == "yes"
        assert row["median"].value == np.median(values) and np.isclose(row["mean"], np.mean(values))
    assert set(table.frame["method"]) == {"MIPF"}  # SORT is the bar, Detections context only
    assert table.note.startswith("Every test is cleared")


def test_a_method_below_the_margin_or_above_the_bound_does_not_clear_and_all_ties_decide_nothing():
    table = _build(_records([0.47, 0.48, 0.46, 0.47, 0.48], [1.4, 1.6, 1.5, 1.45, 1.55]))
    assert table.frame["cleared"].tolist() == ["no", "no"] and table.note.startswith("Not every")
    tracks = table.frame[table.frame["metric"] == "tracks_per_person"].iloc[0]  # 3 of 5 meet it (1.5 does)
    assert np.isclose(tracks["p"], stats.binomtest(3, 5, 0.5, alternative="greater").pvalue)
    tied = _build(_records([0.6] * 5, [1.0] * 5))
    assert tied.frame["cleared"].tolist() == ["undefined", "undefined"]
