"""A store that checks what it reads: each record carries a checksum of its content, and its metrics' types and
declared ranges are checked; a record that fails is named in one line (its path and what failed), left out of
the report and set aside and recomputed by the run command; a record from before checksums is read as legacy."""

import json
import math
import subprocess
import sys

import pyarrow.parquet as pq
import pytest
from conftest import PROJECT_ROOT

from replication.evidence.quantities import QUANTITIES
from replication.runner.config import expand
from replication.runner.execute import TIMING_COLUMNS, execute
from replication.runner.failures import UNDEFINED
from replication.runner.store import CHECKSUM, CORRUPT_SUFFIX, Store, checksum, unsound

TINY = ("scale=quick", "experiment.runs.quick=2")


@pytest.fixture
def stored(make_cfg, tmp_path, capsys):
    """A store holding every run of a tiny hspf_ungm, and those runs."""
    runs = expand(make_cfg("hspf_ungm", *TINY))
    store = Store(tmp_path / "store", "hspf_ungm")
    assert execute(runs, store, n_jobs=1, backend="threading", progress=False) == len(runs)
    capsys.readouterr()
    return store, runs


def edit(store: Store, run, keep_checksum: bool = True, **values) -> dict:
    """Set ``values`` in ``run``'s stored file as a hand would (its checksum kept as it was, or recomputed for
    the new content: an edit that forges it); the record before the edit."""
    path = store.path(run)
    before = json.loads(path.read_text())
    record = {**{k: v for k, v in before.items() if k != CHECKSUM}, **values}
    claimed = before[CHECKSUM] if keep_checksum else checksum(record)
    path.write_text(json.dumps({**record, CHECKSUM: claimed}, indent=1, sort_keys=True))
    return before


def one_line(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    return lines[0]


def test_each_record_is_written_with_the_checksum_of_its_content(stored):
    store, runs = stored
    written = json.loads(store.path(runs[0]).read_text())
    claimed = written.pop(CHECKSUM)
    assert claimed.startswith("sha256:") and claimed == checksum(written)
    assert CHECKSUM not in store.read(runs[0])  # readers get the record, not its checksum
    store.path(runs[0]).write_text(json.dumps({**written, CHECKSUM: claimed}))  # laid out otherwise: still whole
    assert store.read(runs[0]) == written and not store.legacy


def test_an_edited_number_is_caught_named_left_out_and_recomputed(stored, capsys):
    store, runs = stored
    edited = store.path(runs[1])
    before = edit(store, runs[1], rmse=1.5)  # a plausible number: only the checksum can tell

    table = store.load(runs)
    assert runs[1].run_id not in set(table["run_id"]) and len(table) == len(runs) - 1  # the report never uses it
    line = one_line(capsys.readouterr().err)
    assert line.startswith("ignoring 1 corrupt result file(s)") and str(edited) in line and "checksum" in line

    assert execute(runs, store, n_jobs=1, backend="threading", progress=False) == 1  # that run alone
    line = one_line(capsys.readouterr().err)
    assert line.startswith("re-running 1 corrupt result file(s)") and str(edited) in line and "checksum" in line
    assert edited.with_name(edited.name + CORRUPT_SUFFIX).exists()  # set aside, kept for inspection
    again = store.read(runs[1])
    assert again["rmse"] == before["rmse"] != 1.5
    assert {k: v for k, v in again.items() if k not in TIMING_COLUMNS} == \
        {k: v for k, v in before.items() if k not in (*TIMING_COLUMNS, CHECKSUM)}
    assert len(store.load(runs)) == len(runs) and capsys.readouterr().err == ""


@pytest.mark.parametrize("values, reason", [
    ({"rmse": "abc"}, "rmse 'abc' is not a number"),
    ({"rmse": None}, "rmse None is not a number"),
    ({"resample_rate": 140.0}, "resample_rate 140.0 is outside its range [0, 100]"),
    ({"mean_ess": -3.0}, "mean_ess -3.0 is outside its range [0, inf]"),
    ({"wall_s": -0.5}, "wall_s -0.5 is outside its range [0, inf]"),
    ({"rmse": math.nan}, "rmse nan is not finite"),
    ({"degenerate_steps": True}, "degenerate_steps True is not a number"),
])
def test_a_wrong_type_or_range_is_one_line_naming_the_file_even_under_a_forged_checksum(stored, capsys, values,
                                                                                         reason):
    store, runs = stored
    edit(store, runs[2], keep_checksum=False, **values)
    assert len(store.load(runs)) == len(runs) - 1
    line = one_line(capsys.readouterr().err)
    assert f"{store.path(runs[2])} ({reason}" in line, line
    pending, notes = store.pending(runs)
    assert pending == [runs[2]] and len(notes) == 1 and reason in notes[0]


def test_a_metric_that_can_be_undefined_may_be_nan(stored):
    store, runs = stored
    assert "mean_ess" in UNDEFINED
    edit(store, runs[0], keep_checksum=False, mean_ess=math.nan)
    assert math.isnan(store.read(runs[0])["mean_ess"])


def test_a_legacy_record_is_read_with_its_types_checked_said_once_and_not_recomputed(stored, capsys):
    store, runs = stored
    for run in runs:  # as written before records carried a checksum
        record = json.loads(store.path(run).read_text())
        del record[CHECKSUM]
        store.path(run).write_text(json.dumps(record, indent=1, sort_keys=True))
    legacy = Store(store.directory.parent.parent, "hspf_ungm")

    assert execute(runs, legacy, n_jobs=1, backend="threading", progress=False) == 0  # nothing recomputed
    line = one_line(capsys.readouterr().err)
    assert line == (f"{len(runs)} stored record(s) in {legacy.directory} were written before records carried a "
                    "checksum: read as legacy, their types and ranges checked")
    assert len(legacy.load(runs)) == len(runs)
    assert capsys.readouterr().err == ""  # said once

    record = json.loads(store.path(runs[3]).read_text())
    store.path(runs[3]).write_text(json.dumps({**record, "rmse": "abc"}))  # a legacy record is still checked
    assert len(Store(store.directory.parent.parent, "hspf_ungm").load(runs)) == len(runs) - 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 2 and "rmse 'abc' is not a number" in err[0] and f"{len(runs) - 1} stored record(s)" in err[1]


def test_every_recorded_run_holds_its_declared_types_and_ranges():
    """The checks set aside no run the code computed: every metric of every run in the shipped record (which
    was drawn from stores) holds its declared type and range."""
    checked = 0
    for path in sorted((PROJECT_ROOT / "record").rglob("*.parquet")):
        if "curves" in path.parts:
            continue
        columns = [c for c in pq.read_schema(path).names if c in QUANTITIES or "[" in c]
        table = pq.read_table(path, columns=[*columns, "failure"]).to_pydict()
        for name in columns:
            for value, failure in zip(table[name], table["failure"]):
                if value is not None and failure is None:  # None: a metric other runs of the table have
                    assert unsound(name, value) is None, (path, name, value)
                    checked += 1
    assert checked > 1_000_000


@pytest.mark.e2e  # subprocesses: make test-e2e runs it, make test does not
def test_abc_in_a_record_is_one_line_in_report_and_run(stored, tmp_path):
    """``"rmse": "abc"`` in one record: ``pf-replicate report`` draws without it and names the file in one
    line; the run command names it in one line, sets it aside and computes that run again."""
    store, runs = stored
    edit(store, runs[4], rmse="abc")
    common = ["experiment=hspf_ungm", *TINY, f"store={tmp_path / 'store'}", f"reports={tmp_path / 'reports'}",
              "outside_project=true", "progress=false"]
    report = subprocess.run([sys.executable, "-m", "replication", "report", *common, "pdf=false", "n_jobs=1"],
                            cwd=PROJECT_ROOT, capture_output=True, text=True)
    assert report.returncode == 0 and "Traceback" not in report.stderr, report.stderr
    named = [line for line in report.stderr.splitlines() if str(store.path(runs[4])) in line]
    assert len(named) == 1 and "ignoring 1 corrupt result file(s)" in named[0] and "'abc'" in named[0]
    run = subprocess.run([sys.executable, "-m", "replication", *common], cwd=PROJECT_ROOT, capture_output=True,
                         text=True)
    assert run.returncode == 0 and "Traceback" not in run.stderr, run.stderr
    named = [line for line in run.stderr.splitlines() if str(store.path(runs[4])) in line]
    assert len(named) == 1 and named[0].startswith("re-running 1 corrupt result file(s)"), run.stderr
    assert "hspf_ungm: 1 runs computed" in run.stdout
    assert store.read(runs[4])["rmse"] != "abc"
