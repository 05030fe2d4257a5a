"""replication.load_runs and load_frames: an experiment's stored runs and frames as tidy tables (issue 19, item 3)."""

import json

import numpy as np
import pandas as pd
from mot_cases import needs_mot

import replication
from replication.runner.config import expand
from replication.runner.execute import execute
from replication.runner.results import load_frames, write
from replication.runner.store import Store

SMALL = ("scale=quick", "experiment.runs.quick=2", "experiment.model.steps=10")
# bis_pf's 3123 test (three balls) cut to 12 frames, MIPF only, its N swept
BALLS = ("scale=quick", "experiment.runs.quick=1", "experiment.model.sweep.scene=[exp1_3123]",
         "experiment.scenes.exp1_3123.frames=12", "experiment.scenes.exp1_3123.evaluation.from_frame=2",
         "+experiment.methods.MIPF.sweep.n_particles=[20,40]")
# bis_pf Experiment 6 on the first 20 frames of PETS09-S2L1, SORT only
PETS = ("scale=quick", "experiment.runs.quick=1", "experiment.scenes.exp6_pets09.last.quick=20")


def run_stored(make_cfg, tmp_path, experiment, overrides, methods=None):
    """Run ``experiment`` (those ``methods`` only) into the temporary store; its runs and their records."""
    runs = [r for r in expand(make_cfg(experiment, *overrides)) if methods is None or r.method in methods]
    store = Store(tmp_path / "experiments", experiment)
    execute(runs, store, n_jobs=1, progress=False)
    return runs, store.load(runs)


def test_load_runs_gives_a_column_per_parameter_and_metric(make_cfg, tmp_path):
    runs, _ = run_stored(make_cfg, tmp_path, "gps_qmcpf", SMALL)
    table = replication.load_runs("gps_qmcpf", "quick", f"store={tmp_path / 'experiments'}", *SMALL[1:])
    assert len(table) == len(runs)
    pf = table[table["method"] == "PF"]
    assert sorted(pf["method.n_particles"].unique()) == sorted(
        {r.method_params["n_particles"] for r in runs if r.method == "PF"})  # the swept N, as numbers
    assert pd.api.types.is_numeric_dtype(table["rmse"]) and (table["model.steps"] == 10).all()  # a fixed parameter
    assert "per_frame" not in table


def test_load_runs_of_nothing_stored_is_empty(tmp_path):
    assert replication.load_runs("gps_qmcpf", "quick", f"store={tmp_path / 'none'}").empty
    assert load_frames("gps_qmcpf", "quick", f"store={tmp_path / 'none'}").empty


def test_tracking_runs_and_frames_are_tidy_and_match_the_records(make_cfg, tmp_path):
    runs, records = run_stored(make_cfg, tmp_path, "bis_pf", BALLS, methods={"MIPF"})
    args = ("bis_pf", "quick", f"store={tmp_path / 'experiments'}", *BALLS[1:])
    table = replication.load_runs(*args)
    assert len(table) == len(runs) == 2
    assert sorted(table["method.n_particles"]) == [20, 40]  # swept
    assert (table["method.resampling"] == "multinomial").all() and (table["model.scene_spec.frames"] == 12).all()
    assert all(track == [0, 1, 2] for track in table["model.scene_spec.track"])  # fixed, a list kept a list
    assert list(table.columns[:6]) == ["experiment", "method", "condition", "repetition", "run_key", "run_id"]

    frames = load_frames(*args)
    for record in records.to_dict("records"):
        rows = frames[frames["run_key"] == record["run_key"]]
        series, n_targets = record["per_frame"], len(record["per_frame"]["targets"])
        assert len(rows) == record["frames"] * n_targets == 12 * 3  # a row per frame of the sequence and target
        assert (rows.groupby("target")["frame"].apply(list) == [list(range(12))] * 3).all()
        assert (rows[["experiment", "method", "condition", "repetition"]].drop_duplicates().to_dict("records")
                == [{k: record[k] for k in ("experiment", "method", "condition", "repetition")}])
        assert (rows["scene"] == "exp1_3123").all()
        np.testing.assert_array_equal(rows[["x", "y", "w", "h"]].to_numpy().reshape(12, 3, 4), series["box"])
        assert (rows["target"].to_numpy().reshape(12, 3) == series["targets"]).all()
        for name in ("cle", "iou", "dx", "dy", "ess"):
            expected = np.array(series[name], dtype=float)  # ess is None at frame 0
            np.testing.assert_array_equal(rows[name].to_numpy().reshape(12, 3), np.repeat(expected[:, None], 3, 1))


def test_parquet_and_csv_hold_the_same_tables(make_cfg, tmp_path):
    run_stored(make_cfg, tmp_path, "bis_pf", BALLS, methods={"MIPF"})
    table = replication.load_runs("bis_pf", "quick", f"store={tmp_path / 'experiments'}", *BALLS[1:])
    write(table, tmp_path / "runs")
    parquet, csv = pd.read_parquet(tmp_path / "runs.parquet"), tmp_path / "runs.csv"
    assert parquet.to_csv(index=False) == csv.read_text()
    numbers = table.select_dtypes("number").columns
    pd.testing.assert_frame_equal(pd.read_csv(csv)[numbers], table[numbers], check_dtype=False)
    pd.testing.assert_frame_equal(parquet[numbers], table[numbers])  # the same numbers, the same types
    assert [json.loads(t) for t in parquet["model.scene_spec.track"]] == [[0, 1, 2]] * 2

    mixed = pd.DataFrame({"track": [[0, 2], "all"], "n": [1, 2]})  # one Parquet column cannot hold both
    write(mixed, tmp_path / "mixed", csv=False)
    assert pd.read_parquet(tmp_path / "mixed.parquet")["track"].tolist() == ["[0, 2]", "all"]
    assert not (tmp_path / "mixed.csv").exists()


@needs_mot
def test_mot_frames_are_the_records_tracks(make_cfg, tmp_path):
    _, records = run_stored(make_cfg, tmp_path, "bis_pf_pets", PETS, methods={"SORT"})
    frames = load_frames("bis_pf_pets", "quick", f"store={tmp_path / 'experiments'}", *PETS[1:])
    assert len(records) == 1 and (frames["scene"] == "exp6_pets09").all()
    tracks = frames[["frame", "id", "x", "y", "w", "h"]].to_numpy(float)
    np.testing.assert_array_equal(tracks, records["tracks"].iloc[0])  # a row per frame and track, as stored
    assert frames["frame"].between(1, 20).all() and frames["frame"].nunique() <= 20
