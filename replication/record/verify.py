"""``pf-replicate verify [N=200|all] [experiment=a,b] [cheapest=true] [rtol=0] [n_jobs=2] [experiment.<key>=...]``:
re-compute recorded runs in the code and environment at hand and say which differ (``experiment.*``
settings compose the experiments as a record of changed ones was made).

``pf-replicate verify against=store scale=quick`` computes nothing: the store's runs that are recorded
runs (the same identity, config, seed and code: the first repetitions of a quick cell whose scene does
not change with the scale) are compared with the record, into ``<reports>/record/recomputed.json``, which
the report's index shows.

A sample of ``N`` recorded runs, stratified by experiment and by universe of a multiverse (each gives at
least one, the rest in proportion to its runs, drawn with a fixed seed; ``cheapest=true`` takes each
one's quickest recorded runs instead, as the test suite does), is computed again by the runner into a
scratch store and compared
with the record column by column: every metric and kept series exactly (``rtol`` > 0 allows a relative
difference, for a library whose threads change the last bits), a failure by its reason.  Timings,
provenance and parameters are not compared (timings depend on the machine; the others are the run's
identity).  One line per differing run, then the total; exit status 1 if any run differs.
"""

import json
import math
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from replication.condition import PREFIX
from replication.errors import ConfigError, fail
from replication.record.manifest import LIBRARIES, PAGES, RECOMPUTED, Manifest
from replication.record.runs import FAILURE, LABELS, PARAMETERS, UNIVERSE, Record
from replication.run import Run
from replication.runner.execute import TIMING_COLUMNS, execute
from replication.runner.results import SERIES
from replication.runner.store import Store

NOT_COMPARED = (*TIMING_COLUMNS, *LIBRARIES, "code_digest", "git_commit", "git_dirty", "machine",
                "replication_version", "experiment", "method", "repetition", "run_key", "base_seed")
SETTINGS = ("N", "experiment", "cheapest", "rtol", "n_jobs", "progress", "against", "scale", "store", "reports",
            "record")
SAMPLE_SEED = 20261126  # the sample's own stream: the same N gives the same runs


@dataclass(frozen=True)
class Difference:
    run: Run
    columns: tuple[tuple[str, object, object], ...]  # (column, recorded, now)

    def line(self) -> str:
        column, recorded, now = self.columns[0]
        more = f" (and {len(self.columns) - 1} more columns)" if len(self.columns) > 1 else ""
        return (f"{self.run.experiment} {self.run.run_id}: {column} recorded {_short(recorded)}, now {_short(now)}"
                f"{more}")


def sample(recorded: dict[str, list[tuple[Run, dict]]], n: int | None, cheapest: bool) -> list[tuple[Run, dict]]:
    """About ``n`` of the recorded (run, row) pairs (all for None), each stratum (an experiment, a universe)
    at least one and the rest in proportion to its runs: drawn at random with :data:`SAMPLE_SEED`, or its
    quickest with ``cheapest``."""
    total = sum(len(pairs) for pairs in recorded.values())
    rng = np.random.default_rng(SAMPLE_SEED)
    chosen = []
    for name, pairs in sorted(recorded.items()):
        k = len(pairs) if n is None else min(len(pairs), max(1, round(n * len(pairs) / total)))
        if cheapest:
            order = sorted(range(len(pairs)), key=lambda i: pairs[i][1].get("wall_s") or 0.0)[:k]
        else:
            order = sorted(rng.choice(len(pairs), size=k, replace=False))
        chosen += [pairs[i] for i in order]
    return chosen


def compare(row: dict, now: dict, rtol: float = 0.0) -> tuple[tuple[str, object, object], ...]:
    """The columns in which a recomputed record ``now`` differs from the recorded ``row`` (a value one has
    and the other lacks differs too; a series the record does not keep is not compared)."""
    if row.get(FAILURE) is not None or "failure" in now:
        same = row.get(FAILURE) == now.get("failure")
        return () if same else ((FAILURE, row.get(FAILURE), now.get("failure")),)
    columns = [k for k in dict.fromkeys([*row, *(k for k in now if k not in SERIES)])
               if k not in (*NOT_COMPARED, *LABELS, FAILURE) and not k.startswith((*PARAMETERS, PREFIX, UNIVERSE))]
    return tuple((k, row.get(k), now.get(k)) for k in columns if not same_value(row.get(k), now.get(k), rtol))


def same_value(a, b, rtol: float = 0.0) -> bool:
    """Equal as a record holds values: numbers exactly (or within ``rtol``), NaN equal to NaN, lists and
    mappings element by element (a key one mapping lacks is None in it, as a Parquet struct reads back)."""
    if isinstance(a, dict) and isinstance(b, dict):
        return all(same_value(a.get(k), b.get(k), rtol) for k in {*a, *b})
    if isinstance(a, (list, tuple)) and isinstance(b, (list, tuple)):
        return len(a) == len(b) and all(same_value(x, y, rtol) for x, y in zip(a, b))
    if isinstance(a, (int, float)) and isinstance(b, (int, float)) and not isinstance(a, bool):
        if math.isnan(a) or math.isnan(b):
            return math.isnan(a) and math.isnan(b)
        return a == b or abs(a - b) <= rtol * max(abs(a), abs(b))
    return a == b


def strata(cfg, record: Record) -> dict[str, list[tuple[Run, dict]]]:
    """The recorded (run, row) pairs of an experiment, or of each universe of a multiverse (its runs of
    every experiment it re-runs), by the name of the stratum."""
    from replication.runner.config import expand
    from replication.runner.multiverse import load

    if "multiverse" not in cfg.experiment:
        return {cfg.experiment.name: record.found(expand(cfg))}
    multiverse = load(cfg)
    return {f"{multiverse.name} {universe.name}":
            [pair for name in multiverse.experiments
             for pair in record.universe(multiverse.name, universe.name).found(multiverse.runs[universe.name, name])]
            for universe in multiverse.universes}


def verify(cfgs: list, record: Record, n: int | None, cheapest: bool, rtol: float, n_jobs: int,
           progress: bool = True) -> list[Difference]:
    """Re-compute a sample of the record's runs of ``cfgs`` (composed at the paper scale: experiments, and
    multiverses, each universe a stratum); the differences."""
    recorded = {name: pairs for cfg in cfgs for name, pairs in strata(cfg, record).items() if pairs}
    chosen = sample(recorded, n, cheapest)
    differences = []
    with tempfile.TemporaryDirectory(prefix="verify-") as scratch:
        for name in dict.fromkeys(run.experiment for run, _ in chosen):
            pairs = [(run, row) for run, row in chosen if run.experiment == name]
            store = Store(scratch, name)
            execute(list({run.run_id: run for run, _ in pairs}.values()), store, n_jobs=n_jobs, progress=progress)
            for run, row in pairs:
                now = store.read(run)
                now = now if now is not None else {"failure": store.failure_path(run).read_text().strip()}
                columns = compare(row, now, rtol)
                if columns:
                    differences.append(Difference(run, columns))
                    print(differences[-1].line(), flush=True)
    stale = sum(row["run_key"] != run.key for run, row in chosen)
    print(f"verified {len(chosen)} recorded runs of {len(recorded)} experiments and universes"
          + (f" ({stale} made by other code than this)" if stale else "") + ": "
          + (f"{len(differences)} differ" if differences else "all identical"))
    return differences


def recomputed(cfgs: list, store_root: Path, record: Record) -> dict[str, dict]:
    """Per experiment of ``cfgs`` (at any scale), its stored runs that are recorded runs (the same identity
    and key: the same resolved config, seed and code), compared with the record: how many, and a line
    per differing run.  Nothing is computed."""
    from replication.runner.config import expand

    found = {}
    for cfg in (cfg for cfg in cfgs if "multiverse" not in cfg.experiment):  # a quick universe is no paper one
        store, lines, compared = Store(store_root, cfg.experiment.name), [], 0
        for run, row in record.found(expand(cfg)):
            now = store.read(run) if row["run_key"] == run.key else None
            if now is not None:
                compared += 1
                columns = compare(row, now)
                lines += [Difference(run, columns).line()] if columns else []
        found[cfg.experiment.name] = {"compared": compared, "differ": lines}
    return found


def write_recomputed(found: dict[str, dict], out: Path) -> None:
    """Write :func:`recomputed`'s finding for the index and print it: a line per differing run and the total.
    A difference is a finding the index shows at its top, not a failed command (make replicate goes on)."""
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(found, indent=1) + "\n")
    lines = [line for entry in found.values() for line in entry["differ"]]
    print(*lines, sep="\n", end="\n" if lines else "")
    compared = sum(entry["compared"] for entry in found.values())
    outcome = f"{len(lines)} differ" if lines else "all identical"
    print((f"this machine re-computed {compared} recorded runs: {outcome}" if compared
           else "no stored run is a recorded run (other configs or code)") + f" ({out})")


def main(argv: list[str]) -> None:
    if {"--help", "-h"} & set(argv):
        print(__doc__.strip())
        return
    from hydra import compose, initialize_config_dir

    from replication.paths import CONF_DIR, resolve

    changes = [arg for arg in argv if arg.lstrip("+~").startswith("experiment.")]  # the experiments' own settings
    options = dict(arg.partition("=")[::2] for arg in argv if arg not in changes)
    unknown = sorted(set(options) - set(SETTINGS))
    if unknown:
        fail(f"unknown setting {unknown[0]!r}; verify takes {', '.join(f'{k}=' for k in SETTINGS)}")
    try:
        n = None if options.get("N", "200") == "all" else _positive(options.get("N", "200"), "N")
        rtol, n_jobs = _tolerance(options.get("rtol", "0")), _positive(options.get("n_jobs", "2"), "n_jobs")
    except ValueError as error:
        fail(f"verify: {error}")
    paths = [f"{k}={options[k]}" for k in ("store", "reports", "record") if k in options]
    with initialize_config_dir(config_dir=str(CONF_DIR), version_base="1.3"):
        cfg = compose("config", overrides=paths)
        folder = resolve(cfg.record)
        manifest = Manifest.read(folder)
        if not manifest.experiments:
            fail(f"{folder}: no record here (make record writes one from a paper-scale store)")
        damaged = manifest.damaged(folder)
        if damaged:
            fail(f"{folder}: {', '.join(damaged)} no longer match the manifest's SHA-256")
        names = options["experiment"].split(",") if options.get("experiment") else sorted(manifest.experiments)
        missing = sorted(set(names) - set(manifest.experiments))
        if missing:
            fail(f"the record holds no {missing[0]!r}; it holds {', '.join(sorted(manifest.experiments))}")
        scale = options.get("scale", "paper")
        cfgs = [compose("config", overrides=[f"experiment={name}", f"scale={scale}", *paths, *changes])
                for name in names]
    try:
        if options.get("against") == "store":  # the store's runs that are recorded ones, compared
            found = recomputed(cfgs, resolve(cfg.store), Record(folder))
            return write_recomputed(found, resolve(cfg.reports) / PAGES / RECOMPUTED)
        elif "against" in options:
            fail(f"against= takes store (compare the store's runs with the record), got {options['against']!r}")
        else:
            differences = verify(cfgs, Record(folder), n, options.get("cheapest", "false") == "true", rtol,
                                 n_jobs, progress=options.get("progress", "true") == "true")
    except ConfigError as error:
        fail(str(error))
    if differences:
        sys.exit(1)


def _positive(text: str, name: str) -> int:
    if not text.isdigit() or int(text) <= 0:
        raise ValueError(f"{name} must be a positive integer, got {text!r}")
    return int(text)


def _tolerance(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        value = -1.0
    if not 0 <= value < 1:
        raise ValueError(f"rtol must be a number in [0, 1), got {text!r}")
    return value


def _short(value) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."
