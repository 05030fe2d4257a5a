"""Beyond one machine: the dask and ray backends (clusters started from their command lines on the loopback,
as on real machines) and the threading backend store the same records as loky, a multiverse's too; a run lost
with a killed worker is computed again, and nothing else; a local cluster listens on the loopback alone; one
SIGTERM stops every local backend and everything it started."""

import ipaddress
import os
import secrets
import shutil
import signal
import subprocess
import tempfile
import time
from pathlib import Path

import pandas as pd
import pytest
from conftest import PROJECT_ROOT
from test_reliability import (
    INTERRUPTED, NEEDS_PROC, command, descendants, deterministic_columns, processes, still_running, stored_table,
)

from replication.runner.config import expand
from replication.runner.backends import CLUSTER_PACKAGES
from replication.runner.execute import execute
from replication.runner.loopback import dask_cluster, ray_cluster
from replication.runner.store import Store

TINY = ("scale=quick", "experiment.runs.quick=2")


# clusters and subprocesses: make test-e2e runs them, make test does not; one xdist worker runs them all (make test's
# --dist loadgroup), so two ray heads or dask clusters never start at once
pytestmark = [pytest.mark.e2e, pytest.mark.xdist_group("clusters")]


@pytest.fixture(scope="module")
def cluster():
    pytest.importorskip("distributed", reason="distributed is not installed (pip install -e '.[test]')")
    with dask_cluster(2) as address:
        yield address


def loky_records(runs: list, tmp_path, experiment: str = "hspf_ungm") -> pd.DataFrame:
    """The reference: the runs' records computed by the default local backend."""
    loky = Store(tmp_path / "loky", experiment)
    assert execute(runs, loky, n_jobs=2, backend="loky", progress=False) == len(runs)
    return deterministic_columns(loky.load(runs))


def assert_command_line_resumes_on_cluster(cli, tmp_path, runs, expected, *cluster, timeout, env=None):
    """The command line pointed at a cluster (``cluster``: its overrides) with two runs already
    stored: those are not sent again, and the store ends with the reference records."""
    partial = Store(tmp_path / "experiments", "hspf_ungm")  # the store ``cli`` writes to
    execute(runs[:2], partial, n_jobs=1, progress=False)
    result = cli("experiment=hspf_ungm", *TINY, *cluster, timeout=timeout, env=env)
    assert result.returncode == 0, result.stderr
    assert f"{len(runs) - 2} runs computed, 2 already stored" in result.stdout
    pd.testing.assert_frame_equal(deterministic_columns(partial.load(runs)), expected)


def test_dask_cluster_stores_the_same_records_as_loky(make_cfg, cli, tmp_path, cluster):
    runs = expand(make_cfg("hspf_ungm", *TINY))
    expected = loky_records(runs, tmp_path)

    dask = Store(tmp_path / "dask", "hspf_ungm")
    assert execute(runs, dask, backend="dask", address=cluster, progress=False) == len(runs)
    pd.testing.assert_frame_equal(deterministic_columns(dask.load(runs)), expected)

    assert_command_line_resumes_on_cluster(
        cli, tmp_path, runs, expected,
        "parallel.backend=dask", f"parallel.address={cluster}", timeout=120,
    )


# two short runs and two of several seconds, one per worker: one of those is lost with its worker.  Four runs,
# all sent at once (joblib sends 2 x the workers before it sizes batches by their times: never both long together)
LOST = ("scale=quick", "experiment.runs.quick=1", "~experiment.methods.grid",
        "experiment.methods.PF.sweep.n_particles=[100]", "experiment.model.sweep.steps=[10,11,150000,150001]")


def test_a_run_lost_with_its_killed_dask_worker_is_computed_again_and_nothing_else(make_cfg, tmp_path):
    """``kill -9`` of a dask worker in mid-run (as the kernel's out-of-memory killer does): its nanny starts a
    new one, the scheduler sends the lost run again, and the command ends as usual.  Exactly one run starts
    after the kill (its record's ``computed_at - wall_s``); the runs stored before it are not written again; and
    the store ends with loky's records."""
    from distributed import Client

    runs = expand(make_cfg("ungm_horizon", *LOST))
    store = tmp_path / "store"
    with dask_cluster(2) as address, Client(address, timeout=60) as client:
        pids = client.run(os.getpid)  # each worker process's, the nanny's child
        runner = subprocess.Popen(command("ungm_horizon", store, tmp_path / "reports", *LOST, "parallel.backend=dask",
                                          f"parallel.address={address}"),
                                  cwd=PROJECT_ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        deadline = time.monotonic() + 300
        while not (len(stored := sorted(store.glob("ungm_horizon/runs/*.json"))) == 2
                   and all(client.processing().values())):  # the short two stored, both long runs under way
            assert runner.poll() is None and time.monotonic() < deadline, runner.communicate()
            time.sleep(0.05)
        before = {path: path.stat().st_mtime_ns for path in stored}
        time.sleep(1.0)  # computed_at has whole seconds
        killed_at = time.time()
        os.kill(pids[next(iter(client.processing()))], signal.SIGKILL)
        out, err = runner.communicate(timeout=300)
    assert runner.returncode == 0, err
    assert "4 runs computed" in out, out
    assert {path: path.stat().st_mtime_ns for path in before} == before
    records = Store(store, "ungm_horizon").load(runs)
    started = pd.to_datetime(records["computed_at"]).map(pd.Timestamp.timestamp) - records["wall_s"]
    assert (started > killed_at).sum() == 1, records[["run_id", "computed_at", "wall_s"]]
    pd.testing.assert_frame_equal(deterministic_columns(records), loky_records(runs, tmp_path, "ungm_horizon"))


def cmdline(pid: int) -> str:
    try:
        return Path(f"/proc/{pid}/cmdline").read_bytes().replace(b"\0", b" ").decode(errors="replace")
    except OSError:  # ended meanwhile
        return ""


def loky_workers(runner: subprocess.Popen) -> set[int]:
    """The runner's loky worker processes (not loky's resource tracker)."""
    return {pid for pid in descendants(runner.pid) if "popen_loky_posix" in cmdline(pid)}


def ray_workers(runner: subprocess.Popen) -> set[int]:
    """The ray worker processes computing a joblib batch (ray titles them ``ray::PoolActor.run_batch``)."""
    return {pid for pid in processes() if cmdline(pid).startswith("ray::PoolActor.run_batch")}


# loky returns each run as it ends, so the two short runs are stored while the long ones are under way; ray's
# joblib backend returns a worker's batch (here a short and a long run) whole, so none is stored before the end
@NEEDS_PROC
@pytest.mark.parametrize("backend, workers, stored_first", [("loky", loky_workers, 2), ("ray", ray_workers, 0)])
def test_a_worker_killed_in_mid_run_ends_the_command_in_one_line_and_its_rerun_computes_what_was_lost(
        backend, workers, stored_first, make_cfg, request, tmp_path):
    """loky and ray give up on the runs of a worker killed with ``kill -9`` (dask sends them again: above):
    the command ends with one line saying how many runs are stored and to rerun it, the runs stored before
    the kill are kept as they are, and the same command computes the lost ones and nothing else, to loky's
    records."""
    cluster, env = (), None
    if backend == "ray":
        cluster = ("parallel.backend=ray", f"parallel.address={request.getfixturevalue('ray_head')}")
        env = request.getfixturevalue("ray_env")
    runs = expand(make_cfg("ungm_horizon", *LOST))
    store = tmp_path / "store"
    asked = command("ungm_horizon", store, tmp_path / "reports", *LOST, *cluster)
    runner = subprocess.Popen(asked, cwd=PROJECT_ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                              text=True, env=env)
    deadline = time.monotonic() + 300
    while not (len(list(store.glob("ungm_horizon/runs/*.json"))) == stored_first and len(workers(runner)) == 2):
        assert runner.poll() is None and time.monotonic() < deadline, runner.communicate()
        time.sleep(0.05)
    time.sleep(1.0)  # both long runs under way
    before = {path: path.stat().st_mtime_ns for path in sorted(store.glob("ungm_horizon/runs/*.json"))}
    os.kill(min(workers(runner)), signal.SIGKILL)
    out, err = runner.communicate(timeout=300)
    assert runner.returncode == 2, (out, err)
    said = [line for line in err.splitlines() if line.startswith("error: ")]
    assert len(said) == 1 and said[0].startswith("error: ungm_horizon: a worker process ended in mid-run"), err
    assert f"the {len(before)} runs finished before it are stored: rerun the same command" in said[0], err

    again = subprocess.run(asked, cwd=PROJECT_ROOT, capture_output=True, text=True, env=env, timeout=300)
    assert again.returncode == 0, again.stderr
    assert f"{len(runs) - len(before)} runs computed, {len(before)} already stored" in again.stdout, again.stderr
    assert {path: path.stat().st_mtime_ns for path in before} == before  # kept as they were, not computed again
    pd.testing.assert_frame_equal(deterministic_columns(Store(store, "ungm_horizon").load(runs)),
                                  loky_records(runs, tmp_path, "ungm_horizon"))


@pytest.fixture(scope="module")
def ray_tmpdir():
    """Ray's sessions and its file naming the last cluster started, in a folder of the tests' own (short:
    ray's socket paths must fit in 107 characters), removed after; not /tmp/ray, where a later
    ``ray.init()`` would find a cluster long gone."""
    folder = tempfile.mkdtemp(prefix="ray", dir="/tmp")
    yield folder
    shutil.rmtree(folder, ignore_errors=True)


@pytest.fixture(scope="module")
def ray_env(ray_tmpdir):
    """The environment of every process that starts or joins the test's ray head node: token
    authentication (recent ray's default; ``RAY_AUTH_MODE=token``, as a user's command sets it)
    under a token of the test's own. Ray reads ``RAY_AUTH_TOKEN`` before any token file
    (``RAY_AUTH_TOKEN_PATH``, then ``~/.ray/auth_token``), so the test neither needs a token in the
    home directory (a machine that never ran ray has none) nor writes one there."""
    return {**os.environ, "RAY_AUTH_MODE": "token", "RAY_AUTH_TOKEN": secrets.token_hex(32),
            "RAY_TMPDIR": ray_tmpdir}


@pytest.fixture(scope="module")
def ray_head(ray_env):
    """A ray head node of 2 CPUs started as on a real cluster (``ray start --head``); its address.
    It and the command that joins it authenticate with the token in ``ray_env``."""
    pytest.importorskip("ray", reason="ray is not installed (pip install -e '.[test]')")
    with ray_cluster(2, ray_env) as address:
        yield address


def test_ray_cluster_stores_the_same_records_as_loky(make_cfg, cli, tmp_path, ray_env, ray_head):
    """The command line pointed at the cluster, through ray's joblib backend (which returns whole
    batches): the same records as loky, and the runs already stored are not sent again."""
    runs = expand(make_cfg("hspf_ungm", *TINY))
    assert_command_line_resumes_on_cluster(
        cli, tmp_path, runs, loky_records(runs, tmp_path),
        "parallel.backend=ray", f"parallel.address={ray_head}",
        timeout=180, env=ray_env,
    )


MULTIVERSE = ("scale=quick", "experiment.multiverse.runs.quick=2")  # hspf_readings: 2 experiments x its universes


def every_record(store: Path) -> pd.DataFrame:
    """Every run a store holds, of every experiment (a multiverse's universes among them), as written."""
    return pd.concat([stored_table(store, folder.parent.name) for folder in sorted(store.glob("*/runs"))],
                     ignore_index=True)


@pytest.fixture(scope="module")
def multiverse_by_loky(tmp_path_factory) -> pd.DataFrame:
    store = tmp_path_factory.mktemp("loky") / "store"
    done = subprocess.run(command("hspf_readings", store, store.parent / "reports", *MULTIVERSE), cwd=PROJECT_ROOT,
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    return every_record(store)


@pytest.mark.parametrize("backend, head", [("dask", "cluster"), ("ray", "ray_head")])
def test_a_multiverse_on_a_cluster_started_from_its_command_lines_stores_loky_s_records(
        backend, head, request, tmp_path, multiverse_by_loky):
    """``make readings ADDRESS=...``'s command: every universe's runs as loky computes them on this machine."""
    env = local_backend_env(backend, request)
    store = tmp_path / "store"
    done = subprocess.run(command("hspf_readings", store, tmp_path / "reports", *MULTIVERSE, f"parallel.backend={backend}",
                                  f"parallel.address={request.getfixturevalue(head)}"),
                          cwd=PROJECT_ROOT, capture_output=True, text=True, timeout=600, env=env)
    assert done.returncode == 0, done.stderr
    assert "universes of" in done.stdout, done.stdout
    pd.testing.assert_frame_equal(every_record(store), multiverse_by_loky)


@pytest.mark.parametrize("backend", ["threading", "dask", "ray"])
def test_other_local_backends_store_the_same_records_as_loky(make_cfg, tmp_path, monkeypatch, backend, request):
    """threading, and dask and ray with no address (a local cluster of n_jobs workers), against loky.

    ray: ``RAY_ADDRESS=local`` makes ``ray.init()`` start that local cluster rather than join one
    already running on this machine (the ``ray_head`` node, when this module runs whole: it did so,
    unseen, while both shared the token in ``~/.ray/auth_token``), and the cluster gets the test's
    own token, which ``ray.init()`` would otherwise write into ``~/.ray/auth_token``. Token mode is
    left for ``ray.init()`` to turn on, as for any new local cluster: it sets ``RAY_AUTH_MODE`` in
    this process and reloads its configuration (set here, after ``import ray``, it would go unseen
    by this process but not by the cluster's, and the two would not agree); that is undone after."""
    package = CLUSTER_PACKAGES.get(backend)
    if package:
        pytest.importorskip(package, reason=f"{package} is not installed (pip install -e '.[test]')")
    if backend == "ray":
        monkeypatch.setenv("RAY_ADDRESS", "local")
        monkeypatch.setenv("RAY_TMPDIR", request.getfixturevalue("ray_tmpdir"))
        monkeypatch.setenv("RAY_AUTH_TOKEN", secrets.token_hex(32))
        if "RAY_AUTH_MODE" not in os.environ:
            monkeypatch.setenv("RAY_AUTH_MODE", "")  # recorded as unset, so removed again at teardown
            monkeypatch.delenv("RAY_AUTH_MODE")
    runs = expand(make_cfg("hspf_ungm", *TINY))
    frames = []
    for name in ("loky", backend):
        store = Store(tmp_path / name, "hspf_ungm")
        assert execute(runs, store, n_jobs=2, backend=name, progress=False) == len(runs)
        frames.append(deterministic_columns(store.load(runs)))
    pd.testing.assert_frame_equal(frames[0], frames[1])


def test_an_unreachable_ray_address_is_one_line_at_once(make_cfg, tmp_path):
    """ray.init retries an address that does not answer for minutes; the runner checks it first."""
    pytest.importorskip("ray", reason="ray is not installed (pip install -e '.[test]')")
    from replication.runner.backends import BackendError

    import ray

    runs = expand(make_cfg("hspf_ungm", *TINY))
    with pytest.raises(BackendError) as error:
        execute(runs, Store(tmp_path, "hspf_ungm"), backend="ray", address="127.0.0.1:9", progress=False)
    assert str(error.value).startswith("cannot reach ray at parallel.address=127.0.0.1:9: ")
    assert "\n" not in str(error.value)
    assert not ray.is_initialized()  # what makes it quick: ray.init, which retries for minutes, was never called
    assert not (tmp_path / "hspf_ungm").exists()


def test_a_local_dask_cluster_serves_its_dashboard_on_the_loopback_only():
    pytest.importorskip("distributed", reason="distributed is not installed (pip install -e '.[test]')")
    import distributed

    from replication.runner.backends import _dask_client

    with _dask_client(None, 1):
        client = distributed.get_client()
        assert client.dashboard_link.startswith("http://127.0.0.1:"), client.dashboard_link
        assert client.scheduler.address.startswith("tcp://127.0.0.1:"), client.scheduler.address


def test_unreachable_scheduler_is_one_clear_error(make_cfg, tmp_path):
    pytest.importorskip("distributed", reason="distributed is not installed (pip install -e '.[test]')")
    import dask

    from replication.runner.backends import BackendError

    runs = expand(make_cfg("hspf_ungm", *TINY))
    with dask.config.set({"distributed.comm.timeouts.connect": "1s"}), pytest.raises(BackendError) as error:
        execute(runs, Store(tmp_path, "hspf_ungm"), backend="dask", address="tcp://127.0.0.1:9", progress=False)
    assert "parallel.address=tcp://127.0.0.1:9" in str(error.value) and "\n" not in str(error.value)
    assert not (tmp_path / "hspf_ungm").exists()


# four short runs (a ray batch: two per worker), then two that would take minutes, one per worker
BUSY = ("scale=quick", "n_jobs=2", "experiment.runs.quick=1", "~experiment.methods.grid",
        "experiment.methods.PF.sweep.n_particles=[100]", "experiment.model.sweep.steps=[10,11,12,13,1000000,1000001]")
LOCAL_BACKENDS = ["loky", "threading", "dask", "ray"]


def local_backend_env(backend: str, request) -> dict | None:
    """The environment a command running ``backend`` here needs: ray's own (its files in the tests' folder, a
    token of the test's own: ``ray_env``); None (this one's) for the others."""
    package = CLUSTER_PACKAGES.get(backend)
    if package:
        pytest.importorskip(package, reason=f"{package} is not installed (pip install -e '.[test]')")
    return request.getfixturevalue("ray_env") if backend == "ray" else None


def process_group(leader: int) -> set[int]:
    """The live processes of ``leader``'s process group."""
    group = set()
    for pid in processes():
        try:
            if os.getpgid(pid) == leader:
                group.add(pid)
        except ProcessLookupError:
            pass
    return still_running(group)


@NEEDS_PROC
@pytest.mark.parametrize("backend", LOCAL_BACKENDS)
def test_one_sigterm_stops_every_local_backend_and_all_it_started(tmp_path, backend, request):
    """``kill <runner>`` once, with both workers in runs of minutes: the runner exits 143 with its one line,
    and every process of its group, and every process it started, is gone.  The seconds that takes are
    measured and printed (a few, on two loaded cores), not asserted: the bound is a generous 30 s."""
    env = local_backend_env(backend, request)
    store = tmp_path / "store"
    with open(tmp_path / "output", "w") as output, open(tmp_path / "errors", "w") as errors:  # not pipes: a
        runner = subprocess.Popen(  # process left holding one would block its reader
            command("ungm_horizon", store, tmp_path / "reports", *BUSY, f"parallel.backend={backend}"),
            cwd=PROJECT_ROOT, stdout=output, stderr=errors, start_new_session=True, env=env)
    started, deadline = set(), time.monotonic() + 600
    while len(list(store.glob("ungm_horizon/runs/*.json"))) < 4 and runner.poll() is None:
        assert time.monotonic() < deadline, "the four short runs were not stored in 10 minutes"
        started |= descendants(runner.pid)
        time.sleep(0.05)
    time.sleep(1.0)  # the two long runs under way
    started |= descendants(runner.pid) | process_group(runner.pid)
    assert runner.poll() is None, (tmp_path / "output").read_text()
    sent = time.monotonic()
    runner.send_signal(signal.SIGTERM)
    try:
        while (runner.poll() is None or still_running(started) or process_group(runner.pid)) \
                and time.monotonic() - sent < 30:
            time.sleep(0.05)
        seconds = time.monotonic() - sent
        left = still_running(started) | process_group(runner.pid)
    finally:
        for pid in still_running(started) | process_group(runner.pid):
            os.kill(pid, signal.SIGKILL)  # not left to the suite
    print(f"{backend}: stopped in {seconds:.1f} s after one SIGTERM ({len(started)} processes)")
    assert not left, {pid: Path(f"/proc/{pid}/cmdline").read_bytes()[:120] for pid in left}
    err = (tmp_path / "errors").read_text()
    assert runner.wait(timeout=1) == 143, err
    assert len(err.strip().splitlines()) == 1 and INTERRUPTED.fullmatch(err.strip()), err


def listening(pids: set[int]) -> set[tuple[str, int, str]]:
    """The (address, port, process name) of every socket ``pids`` listen on."""
    import psutil

    found = set()
    for pid in pids:
        try:
            process = psutil.Process(pid)
            found |= {(c.laddr.ip, c.laddr.port, process.name()) for c in process.net_connections(kind="inet")
                      if c.status == psutil.CONN_LISTEN}
        except (psutil.NoSuchProcess, psutil.AccessDenied):
            pass
    return found


def loopback(address: str) -> bool:
    """127.0.0.0/8 and ::1, and 127.0.0.0/8 written as IPv6 (``::ffff:127.0.0.1``, ray's gRPC servers)."""
    ip = ipaddress.ip_address(address)
    return ip.is_loopback or bool(getattr(ip, "ipv4_mapped", None) and ip.ipv4_mapped.is_loopback)


@NEEDS_PROC
@pytest.mark.parametrize("backend", ["dask", "ray"])
def test_a_local_cluster_listens_on_the_loopback_alone_and_runs_at_the_runners_priority(tmp_path, backend,
                                                                                       request):
    """Every socket the run's processes (the runner, its cluster's scheduler or GCS, raylet and agents, every
    worker) listen on, sampled while it runs, is on 127.0.0.0/8 or ::1: nothing on another interface, nor
    on all of them (0.0.0.0, ::).  And every one of them runs at the runner's nice value: ray starts its
    workers at nice 15 unless told, where beside any other busy process they get a few per cent of a core
    (a ray test of the killed worker hung past its timeout so beside the record's rebuild)."""
    pytest.importorskip("psutil", reason="psutil is not installed (distributed's own dependency)")
    env = local_backend_env(backend, request)
    runner = subprocess.Popen(
        command("hspf_ungm", tmp_path / "store", tmp_path / "reports", *TINY, "n_jobs=2", f"parallel.backend={backend}"),
        cwd=PROJECT_ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, env=env)
    seen, nice, deadline = set(), {}, time.monotonic() + 600
    while runner.poll() is None and time.monotonic() < deadline:
        started = descendants(runner.pid)
        seen |= listening({runner.pid} | started)
        nice |= niceness(started)
        time.sleep(0.2)
    _, err = runner.communicate(timeout=60)
    assert runner.returncode == 0, err
    assert seen, "no listening socket seen: the cluster was not sampled"
    assert {address for address, *_ in seen if not loopback(address)} == set(), sorted(seen)
    assert any(WORKERS[backend] in line for line, _ in nice.values()), nice  # its workers were sampled
    assert {pid: seen for pid, seen in nice.items() if seen[1] != os.nice(0)} == {}


WORKERS = {"dask": "multiprocessing.spawn", "ray": "ray::"}  # in the command line of each cluster's workers


def niceness(pids: set[int]) -> dict[int, tuple[str, int]]:
    """The command line and nice value of each of ``pids`` still running."""
    found = {}
    for pid in pids:
        try:
            found[pid] = cmdline(pid)[:160], os.getpriority(os.PRIO_PROCESS, pid)
        except ProcessLookupError:  # ended meanwhile
            pass
    return found
