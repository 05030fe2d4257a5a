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
