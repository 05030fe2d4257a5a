"""The paper-scale record as a read-only layer beneath the store (``replication.record.layer``): a paper-scale
request reads the runs the record holds as this code computes them (its SHA-256 checked), computes only the
rest, says how many came from the record, and ``dry_run=true`` says it all before anything runs."""

import subprocess
import sys

import pytest

from conftest import PROJECT_ROOT
from replication.errors import ConfigError
from replication.evidence.schema import Summary
from replication.record.layer import beneath, missing, said
from replication.record.manifest import Manifest
from replication.record.runs import Record
from replication.record.write import write, write_experiment
from replication.runner.config import expand
from replication.runner.execute import execute
from replication.runner.store import Store

UNGM = ("scale=paper", "experiment.runs.paper=2")
# the command line in a process where computing any run fails the command (every run goes through _records)
NOTHING_COMPUTED = ("import sys, replication.runner.execute as e\n"
                    "def computed(*args, **kwargs):\n    raise AssertionError('a run was computed')\n"
                    "e._records = computed\n"
                    "from replication.cli import main; main(sys.argv[1:])")


@pytest.fixture
def recorded(make_cfg, tmp_path):
    """hspf_ungm at the paper scale, 2 runs of each of its 3 methods, computed in a store of their own
    (``computed``) and recorded from it into ``record``; the request's own store is empty."""
    cfg = make_cfg("hspf_ungm", *UNGM, f"record={tmp_path / 'record'}")
    runs = expand(cfg)
    execute(runs, Store(tmp_path / "computed", "hspf_ungm"), n_jobs=1, progress=False)
    write([cfg], tmp_path / "computed", tmp_path / "record")
    return cfg, runs


def test_the_runs_the_record_holds_are_read_from_it_and_only_the_rest_computed(make_cfg, tmp_path, recorded, capsys):
    cfg, runs = recorded
    store = Store(tmp_path / "experiments", "hspf_ungm")
    held = beneath(cfg, runs, store)
    assert held.recorded == {run.run_id for run in runs} and held.computed(runs) == []
    ours, theirs = (table.set_index("run_id").sort_index() for table in
                    (held.load(runs), Store(tmp_path / "computed", "hspf_ungm").load(runs)))
    assert list(ours.index) == list(theirs.index) and ours["rmse"].equals(theirs["rmse"])
    assert said("hspf_ungm", [held], len(runs)) == (
        f"hspf_ungm: 6 of 6 runs read from the record ({tmp_path / 'record'}, SHA-256 checked), not computed "
        "(skip_recorded=false computes them)")
    more = make_cfg("hspf_ungm", "scale=paper", "experiment.runs.paper=3", f"record={tmp_path / 'record'}")
    runs3 = expand(more)  # a repetition more than recorded: only it is computed
    assert {run.repetition for run in beneath(more, runs3, store).computed(runs3)} == {2}
    execute(runs3[:1], store, n_jobs=1, progress=False)  # the store on top: what it holds is read from it
    assert runs3[0].run_id not in beneath(more, runs3, store).recorded
    for off in ("scale=quick", "skip_recorded=false"):
        other = make_cfg("hspf_ungm", *UNGM, off, f"record={tmp_path / 'record'}")
        assert not beneath(other, expand(other), store).recorded, off
    nowhere = make_cfg("hspf_ungm", *UNGM, f"record={tmp_path / 'nowhere'}")  # an installed copy: no record
    assert not beneath(nowhere, runs, store).recorded
    said_missing = missing(nowhere)
    assert said_missing.startswith(f"no record at {tmp_path / 'nowhere'}") and "record=<its path>" in said_missing
    assert missing(cfg) is None
    path = tmp_path / "record" / "hspf_ungm" / "runs.parquet"  # a damaged record is not read, and said once
    path.write_bytes(path.read_bytes() + b"\0")
    capsys.readouterr()
    assert not beneath(cfg, runs, store).recorded and not beneath(cfg, runs, store).recorded
    error = capsys.readouterr().err
    assert error.count("\n") == 1 and f"{path} does not have the SHA-256" in error, error


@pytest.mark.e2e  # a subprocess, a killed runner or a cluster: make test-e2e runs it, make test does not
def test_a_paper_scale_request_for_a_recorded_experiment_computes_nothing_and_says_so(recorded, tmp_path):
    command = [sys.executable, "-c", NOTHING_COMPUTED, "experiment=hspf_ungm", f"record={tmp_path / 'record'}",
               f"store={tmp_path / 'experiments'}", f"reports={tmp_path / 'reports'}", "outside_project=true",
               "progress=false", "scale=paper"]

    def request(*args):
        return subprocess.run([*command, *args], cwd=PROJECT_ROOT, capture_output=True, text=True, timeout=300)

    plan = request("experiment.runs.paper=3", "dry_run=true")
    assert plan.returncode == 0, plan.stderr
    lines = plan.stdout.splitlines()
    assert lines[0] == "hspf_ungm: 9 runs at the paper scale: 0 stored, 6 read from the record, 3 to compute"
    assert lines[1].startswith("hspf_ungm: 9 runs, 3 to compute, about ") and "(from 6 stored runs' times)" in lines[1]
    assert lines[2].startswith("hspf_ungm: a dry run: nothing computed or written")
    assert not (tmp_path / "experiments").exists() and not (tmp_path / "reports").exists()
    done = request("experiment.runs.paper=2")
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines()[:2] == [
        f"hspf_ungm: 6 of 6 runs read from the record ({tmp_path / 'record'}, SHA-256 checked), not computed "
        "(skip_recorded=false computes them)",
        f"hspf_ungm: 0 runs computed, 0 already stored in {tmp_path / 'experiments' / 'hspf_ungm' / 'runs'}, "
        "6 read from the record"]
    assert not list((tmp_path / "experiments").rglob("*.json"))  # nothing copied into the store
    summary = Summary.read(tmp_path / "reports" / "hspf_ungm" / "summary.json")
    assert (summary.scale, summary.n_records, summary.n_runs) == ("paper", 6, 6)
    lacking = request("experiment.runs.paper=3")  # the probe bites: a run the record lacks is computed
    assert lacking.returncode != 0 and "a run was computed" in lacking.stderr


def test_the_record_keeps_the_rows_of_the_runs_read_from_it(make_cfg, tmp_path, recorded):
    cfg, runs = recorded
    record = tmp_path / "record"
    before = Manifest.read(record)
    assert write([cfg], tmp_path / "experiments", record) == before  # nothing new in the store: as recorded
    more = make_cfg("hspf_ungm", "scale=paper", "experiment.runs.paper=3", f"record={record}")
    runs3, store = expand(more), Store(tmp_path / "experiments", "hspf_ungm")
    assert execute(beneath(more, runs3, store).computed(runs3), store, n_jobs=1, progress=False) == 3
    entry = write([more], tmp_path / "experiments", record).experiments["hspf_ungm"]
    assert entry.runs == 9 and entry.before is not None
    again = Record(record).load(runs3).set_index("run_id").sort_index()
    first = Store(tmp_path / "computed", "hspf_ungm").load(runs).set_index("run_id")
    assert again.loc[first.index, "rmse"].equals(first["rmse"])  # the recorded rows kept as they were


def test_curves_are_drawn_from_the_record_only_for_the_runs_it_holds_whole(make_cfg, tmp_path):
    """demo_scene's curve figure: from the record's table where it recorded exactly the runs asked for; where
    some runs are computed, neither that table nor a record written without their series."""
    synthetic = ("scale=paper", "experiment.model.sweep.scene=[synthetic_head]", f"record={tmp_path / 'record'}")
    one = make_cfg("demo_scene", *synthetic, "experiment.runs.paper=1")
    execute(expand(one), Store(tmp_path / "computed", "demo_scene"), n_jobs=1, progress=False)
    write([one], tmp_path / "computed", tmp_path / "record")
    store = Store(tmp_path / "experiments", "demo_scene")
    assert set(beneath(one, expand(one), store).curves) == {"error_curve"}
    two = make_cfg("demo_scene", *synthetic, "experiment.runs.paper=2")
    runs = expand(two)
    held = beneath(two, runs, store)
    assert held.curves == {} and len(held.recorded) == 1
    execute(held.computed(runs), store, n_jobs=1, progress=False)
    assert "per_frame" not in held.load(runs) and len(held.load(runs)) == 2  # as the record keeps them
    with pytest.raises(ConfigError, match="demo_scene: 1 of 2 runs are in the record only, which keeps no "
                                          "per-frame series for its curve figure 'error_curve'"):
        write_experiment(two, tmp_path / "experiments", tmp_path / "record")
