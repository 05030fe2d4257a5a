"""``pf-replicate [run|report|scenes|export|record|verify|diff|findings] key=value ...`` (or ``python -m replication``): the one
entry point.

``run`` (the default) checks the request, runs what is missing and writes the experiment's report;
``report`` redraws reports from stored runs (:mod:`replication.report.__main__`); ``scenes`` writes
an experiment's synthetic scenes as video (:mod:`replication.scenes.__main__`); ``export`` writes a
tracking experiment's runs in the OTB and GOT-10k toolkits' result layouts (:mod:`replication.export`);
``record`` writes the paper-scale record from the store and ``verify`` re-computes a sample of it,
grades it (:mod:`replication.record`) and judges the verdicts again with it; ``diff A B`` lists the
claims and cells whose verdict or estimate differ between two records or reports
(:mod:`replication.report.diff`); ``findings`` renders each paper's findings from the record into
``docs/findings/`` (:mod:`replication.report.findings`).

Errors a user can fix (an unknown command, experiment or key, a value of the wrong type or out of range, a
broken experiment file, an output folder outside the project or not writable) are one line on
stderr and exit status 2 before anything heavy is imported or written; never a Hydra traceback.
Ctrl-C (SIGINT) and SIGTERM stop the workers, keep every run already stored and exit with one line
and status 130 (143 after SIGTERM); no worker or companion outlives this process, however it ends.
Runs whose numbers are not finite are recorded as failed, named with their count, and make the
command exit with status 3.
"""

import importlib
import os
import re
import signal
import subprocess
import sys
from pathlib import Path
from typing import TYPE_CHECKING

import hydra
from omegaconf import DictConfig

from replication import __version__
from replication.arguments import names
from replication.atomic import DiskFull
from replication.errors import ConfigError, fail
from replication.evidence.settings import configure
from replication.paths import CONF_DIR, HOME_VARIABLE, experiment_names, project_dir, resolve
from replication.runner.lifeline import (
    child_environment, exit_uncollected, interrupt_status, stop_children, stop_on_sigterm,
    watch_parent_from_environment,
)
from replication.runner.preflight import check_yaml, preflight

if TYPE_CHECKING:  # imported where they are used: the numerical stack loads after the checks that need none
    from replication.run import Run
    from replication.runner.store import Store

HYDRA_FLAGS = ("--help", "-h", "--hydra-help", "--info", "-i", "--cfg", "-c", "--shell-completion", "-sc")
MULTIRUN_FLAGS = ("--multirun", "-m")
FLAGS_WITH_VALUES = ("--config-dir", "-cd", "--config-path", "-cp", "--config-name", "-cn")  # Hydra's: the next word
# each subcommand's function of argv, imported only when chosen
SUBCOMMANDS = {
    "run": "replication.cli:run",
    "report": "replication.report.__main__:main",
    "scenes": "replication.scenes.__main__:main",
    "export": "replication.export:main",
    "record": "replication.record.__main__:main",
    "verify": "replication.cli:verify",
    "diff": "replication.report.diff:main",
    "findings": "replication.report.__main__:findings",
}

COMMAND_LIKE = re.compile(r"[A-Za-z][\w-]*")  # a first word that is no key=value, +key, ~key or flag


def config_dirs(argv: list[str]) -> list[Path]:
    """The folders Hydra's ``--config-dir`` / ``-cd`` adds to the config search path (a user's own experiments)."""
    found = []
    for i, arg in enumerate(argv):
        if arg.startswith("--config-dir="):
            found.append(Path(arg.split("=", 1)[1]))
        elif arg in ("--config-dir", "-cd") and i + 1 < len(argv):
            found.append(Path(argv[i + 1]))
    return found


def experiment_file(name: str, argv: list[str]) -> Path:
    """The YAML file Hydra will read for ``experiment=name`` (a ``--config-dir``'s first)."""
    for folder in (*config_dirs(argv), CONF_DIR):
        path = Path(folder) / "experiment" / f"{name}.yaml"
        if path.exists():
            return path
    raise ConfigError(f"unknown experiment {name!r}; known: {', '.join(experiment_names(*config_dirs(argv)))}")


def chosen_experiments(argv: list[str]) -> dict[str, dict]:
    """The experiments the command line names (several in a multirun), each checked to exist and to
    parse, with its file as written; none for Hydra's own flags, which describe the app rather than run it."""
    chosen = [arg.partition("=")[2] for arg in argv if arg.startswith("experiment=")]
    if not chosen and any(arg in HYDRA_FLAGS for arg in argv):
        return {}
    if not chosen:
        known = ", ".join(experiment_names(*config_dirs(argv)))
        raise ConfigError(f"name an experiment: pf-replicate experiment=<name>; known: {known}")
    return {name: check_yaml(experiment_file(name, argv)) for name in names(chosen[-1])}


def own_claims(argv: list[str]) -> list[str]:
    """``claims_dir=<folder>/claims`` where a ``--config-dir`` folder holds a ``claims/`` folder and the request
    names no ``claims_dir=`` itself: a user's experiments and their claims sit side by side."""
    if any(arg.startswith("claims_dir=") for arg in argv):
        return []
    found = [folder / "claims" for folder in config_dirs(argv) if (folder / "claims").is_dir()]
    return [f"claims_dir={found[0].resolve()}"] if found else []


def check_request(argv: list[str]) -> None:
    """Compose the config as Hydra will and check it (:mod:`replication.runner.preflight`), so that
    a bad override (an unknown key written without ``+``, a malformed or out-of-range value) is one
    line rather than Hydra's multi-line report or a failure after work has started."""
    from hydra import compose, initialize_config_dir
    from hydra.errors import HydraException

    written = chosen_experiments(argv)
    if not written or any(arg in HYDRA_FLAGS for arg in argv):
        return
    multirun = any(arg in MULTIRUN_FLAGS for arg in argv)
    flag_values = {i + 1 for i, arg in enumerate(argv) if arg in FLAGS_WITH_VALUES}
    overrides = [
        arg for i, arg in enumerate(argv)
        if i not in flag_values and not arg.startswith(("-", "experiment="))
        and not arg.lstrip("+~").startswith(("hydra.", "hydra/"))
        and not (multirun and "," in arg)  # a multirun's sweep: each of its values is a job of its own
    ]
    dirs = [str(Path(d).resolve()) for d in config_dirs(argv)]
    searchpath = [f"hydra.searchpath=[{','.join(f'file://{d}' for d in dirs)}]"] if dirs else []
    for name in written:
        try:
            with initialize_config_dir(config_dir=str(CONF_DIR), version_base="1.3"):
                cfg = compose("config", overrides=[f"experiment={name}", *overrides, *searchpath])
        except HydraException as error:
            lines = [line.strip() for line in str(error).splitlines() if line.strip()]
            unknown = re.fullmatch(r"Could not override '(.+)'\.", lines[0]) if lines else None
            if unknown:
                key = unknown[1]
                raise ConfigError(
                    f"unknown key {key!r} (check the spelling; a key the config lacks is added as +{key}=...)"
                ) from None
            raise ConfigError(" ".join(lines) or error.__class__.__name__) from None
        preflight(cfg, written[name])


def interrupted(held: "list[tuple[Store, list[Run]]] | None" = None) -> None:
    """The one line of a Ctrl-C or SIGTERM, and exit status 128 + the signal (130, 143) as shells expect: how
    many of the request's runs (each with the store that holds it, in ``held``) are stored, whenever they were."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # a second Ctrl-C while we count must not print a traceback
    stop_children()
    if held is None:
        print("interrupted: rerun the same command to resume", file=sys.stderr)
    else:
        print(f"interrupted: {stored(held)} runs stored, rerun the same command to resume", file=sys.stderr)
    raise SystemExit(interrupt_status())


def stored(held: "list[tuple[Store, list[Run]]]") -> int:
    """How many distinct runs of ``held`` (runs, each list with the store that is to hold it) are stored: a run
    two universes share, or an experiment's runs listed twice, counted once."""
    return len({path for store, runs in held for run in runs if (path := store.path(run)).exists()})


def draw_experiment(cfg: DictConfig, runs: list, held) -> None:
    """The experiment's report from its runs (``held``: the store's, and the record's beneath them), judged
    (evidence), then drawn (report), and the index with its new summary."""
    from hydra.core.hydra_config import HydraConfig

    from replication.evidence.scorecard import Scorecard
    from replication.report.experiments import write_experiment
    from replication.report.pages.index import write_index
    from replication.runner.results import Results

    results = Results.of(cfg, runs, held, tuple(HydraConfig.get().overrides.task), held.curves)
    written = write_experiment(cfg, results)
    # the scorecard with this experiment's new summary, against the same published values as the page
    index = write_index(resolve(cfg.reports), Scorecard.read(resolve(cfg.reports), cfg.published_values))
    print(f"{cfg.experiment.name}: report in {written}; index in {index}")


@hydra.main(config_path=str(CONF_DIR), config_name="config", version_base="1.3")
def run_experiment(cfg: DictConfig) -> None:
    # the numerical stack is imported here, after every check that does not need it has passed
    from replication.record.layer import beneath, missing, said
    from replication.runner.backends import BackendError
    from replication.runner.execute import execute
    from replication.runner.failures import exit_if_failed
    from replication.runner.store import Store
    from replication.runner.validate import prepare
    from replication.runner.variant import differences, report_name

    if "multiverse" in cfg.experiment:
        return run_multiverse(cfg)
    try:
        runs, skipped, (backend, n_jobs, address) = prepare(cfg)
        configure(cfg.inference)  # before any run: a mistyped setting fails now, not after hours of runs
        reported_as = report_name(cfg, differences(cfg))  # a bad label fails now too
    except ConfigError as error:
        fail(str(error))
    if reported_as != cfg.experiment.name:
        what = ("this request changes the shipped experiment (your data or settings)"
                if cfg.experiment.name in experiment_names() else "your own experiment")
        named = "" if cfg.get("label") else " (a digest of what it changes; label=<name> names it)"
        print(f"{cfg.experiment.name}: {what}: reported as {reported_as}{named}, judging no paper claim"
              + (f" (your own claims in {cfg.claims_dir})" if cfg.get("claims_dir") else ""))
    for message in skipped:
        print(f"skipped: {message}", file=sys.stderr)
    store = Store(resolve(cfg.store), cfg.experiment.name)
    held = beneath(cfg, runs, store)  # at paper scale, the record's runs beneath the store
    if note := missing(cfg):
        print(note, file=sys.stderr)
    if cfg.dry_run:
        plan(cfg, runs, held, n_jobs)
        if reported_as == cfg.experiment.name:  # as a run does: a changed experiment runs without its companions
            run_companions(cfg)
        return
    if held.recorded:
        print(said(cfg.experiment.name, [held], len(runs)), flush=True)
    try:
        computed = held.computed(runs)
        done = execute(computed, store, n_jobs=n_jobs, backend=backend, progress=cfg.progress, address=address)
        stored = len(computed) - done
        print(f"{cfg.experiment.name}: {done} runs computed, {stored} already stored in {store.directory}"
              + (f", {len(held.recorded)} read from the record" if held.recorded else ""))
        if cfg.draw:
            draw_experiment(cfg, runs, held)
        if reported_as != cfg.experiment.name and cfg.experiment.get("also"):
            print(f"skipped: {', '.join(cfg.experiment.also)}, run beside {cfg.experiment.name} as shipped, since "
                  "this request changes it (your data or settings); run one by name if you want it", file=sys.stderr)
        else:
            run_companions(cfg)
        exit_if_failed(held, runs)
    except (BackendError, DiskFull) as error:  # the store's (StoreFull) or the reports'
        fail(str(error))
    except MemoryError as error:  # beyond the lower bound the checks hold to (replication.runner.bounds)
        fail(f"{cfg.experiment.name}: a run ran out of memory ({error}): ask for fewer particles or fewer workers "
             "(n_jobs)")
    except KeyboardInterrupt:
        interrupted([(store, runs)])


def plan(cfg: DictConfig, runs: list, held, n_jobs: int) -> None:
    """``dry_run=true``: how many runs the request has, how many are stored and how many read from the record
    (``held``, :class:`~replication.record.layer.Layered`), and roughly how long the rest would take
    (:func:`~replication.runner.execute.forecast`, from the times of the runs stored or recorded); nothing is
    run or written."""
    from replication.runner.execute import forecast

    computed = held.computed(runs)
    pending = [run for run in computed if not (held.store.path(run).exists() or held.store.failure_path(run).exists())]
    name = cfg.experiment.name
    print(f"{name}: {len(runs):,} runs at the {cfg.scale} scale: {len(computed) - len(pending):,} stored, "
          f"{len(held.recorded):,} read from the record, {len(pending):,} to compute")
    if pending:
        print(forecast(runs, pending, held, n_jobs))
    print(f"{name}: a dry run: nothing computed or written (without dry_run=true this request runs)", flush=True)


def run_multiverse(cfg: DictConfig) -> None:
    """Run every universe of a paper's multiverse (:mod:`replication.runner.multiverse`) into its base
    experiments' stores, then write its report and the index."""
    from replication.record.layer import missing, reader, said, universes_beneath
    from replication.runner.backends import BackendError
    from replication.runner.execute import execute
    from replication.runner.multiverse import load
    from replication.runner.validate import parallel_settings

    try:
        multiverse = load(cfg)
        backend, n_jobs, address = parallel_settings(cfg)
        configure(cfg.inference)
    except ConfigError as error:
        fail(str(error))
    for message in multiverse.skipped:
        print(f"skipped: {message}", file=sys.stderr)
    name = cfg.experiment.name
    distinct = sum(len(multiverse.runs_of(experiment)) for experiment in multiverse.experiments)
    print(f"{name}: {len(multiverse.universes)} universes of {len(multiverse.choices)} choices, "
          f"{distinct} distinct runs")
    recorded, layers = universes_beneath(cfg, multiverse)
    if note := missing(cfg):
        print(note, file=sys.stderr)
    if (read := said(name, list(layers.values()), distinct)) and not cfg.dry_run:
        print(read, flush=True)
    print(multiverse_forecast(cfg, multiverse, recorded, n_jobs, layers), flush=True)
    if cfg.dry_run:
        counted = ", ".join(f"{len(runs):,} {where}" for where, runs in universes_left(cfg, multiverse, recorded,
                                                                                        layers).items())
        print(f"{name}: {len(recorded)} of {len(multiverse.universes)} universes read whole from the record; of "
              f"the others' runs {counted}")
        print(f"{name}: a dry run: nothing computed or written (without dry_run=true this request runs)")
        return
    try:
        # universe by universe, the default first: a multiverse stopped part-way (a session's end, a Ctrl-C)
        # leaves whole universes, which the record takes one by one (replication.record.write)
        for number, universe in enumerate(multiverse.universes, 1):
            where = f"{name}: universe {number}/{len(multiverse.universes)} ({universe.name})"
            if universe.name in recorded:
                print(f"{where}: in the record as this code computes it (skip_recorded=false runs it)", flush=True)
                continue
            for experiment in multiverse.experiments:
                held = layers[universe.name, experiment]
                runs = held.computed(multiverse.runs[universe.name, experiment])
                done = execute(runs, held.store, n_jobs=n_jobs, backend=backend, progress=cfg.progress, address=address)
                print(f"{where}: {experiment}: {done} runs computed, {len(runs) - done} already stored"
                      + (f", {len(held.recorded)} read from the record" if held.recorded else ""), flush=True)
        if cfg.draw:
            from hydra.core.hydra_config import HydraConfig

            from replication.evidence.scorecard import Scorecard
            from replication.report.experiments import write_multiverse
            from replication.report.pages.index import write_index

            written = write_multiverse(cfg, multiverse, tuple(HydraConfig.get().overrides.task),
                                       reader(recorded, layers))
            index = write_index(resolve(cfg.reports), Scorecard.read(resolve(cfg.reports), cfg.published_values))
            print(f"{name}: report in {written}; index in {index}")
    except (BackendError, DiskFull) as error:  # the store's (StoreFull) or the reports'
        fail(str(error))
    except KeyboardInterrupt:  # a universe's runs may be another's: each counted once
        interrupted([(held.store, held.computed(multiverse.runs[universe, experiment]))
                     for (universe, experiment), held in layers.items()])


def multiverse_forecast(cfg: DictConfig, multiverse, recorded: dict, n_jobs: int, layers: dict | None = None) -> str:
    """How many of the multiverse's runs are left to compute (neither in the store nor in a universe read from
    the record, nor read from the record beneath the store: ``layers``, a
    :class:`~replication.record.layer.Layered` per universe and experiment) and, at paper scale, roughly how
    long: each at the mean time the record gives its method and condition in the default universe (the base
    experiments), over the workers."""
    from joblib import effective_n_jobs

    from replication.record.runs import Record
    from replication.runner.execute import duration

    left = universes_left(cfg, multiverse, recorded, layers)["to compute"]
    said = f"{multiverse.name}: {len(left):,} runs to compute"
    base = [run for experiment in multiverse.experiments for run in multiverse.runs["default", experiment]]
    record = Record(resolve(cfg.record))  # the base experiments' records, else the default universe's
    times = {**record.seconds(base), **record.universe(multiverse.name, "default").seconds(base)} \
        if cfg.scale == "paper" and left else {}
    timed = [times[key] for key in ((r.experiment, r.method, str(r.condition)) for r in left.values()) if key in times]
    if not timed:
        return said
    workers = min(effective_n_jobs(n_jobs), len(left))
    unknown = f"; {len(left) - len(timed):,} with no recorded time not counted" if len(timed) < len(left) else ""
    return (f"{said}, about {duration(sum(timed) / workers)} on {workers} worker(s) (from the record's times of "
            f"the same methods and conditions{unknown})")


def universes_left(cfg: DictConfig, multiverse, recorded: dict, layers: dict | None = None) -> dict[str, dict]:
    """The distinct runs of the universes not read whole from the record (``recorded``), by where they are:
    ``stored`` (a file's presence, not its soundness: a forecast reads no records), ``read from the record``
    beneath the store (``layers``, per universe and experiment) and ``to compute``, each by experiment and run
    id."""
    from replication.runner.store import Store

    found = {"stored": {}, "read from the record": {}, "to compute": {}}
    for universe in multiverse.universes:
        for experiment in multiverse.experiments if universe.name not in recorded else ():
            store, layer = Store(resolve(cfg.store), experiment), (layers or {}).get((universe.name, experiment))
            for run in multiverse.runs[universe.name, experiment]:
                where = ("stored" if store.path(run).exists() or store.failure_path(run).exists() else
                         "read from the record" if layer and run.run_id in layer.recorded else "to compute")
                found[where][experiment, run.run_id] = run
    return found


def run_companions(cfg: DictConfig) -> None:
    """Run the experiments a paper's main one names in ``also:`` (e.g. hspf's UNGM half), with the same
    settings except those addressed to this experiment (``experiment.*``, its ``sequences=``)."""
    own = ("experiment=", "experiment.", "+experiment.", "~experiment.", "sequences=", "-")
    shared = [a for a in sys.argv[1:] if not a.startswith(own)]
    for name in cfg.experiment.get("also", []) or []:
        print(f"{cfg.experiment.name}: also {name}")
        status = subprocess.run([sys.executable, "-m", "replication", f"experiment={name}", *shared],
                                env=child_environment()).returncode
        if status:
            raise SystemExit(status)


# loky's resource tracker (a child process) warns about semaphores its killed workers leaked: after a
# Ctrl-C, or a clean stop, that is noise on the user's terminal, not a problem with the results.
QUIET_CHILDREN = "ignore::UserWarning:joblib.externals.loky.backend.resource_tracker"


def run(argv: list[str]) -> None:
    """``pf-replicate [run] experiment=<name> ...``: check everything, then hand over to Hydra."""
    if "--version" in argv:
        print(f"pf-replicate {__version__}")
        return
    argv = [*argv, *own_claims(argv)]
    try:
        check_request(argv)
    except ConfigError as error:
        fail(str(error))
    sys.argv = [sys.argv[0], *argv]  # Hydra reads the command line itself
    run_experiment()


def verify(argv: list[str]) -> None:
    """``pf-replicate verify ...``: the record's runs re-computed and graded (:mod:`replication.record.verify`),
    then its verdicts judged again with them (:func:`replication.report.diff.verdicts`): above both layers."""
    from replication.record.verify import main as recompute
    from replication.report.diff import verdicts

    recompute(argv, verdicts)


def main(argv: list[str] | None = None) -> None:
    argv = sys.argv[1:] if argv is None else argv
    if QUIET_CHILDREN not in os.environ.get("PYTHONWARNINGS", ""):
        os.environ["PYTHONWARNINGS"] = ",".join(filter(None, [os.environ.get("PYTHONWARNINGS"), QUIET_CHILDREN]))
    os.environ[HOME_VARIABLE] = str(project_dir())  # workers and companions resolve paths as we do
    stop_on_sigterm()
    watch_parent_from_environment()  # a companion experiment ends with the runner that started it
    if argv and argv[0] not in SUBCOMMANDS and COMMAND_LIKE.fullmatch(argv[0]):  # a word: no setting, no flag
        fail(f"unknown command {argv[0]!r}; commands: {', '.join(SUBCOMMANDS)} (pf-replicate --help)")
    command, argv = (argv[0], argv[1:]) if argv and argv[0] in SUBCOMMANDS else ("run", argv)
    try:
        module, function = SUBCOMMANDS[command].split(":")
        getattr(importlib.import_module(module), function)(argv)
    except DiskFull as error:  # a report, the record or an export: the folder named, its files whole
        fail(str(error))
    except KeyboardInterrupt:
        interrupted()
    finally:
        exit_uncollected()
