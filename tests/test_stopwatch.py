"""The two clocks of a run: waiting accrues wall time only, working accrues both, and blocks add up."""

import time

import numpy as np

from replication.record.manifest import _load, _summed
from replication.stopwatch import Stopwatch, load_1m


def test_a_thread_that_waits_spends_wall_time_but_no_cpu_time():
    with Stopwatch() as stopwatch:
        time.sleep(0.05)
    assert stopwatch.wall >= 0.05
    assert stopwatch.cpu < 0.5 * stopwatch.wall  # sleeping is not work, however loaded the machine


def test_blocks_add_up_and_the_last_is_kept():
    stopwatch, walls = Stopwatch(), []
    for n in (10_000, 200_000):
        with stopwatch:
            sum(i * i for i in range(n))
        walls.append(stopwatch.last_wall)
    assert stopwatch.wall == sum(walls) and walls[1] > 0
    assert stopwatch.cpu > 0


def test_the_load_is_a_non_negative_number_where_the_system_says():
    load = load_1m()
    assert load is None or load >= 0


def test_the_manifest_sums_cpu_time_and_takes_the_median_and_largest_load():
    rows = [{"cpu_s": 1.25, "load_1m": 2.0}, {"cpu_s": 2.5, "load_1m": 0.5}, {"cpu_s": None, "load_1m": 7.0}, {}]
    assert _summed(rows, "cpu_s") == 3.8  # 3.75 rounded to 0.1 s
    assert _load(rows) == (2.0, 7.0)
    assert _summed([{}], "cpu_s") is None and _load([{}]) is None


def test_every_time_a_run_records_is_left_out_of_the_determinism_checks():
    """A run's numbers are compared across jobs, resumptions and machines without its times (which no two
    computations share): every machine-dependent quantity a run records is a timing column."""
    from replication.evidence.quantities import QUANTITIES
    from replication.runner.execute import TIMING_COLUMNS

    published_only = {"time", "run_time", "time_per_frame"}  # the papers' names for their tables' cells
    timed = {name for name, q in QUANTITIES.items() if q.machine_dependent} - published_only
    assert timed <= set(TIMING_COLUMNS), timed - set(TIMING_COLUMNS)
    assert {"cpu_s", "cpu_ms_per_frame", "cpu_ms_per_step", "cpu_filter_s", "load_1m"} <= set(TIMING_COLUMNS)


def test_the_reference_work_is_timed_once_per_interval_and_again_after_it(monkeypatch):
    from replication import stopwatch

    assert stopwatch.reference_ms(repeats=1) > 0
    measured, clock = [], [100.0]
    monkeypatch.setattr(stopwatch.time, "monotonic", lambda: clock[0])
    every = stopwatch._Every(lambda: measured.append(clock[0]) or float(len(measured)), 60.0)
    assert every() == 1.0 and every() == 1.0  # the first call measures, the next within a minute reuses it
    clock[0] += 59.9
    assert every() == 1.0
    clock[0] += 0.1
    assert every() == 2.0 and measured == [100.0, 160.0]


def test_a_reading_on_a_column_its_runs_never_recorded_is_not_testable_and_says_why():
    """The record's runs predate the CPU clock: the CPU-time reading of hspf.cost is not testable on them, and
    says which column is missing, while the wall-clock reading beside it is tested."""
    import pandas as pd

    from replication.evidence.claims import evaluate
    from replication.evidence.verdict import Outcome

    noise = np.random.default_rng(4).normal(0.0, 0.02, (10, 2))
    rows = [{"method": m, "condition": "", "data_condition": "", "repetition": r, "ms_per_step": t + noise[r, i]}
            for r in range(10) for i, (m, t) in enumerate((("HSPF", 1.2), ("PF", 1.0)))]
    results = evaluate("hspf_ungm", {"name": "hspf_ungm", "paper": "hspf"}, pd.DataFrame(rows), {})["hspf.cost"]
    cpu = next(result for name, result in results.items() if name.endswith("on thread CPU time"))
    assert cpu.verdict.outcome is Outcome.NOT_TESTABLE and "no run recorded cpu_ms_per_step" in cpu.verdict.why
    wall = results["HSPF no more than 50 % slower than PF per step, paired by run (this machine)"]
    assert wall.verdict.outcome is not Outcome.NOT_TESTABLE
