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
def test_the_benchmark_profiles_every_method_of_the_costliest_experiments_on_its_median_run(tmp_path):
    """A record of two experiments: the one costing more comes first, each of its methods (costliest first)
    profiled on its recorded run of median time, its time split by part and by library; a run this code
    does not make (an older record's) is named, never profiled; the profiles go to record/profile.json."""
    import json

    import pandas as pd

    sys.path.insert(0, str(SCRIPT.parent))
    try:
        from profile_run import runs_of, slowest_profiles, write_profile
    finally:
        sys.path.remove(str(SCRIPT.parent))
    runs = [r for r in runs_of("hspf_ungm", "paper") if r.repetition == 0]
    pf, hspf = (next(r for r in runs if r.method == m) for m in ("PF", "HSPF"))
    for name, rows in (("hspf_ungm", [("PF", "older", 0, 1.0), ("PF", pf.key, 0, 4.0), ("PF", pf.key, 1, 9.0),
                                      ("HSPF", hspf.key, 0, 5.0)]),
                       ("gps_qmcpf", [("PF", "not-a-key-of-this-code", 0, 2.0)])):
        (tmp_path / name).mkdir()
        pd.DataFrame(rows, columns=["method", "run_key", "repetition", "wall_s"]).to_parquet(
            tmp_path / name / "runs.parquet")
    table = slowest_profiles(tmp_path, count=2, top=3)
    assert list(zip(table["experiment"], table["method"])) == [("hspf_ungm", "PF"), ("hspf_ungm", "HSPF"),
                                                                ("gps_qmcpf", "PF")]
    first = table.iloc[0]
    assert first["run"] == pf.run_id and first["recorded s"] == 4.0  # the median of 1, 4 and 9 s
    assert first["share of the experiment's CPU"] == pytest.approx(14 / 19) and table.iloc[1]["run"] == hspf.run_id
    for family in ("part: ", "library: "):  # every second counted once in each split
        assert table.iloc[:2][[c for c in table.columns if c.startswith(family)]].fillna(0).sum(axis=1).tolist() \
            == pytest.approx([1.0, 1.0])
    assert first["part: filter"] > 0 and first["costliest functions (own s)"].count(";") == 2
    assert "not in this code's runs" in table.iloc[2]["run"]
    written = json.loads(write_profile(table, tmp_path).read_text())
    assert [m["method"] for m in written["methods"]] == ["PF", "HSPF", "PF"] and written["made"]["code_digest"]
    assert written["stages"] == ["frames", "likelihood", "filter", "scoring", "rest"]
    assert written["methods"][0]["cpu_minutes"] == pytest.approx(14 / 60, abs=0.05)
    assert written["methods"][0]["parts"]["filter"] == pytest.approx(first["part: filter"], abs=1e-3)
    assert written["methods"][2]["parts"] == {}


def test_a_profiles_time_goes_to_the_part_of_the_project_function_that_spent_it():
    """Own time of a project function to its part; a library function's to its callers' parts in proportion
    to the time it spent for each, followed up through a library caller; a cycle of library calls ends."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("profile_run", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    package = module.PACKAGE_DIR
    scene, weigh = (str(package / "scenes" / "synthetic.py"), 1, "frame"), (str(package / "smc" / "loop.py"), 1, "weigh")
    numpy_sum, inner = ("~", 0, "<sum>"), ("/x/site-packages/numpy/inner.py", 1, "helper")
    a, b = ("/x/lib/a.py", 1, "a"), ("/x/lib/b.py", 1, "b")

    class Stats:
        stats = {scene: (1, 1, 2.0, 4.0, {}), weigh: (1, 1, 1.0, 5.0, {}),
                 inner: (2, 2, 3.0, 4.0, {scene: (1, 1, 1.0, 1.0), weigh: (1, 1, 2.0, 3.0)}),
                 numpy_sum: (1, 1, 4.0, 4.0, {inner: (1, 1, 4.0, 4.0)}),
                 a: (1, 1, 1.0, 1.0, {b: (1, 1, 1.0, 1.0)}), b: (1, 1, 1.0, 1.0, {a: (1, 1, 1.0, 1.0)})}

    seconds = module.staged(Stats())
    # inner's 3 s and numpy's 4 s split 1:2 between the scene and the filter; a and b call only each other
    assert seconds == pytest.approx({"frames": 2.0 + 7 / 3, "filter": 1.0 + 14 / 3, "rest": 2.0})
    assert module.stage(str(package / "metrics" / "tracking.py")) == "scoring" and module.stage("~") is None
    assert module.stage(str(package / "runner" / "execute.py")) == "rest"
