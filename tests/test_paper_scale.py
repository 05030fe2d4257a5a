"""Paper-scale checks of the UNGM results (slow: deselected by ``make test``, run by ``make test-all``)."""

import pytest

from replication.evidence.tables.comparison import excess_over_floor
from replication.runner.config import expand
from replication.runner.execute import execute
from replication.runner.store import Store


@pytest.mark.slow
def test_bootstrap_pf_with_500_particles_is_at_the_bayes_floor(make_cfg, tmp_path):
    """100 paired runs: the PF's excess RMSE over the point-mass filter is small and not negative."""
    cfg = make_cfg("gps_qmcpf", "scale=paper")
    runs = expand(cfg)
    store = Store(tmp_path / "store", cfg.experiment.name)
    execute(runs, store, n_jobs=2, progress=False)
    records = store.load(runs)
    assert len(records) == len(runs)
    assert set(records.groupby(["method", "condition"]).size()) == {100}  # every cell has the paper's 100 runs
    excess = excess_over_floor(records, ["grid"])
    estimate = excess[("PF", "N=500")]
    assert estimate.runs == 100
    assert estimate.low > -0.05  # the floor is a floor: no filter beats it on average
    assert estimate.value < 0.25  # 500 particles are enough for this 1-D model
    floor = records[records["method"] == "grid"]["rmse"].mean()
    assert 3.5 < floor < 5.5, floor
