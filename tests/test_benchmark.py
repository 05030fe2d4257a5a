"""benchmarks/benchmark.py, as ``make replicate`` runs it: it ends, writes its tables with the machine's load beside
every timed ratio, and links its page from the reports' index (a script, so no timing is asserted)."""

import os
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

SCRIPT = Path(__file__).resolve().parent.parent / "benchmarks" / "benchmark.py"


@pytest.mark.e2e  # a subprocess of about a minute
def test_the_benchmark_script_writes_its_page_and_the_load_beside_each_ratio(tmp_path):
    done = subprocess.run([sys.executable, str(SCRIPT)], capture_output=True, text=True, timeout=600, cwd=tmp_path,
                          env={**os.environ, "REPLICATION_HOME": str(tmp_path)})
    assert done.returncode == 0, done.stderr[-2000:]
    out = tmp_path / "reports" / "benchmark"
    ratios = pd.read_csv(out / "ratios.csv")
    timed = ratios[ratios["target"] != "-"]
    assert len(timed) == 2 and timed["load_1m"].str.fullmatch(r"\d+\.\d\d \(\d+\.\d\d-\d+\.\d\d\)").all(), ratios
    assert pd.read_csv(out / "likelihood_rounds.csv")["load_1m"].ge(0).all()
    assert 'href="benchmark/index.html"' in (tmp_path / "reports" / "index.html").read_text()
