"""The runner: validation before work, identity-keyed seeds, determinism, atomic store and resume."""

import json
import os
import re
import shutil
import signal
import stat
import subprocess
import sys
import time

import numpy as np
import pandas as pd
import pytest
from conftest import PROJECT_ROOT, SMALL
from omegaconf import open_dict

from replication.errors import ConfigError
from replication.runner.config import expand
from replication.runner.execute import TIMING_COLUMNS, execute
from replication.runner.provenance import code_digest
from replication.runner.store import CHECKSUM, Store, checksum
from replication.seeding import seed_sequence


def deterministic_columns(frame: pd.DataFrame) -> pd.DataFrame:
    """Everything in a record except wall-clock timings, sorted by run."""
    return frame.drop(columns=list(TIMING_COLUMNS), errors="ignore").sort_values("run_id").reset_index(drop=True)


@pytest.mark.parametrize(
    "args, message",
    [
        (("experiment=no_such_paper",), "unknown experiment 'no_such_paper'"),
        ((), "name an experiment"),
        (("experiment=gps_qmcpf", "experiment.methods.PF.filter=magic"), "unknown filter 'magic'"),
        (("experiment=gps_qmcpf", "+experiment.methods.XPF.n_particles=10"), "experiment.methods.XPF names no filter"),
        (("experiment=hspf_ungm", "experiment.methods.PF.n_particles=0"), "n_particles must be a positive"),
        (("experiment=gps_qmcpf", "experiment.methods.PF.sweep.n_particles=[100,-5]"), "positive integer, got -5"),
        (("experiment=gps_qmcpf", "experiment.methods.PF.sweep.n_particles=5"), "must be a non-empty list"),
        (("experiment=gps_qmcpf", "scale=huge"), "scale must be one of"),
        (("experiment=gps_qmcpf", "experiment.model.name=lorenz"), "unknown model 'lorenz'"),
        (("experiment=gps_qmcpf", "experiment.model.Q=-1"), "experiment.model.Q must be positive"),
        (("experiment=gps_qmcpf", "experiment.methods.PF.resampling=bogus"), "unknown resampling"),
    ],
)
def test_bad_requests_fail_fast_with_one_line(cli, tmp_path, args, message):
    result = cli(*args, timeout=60)
    assert result.returncode == 2, result.stderr
    assert message in result.stderr
    assert "Traceback" not in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1, result.stderr
    assert not (tmp_path / "experiments").exists()  # no work started


@pytest.mark.parametrize(
    "args, expected",
    [
        (("--help",), "experiment: bis_pf, "),  # the experiments and the main settings, in a page
        (("experiment=bis_pf", "--help"), "Main settings"),
        (("--cfg", "job"), "base_seed: 20261121"),
        (("--info", "searchpath"), "Config search path"),
        (("--version",), "pf-replicate 0.1.0"),
    ],
)
def test_hydra_flags_describe_the_app_without_an_experiment(args, expected):
    result = subprocess.run([sys.executable, "-m", "replication", *args], cwd=PROJECT_ROOT, capture_output=True,
                            text=True, timeout=60, check=False)
    assert result.returncode == 0, result.stderr
    assert expected in result.stdout
    assert len(result.stdout.splitlines()) < 60


@pytest.mark.e2e  # a subprocess, a killed runner or a cluster: make test-e2e runs it, make test does not
def test_a_users_own_experiment_runs_from_hydras_config_dir(cli, tmp_path):
    """``--config-dir`` (Hydra's way to add configs) makes a user's ``experiment/<name>.yaml`` known."""
    own = tmp_path / "my_conf" / "experiment"
    own.mkdir(parents=True)
    text = (PROJECT_ROOT / "conf" / "experiment" / "demo_scene.yaml").read_text()
    (own / "my_scene.yaml").write_text(text.replace("name: demo_scene", "name: my_scene", 1))
    result = cli("--config-dir", str(own.parent), "experiment=my_scene", "scale=quick", "experiment.runs.quick=1")
    assert result.returncode == 0, result.stderr
    assert (tmp_path / "experiments" / "my_scene" / "runs").is_dir()
    unknown = cli("experiment=my_scene", timeout=60)  # without the folder it is not an experiment
    assert unknown.returncode == 2 and "unknown experiment 'my_scene'" in unknown.stderr


def test_the_report_command_prints_its_usage():
    result = subprocess.run([sys.executable, "-m", "replication.report", "--help"], cwd=PROJECT_ROOT,
                            capture_output=True, text=True, timeout=60, check=False)
    assert result.returncode == 0 and "rebuild reports from stored runs only" in result.stdout, result.stderr


def test_expansion_is_method_by_condition_by_repetition(make_cfg):
    runs = expand(make_cfg("gps_qmcpf", *SMALL))
    assert len(runs) == (5 * 3 + 1) * 3  # five filters at N = 500, 200, 100 and the grid, 3 repetitions each
    assert {(r.method, r.condition.get("N")) for r in runs if r.method in ("PF", "grid")} == {
        ("PF", 500), ("PF", 200), ("PF", 100), ("grid", None)
    }
    assert len({r.run_id for r in runs}) == len(runs)
    paper = expand(make_cfg("gps_qmcpf", "scale=paper"))  # quick is the default
    assert len(paper) == 16 * 100


def test_model_sweeps_share_data_per_condition(make_cfg):
    runs = expand(make_cfg("ungm_horizon", *SMALL))
    first = {r.method + str(r.condition): r for r in runs if r.repetition == 0}
    a, b = first["PFT=50;N=100"], first["gridT=50"]
    assert a.data_condition == b.data_condition and str(a.data_condition) == "T=50" and a.data_condition.get("T") == 50
    assert a.rng("data").random() == b.rng("data").random()  # common random numbers for the data
    assert a.rng("filter").random() != b.rng("filter").random()
    assert first["PFT=10;N=100"].rng("data").random() != a.rng("data").random()


def test_a_methods_only_block_reads_a_key_inside_a_block(make_cfg):
    """bis_pf_pets_pipeline runs the references once per sequence: their only: names dotted keys."""
    runs = expand(make_cfg("bis_pf_pets_pipeline", "scale=paper", "experiment.runs.paper=1"))
    sort = [r for r in runs if r.method == "SORT"]
    assert sorted(r.condition.get("scene") for r in sort) == ["eth_sunnyday", "mot16_11", "tud_campus"]
    assert all(r.model["association"]["box"] == "estimate" and r.model["deaths"]["seconds"] == 0.2 for r in sort)
    assert sum(r.method == "MIPF" for r in runs) == 3 * 3 * 2 * 3  # sequences x boxes x births x deaths


def test_a_model_sweep_may_set_a_key_inside_a_block_and_leaves_the_block_of_the_others_alone(make_cfg):
    runs = expand(make_cfg("bis_pf_pets_tuning", "scale=quick", "experiment.runs.quick=1"))
    frames = {(r.condition.get("births.frames"), r.model["births"]["frames"]) for r in runs}
    assert frames == {(2, 2), (3, 3)}  # each run's births.frames is its condition's
    assert all(r.model["births"]["min_iou"] == 0.3 for r in runs)  # the rest of the block as configured
    assert all(r.model["deaths"]["min_rho"] is None and r.model["deaths"]["frames"] == 5 for r in runs)
    cfg = make_cfg("bis_pf_pets_tuning", "scale=quick")
    with open_dict(cfg):
        cfg.experiment.model.sweep["proposal.alpha.x"] = [1]
    with pytest.raises(ConfigError, match="sweep proposal.alpha.x: alpha is 0.5, not a block of keys"):
        expand(cfg)


def test_seed_is_a_function_of_identity_only():
    a = seed_sequence(7, "filter", "PF", "N=500", 3)
    b = seed_sequence(7, "filter", "PF", "N=500", 3)
    assert a.generate_state(4).tolist() == b.generate_state(4).tolist()
    assert seed_sequence(7, "filter", "PF", "N=500", 4).generate_state(4).tolist() != a.generate_state(4).tolist()
    assert seed_sequence(8, "filter", "PF", "N=500", 3).generate_state(4).tolist() != a.generate_state(4).tolist()
    # the same as walking SeedSequence.spawn: a child's spawn key extends its parent's
    assert a.spawn(1)[0].spawn_key == a.spawn_key + (0,)


def test_one_job_and_two_jobs_and_any_order_give_identical_records(make_cfg, tmp_path):
    cfg = make_cfg("gps_qmcpf", *SMALL)
    runs = expand(cfg)
    frames = []
    for label, n_jobs, order in [("one", 1, runs), ("two", 2, runs), ("shuffled", 2, runs[::-1])]:
        store = Store(tmp_path / label, cfg.experiment.name)
        assert execute(order, store, n_jobs=n_jobs, progress=False) == len(runs)
        frames.append(deterministic_columns(store.load(runs)))
    assert len(frames[0]) == len(runs)
    pd.testing.assert_frame_equal(frames[0], frames[1])
    pd.testing.assert_frame_equal(frames[0], frames[2])


def test_rerun_skips_stored_runs_and_more_repetitions_reuse_them(make_cfg, tmp_path):
    cfg = make_cfg("hspf_ungm", *SMALL)
    runs = expand(cfg)
    store = Store(tmp_path / "store", cfg.experiment.name)
    assert execute(runs, store, n_jobs=1, progress=False) == len(runs)
    assert execute(runs, store, n_jobs=1, progress=False) == 0
    more = expand(make_cfg("hspf_ungm", "scale=quick", "experiment.runs.quick=5"))
    assert execute(more, store, n_jobs=1, progress=False) == len(more) - len(runs)


def test_changed_config_lands_in_new_files(make_cfg, tmp_path):
    base = expand(make_cfg("hspf_ungm", *SMALL))
    changed = expand(make_cfg("hspf_ungm", *SMALL, "experiment.model.Q=5"))
    relabelled = expand(make_cfg("hspf_ungm", *SMALL, "experiment.methods.PF.label=renamed"))
    assert {r.run_id for r in base}.isdisjoint({r.run_id for r in changed})
    assert {r.run_id for r in base} == {r.run_id for r in relabelled}  # a label changes no number
    store = Store(tmp_path / "store", "hspf_ungm")
    execute(base, store, n_jobs=1, progress=False)
    assert store.load(changed).empty


def test_code_digest_leaves_out_the_modules_that_only_read_runs(tmp_path):
    def digest(copy: str, *changed: str) -> str:
        """The digest of a copy of the package with a comment added to each of ``changed``."""
        package = tmp_path / copy / "replication"
        shutil.copytree(PROJECT_ROOT / "replication", package, ignore=shutil.ignore_patterns("__pycache__"))
        for module in changed:
            with open(package / module, "a") as source:
                source.write("# a change\n")
        return code_digest(package)

    before = digest("same")
    assert digest("readers", "export.py", "report/render.py") == before != digest("metric", "metrics/tracking.py")


@pytest.mark.e2e  # a subprocess, a killed runner or a cluster: make test-e2e runs it, make test does not
def test_changed_code_lands_in_new_runs(tmp_path):
    """A copy of the project whose bootstrap filter differs by one comment recomputes the bootstrap PF's
    runs and no other; a change to the report layer, the command line or the reader of records reuses them.
    Run through the CLI."""
    copy = tmp_path / "project"
    shutil.copytree(PROJECT_ROOT, copy, ignore=shutil.ignore_patterns(".venv", ".git", "experiments", "reports",
                                                                      "__pycache__", "*.egg-info"))
    env = {**os.environ, "PYTHONPATH": str(copy)}
    command = [sys.executable, "-m", "replication", "experiment=hspf_ungm", "scale=quick",
               "experiment.runs.quick=2", "progress=false", "n_jobs=1"]

    def computed() -> int:
        done = subprocess.run(command, cwd=copy, env=env, capture_output=True, text=True, timeout=300)
        assert done.returncode == 0, done.stderr
        return int(re.search(r"(\d+) runs computed", done.stdout)[1])

    first = computed()
    assert first > 0 and computed() == 0
    for reader in ("report/render.py", "cli.py", "runner/results.py"):  # they never compute a run
        with open(copy / "replication" / reader, "a") as code:
            code.write("# a change that computes nothing\n")
    assert computed() == 0
    runs_dir = copy / "experiments" / "hspf_ungm" / "runs"
    earlier = set(runs_dir.glob("*.json"))  # they stay beside the new runs: read a new one
    with open(copy / "replication" / "filters" / "bootstrap.py", "a") as code:
        code.write("# a filter change\n")
    assert computed() == first // 3  # PF's runs; HSPF's and the grid's are kept
    record = json.loads(min(set(runs_dir.glob("*.json")) - earlier).read_text())
    assert record["code_digest"] == code_digest(copy / "replication") != code_digest()
    assert {"git_commit", "git_dirty", "numpy_version", "scipy_version", "opencv_version", "numba_version",
            "machine", "computed_at"} <= set(record)


def test_store_write_is_atomic(tmp_path, make_cfg):
    run = expand(make_cfg("hspf_ungm", *SMALL))[0]
    store = Store(tmp_path, "hspf_ungm")

    class Unserialisable:
        pass

    with pytest.raises(TypeError):
        store.write(run, {"x": Unserialisable()})
    assert not store.has(run)
    assert [p for p in tmp_path.rglob("*") if p.is_file()] == []  # no partial file, no stray temporary
    store.write(run, {"x": 1.0})
    assert json.loads(store.path(run).read_text()) == {"x": 1.0, CHECKSUM: checksum({"x": 1.0})}


@pytest.mark.parametrize("umask, mode", [(0o022, 0o644), (0o002, 0o664), (0o077, 0o600)])
def test_stored_files_are_created_as_open_creates_them(tmp_path, make_cfg, umask, mode):
    """Records and failures get 0o666 less the umask (readable by the group under the usual 022), not 0o600."""
    first, second = expand(make_cfg("hspf_ungm", *SMALL))[:2]
    store = Store(tmp_path, "hspf_ungm")
    previous = os.umask(umask)
    try:
        store.write(first, {"x": 1.0})
        store.write_failure(second, "not finite: rmse=nan")
    finally:
        os.umask(previous)
    assert {stat.S_IMODE(p.stat().st_mode) for p in (store.path(first), store.failure_path(second))} == {mode}


@pytest.mark.e2e  # a subprocess, a killed runner or a cluster: make test-e2e runs it, make test does not
def test_interrupted_job_resumes_to_the_same_table(tmp_path):
    """Kill a real run part-way (SIGKILL: no clean-up), resume it, compare with an uninterrupted run."""
    args = ["experiment=ungm_horizon", "scale=quick", "experiment.runs.quick=6", "n_jobs=2", "progress=false"]

    def command(store):
        return [sys.executable, "-m", "replication", *args, f"store={store}", f"reports={tmp_path / 'reports'}",
                "outside_project=true"]

    reference = subprocess.run(command(tmp_path / "a"), cwd=PROJECT_ROOT, capture_output=True, text=True)
    assert reference.returncode == 0, reference.stderr
    runs_dir = tmp_path / "b" / "ungm_horizon" / "runs"
    process = subprocess.Popen(command(tmp_path / "b"), cwd=PROJECT_ROOT, start_new_session=True)
    deadline = time.time() + 120
    while time.time() < deadline and len(list(runs_dir.glob("*.json"))) < 10:
        time.sleep(0.02)
    os.killpg(process.pid, signal.SIGKILL)
    process.wait()
    partial = len(list(runs_dir.glob("*.json")))
    total = len(list((tmp_path / "a" / "ungm_horizon" / "runs").glob("*.json")))
    assert 10 <= partial < total, (partial, total)
    resumed = subprocess.run(command(tmp_path / "b"), cwd=PROJECT_ROOT, capture_output=True, text=True)
    assert resumed.returncode == 0, resumed.stderr
    assert f"{total - partial} runs computed, {partial} already stored" in resumed.stdout

    def table(store):
        records = [json.loads(p.read_text()) for p in (store / "ungm_horizon" / "runs").glob("*.json")]
        return deterministic_columns(pd.DataFrame(records).drop(columns=CHECKSUM))  # it hashes the timings too

    pd.testing.assert_frame_equal(table(tmp_path / "a"), table(tmp_path / "b"))


@pytest.mark.e2e  # a subprocess, a killed runner or a cluster: make test-e2e runs it, make test does not
def test_cli_end_to_end_writes_report(cli, tmp_path):
    result = cli("experiment=gps_qmcpf", "experiment.also=[]", *SMALL)  # not its helicopter half
    assert result.returncode == 0, result.stderr
    assert "48 runs computed, 0 already stored" in result.stdout
    out = tmp_path / "reports" / "quick" / "gps_qmcpf"  # the quick scale's page, apart from the paper scale's
    table = pd.read_csv(out / "table1_rmse.csv")
    assert list(table["condition"].fillna("-")) == ["N=500", "N=200", "N=100"] * 5 + ["-"]
    assert np.all(table["runs"] == 3)
    assert (tmp_path / "reports" / "index.html").exists()
    again = cli("experiment=gps_qmcpf", "experiment.also=[]", *SMALL)
    assert "0 runs computed, 48 already stored" in again.stdout


@pytest.mark.e2e  # a subprocess, a killed runner or a cluster: make test-e2e runs it, make test does not
def test_a_paper_experiment_runs_its_companions_with_the_shared_settings(cli, tmp_path):
    """``also:`` runs the paper's other half with the same scale and store, not the parent's own overrides."""
    result = cli("experiment=hspf_ungm", "+experiment.also=[ungm_horizon]", "experiment.runs.quick=2", "scale=quick")
    assert result.returncode == 0, result.stderr
    assert "hspf_ungm: also ungm_horizon" in result.stdout
    horizon = list((tmp_path / "experiments" / "ungm_horizon" / "runs").glob("*.json"))
    per_condition = {p.name.rsplit("__r", 1)[0] for p in horizon}
    assert len(horizon) == 20 * len(per_condition)  # its own quick scale (20 runs), not the parent's runs.quick=2


def test_workers_keep_freed_memory_on_glibc():
    """The allocator setting every run starts with (replication.runner.memory) takes on glibc Linux."""
    import platform

    from replication.runner.memory import retain_freed_memory

    if platform.system() != "Linux" or platform.libc_ver()[0] != "glibc":
        pytest.skip("mallopt thresholds are glibc's")
    assert retain_freed_memory() is True


@pytest.mark.e2e  # a subprocess, a killed runner or a cluster: make test-e2e runs it, make test does not
def test_a_multirun_sweep_goes_through_the_store_and_is_drawn_from_it(cli, tmp_path):
    """``-m key=a,b`` stores every value's runs (shared runs once); ``replication.report sweep=`` reads them back."""
    settings = ["scale=quick", "experiment.runs.quick=3", "experiment.model.sweep.steps=[10]"]
    result = cli("-m", "experiment=ungm_horizon", *settings, "experiment.methods.grid.n_points=201,1601")
    assert result.returncode == 0, result.stderr
    assert "9 runs computed, 0 already stored" in result.stdout and "3 runs computed, 6 already stored" in result.stdout
    assert "sweep not drawn (ungm_horizon: no table names a metric" in result.stderr  # and the command to finish
    assert list((tmp_path / "experiments" / "multirun").glob("*/multirun.yaml"))  # Hydra's record, under the store
    report = subprocess.run(
        [sys.executable, "-m", "replication.report", "experiment=ungm_horizon", *settings, f"store={tmp_path / 'experiments'}",
         f"reports={tmp_path / 'reports'}", "sweep=experiment.methods.grid.n_points=201,1601,3201", "metric=rmse"],
        cwd=PROJECT_ROOT, capture_output=True, text=True,
    )
    assert report.returncode == 0, report.stderr
    assert "n_points=3201: 3 of 9 runs not stored" in report.stderr  # a value never run is named, not drawn
    (out,) = (tmp_path / "reports" / "quick").glob("ungm_horizon@*/sweeps")  # T=10 only: not as shipped
    table = pd.read_csv(out / "experiment.methods.grid.n_points.csv").set_index("condition")
    records = pd.DataFrame([json.loads(p.read_text()) for p in (tmp_path / "experiments" / "ungm_horizon" / "runs").glob("*.json")])
    grid = records[records["method"] == "grid"]  # two configs, 3 runs each
    assert len(grid) == 6 and set(table.index) == {"T=10;n_points=201", "T=10;n_points=1601", "T=10;N=100", "T=10;N=500"}
    assert sorted(table.loc[["T=10;n_points=201", "T=10;n_points=1601"], "mean"]) == pytest.approx(
        sorted(grid.groupby("run_key")["rmse"].mean()))
    assert table.loc["T=10;N=500", "runs"] == 3  # PF does not depend on the grid: once, as a reference line
    assert (out / "experiment.methods.grid.n_points.png").stat().st_size > 10_000
    assert 'href="sweeps/experiment.methods.grid.n_points.html"' in (out.parent / "index.html").read_text()
    bad = subprocess.run([sys.executable, "-m", "replication.report", "experiment=ungm_horizon", *settings,
                          f"store={tmp_path / 'experiments'}", "sweep=experiment.methods.grid.n_points=201", "metric=nope"],
                         cwd=PROJECT_ROOT, capture_output=True, text=True)
    assert bad.returncode == 2 and bad.stderr.count("\n") == 1 and "metric 'nope'" in bad.stderr


@pytest.mark.e2e  # a subprocess, a killed runner or a cluster: make test-e2e runs it, make test does not
def test_a_multirun_draws_its_sweep_at_its_end(cli, tmp_path):
    """The Hydra callback draws the sweep of one setting when the multirun ends: no retyping."""
    result = cli("-m", "experiment=hspf_ungm", "scale=quick", "experiment.runs.quick=5", "experiment.methods.grid.n_points=201",
                 "experiment.methods.PF.n_particles=50,100")
    assert result.returncode == 0, result.stderr
    (sweeps,) = (tmp_path / "reports" / "quick").glob("hspf_ungm@*/sweeps")  # a grid of 201 points: not as shipped
    page = sweeps / "experiment.methods.PF.n_particles.html"
    assert page.exists() and "sweep: " in result.stdout
    table = pd.read_csv(page.with_suffix(".csv"))
    swept = table[table["method"] == "PF"]
    assert set(swept["condition"]) == {"n_particles=50", "n_particles=100"} and (swept["runs"] == 5).all()


def test_tab_completion_offers_experiments_and_keys():
    """Hydra's shell completion through the one entry point: what bash's completion function asks."""
    def complete(line: str) -> list[str]:
        env = {**os.environ, "COMP_LINE": line, "COMP_POINT": str(len(line))}
        done = subprocess.run([sys.executable, "-m", "replication", "-sc", "query=bash"], cwd=PROJECT_ROOT, env=env,
                              capture_output=True, text=True, timeout=60, check=False)
        assert done.returncode == 0, done.stderr
        return done.stdout.split()

    assert complete("pf-replicate experiment=hspf_u") == [
        "experiment=hspf_ungm", "experiment=hspf_ungm_cost", "experiment=hspf_ungm_sweep"]
    assert "scale=" in complete("pf-replicate experiment=hspf sc")



def test_a_table_whose_scene_is_not_run_is_named_before_any_work(make_cfg):
    """Issue 30: bis_pf without its 3123 scene says, before running, which tables it leaves out."""
    from replication.runner.validate import prepare

    _, skipped, _ = prepare(make_cfg("bis_pf", "scale=quick", "experiment.model.sweep.scene=[exp2_16_targets]"))
    named = [line for line in skipped if "table" in line]
    assert named == ["bis_pf: table modes_3123 needs {scene: exp1_3123}, which no run of this request has: its page "
                     "will leave it out"]  # table3_stability matches 16 balls too: it stays
    _, everything, _ = prepare(make_cfg("bis_pf", "scale=quick"))
    assert not [line for line in everything if "table" in line]


@pytest.mark.e2e  # subprocesses: make test-e2e runs it, make test does not
def test_runs_stored_without_a_report_are_drawn_later_as_if_drawn_as_they_went(cli, tmp_path):
    """``draw=false`` (make replicate's runs) computes and stores the runs and draws nothing; the report
    command then draws the page and summary that drawing as the runs go gives (from the same stored runs)."""
    settings = ("experiment=hspf_ungm", "experiment.runs.quick=2", "scale=quick")
    stored = cli(*settings, "draw=false")
    assert stored.returncode == 0, stored.stderr
    assert "runs computed, 0 already stored" in stored.stdout and "report in" not in stored.stdout
    page = tmp_path / "reports" / "quick" / "hspf_ungm"
    assert not page.exists()
    later = subprocess.run([sys.executable, "-m", "replication", "report", *settings, "pdf=false",
                            f"store={tmp_path / 'experiments'}", f"reports={tmp_path / 'reports'}",
                            "outside_project=true", "progress=false"],
                           cwd=PROJECT_ROOT, capture_output=True, text=True, timeout=300)
    assert later.returncode == 0, later.stderr
    summary = json.loads((page / "summary.json").read_text())
    drawn = cli(*settings)
    assert drawn.returncode == 0, drawn.stderr
    assert "0 runs computed" in drawn.stdout and "hspf_ungm: report in" in drawn.stdout
    assert json.loads((page / "summary.json").read_text()) == summary
