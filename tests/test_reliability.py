"""Reliability of the runner: corrupt result files, interruption at any moment, concurrent writers,
and bad configs that fail at once in one line naming the key."""

import json
import os
import random
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from conftest import PROJECT_ROOT, SMALL
from joblib import Parallel, delayed

from replication.cli import check_request
from replication.errors import ConfigError
from replication.runner.config import expand
from replication.runner.backends import parallel_backend
from replication.runner.execute import TIMING_COLUMNS, execute, forecast, schedule
from replication.runner.store import CHECKSUM, Store
from replication.runner.validate import prepare

TINY = ("scale=quick", "experiment.runs.quick=2")
INTERRUPTED = re.compile(r"interrupted: (\d+) runs stored, rerun the same command to resume")


def deterministic_columns(frame: pd.DataFrame) -> pd.DataFrame:
    """Everything in a record except wall-clock timings, sorted by run."""
    return frame.drop(columns=list(TIMING_COLUMNS), errors="ignore").sort_values("run_id").reset_index(drop=True)


def stored_table(store_root: Path, experiment: str) -> pd.DataFrame:
    """The store's files as written (each record's checksum left out: it hashes the timings too)."""
    records = [json.loads(p.read_text()) for p in (store_root / experiment / "runs").glob("*.json")]
    return deterministic_columns(pd.DataFrame(records).drop(columns=CHECKSUM))


def command(experiment: str, store: Path, reports: Path, *args: str) -> list[str]:
    return [
        sys.executable, "-m", "replication", f"experiment={experiment}", *args,
        f"store={store}", f"reports={reports}", "outside_project=true", "progress=false",
    ]


def test_corrupt_result_files_are_set_aside_and_rerun(make_cfg, tmp_path, capsys):
    cfg = make_cfg("hspf_ungm", *TINY)
    runs = expand(cfg)
    reference = Store(tmp_path / "reference", cfg.experiment.name)
    execute(runs, reference, n_jobs=1, progress=False)

    store = Store(tmp_path / "store", cfg.experiment.name)
    assert execute(runs, store, n_jobs=1, progress=False) == len(runs)
    truncated, garbled, keyless, misplaced = (store.path(run) for run in runs[:4])
    truncated.write_text(truncated.read_text()[:100])  # a full disk or an interrupted copy
    garbled.write_bytes(os.urandom(300))
    record = json.loads(keyless.read_text())
    del record["run_key"], record["rmse"]
    keyless.write_text(json.dumps(record))  # valid JSON, but not a whole record
    misplaced.write_text(store.path(runs[5]).read_text())  # another run's record under this run's name
    capsys.readouterr()

    # the report reads around them: never aggregated, never a crash
    partial = store.load(runs)
    assert len(partial) == len(runs) - 4 and not set(partial["run_id"]) & {r.run_id for r in runs[:4]}
    err = capsys.readouterr().err
    assert err.startswith("ignoring 4 corrupt result file(s)") and len(err.strip().splitlines()) == 1

    assert execute(runs, store, n_jobs=1, progress=False) == 4  # exactly the four damaged runs
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1, err
    assert err.startswith("re-running 4 corrupt result file(s): "), err
    for path, reason in [(truncated, "invalid JSON"), (garbled, ""), (keyless, "missing run_key"),
                         (misplaced, "run_id")]:
        assert path.name in err and reason in err
        assert Path(f"{path}.corrupt").exists()  # kept for inspection, out of the way
    assert len(list(store.directory.glob("*.json"))) == len(runs)
    expected = deterministic_columns(reference.load(runs))
    pd.testing.assert_frame_equal(deterministic_columns(store.load(runs)), expected)
    assert capsys.readouterr().err == ""  # nothing corrupt left
    assert execute(runs, store, n_jobs=1, progress=False) == 0


def processes() -> dict[int, tuple[int, str]]:
    """Every process on this machine: its parent's pid and its state (R, S, Z...), from /proc."""
    table = {}
    for entry in Path("/proc").iterdir():
        try:
            if entry.name.isdigit():
                state, parent = (entry / "stat").read_text().rsplit(")", 1)[1].split()[:2]
                table[int(entry.name)] = (int(parent), state)
        except OSError:  # ended meanwhile
            pass
    return table


def descendants(pid: int) -> set[int]:
    """The processes ``pid`` started, and the ones they started, and so on."""
    table, found, parents = processes(), set(), {pid}
    while parents:
        parents = {child for child, (parent, _) in table.items() if parent in parents} - found
        found |= parents
    return found


def still_running(pids: set[int]) -> set[int]:
    table = processes()
    return {pid for pid in pids if pid in table and table[pid][1] != "Z"}


def assert_all_end(pids: set[int], within: float = 5.0) -> None:
    """Every one of ``pids`` ends within ``within`` seconds; any left are killed (not left to the suite)."""
    deadline = time.time() + within
    while still_running(pids) and time.time() < deadline:
        time.sleep(0.1)
    left = {pid: Path(f"/proc/{pid}/cmdline").read_bytes()[:120] for pid in still_running(pids)}
    for pid in left:
        os.kill(pid, signal.SIGKILL)
    assert not left, left


NEEDS_PROC = pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="reads the process table in /proc")


@pytest.mark.e2e  # a subprocess, a killed runner or a cluster: make test-e2e runs it, make test does not
@NEEDS_PROC
def test_a_request_says_its_size_and_rough_duration_before_it_starts(make_cfg, tmp_path):
    """How many runs, how many to compute, and about how long: the stored runs' wall times of each method and
    condition (their mean over every stored run where a condition has none) over the workers."""
    runs = expand(make_cfg("hspf_ungm", "scale=quick", "experiment.runs.quick=2"))
    store = Store(tmp_path / "store", "hspf_ungm")
    assert forecast(runs, runs, store, 2) == \
        f"hspf_ungm: {len(runs)} runs, {len(runs)} to compute (no stored run of it to time them by)"
    execute(runs[:3], store, n_jobs=1, backend="threading", progress=False)
    pending = store.pending(runs)[0]
    walls = {run.run_id: store.read(run)["wall_s"] for run in runs[:3]}
    same = {r.run_id: [walls[s.run_id] for s in runs[:3] if (s.method, s.condition) == (r.method, r.condition)]
            for r in pending}
    expected = sum(np.mean(same[r.run_id] or list(walls.values())) for r in pending) / 2
    said = forecast(runs, pending, store, 2)
    assert said.startswith(f"hspf_ungm: {len(runs)} runs, {len(pending)} to compute, about ")
    assert said.endswith("on 2 worker(s) (from 3 stored runs' times)")
    assert said.split("about ")[1].split(" on")[0] == f"{expected:.0f} s"


def test_a_full_disk_is_one_line_naming_the_store_and_keeps_what_was_stored(make_cfg, tmp_path, monkeypatch):
    """No space left mid-run: StoreFull names the folder and says the stored runs are kept (the command line
    prints it as one line); no temporary file is left, and the same command then completes the rest."""
    import errno

    import replication.atomic as atomic_module
    from replication.runner.store import StoreFull

    runs = expand(make_cfg("hspf_ungm", "scale=quick", "experiment.runs.quick=2"))
    store = Store(tmp_path / "store", "hspf_ungm")
    writes = []

    def filling(path, mode="r", *args, **kwargs):
        writes.append(path)
        if len(writes) > 2:
            raise OSError(errno.ENOSPC, "No space left on device", str(path))
        return open(path, mode, *args, **kwargs)

    monkeypatch.setattr(atomic_module, "open", filling, raising=False)
    with pytest.raises(StoreFull) as full:
        execute(runs, store, n_jobs=1, backend="threading", progress=False)
    message = str(full.value)
    assert message.startswith(f"{store.directory}: no space left on its disk") and "kept" in message
    assert "\n" not in message
    assert sum(store.has(run) for run in runs) == 2 and not list(store.directory.glob(".*.tmp"))
    monkeypatch.undo()
    assert execute(runs, store, n_jobs=1, backend="threading", progress=False) == len(runs) - 2


def test_runs_start_scene_by_scene_and_repetition_by_repetition(make_cfg):
    """The schedule keeps every run, puts one repetition's methods and particle counts together inside each
    scene (the runs a comparison pairs are computed close in time), and spreads each condition's runs over
    its scene's whole span."""
    runs = expand(make_cfg("ism_pf_particles", "scale=quick"))
    order = schedule(runs)
    assert sorted(r.run_id for r in order) == sorted(r.run_id for r in runs)
    keys = [(str(r.data_condition), r.repetition) for r in order]
    blocks = list(dict.fromkeys(keys))
    assert keys == sorted(keys, key=blocks.index)  # each (scene, repetition) one contiguous block
    repetitions = list(range(max(r.repetition for r in runs) + 1))
    assert [b[1] for b in blocks] == repetitions * 2 and len({b[0] for b in blocks}) == 2
    scene = [r for r in order if str(r.data_condition) == blocks[0][0]]
    positions = [i for i, r in enumerate(scene) if r.method == "PF" and str(r.condition).endswith("N=1100")]
    assert len(positions) == len(repetitions) and positions[-1] - positions[0] > len(scene) / 2  # spread over it


def test_sigint_sigterm_and_sigkill_at_random_moments_resume_to_the_same_table(make_cfg, tmp_path):
    """Ctrl-C at one random moment, SIGTERM at another, SIGKILL at a third, resume: the table of an
    uninterrupted run.  SIGTERM is handled as Ctrl-C, with status 143 (128 + 15), and leaves no process.

    A moment is "when the k-th run has landed, plus a random delay", k and the
    delay drawn from a seeded generator (RELIABILITY_SEED), so that on a fast or
    a loaded machine alike the signal falls while runs are in flight.
    """
    rng = random.Random(int(os.environ.get("RELIABILITY_SEED", "20261121")))
    args = ("scale=quick", "experiment.runs.quick=4", "experiment.model.sweep.steps=[10,25,50]", "n_jobs=2")
    runs = expand(make_cfg("ungm_horizon", *args))
    reference = Store(tmp_path / "reference", "ungm_horizon")
    execute(runs, reference, n_jobs=1, progress=False)
    store = tmp_path / "store"
    runs_dir = store / "ungm_horizon" / "runs"
    cmd = command("ungm_horizon", store, tmp_path / "reports", *args)

    def stored() -> int:
        return len(list(runs_dir.glob("*.json")))

    def start_and_signal(sig: int, landed: int) -> tuple[subprocess.Popen, set[int]]:
        """Start the command, wait until ``landed`` runs are stored and a random moment more, signal;
        return the process and the processes it had started."""
        process = subprocess.Popen(cmd, cwd=PROJECT_ROOT, start_new_session=True, text=True,
                                   stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        deadline = time.time() + 50
        while stored() < landed and process.poll() is None and time.time() < deadline:
            time.sleep(0.005)
        time.sleep(rng.uniform(0.0, 0.1))
        started = descendants(process.pid)
        if process.poll() is None and sig == signal.SIGTERM:
            os.kill(process.pid, sig)  # the runner alone, as kill <pid> does
        elif process.poll() is None:
            os.killpg(process.pid, sig)  # the whole group, as a terminal's Ctrl-C does
        return process, started

    def interrupted(sig: int, landed: int, status: int) -> int:
        """Interrupt a run with ``sig``: it exits with ``status`` and one line counting the runs stored."""
        process, started = start_and_signal(sig, landed)
        _, err = process.communicate(timeout=60)
        assert process.returncode == status, (process.returncode, err)
        assert "Traceback" not in err and len(err.strip().splitlines()) == 1, err
        match = INTERRUPTED.fullmatch(err.strip())
        assert match and int(match[1]) == stored(), err
        assert_all_end(started)
        return stored()

    after_sigint = interrupted(signal.SIGINT, rng.randint(1, len(runs) // 4), status=130)
    assert 1 <= after_sigint < len(runs)
    after_sigterm = interrupted(signal.SIGTERM, rng.randint(after_sigint + 1, max(after_sigint + 1, len(runs) // 2)),
                                status=143)
    assert after_sigint < after_sigterm < len(runs), (after_sigint, after_sigterm, len(runs))

    landed = rng.randint(after_sigterm + 1, max(after_sigterm + 1, 3 * len(runs) // 4))
    process, _ = start_and_signal(signal.SIGKILL, landed=landed)
    process.communicate(timeout=60)
    assert process.returncode == -signal.SIGKILL
    after_sigkill = stored()
    assert after_sigterm < after_sigkill < len(runs), (after_sigterm, after_sigkill, len(runs))

    resumed = subprocess.run(cmd, cwd=PROJECT_ROOT, capture_output=True, text=True, timeout=120)
    assert resumed.returncode == 0, resumed.stderr
    assert f"{len(runs) - after_sigkill} runs computed, {after_sigkill} already stored" in resumed.stdout
    typed = [c for c in reference.load(runs) if c.startswith("condition.")]  # added on loading, not stored
    pd.testing.assert_frame_equal(stored_table(store, "ungm_horizon"),
                                  deterministic_columns(reference.load(runs).drop(columns=typed)))


@pytest.mark.e2e  # a subprocess, a killed runner or a cluster: make test-e2e runs it, make test does not
@NEEDS_PROC
@pytest.mark.parametrize(
    "experiment, args",
    [
        # its own workers, busy: two short runs, then two long ones (minutes, were they not stopped)
        ("ungm_horizon", ("experiment.runs.quick=2", "~experiment.methods.grid",
                          "experiment.methods.PF.sweep.n_particles=[100]", "experiment.model.sweep.steps=[10,1000000]")),
        # its companion (also:), and the companion's workers
        ("hspf_ungm", ("experiment.runs.quick=1", "experiment.report={}", "+experiment.also=[ungm_horizon]")),
    ],
    ids=["workers", "companion"],
)
def test_no_worker_or_companion_outlives_a_killed_runner(tmp_path, experiment, args):
    """``kill -9`` of the runner once a run of ungm_horizon is stored: within seconds, every process it
    started (loky workers and resource trackers, a companion experiment and the companion's) has ended."""
    store, watched = tmp_path / "store", "ungm_horizon"
    with open(tmp_path / "output", "w") as output:  # not a pipe: orphans holding it would block the reader
        process = subprocess.Popen(command(experiment, store, tmp_path / "reports", "scale=quick", "n_jobs=2", *args),
                                   cwd=PROJECT_ROOT, stdout=output, stderr=subprocess.STDOUT)
    started, deadline = set(), time.time() + 120
    while not any((store / watched / "runs").glob("*.json")) and process.poll() is None and time.time() < deadline:
        started |= descendants(process.pid)
        time.sleep(0.02)
    started |= descendants(process.pid)
    assert process.poll() is None, (tmp_path / "output").read_text()
    assert len(started) >= 4, started  # two workers and two resource trackers at least
    process.kill()
    process.wait()
    assert_all_end(started)


@pytest.mark.parametrize("backend", ["loky", "dask"])
def test_local_workers_leave_ctrl_c_to_the_parent(backend):
    """A worker waiting for its next run must not turn the group's SIGINT into a traceback."""
    if backend == "dask":
        pytest.importorskip("distributed", reason="distributed is not installed (pip install -e '.[test]')")
    with parallel_backend(backend, n_jobs=2):
        ignored = Parallel()(delayed(lambda: signal.getsignal(signal.SIGINT) == signal.SIG_IGN)() for _ in range(4))
    assert ignored == [True] * 4
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler  # the parent still gets Ctrl-C


@pytest.mark.e2e  # a subprocess, a killed runner or a cluster: make test-e2e runs it, make test does not
def test_two_processes_writing_one_store_leave_one_record_per_run(make_cfg, tmp_path):
    runs = expand(make_cfg("hspf_ungm", *TINY))
    reference = Store(tmp_path / "reference", "hspf_ungm")
    execute(runs, reference, n_jobs=1, progress=False)
    store = tmp_path / "shared"
    cmd = command("hspf_ungm", store, tmp_path / "reports", *TINY, "n_jobs=1")
    processes = [
        subprocess.Popen(cmd, cwd=PROJECT_ROOT, text=True, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
        for _ in range(2)
    ]
    outputs = [p.communicate(timeout=120) for p in processes]
    for process, (out, err) in zip(processes, outputs):
        assert process.returncode == 0, err
    computed = [int(re.search(r"(\d+) runs computed", out)[1]) for out, _ in outputs]
    assert sum(computed) >= len(runs)  # between them every run, some possibly twice
    files = sorted(p.name for p in (store / "hspf_ungm" / "runs").iterdir())
    assert files == sorted(Store(store, "hspf_ungm").path(r).name for r in runs)  # no temporaries, no duplicates
    pd.testing.assert_frame_equal(stored_table(store, "hspf_ungm"), deterministic_columns(reference.load(runs)))


OTB_SCENE = ("experiment=ism_pf_otb", "experiment.model.sweep.scene=[Girl]")


@pytest.mark.parametrize(
    "args, message",
    [
        (("experiment=hspf_ungm", "+experiment.methods.PF.bogus=1"), "'bogus'"),
        (("experiment=hspf_ungm", "experiment.methods.PF.n_particles=abc"),
         "experiment.methods.PF.n_particles must be an integer, got 'abc'"),
        (("experiment=hspf_ungm", "experiment.runs.quick=-1"), "experiment.runs.quick must be a positive integer"),
        (("experiment=hspf_ungm", "experiment.model.Q=abc"), "experiment.model.Q must be a number, got 'abc'"),
        (("experiment=hspf_ungm", "experiment.runs.quick=1000000000"),
         "experiment.runs.quick = 1,000,000,000 runs per condition, against the paper's 100: pass force=true"),
        ((*OTB_SCENE, "+experiment.scenes.Girl.root=/no/such/otb"), "experiment.scenes.Girl.root: no folder"),
    ],
)
def test_bad_configs_fail_at_once_in_one_line_naming_the_key(cli, tmp_path, args, message):
    """(What makes them quick, no heavy import before a config error, is tests/test_bad_input.py's.)"""
    result = cli(*args, "scale=quick", timeout=300)
    assert result.returncode == 2, result.stderr
    assert message in result.stderr
    assert "Traceback" not in result.stderr and len(result.stderr.strip().splitlines()) == 1, result.stderr
    assert not (tmp_path / "experiments").exists()  # no work started


@pytest.mark.parametrize(
    "experiment, overrides, key",
    [
        ("hspf_ungm", ("+experiment.methods.PF.bogus=1",), "bogus"),
        ("hspf_ungm", ("experiment.methods.PF.n_particles=abc",), "n_particles"),
        ("gps_qmcpf", ("experiment.methods.PF.sweep.n_particles=[100,abc]",), "sweep.n_particles"),
        ("hspf_ungm", ("experiment.runs.quick=-1",), "runs.quick"),
        ("ism_pf_otb", ("+experiment.scenes.Girl.root=/no/such/otb",), "scenes.Girl.root"),
        ("ism_pf_otb", ("~experiment.scenes.Girl.name",), "scenes.Girl.name"),
        ("hspf_ungm", ("parallel.backend=spark",), "parallel.backend"),
        ("hspf_ungm", ("parallel.address=tcp://localhost:8786",), "parallel.address"),
        ("hspf_ungm", ("+parallel.adress=tcp://localhost:8786",), "parallel.adress"),
        ("hspf_ungm", ("n_jobs=abc",), "n_jobs"),
        ("hspf_ungm", ("n_jobs=0",), "n_jobs"),
    ],
)
def test_config_checks_fail_before_any_scene_is_built(make_cfg, monkeypatch, experiment, overrides, key):
    """What would make a check slow is building a scene (reading a sequence's frames, drawing a synthetic one):
    every check fails before the first is built."""
    from replication.scenes import factory

    def built(spec):
        raise AssertionError(f"a scene was built before the check: {spec.get('name')}")

    monkeypatch.setattr(factory, "build_sequence", built)
    factory._cached.cache_clear()
    cfg = make_cfg(experiment, "scale=quick", *overrides)
    with pytest.raises(ConfigError) as error:
        prepare(cfg)
    assert key in str(error.value) and "\n" not in str(error.value)


@pytest.mark.parametrize(
    "argv, message",
    [
        (["experiment=hspf_ungm", "n_job=4"], "unknown key 'n_job'"),
        (["experiment=hspf_ungm", "experiment.methods.PF.bogus=1"], "unknown key 'experiment.methods.PF.bogus'"),
        (["experiment=hspf_ungm", "n_jobs=[1"], "no viable alternative"),
    ],
)
def test_hydra_override_errors_are_one_line(argv, message):
    """(That they come before any heavy import is tests/test_bad_input.py's, in a fresh interpreter.)"""
    with pytest.raises(ConfigError) as error:
        check_request(argv)
    assert message in str(error.value) and "\n" not in str(error.value)


def test_every_shipped_experiment_passes_the_checks(make_cfg):
    for experiment in ("gps_qmcpf", "ism_pf_otb", "bis_pf", "fusion_pf"):
        runs, _, settings = prepare(make_cfg(experiment, *SMALL))
        assert runs and settings == ("loky", 2, None)
    assert prepare(make_cfg("hspf_ungm", *SMALL, "parallel.backend=threading"))[2] == ("threading", 2, None)



GRID_RUN = """
from hydra import compose, initialize_config_dir
from replication.paths import CONF_DIR
from replication.runner.config import expand
from replication.runner.execute import perform
with initialize_config_dir(config_dir=str(CONF_DIR), version_base="1.3"):
    cfg = compose("config", overrides=["experiment=ungm_horizon", "scale=paper"])
run = [r for r in expand(cfg) if r.method == "grid" and "T=100" in str(r.condition) and r.repetition == 74][0]
print(perform(run)["rmse"].hex())
"""


@pytest.mark.e2e
def test_a_run_gives_the_same_bits_whatever_blas_threads_its_process_has():
    """The grid filter's products at T = 100 are big enough for OpenBLAS to split them between threads,
    which sums them in another order: a run computed in the main process (n_jobs=1, every core) gave
    another last bit than in a one-thread worker until perform set one BLAS thread wherever it runs."""
    results = set()
    for threads in ("1", "2"):
        env = {**os.environ, "OPENBLAS_NUM_THREADS": threads, "OMP_NUM_THREADS": threads}
        done = subprocess.run([sys.executable, "-c", GRID_RUN], capture_output=True, text=True, env=env,
                              cwd=PROJECT_ROOT, timeout=300)
        assert done.returncode == 0, done.stderr
        results.add(done.stdout.split()[-1])
    assert len(results) == 1, results


MIL_RUN = """
import json, sys
import cv2
from hydra import compose, initialize_config_dir
from replication.paths import CONF_DIR
from replication.runner.config import expand
from replication.runner.execute import TIMING_COLUMNS, _performed, perform
with initialize_config_dir(config_dir=str(CONF_DIR), version_base="1.3"):
    cfg = compose("config", overrides=["experiment=hspf", "scale=quick"])
run = [r for r in expand(cfg) if r.method == "MIL" and str(r.condition) == "scene=Girl"][0]
if sys.argv[1] == "pool":
    cv2.setNumThreads(2)
    record = _performed(run)
else:
    record = perform(run)
record["per_frame"].pop("seconds")
# the machine's details say how many threads the BLAS had as the run ended: the two arms differ there by design
print(cv2.getNumThreads(), json.dumps({k: v for k, v in record.items() if k not in (*TIMING_COLUMNS, "machine_detail")},
                                      sort_keys=True))
"""


@pytest.mark.e2e
def test_a_run_computes_on_one_opencv_thread_and_gives_what_a_pool_of_them_gives():
    """perform leaves OpenCV one thread (its pool spun on every core of every worker), and a run that
    uses OpenCV's threads most, MIL's samples, gives the same record on a pool of two as on one: so the
    runs recorded before the limit stand."""
    outputs = {}
    for arm in ("pool", "perform"):
        done = subprocess.run([sys.executable, "-c", MIL_RUN, arm], capture_output=True, text=True,
                              cwd=PROJECT_ROOT, timeout=300)
        assert done.returncode == 0, done.stderr
        outputs[arm] = done.stdout.strip().splitlines()[-1].split(" ", 1)
    assert outputs["pool"][0] == "2" and outputs["perform"][0] == "1"
    assert outputs["pool"][1] == outputs["perform"][1]


def test_an_interrupted_multiverse_counts_every_stored_run_of_the_request_once(make_cfg, tmp_path):
    """The interrupted line of a multiverse stopped in a later universe counts the runs its earlier universes
    stored too (it counted only the step it was in: "0 runs stored" after a whole universe), each run once
    where universes share it, across the experiments' stores."""
    from replication.cli import stored

    runs = {name: expand(make_cfg(name, *TINY)) for name in ("hspf_ungm", "ungm_horizon")}
    stores = {name: Store(tmp_path, name) for name in runs}
    for name, count in {"hspf_ungm": 3, "ungm_horizon": 2}.items():
        for run in runs[name][:count]:
            stores[name].path(run).parent.mkdir(parents=True, exist_ok=True)
            stores[name].path(run).write_text("{}")
    held = [(stores["hspf_ungm"], runs["hspf_ungm"]), (stores["ungm_horizon"], runs["ungm_horizon"]),
            (stores["hspf_ungm"], runs["hspf_ungm"][1:4])]  # a later universe sharing two stored runs
    assert stored(held) == 5
    assert stored(held[2:]) == 2
