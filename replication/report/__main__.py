"""``python -m replication.report [scale=quick] [experiment=a,b]``: rebuild reports from stored runs only.

Nothing is run: each experiment's report is redrawn from the records in the
store, and ``reports/index.html`` links them.
"""

import sys

from hydra import compose, initialize_config_dir

from replication.paths import CONF_DIR, experiment_names, resolve
from replication.report.experiment import write_experiment_report
from replication.report.index import write_index
from replication.runner.cli import fail
from replication.runner.config import ConfigError, expand
from replication.runner.store import Store


def main(argv: list[str]) -> None:
    chosen = [a.split("=", 1)[1].split(",") for a in argv if a.startswith("experiment=")]
    names = chosen[-1] if chosen else experiment_names()
    overrides = [a for a in argv if not a.startswith("experiment=")]
    unknown = sorted(set(names) - set(experiment_names()))
    if unknown:
        fail(f"unknown experiment {unknown[0]!r}; known: {', '.join(experiment_names())}")
    with initialize_config_dir(config_dir=str(CONF_DIR), version_base="1.3"):
        for name in names:
            cfg = compose("config", overrides=[f"experiment={name}", *overrides])
            try:
                runs = expand(cfg)
            except ConfigError as error:
                fail(str(error))
            page = write_experiment_report(cfg, runs, Store(resolve(cfg.store), name))
            print(f"{name}: {page}")
        print(f"index: {write_index(resolve(cfg.reports))}")


if __name__ == "__main__":
    main(sys.argv[1:])
