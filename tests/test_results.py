"""replication.load_runs: an experiment's stored runs as one tidy table (issue 19, item 3)."""

import pandas as pd

import replication
from replication.runner.config import expand
from replication.runner.execute import execute
from replication.runner.store import Store

SMALL = ("scale=quick", "experiment.runs.quick=2", "experiment.model.steps=10")


def test_load_runs_gives_a_column_per_parameter_and_metric(make_cfg, tmp_path):
    cfg = make_cfg("gps_qmcpf", *SMALL)
    runs = expand(cfg)
    execute(runs, Store(tmp_path / "experiments", "gps_qmcpf"), n_jobs=1, progress=False)
    table = replication.load_runs("gps_qmcpf", "quick", f"store={tmp_path / 'experiments'}", *SMALL[1:])
    assert len(table) == len(runs)
    pf = table[table["method"] == "PF"]
    assert sorted(pf["method.n_particles"].unique()) == sorted(
        {r.method_params["n_particles"] for r in runs if r.method == "PF"})  # the swept N, as numbers
    assert pd.api.types.is_numeric_dtype(table["rmse"]) and (table["model.steps"] == 10).all()  # a fixed parameter
    assert "per_frame" not in table


def test_load_runs_of_nothing_stored_is_empty(tmp_path):
    assert replication.load_runs("gps_qmcpf", "quick", f"store={tmp_path / 'none'}").empty
