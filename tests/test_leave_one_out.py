"""The leave-one-out table: the rule picks on the other sequences and is shown on the one left out."""

import numpy as np
import pandas as pd

from replication.evidence.tables.table import TableKind


def _records():
    """MIPF on three sequences at two settings (box=a, box=b), SORT once per sequence; 3 runs each.  Setting a
    is better on A and B, b on C; b starts too many tracks on A."""
    mota = {("A", "a"): 0.6, ("A", "b"): 0.5, ("B", "a"): 0.4, ("B", "b"): 0.3, ("C", "a"): 0.2, ("C", "b"): 0.5}
    tracks = {("A", "b"): 2.0}
    rows = []
    for (scene, box), value in mota.items():
        for r, noise in enumerate((-0.01, 0.0, 0.01)):
            rows.append({"method": "MIPF", "condition": f"scene={scene};box={box}", "condition.scene": scene,
                         "condition.box": box, "repetition": r, "mota": value + noise, "hota": value / 2,
                         "tracks_per_person": tracks.get((scene, box), 1.2) + noise})
    for scene, value in {"A": 0.55, "B": 0.35, "C": 0.3}.items():
        for r in range(3):
            rows.append({"method": "SORT", "condition": f"scene={scene};box=a", "condition.scene": scene,
                         "condition.box": "a", "repetition": r, "mota": value, "hota": value / 2,
                         "tracks_per_person": 3.0})
    return pd.DataFrame(rows)


def test_each_sequence_left_out_gets_the_setting_the_rule_picks_on_the_others():
    spec = {"name": "loo", "kind": "leave_one_out", "objective": "mota", "method": "MIPF", "reference": "SORT",
            "constraint": {"metric": "tracks_per_person", "below": 1.5}, "metrics": ["mota", "tracks_per_person"]}
    table = TableKind.of(spec, {"paper": "bis_pf", "methods": {}}, pd.DataFrame()).build(_records())
    frame = table.frame
    picked = dict(zip(frame.loc[frame["method"] == "MIPF", "left out"], frame.loc[frame["method"] == "MIPF", "setting"]))
    # left out A: on B and C, a averages 0.3 and b 0.4, and b meets the constraint there (1.2): b.
    # left out B: b's mean tracks per person on A and C is 1.6 (above 1.5), so a, though b's MOTA is higher.
    # left out C: a averages 0.5 against b's 0.4: a.
    assert picked == {"A": "box=b", "B": "box=a", "C": "box=a"}
    mipf_a = frame[(frame["method"] == "MIPF") & (frame["left out"] == "A")].iloc[0]
    assert np.isclose(mipf_a["mota"].value, 0.5) and mipf_a["runs"] == 3  # b's own MOTA on A
    sort_c = frame[(frame["method"] == "SORT") & (frame["left out"] == "C")].iloc[0]
    assert sort_c["setting"] == "-" and np.isclose(sort_c["mota"].value, 0.3)
    assert "A: box=b, B: box=a, C: box=a" in table.note
    # MIPF on the left-out sequences: 0.5 (A at b), 0.4 (B at a), 0.2 (C at a); SORT 0.55, 0.35, 0.3
    assert table.note.endswith("MOTA ranges over the sequences: MIPF 0.2 to 0.5; SORT 0.3 to 0.55.")
