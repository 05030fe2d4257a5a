"""``pf-replicate record [experiment=a,b] [store=experiments] [record=record]``: write the paper-scale
record (:mod:`replication.record.write`) of every experiment and multiverse whose paper-scale runs the
store holds (``make replicate SCALE=paper``, ``make readings SCALE=paper``), the others skipped with a
line; or of those named, each of which must have all its runs stored."""

import sys
from dataclasses import dataclass

from replication.arguments import read
from replication.errors import ConfigError, fail
from replication.paths import experiment_names


@dataclass(frozen=True)
class Options:
    experiment: tuple[str, ...] | None = None  # every experiment whose runs the store holds by default


def main(argv: list[str]) -> None:
    if {"--help", "-h"} & set(argv):
        print(__doc__.strip())
        return
    from hydra import compose, initialize_config_dir

    from replication.paths import CONF_DIR, resolve
    from replication.record.write import SCALE, write

    options, overrides = read(argv, Options, "record", handed=("store", "record"))
    chosen = options.experiment is not None
    names = options.experiment if chosen else experiment_names()
    unknown = sorted(set(names) - set(experiment_names()))
    if unknown:
        fail(f"unknown experiment {unknown[0]!r}; known: {', '.join(experiment_names())}")
    with initialize_config_dir(config_dir=str(CONF_DIR), version_base="1.3"):
        cfgs = [compose("config", overrides=[f"experiment={name}", f"scale={SCALE}", *overrides]) for name in names]
        try:  # all by default: those whose paper-scale runs are not all stored are skipped, and said
            manifest = write(cfgs, resolve(cfgs[0].store), resolve(cfgs[0].record), skip_incomplete=not chosen)
        except ConfigError as error:
            fail(str(error))
    print(f"record: {resolve(cfgs[0].record)} ({len(manifest.experiments)} experiments)", file=sys.stderr)


if __name__ == "__main__":
    main(sys.argv[1:])
