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


def test_against_a_deterministic_reference_the_test_is_the_one_sample_t_against_its_value_less_the_margin():
    mota = np.array([0.49, 0.50, 0.51, 0.495, 0.505])  # mean 0.5: SORT's value, within the 0.01 margin
    table = _build(_records(mota, [1.2, 1.3, 1.25, 1.3, 1.2]))
    row = table.frame[table.frame["metric"] == "mota"].iloc[0]
    expected = stats.ttest_1samp(mota, 0.5 - 0.01, alternative="greater").pvalue
    assert np.isclose(row["p"], expected, rtol=1e-12) and row["cleared"] == "yes"
    tracks = table.frame[table.frame["metric"] == "tracks_per_person"].iloc[0]
    upper = 1.25 + stats.t.ppf(0.95, 4) * np.std([1.2, 1.3, 1.25, 1.3, 1.2], ddof=1) / np.sqrt(5)
    assert np.isclose(tracks["mean"].high, upper, rtol=1e-12) and tracks["cleared"] == "yes"
    assert set(table.frame["method"]) == {"MIPF"}  # SORT is the bar, Detections context only
    assert table.note.startswith("Every test is cleared")


def test_a_method_below_the_margin_or_above_the_bound_does_not_clear_and_all_ties_decide_nothing():
    table = _build(_records([0.47, 0.48, 0.46, 0.47, 0.48], [1.4, 1.6, 1.5, 1.45, 1.55]))
    assert table.frame["cleared"].tolist() == ["no", "no"] and table.note.startswith("Not every")
    tied = _build(_records([0.6] * 5, [1.0] * 5))
    assert tied.frame["cleared"].tolist() == ["undefined", "undefined"]
