"""Command line: check the request, run what is missing, write the experiment's report.

Errors a user can fix (unknown experiment or key, a value of the wrong type,
a bad backend or data path) are one line on stderr and exit status 2, before
any work starts; never a Hydra traceback.  Ctrl-C (SIGINT) stops the workers,
keeps every run already stored and exits with status 130 and one line.
"""

import inspect
import os
import re
import signal
import subprocess
import sys
import types
import typing

import hydra
from omegaconf import DictConfig, OmegaConf

from replication.paths import CONF_DIR, experiment_names, resolve
from replication.runner.config import ConfigError, Run, at_scale, expand
from replication.runner.execute import BackendError, check_backend, execute
from replication.runner.store import Store

RESERVED_METHOD_KEYS = ("filter", "label", "sweep", "only", "observation")  # read by expand, not by the filter
PARALLEL_KEYS = ("backend", "address")


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


def parallel_settings(cfg: DictConfig) -> tuple[str, int, str | None]:
    """``(backend, n_jobs, address)`` from ``parallel.*`` and ``n_jobs``, checked."""
    parallel = cfg.get("parallel") or {}
    if not isinstance(parallel, (dict, DictConfig)):
        raise ConfigError(f"parallel must hold backend and address (parallel.backend=dask), got {parallel!r}")
    unknown = sorted(set(parallel) - set(PARALLEL_KEYS))
    if unknown:
        raise ConfigError(f"unknown key parallel.{unknown[0]}; parallel takes {', '.join(PARALLEL_KEYS)}")
    backend = parallel.get("backend") or "loky"
    n_jobs = cfg.get("n_jobs", 2)
    if isinstance(n_jobs, bool) or not isinstance(n_jobs, int) or n_jobs == 0:
        raise ConfigError(f"n_jobs must be a positive number of workers or -1 for all cores, got {n_jobs!r}")
    address = parallel.get("address")
    try:
        check_backend(backend, address)
    except BackendError as error:
        raise ConfigError(str(error)) from None
    return backend, n_jobs, address


def check_method_parameters(cfg: DictConfig) -> None:
    """Each method parameter against the type its filter declares (``n_particles: int``),
    so that ``n_particles=abc`` names the key instead of failing inside ``int()``."""
    from replication.filters import FILTERS

    if not isinstance(cfg.experiment.get("methods"), DictConfig):
        return  # expand says what is wrong
    methods = at_scale(OmegaConf.to_container(cfg.experiment.methods, resolve=True), cfg.scale)
    for method, params in methods.items():
        if not isinstance(params, dict) or params.get("filter") not in FILTERS:
            continue
        declared = _declared_types(FILTERS[params["filter"]])
        values = [
            (f"experiment.methods.{method}.{k}", k, v) for k, v in params.items() if k not in RESERVED_METHOD_KEYS
        ]
        sweep = params.get("sweep")
        if isinstance(sweep, dict):
            values += [
                (f"experiment.methods.{method}.sweep.{k}", k, v)
                for k, vs in sweep.items() if isinstance(vs, list) for v in vs
            ]
        for key, name, value in values:
            wanted = _type_mismatch(value, declared.get(name))
            if wanted:
                raise ConfigError(f"{key} must be {wanted}, got {value!r}")


def _declared_types(builder) -> dict[str, typing.Any]:
    try:
        parameters = inspect.signature(builder, eval_str=True).parameters
    except (NameError, TypeError, ValueError):
        return {}
    return {name: p.annotation for name, p in parameters.items() if p.annotation is not p.empty}


SIMPLE_TYPES = {bool: "true or false", int: "an integer", float: "a number", str: "a string"}


def _type_mismatch(value: typing.Any, declared: typing.Any) -> str | None:
    """What ``value`` should have been if it does not fit ``declared``; None if it fits or if
    ``declared`` is not a simple type (or an optional one)."""
    if typing.get_origin(declared) in (typing.Union, types.UnionType):
        members = typing.get_args(declared)
        if value is None and type(None) in members:
            return None
        members = [m for m in members if m is not type(None)]
        if len(members) != 1:
            return None
        declared = members[0]
    if declared not in SIMPLE_TYPES:
        return None
    fits = {
        bool: isinstance(value, bool),
        int: isinstance(value, int) and not isinstance(value, bool),
        float: isinstance(value, (int, float)) and not isinstance(value, bool),
        str: isinstance(value, str),
    }[declared]
    return None if fits else SIMPLE_TYPES[declared]


def check_scenes(cfg: DictConfig) -> None:
    """An OTB scene names its sequence, and a ``root:`` given for it exists.

    (A sequence absent from the shared OTB folder is not an error: its
    conditions are skipped, so the suite runs on machines without the data.)
    """
    from replication.scenes.otb import OTB_ROOT

    if not isinstance(cfg.experiment.get("scenes"), DictConfig):
        return
    scenes = at_scale(OmegaConf.to_container(cfg.experiment.scenes, resolve=True), cfg.scale)
    for name, spec in scenes.items():
        if not isinstance(spec, dict) or spec.get("kind") != "otb":
            continue
        if not isinstance(spec.get("name"), str) or not spec["name"]:
            raise ConfigError(f"experiment.scenes.{name}.name: an OTB scene names its sequence (e.g. name: Girl)")
        if "root" in spec:
            root = resolve(str(spec["root"]))
            if not root.is_dir():
                raise ConfigError(
                    f"experiment.scenes.{name}.root: no folder {root} (leave root out for the shared {OTB_ROOT})"
                )


def prepare(cfg: DictConfig) -> tuple[list[Run], list[str], tuple[str, int, str | None]]:
    """Everything checked before any work: ``(runs, skipped, (backend, n_jobs, address))``.

    Raises :class:`ConfigError` with a one-line message naming the bad key.
    """
    settings = parallel_settings(cfg)
    check_method_parameters(cfg)
    check_scenes(cfg)
    skipped: list[str] = []
    runs = expand(cfg, skipped)
    if not runs:
        why = "; ".join(s.removeprefix(f"{cfg.experiment.name}: ").removesuffix(": skipped") for s in skipped)
        why = f": {why}" if why else ""
        raise ConfigError(f"{cfg.experiment.name}: nothing to run (every condition was skipped{why})")
    return runs, skipped, settings


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
        check_experiment_argument(argv)
        check_overrides(argv)
        run_experiment()
    except KeyboardInterrupt:
        interrupted()

