"""Command line: check the request, run what is missing, write the experiment's report.

Errors a user can fix (unknown experiment or key, a value of the wrong type,
a bad backend or data path) are one line on stderr and exit status 2, before
any work starts; never a Hydra traceback.  Ctrl-C (SIGINT) stops the workers,
keeps every run already stored and exits with status 130 and one line.
"""

import os
import re
import signal
import subprocess
import sys
from pathlib import Path

import hydra
from omegaconf import DictConfig

from replication import __version__
from replication.errors import ConfigError, fail
from replication.paths import CONF_DIR, experiment_names, resolve
from replication.run import Run
from replication.runner.execute import BackendError, execute
from replication.runner.store import Store
from replication.runner.validate import parallel_settings, prepare

HYDRA_FLAGS = ("--help", "-h", "--hydra-help", "--info", "-i", "--cfg", "-c", "--shell-completion", "-sc")


def config_dirs(argv: list[str]) -> list[Path]:
    """The folders Hydra's ``--config-dir`` / ``-cd`` adds to the config search path (a user's own experiments)."""
    found = []
    for i, arg in enumerate(argv):
        if arg.startswith("--config-dir="):
            found.append(Path(arg.split("=", 1)[1]))
        elif arg in ("--config-dir", "-cd") and i + 1 < len(argv):
            found.append(Path(argv[i + 1]))
    return found


def check_experiment_argument(argv: list[str]) -> None:
    """Catch a missing or unknown ``experiment=`` before Hydra turns it into a traceback (Hydra's own
    flags, which describe the app rather than run it, need none).  Experiments in a ``--config-dir``'s
    ``experiment/`` folder are known too."""
    known = experiment_names(*config_dirs(argv))
    chosen = [arg.split("=", 1)[1] for arg in argv if arg.startswith("experiment=")]
    if not chosen and any(arg in HYDRA_FLAGS for arg in argv):
        return
    if not chosen:
        fail(f"name an experiment: python -m replication experiment=<name>; known: {', '.join(known)}")
    for name in chosen[-1].split(","):
        if name not in known:
            fail(f"unknown experiment {name!r}; known: {', '.join(known)}")


def check_overrides(argv: list[str]) -> None:
    """Compose the config as Hydra will, so that a bad override (an unknown key written
    without ``+``, a malformed value) is one line rather than Hydra's multi-line report."""
    from hydra import compose, initialize_config_dir
    from hydra.errors import HydraException

    if any(arg.startswith("-") for arg in argv):  # --multirun, --cfg, --help ...: Hydra's own business
        return
    overrides = [arg for arg in argv if not arg.lstrip("+~").startswith(("hydra.", "hydra/"))]
    try:
        with initialize_config_dir(config_dir=str(CONF_DIR), version_base="1.3"):
            compose("config", overrides=overrides)
    except HydraException as error:
        lines = [line.strip() for line in str(error).splitlines() if line.strip()]
        unknown = re.fullmatch(r"Could not override '(.+)'\.", lines[0]) if lines else None
        if unknown:
            key = unknown[1]
            fail(f"unknown key {key!r} (check the spelling; a key the config lacks is added as +{key}=...)")
        fail(" ".join(lines) or error.__class__.__name__)


def interrupted(store: Store | None = None, runs: list[Run] | None = None) -> None:
    """The one line of a Ctrl-C, and exit status 130 (128 + SIGINT) as shells expect."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # a second Ctrl-C while we count must not print a traceback
    if store is None or runs is None:
        print("interrupted: rerun the same command to resume", file=sys.stderr)
    else:
        stored = sum(store.path(run).exists() for run in runs)
        print(f"interrupted: {stored} runs stored, rerun the same command to resume", file=sys.stderr)
    raise SystemExit(130)


@hydra.main(config_path=str(CONF_DIR), config_name="config", version_base="1.3")
def run_experiment(cfg: DictConfig) -> None:
    if "multiverse" in cfg.experiment:
        return run_multiverse(cfg)
    try:
        runs, skipped, (backend, n_jobs, address) = prepare(cfg)
    except ConfigError as error:
        fail(str(error))
    for message in skipped:
        print(f"skipped: {message}", file=sys.stderr)
    store = Store(resolve(cfg.store), cfg.experiment.name)
    try:
        done = execute(runs, store, n_jobs=n_jobs, backend=backend, progress=cfg.progress, address=address)
        stored = len(runs) - done
        print(f"{cfg.experiment.name}: {done} runs computed, {stored} already stored in {store.directory}")
        from replication.report.experiment import write_experiment_report
        from replication.report.index import write_index

        written = write_experiment_report(cfg, runs, store)
        print(f"{cfg.experiment.name}: report in {written}; index in {write_index(resolve(cfg.reports))}")
        run_companions(cfg)
    except BackendError as error:
        fail(str(error))
    except KeyboardInterrupt:
        interrupted(store, runs)


def run_multiverse(cfg: DictConfig) -> None:
    """Run every universe of a paper's multiverse (:mod:`replication.runner.multiverse`) into its base
    experiments' stores, then write its report and the index."""
    from replication.runner.multiverse import load

    try:
        multiverse = load(cfg)
        backend, n_jobs, address = parallel_settings(cfg)
    except ConfigError as error:
        fail(str(error))
    for message in multiverse.skipped:
        print(f"skipped: {message}", file=sys.stderr)
    name = cfg.experiment.name
    print(f"{name}: {len(multiverse.universes)} universes of {len(multiverse.choices)} choices")
    store, runs = None, None
    try:
        for experiment in multiverse.experiments:
            store, runs = Store(resolve(cfg.store), experiment), multiverse.runs_of(experiment)
            done = execute(runs, store, n_jobs=n_jobs, backend=backend, progress=cfg.progress, address=address)
            print(f"{name}: {experiment}: {done} runs computed, {len(runs) - done} already stored")
        from replication.report.index import write_index
        from replication.report.multiverse import write_multiverse_report

        written = write_multiverse_report(cfg, multiverse)
        print(f"{name}: report in {written}; index in {write_index(resolve(cfg.reports))}")
    except BackendError as error:
        fail(str(error))
    except KeyboardInterrupt:
        interrupted(store, runs)


def run_companions(cfg: DictConfig) -> None:
    """Run the experiments a paper's main one names in ``also:`` (e.g. hspf's UNGM half), with the same
    settings except those addressed to this experiment (``experiment.*``)."""
    shared = [a for a in sys.argv[1:] if not a.startswith(("experiment=", "experiment.", "+experiment.", "-"))]
    for name in cfg.experiment.get("also", []) or []:
        print(f"{cfg.experiment.name}: also {name}")
        status = subprocess.run([sys.executable, "-m", "replication", f"experiment={name}", *shared]).returncode
        if status:
            raise SystemExit(status)


# loky's resource tracker (a child process) warns about semaphores its killed workers leaked: after a
# Ctrl-C, or a clean stop, that is noise on the user's terminal, not a problem with the results.
QUIET_CHILDREN = "ignore::UserWarning:joblib.externals.loky.backend.resource_tracker"


def main() -> None:
    if QUIET_CHILDREN not in os.environ.get("PYTHONWARNINGS", ""):
        os.environ["PYTHONWARNINGS"] = ",".join(filter(None, [os.environ.get("PYTHONWARNINGS"), QUIET_CHILDREN]))
    try:
        argv = sys.argv[1:]
        if "--version" in argv:
            print(f"replication {__version__}")
            return
        check_experiment_argument(argv)
        check_overrides(argv)
        run_experiment()
    except KeyboardInterrupt:
        interrupted()

