"""What a request may ask of this machine (replication.runner.bounds): local workers within the cores, particles
and runs within the memory, each refused in one line before anything is allocated; a huge forced request
counted before its runs are built and listed with its progress; and how an interrupted runner ends."""

import gc
import signal
import subprocess
import sys
import time

import pytest
from conftest import PROJECT_ROOT

from replication.errors import ConfigError
from replication.runner import bounds, config, execute as execute_module
from replication.runner.bounds import (
    CORES_MULTIPLE, PARTICLE_BYTES, RUN_BYTES, check_particles, check_runs, check_workers, largest_particle_count,
    usable_cores,
)
from replication.runner.config import expand
from replication.runner.execute import execute
from replication.runner.preflight import check_machine
from replication.runner.store import Store

# The command line in-process; on exit, whether the numerical stack and joblib (every local backend's
# executor) had been imported by then: a refusal before them started no worker.
PROBE = (
    "import atexit, sys; atexit.register(lambda: print('imported:', sorted({'numpy', 'joblib'} & set(sys.modules))));"
    "from replication.cli import main; main(sys.argv[1:])"
)


def probe(tmp_path, *args):
    out = [f"store={tmp_path / 'experiments'}", f"reports={tmp_path / 'reports'}", "outside_project=true"]
    return subprocess.run([sys.executable, "-c", PROBE, *out, *args, "progress=false"], cwd=PROJECT_ROOT,
                          capture_output=True, text=True, timeout=120)


def assert_refused(result, tmp_path, *named):
    assert result.returncode == 2, result.stderr
    assert len(result.stderr.strip().splitlines()) == 1 and "Traceback" not in result.stderr, result.stderr
    assert all(name in result.stderr for name in named), result.stderr
    assert not (tmp_path / "experiments").exists() and not (tmp_path / "reports").exists()


def test_more_local_workers_than_the_cores_allow_are_refused_before_any_is_started(tmp_path):
    result = probe(tmp_path, "experiment=hspf_ungm", f"n_jobs={CORES_MULTIPLE * usable_cores() + 1}")
    assert_refused(result, tmp_path, f"n_jobs={CORES_MULTIPLE * usable_cores() + 1:,} local workers",
                   "n_jobs_beyond_cores=true")
    assert "imported: []" in result.stdout  # neither numpy nor joblib: no executor, no worker


def test_as_many_workers_as_the_cores_allow_or_confirmed_or_on_a_cluster_pass(make_cfg):
    check_workers(CORES_MULTIPLE * usable_cores(), beyond_cores=False)
    check_workers(-1, beyond_cores=False)
    check_workers(100_000, beyond_cores=True)
    with pytest.raises(ConfigError, match="n_jobs_beyond_cores"):
        check_machine(make_cfg("hspf_ungm", "n_jobs=100000"))
    check_machine(make_cfg("hspf_ungm", "n_jobs=100000", "n_jobs_beyond_cores=true"))
    # a cluster's workers are its own: n_jobs does not count there
    check_machine(make_cfg("hspf_ungm", "n_jobs=100000", "parallel.backend=dask", "parallel.address=tcp://h:8786"))


def test_a_particle_count_that_cannot_fit_is_refused_in_one_line_before_anything_heavy(tmp_path):
    result = probe(tmp_path, "experiment=hspf_ungm", "scale=quick", "experiment.methods.PF.n_particles=10000000000")
    assert_refused(result, tmp_path, "experiment.methods.PF.n_particles = 10,000,000,000: at least",
                   "of memory is available")
    assert "imported: []" in result.stdout


def test_the_particle_estimate_is_a_lower_bound_over_the_workers_running_at_once(monkeypatch):
    monkeypatch.setattr(bounds, "available_memory", lambda: 10 * 2**30)
    experiment = {"model": {"steps": 60},
                  "methods": {"PF": {"n_particles": 500, "sweep": {"n_particles": [100, 30_000_000]}},
                              "grid": {"n_points": 1601}}}
    assert largest_particle_count(experiment, "experiment") == (30_000_000, "experiment.methods.PF.sweep.n_particles")
    fits = 10 * 2**30 // PARTICLE_BYTES  # particles that fit in one worker
    check_particles({"methods": {"PF": {"n_particles": fits}}}, n_jobs=1)
    with pytest.raises(ConfigError) as refused:
        check_particles({"methods": {"PF": {"n_particles": fits // 2 + 1}}}, n_jobs=2)  # two workers at once
    assert str(refused.value) == (f"experiment.methods.PF.n_particles = {fits // 2 + 1:,}: at least 10.0 GiB needed "
                                  f"({PARTICLE_BYTES} bytes a particle at least, in each of 2 worker(s) at once); "
                                  "10.0 GiB of memory is available")
    check_particles({"methods": {"PF": {"n_particles": fits // 2}}}, n_jobs=2)
    check_runs("experiment.runs.quick", 10 * 2**30 // RUN_BYTES)
    with pytest.raises(ConfigError, match=r"experiment.runs.quick: 10,485,761 runs: at least 10.0 GiB needed"):
        check_runs("experiment.runs.quick", 10 * 2**30 // RUN_BYTES + 1)


def test_a_forced_run_count_that_cannot_fit_is_refused_before_any_run_is_built(make_cfg, monkeypatch):
    built = []
    monkeypatch.setattr(config, "Run", lambda *args: built.append(args))
    cfg = make_cfg("hspf_ungm", "scale=quick", "force=true", "experiment.runs.quick=1000000000")
    with pytest.raises(ConfigError) as refused:
        expand(cfg)
    assert str(refused.value).startswith("experiment.runs.quick = 1,000,000,000 per condition x 3 conditions: "
                                         "3,000,000,000 runs: at least 2.8 TiB needed")
    assert built == []  # counted, not listed


def test_a_forced_large_request_shows_its_progress_while_its_runs_are_listed_and_checked(make_cfg, tmp_path,
                                                                                          monkeypatch, capsys):
    for module in (config, execute_module):
        monkeypatch.setattr(module, "MANY_RUNS", 6)  # as 100,000 runs would
    runs = expand(make_cfg("hspf_ungm", "scale=quick", "experiment.runs.quick=2", "progress=true"))
    assert "hspf_ungm: listing its runs: 100%" in capsys.readouterr().err
    store = Store(tmp_path / "store", "hspf_ungm")
    for run in runs:  # all stored: execute checks the store, then has nothing to run
        store.write_failure(run, "stand-in")
    assert execute(runs, store, n_jobs=1, progress=True) == 0
    assert "hspf_ungm: checking the store: 100%" in capsys.readouterr().err
    few = expand(make_cfg("hspf_ungm", "scale=quick", "experiment.runs.quick=1", "progress=true"))
    assert len(few) < 6 and "listing" not in capsys.readouterr().err  # a small request lists its runs unannounced


@pytest.mark.e2e  # a subprocess computing a run
def test_a_run_out_of_memory_beyond_the_lower_bound_is_one_line(tmp_path):
    """HSPF's harmony search holds an N x N table: 100,000 particles pass the linear bound, then need 75 GiB."""
    result = probe(tmp_path, "experiment=hspf_ungm", "scale=quick", "experiment.runs.quick=1",
                   "experiment.methods.HSPF.n_particles=100000", "~experiment.methods.PF", "~experiment.methods.grid")
    assert result.returncode == 2, result.stderr
    assert len(result.stderr.strip().splitlines()) == 1 and "Traceback" not in result.stderr, result.stderr
    assert "hspf_ungm: a run ran out of memory (Unable to allocate" in result.stderr
    assert "fewer particles or fewer workers (n_jobs)" in result.stderr


def test_an_interrupted_runner_stops_its_children_and_exits_without_a_last_collection(tmp_path):
    """A child the clean-up left (a loky worker caught starting) gets SIGTERM; the heap is frozen, so that
    the exit skips the garbage collection of every object (seconds, with numba's kernels loaded)."""
    script = (
        "import gc, subprocess, sys\n"
        "from replication.runner.lifeline import exit_uncollected, stop_children\n"
        "child = subprocess.Popen([sys.executable, '-c', 'import time; time.sleep(120)'])\n"
        "stop_children()\n"
        "print('child:', child.wait(timeout=30))\n"
        "exit_uncollected()\n"
        "print('frozen:', gc.get_freeze_count() > 0)\n"
    )
    done = subprocess.run([sys.executable, "-c", script], cwd=PROJECT_ROOT, capture_output=True, text=True, timeout=60)
    assert done.stdout.split("\n")[:2] == [f"child: -{signal.SIGTERM.value}", "frozen: True"], done
    assert gc.get_freeze_count() == 0  # the suite's own process is left as it is


def test_a_process_tree_taken_before_its_root_ends_is_ended_whole():
    """What a local ray cluster's shutdown relies on: the tree of the processes it started, taken while its
    raylet lives, holds the agents the raylet started; once the raylet has gone they are orphans no walk from
    it finds, and :func:`end_within` kills each one still running after its grace, SIGTERM ignored or not."""
    from replication.runner import lifeline

    root = subprocess.Popen(["sh", "-c", "(trap '' TERM; sleep 120) & (trap '' TERM; sleep 120) & wait"])
    deadline = time.monotonic() + 30
    while len(tree := lifeline.descendants({root.pid})) < 5 and time.monotonic() < deadline:  # sh, 2 x (sh, sleep)
        time.sleep(0.05)
    assert len(tree) >= 3 and root.pid in tree, tree
    root.kill()
    root.wait()
    orphans = tree - {root.pid}
    assert lifeline.descendants({root.pid}) == set() and lifeline.descendants(orphans) >= orphans
    started = time.monotonic()
    lifeline.end_within(tree, 0.5)
    assert 0.5 <= time.monotonic() - started < 10
    while lifeline.descendants(orphans) and time.monotonic() < deadline:  # SIGKILLed: gone once the kernel reaps
        time.sleep(0.05)
    assert lifeline.descendants(orphans) == set()
