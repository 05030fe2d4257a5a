"""Runs whose numbers are not finite fail with their reason stored, are counted by the run command and
the report, left out of every statistic, and not computed again."""

import dataclasses
import json
import math

import numpy as np
import pandas as pd
import pytest

from replication.runner.config import expand
from replication.runner.execute import perform
from replication.runner.failures import FAILED_STATUS, UNDEFINED, failure

NAN, INF = math.nan, math.inf


@pytest.mark.parametrize(
    "record, reason",
    [
        ({"rmse": 1.0, "runs": 3, "sequence": "Girl", "ess": [None, 2.0]}, None),
        ({"rmse": 1.0, **{metric: NAN for metric in UNDEFINED}, "fps": INF}, None),  # undefined, legitimately
        ({"rmse": NAN, "mean_ess": NAN}, "not finite: rmse=nan"),
        ({"rmse": np.float32(INF)}, "not finite: rmse=inf"),
        ({"mean_cle": 1.0, "per_frame": {"cle": [1.0, 2.0], "box": [[[1.0, -INF]]]}}, "not finite: per_frame.box=-inf"),
        ({"per_frame": {"cle": [NAN]}, "a": NAN, "b": -INF, "c": 1.0, "d": NAN, "e": NAN},
         "not finite: a=nan, b=-inf, d=nan and 2 more"),  # the metrics first, then the series
    ],
)
def test_a_record_fails_on_a_number_that_is_not_finite_and_may_be_undefined(record, reason):
    assert failure(record) == reason


def test_a_run_stopped_by_nan_log_weights_fails_with_the_reason(make_cfg):
    run = next(r for r in expand(make_cfg("hspf_ungm", "scale=quick", "experiment.runs.quick=1")) if r.method == "PF")
    assert perform(dataclasses.replace(run, model={**run.model, "Q": NAN})) == {
        "run_id": run.run_id, "failure": "log-weights contain NaN or +inf"}


@pytest.mark.e2e  # a subprocess, a killed runner or a cluster: make test-e2e runs it, make test does not
def test_failed_runs_are_recorded_counted_and_not_rerun(cli, tmp_path):
    """A variance so large that the grid filter's posterior overflows to NaN: its runs fail, the others
    are stored; the command says so and exits 3, the report counts them, a rerun computes nothing."""
    args = ("experiment=hspf_ungm", "scale=quick", "experiment.runs.quick=2", "experiment.model.Q=1e200", "label=huge_q")
    line = "failed: 2 runs of hspf_ungm: not finite: rmse=nan"
    result = cli(*args)
    assert result.returncode == FAILED_STATUS, result.stderr
    assert result.stderr.strip().splitlines()[-1] == line, result.stderr
    assert "6 runs computed" in result.stdout
    runs = tmp_path / "experiments" / "hspf_ungm" / "runs"
    failed = sorted(runs.glob("*.failed"))
    assert [p.name.split("__")[0] for p in failed] == ["grid", "grid"] and len(list(runs.glob("*.json"))) == 4
    assert {p.read_text() for p in failed} == {"not finite: rmse=nan\n"}

    report = tmp_path / "reports" / "quick" / "hspf_ungm@huge_q"  # not the experiment as shipped: its own report
    assert "2 runs failed: not finite: rmse=nan" in (report / "index.html").read_text()
    assert json.loads((report / "summary.json").read_text())["failed"] == {"not finite: rmse=nan": 2}
    table = pd.read_csv(report / "table1_rmse.csv")  # PF and HSPF from their 2 runs each, no grid row
    assert len(table) == 2 and not table["method"].str.contains("grid|point-mass").any() and (table["runs"] == 2).all()
    assert len(pd.read_csv(report / "runs.csv")) == 4
    assert "4 / 6 (2 failed)" in (tmp_path / "reports" / "index.html").read_text()

    written = [p.stat().st_mtime_ns for p in failed]
    again = cli(*args)
    assert again.returncode == FAILED_STATUS and again.stderr.strip().splitlines()[-1] == line, again.stderr
    assert "0 runs computed, 6 already stored" in again.stdout
    assert [p.stat().st_mtime_ns for p in failed] == written


def test_the_check_reads_series_as_arrays_and_finds_what_an_item_by_item_walk_finds():
    """failure() checks a list of numbers as one array; on nested records with None, strings, ints, booleans,
    ragged lists and non-finite numbers anywhere, it gives the reason an item-by-item walk gives."""
    def walk(value, key=""):
        if isinstance(value, dict):
            for name, item in value.items():
                yield from walk(item, f"{key}.{name}" if key else str(name))
        elif isinstance(value, (list, tuple)):
            for item in value:
                yield from walk(item, key)
        elif isinstance(value, (float, np.floating)):
            yield key, float(value)

    def by_walk(record):
        bad = {}
        for key, value in walk(record):
            if not math.isfinite(value) and key not in UNDEFINED:
                bad.setdefault(key, value)
        return sorted(bad.items(), key=lambda item: "." in item[0])

    rng = np.random.default_rng(0)
    odd = [NAN, INF, -INF, None, "x", 3, True, 2.5]
    for _ in range(300):
        def item(depth):
            roll = rng.random()
            if depth < 3 and roll < 0.3:
                return [item(depth + 1) for _ in range(int(rng.integers(0, 4)))]
            if depth < 3 and roll < 0.4:
                return {f"k{i}": item(depth + 1) for i in range(int(rng.integers(1, 3)))}
            if roll < 0.55:
                return rng.normal(size=(int(rng.integers(1, 4)), 3)).tolist()  # a regular series
            return odd[int(rng.integers(len(odd)))] if roll < 0.8 else float(rng.normal())
        record = {f"m{i}": item(0) for i in range(4)}
        expected = by_walk(record)
        reason = failure(record)
        assert (reason is None) == (not expected)
        if expected:
            assert reason.startswith("not finite: " + f"{expected[0][0]}={expected[0][1]}")


def test_a_run_during_which_numba_compiles_is_timed_again(make_cfg, monkeypatch):
    """The first use of a kernel in a fresh checkout compiles it (seconds): that run is computed again and
    its second record kept, so its times are the method's, not the compiler's; a run that compiles
    nothing is computed once."""
    from numba import njit

    from replication.runner import execute

    run = expand(make_cfg())[0]
    calls, kernel = [], njit(lambda x: x + 1.0)  # no cache: compiled at its first call

    class Compiling:  # a task whose first run compiles a new kernel
        def run(self, run):
            calls.append(kernel(1.0))
            return {"rmse": 1.0, "calls": len(calls)}

    monkeypatch.setattr(execute.TASKS[run.task], "run", Compiling().run)
    assert perform(run)["calls"] == 2 and len(calls) == 2  # compiled during the first: computed again
    assert perform(run)["calls"] == 3 and len(calls) == 3  # compiled already: computed once
