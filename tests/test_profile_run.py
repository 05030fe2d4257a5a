"""benchmarks/profile_run.py: one run profiled, its time split by library; a request that names no run is one line."""

import re
import subprocess
import sys
from pathlib import Path

import pytest

SCRIPT = Path(__file__).resolve().parent.parent / "benchmarks" / "profile_run.py"


@pytest.mark.e2e
def test_profile_of_one_run_splits_its_time_by_library(tmp_path):
    done = subprocess.run([sys.executable, str(SCRIPT), "hspf_ungm", "PF", "--top", "5"],
                          capture_output=True, text=True, timeout=300, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    lines = done.stdout.splitlines()
    assert lines[0].startswith("PF__") and "s under the profiler" in lines[0]
    shares = dict((name, int(p)) for name, p in re.findall(r"(\w+) (\d+)%", lines[1]))
    assert "replication" in shares and 95 <= sum(shares.values()) <= 105  # every second counted once


@pytest.mark.e2e
def test_a_request_matching_no_run_says_so(tmp_path):
    done = subprocess.run([sys.executable, str(SCRIPT), "hspf_ungm", "PF", "N=123456"],
                          capture_output=True, text=True, timeout=300, cwd=tmp_path)
    assert done.returncode == 1
    assert done.stderr.strip() == "hspf_ungm at quick scale has no run of 'PF' matching 'N=123456'"


def test_profiled_functions_are_put_in_their_library():
    import importlib.util

    spec = importlib.util.spec_from_file_location("profile_run", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    assert module.part("~", "<cvtColor>") == "OpenCV"
    assert module.part("~", "<method 'reduce' of 'numpy.ufunc' objects>") == "numpy"
    assert module.part("/x/site-packages/pandas/core/frame.py", "__getitem__") == "pandas"
    assert module.part("/work/main/replication/smc/loop.py", "weigh") == "replication"
    assert module.part("~", "<built-in method builtins.len>") == "Python"


@pytest.mark.e2e
def test_the_benchmark_profiles_the_longest_run_of_the_costliest_method_of_the_costliest_experiments(tmp_path):
    """A record of two experiments: the one costing more comes first, profiled on its costliest method's
    longest run; a run this code does not make (an older record's) is named, never profiled."""
    import pandas as pd

    sys.path.insert(0, str(SCRIPT.parent))
    try:
        from benchmark import slowest_profiles
        from profile_run import runs_of
    finally:
        sys.path.remove(str(SCRIPT.parent))
    runs = [r for r in runs_of("hspf_ungm", "paper") if r.repetition == 0]
    pf, hspf = (next(r for r in runs if r.method == m) for m in ("PF", "HSPF"))
    for name, rows in (("hspf_ungm", [("PF", pf.key, 9.0), ("PF", "older", 1.0), ("HSPF", hspf.key, 5.0)]),
                       ("gps_qmcpf", [("PF", "not-a-key-of-this-code", 2.0)])):
        (tmp_path / name).mkdir()
        pd.DataFrame(rows, columns=["method", "run_key", "wall_s"]).to_parquet(tmp_path / name / "runs.parquet")
    table = slowest_profiles(tmp_path, count=2, top=3)
    first, second = table.iloc[0], table.iloc[1]
    assert (first["experiment"], first["method"], first["run"]) == ("hspf_ungm", "PF", pf.run_id)
    assert first["share of the experiment's CPU"] == pytest.approx(10 / 15) and first["recorded s"] == 9.0
    shares = first[[c for c in table.columns if c.endswith(" share")]].astype(float)
    assert shares.sum() == pytest.approx(1.0) and first["profiled s"] > 0
    assert first["costliest functions (own s)"].count(";") == 2
    assert second["experiment"] == "gps_qmcpf" and "not in this code's runs" in second["run"]
