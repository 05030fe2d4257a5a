"""Command line: check the request, run what is missing, write the experiment's report.

Errors a user can fix (unknown experiment, bad parameter) are one line on
stderr and exit status 2, before any work starts; never a Hydra traceback.
"""

import sys

import hydra
from omegaconf import DictConfig

from replication.paths import CONF_DIR, experiment_names, resolve
from replication.runner.config import ConfigError, expand
from replication.runner.execute import execute
from replication.runner.store import Store


def fail(message: str) -> None:
    print(f"error: {message}", file=sys.stderr)
    raise SystemExit(2)


def check_experiment_argument(argv: list[str]) -> None:
    """Catch a missing or unknown ``experiment=`` before Hydra turns it into a traceback."""
    known = experiment_names()
    chosen = [arg.split("=", 1)[1] for arg in argv if arg.startswith("experiment=")]
    if not chosen:
        fail(f"name an experiment: python -m replication experiment=<name>; known: {', '.join(known)}")
    for name in chosen[-1].split(","):
        if name not in known:
            fail(f"unknown experiment {name!r}; known: {', '.join(known)}")


@hydra.main(config_path=str(CONF_DIR), config_name="config", version_base="1.3")
def run_experiment(cfg: DictConfig) -> None:
    from replication.report.experiment import write_experiment_report
    from replication.report.index import write_index

    skipped = []
    try:
        runs = expand(cfg, skipped)
    except ConfigError as error:
        fail(str(error))
    for message in skipped:
        print(f"skipped: {message}", file=sys.stderr)
    if not runs:
        fail(f"{cfg.experiment.name}: nothing to run (every condition was skipped)")
    if cfg.n_jobs == 0:
        fail("n_jobs must be a positive number of workers or -1 for all cores")
    store = Store(resolve(cfg.store), cfg.experiment.name)
    done = execute(runs, store, n_jobs=cfg.n_jobs, backend=cfg.backend, progress=cfg.progress)
    print(f"{cfg.experiment.name}: {done} runs computed, {len(runs) - done} already stored in {store.directory}")
    written = write_experiment_report(cfg, runs, store)
    print(f"{cfg.experiment.name}: report in {written}; index in {write_index(resolve(cfg.reports))}")


def main() -> None:
    check_experiment_argument(sys.argv[1:])
    run_experiment()
