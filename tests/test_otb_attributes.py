"""OTB's per-attribute view: precision at 20 px and success AUC per attribute, the mean over the sequences
that carry it, on hand cases whose per-frame errors give the exact answer."""

import math

import numpy as np
import pandas as pd
import pytest

from conftest import typed

from replication.metrics import tracking as tm
from replication.report import figures
from replication.report.figures import metric as metric_figures, tracking as tracking_figures
from replication.evidence.tables import TableKind
from replication.scenes.otb import otb_attributes
from replication.runner.footage import SceneFootage

FOOTAGE = SceneFootage()  # the video the runs saw, as the pages are given it
# Suv carries OCC, IPR and OV; Girl SV, OCC, IPR and OPR (OTB-100's list).  The scene keys are ours.
EXPERIMENT = {
    "methods": {"A": {"label": "method A"}, "B": {}},
    "scenes": {"suv": {"kind": "otb", "name": "Suv"}, "girl": {"kind": "otb", "name": "Girl"},
               "mine": {"kind": "otb", "name": "NotInOTB"}, "blob": {"kind": "synthetic"}},
}
GOOD, POOR, NONE = 0.82, 0.33, 0.02  # overlaps above 17, 7 and 1 of the 21 success thresholds (0, 0.05, ..., 1)


def record(method: str, condition: str, repetition: int, errors: list[float], overlaps: list[float]) -> dict:
    """A run scored from its per-frame centre errors and overlaps, as the tracking task scores it."""
    return {"method": method, "condition": condition, "repetition": repetition,
            "precision20": tm.precision_at(np.array(errors)), "success_auc": tm.success_auc(np.array(overlaps))}


def hand_records() -> pd.DataFrame:
    return typed(pd.DataFrame([
        # A on Suv, two runs: precision 2/4 and 3/4, success 38/84 and 52/84 -> means 5/8 and 45/84
        record("A", "scene=suv", 0, [5, 25, 10, 40], [GOOD, POOR, 0.61, NONE]),
        record("A", "scene=suv", 1, [5, 5, 5, 40], [GOOD, GOOD, GOOD, NONE]),
        # A on Girl, one run: precision 0, success 4/84
        record("A", "scene=girl", 0, [30, 30, 30, 30], [NONE] * 4),
        # B on Suv only: precision 1, success 20/21
        record("B", "scene=suv", 0, [0, 0, 0, 0], [0.97] * 4),
        # not counted: a synthetic scene and a sequence OTB does not list
        record("A", "scene=blob", 0, [0, 0, 0, 0], [0.97] * 4),
        record("A", "scene=mine", 0, [0, 0, 0, 0], [0.97] * 4),
    ]))


def test_attribute_table_averages_sequences_not_runs():
    table = TableKind.of({"name": "attributes", "kind": "otb_attributes"}, EXPERIMENT, pd.DataFrame(), FOOTAGE).build(
        hand_records())
    frame = table.frame
    rows = {(row["method"], row["attribute"].split()[0]): row for _, row in frame.iterrows()}
    assert list(rows) == [("method A", "SV"), ("method A", "OCC"), ("B", "OCC"), ("method A", "IPR"),
                          ("B", "IPR"), ("method A", "OPR"), ("method A", "OV"), ("B", "OV")]  # OTB's order
    expected = {  # (precision, success): Suv and Girl weigh the same, whatever their runs
        ("method A", "OCC"): ((5 / 8 + 0) / 2, (45 / 84 + 4 / 84) / 2),  # pooled runs would give 5/12
        ("method A", "IPR"): ((5 / 8 + 0) / 2, (45 / 84 + 4 / 84) / 2),
        ("method A", "SV"): (0.0, 4 / 84),
        ("method A", "OPR"): (0.0, 4 / 84),
        ("method A", "OV"): (5 / 8, 45 / 84),
        ("B", "OCC"): (1.0, 20 / 21),
        ("B", "IPR"): (1.0, 20 / 21),
        ("B", "OV"): (1.0, 20 / 21),
    }
    for key, (precision, success) in expected.items():
        assert rows[key]["precision20"].value == pytest.approx(precision, abs=1e-12), key
        assert rows[key]["success_auc"].value == pytest.approx(success, abs=1e-12), key
        assert math.isnan(rows[key]["precision20"].low)  # 1 or 2 runs per sequence: no interval
    assert rows[("method A", "OCC")]["sequences"] == "2: Girl, Suv"
    assert rows[("method A", "OCC")]["runs"] == 1  # the fewest on one sequence
    assert rows[("method A", "OV")]["sequences"] == "Suv only (one sequence, not a population)"
    assert rows[("B", "OCC")]["sequences"].startswith("Suv only")  # B ran on Suv alone
    assert rows[("method A", "OCC")]["attribute"] == "OCC (occlusion)"
    shown = table.shown()
    assert shown.loc[frame.index[1], "precision20"] == "0.3125"  # no interval shown


def test_attribute_interval_needs_five_runs_per_sequence_and_keeps_sequences_fixed():
    """Five runs on each sequence give an interval over runs within each sequence; four on one do not."""
    def runs(scene, n, precision):  # run r of n: r of 4 frames lost, so precision varies by run
        return [record("A", f"scene={scene};N=10", r, [5] * (4 - (r + precision) % 3) + [50] * ((r + precision) % 3),
                       [GOOD] * 4) for r in range(n)]

    five = typed(pd.DataFrame(runs("suv", 5, 0) + runs("girl", 5, 1)))
    occlusion = TableKind.of({"name": "a", "kind": "otb_attributes"}, EXPERIMENT, pd.DataFrame(), FOOTAGE).build(five).frame
    occlusion = occlusion[occlusion["attribute"].str.startswith("OCC")].iloc[0]
    estimate = occlusion["precision20"]
    suv, girl = (five[five["condition"].str.contains(s)]["precision20"].mean() for s in ("suv", "girl"))
    assert estimate.value == pytest.approx((suv + girl) / 2)
    assert estimate.low < estimate.value < estimate.high and 0.0 <= estimate.low and estimate.high <= 1.0
    assert occlusion["condition"] == "N=10" and occlusion["runs"] == 5 and estimate.runs == 10
    four = typed(pd.DataFrame(runs("suv", 5, 0) + runs("girl", 4, 1)))
    frame = TableKind.of({"name": "a", "kind": "otb_attributes"}, EXPERIMENT, pd.DataFrame(), FOOTAGE).build(four).frame
    defined = dict(zip(frame["attribute"].str.split().str[0], frame["precision20"].map(lambda e: e.defined)))
    assert defined == {"SV": False, "OCC": False, "IPR": False, "OPR": False, "OV": True}  # OV: Suv only


def test_no_listed_sequence_gives_an_empty_table_and_every_listed_code_is_an_attribute():
    synthetic = typed(pd.DataFrame([record("A", "scene=blob", 0, [0], [0.9])]))
    assert TableKind.of({"name": "a", "kind": "otb_attributes"}, EXPERIMENT, pd.DataFrame(), FOOTAGE).build(synthetic).empty
    meanings, sequences = otb_attributes()
    assert list(meanings) == ["IV", "SV", "OCC", "DEF", "MB", "FM", "IPR", "OPR", "OV", "BC", "LR"]
    assert sequences["Suv"] == ["OCC", "IPR", "OV"] and sequences["Jogging-2"] == ["OCC", "DEF", "OPR"]


def test_attribute_map_shows_each_method_per_attribute_and_frames_the_best(keep_figures, tmp_path):
    drawn = keep_figures(metric_figures, tracking_figures)
    figures.draw(hand_records(), {"kind": "attribute_map", "name": "m"}, EXPERIMENT, tmp_path / "m.png", footage=FOOTAGE)
    precision = drawn[0].axes[0]
    assert [t.get_text() for t in precision.get_xticklabels()] == ["SV\nGirl", "OCC\n2 seq.", "IPR\n2 seq.",
                                                                   "OPR\nGirl", "OV\nSuv"]
    assert [t.get_text() for t in precision.get_yticklabels()] == ["method A", "B"]
    cells = {(round(t.get_position()[1]), round(t.get_position()[0])): t.get_text() for t in precision.texts}
    assert cells[(0, 1)] == "0.31" and cells[(1, 1)] == "1.00" and (1, 0) not in cells  # B never ran on Girl
    framed = {(round(p.get_x() + 0.5), round(p.get_y() + 0.5)) for p in precision.patches}
    assert framed == {(0, 0), (1, 1), (2, 1), (3, 0), (4, 1)}  # (column, row) of each attribute's best
    assert "MB" in drawn[0].axes[1].get_xlabel()  # no sequence here has motion blur
