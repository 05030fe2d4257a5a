"""The checks a request passes before any work starts.

Each raises :class:`ConfigError` with one line naming the bad key: a value of
the wrong type for the filter it goes to, an unknown ``parallel.*`` key or
backend, an OTB scene whose folder does not exist.  :func:`prepare` runs them
all and expands the experiment into its runs.
"""

import inspect
import types
import typing

from omegaconf import DictConfig, OmegaConf

from replication.errors import ConfigError
from replication.filters.registry import builder
from replication.paths import resolve
from replication.run import Run
from replication.runner.config import expand
from replication.scales import at_scale
from replication.runner.execute import BackendError, check_backend

RESERVED_METHOD_KEYS = ("filter", "label", "sweep", "only", "observation")  # read by expand, not by the filter
PARALLEL_KEYS = ("backend", "address")


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
    if not isinstance(cfg.experiment.get("methods"), DictConfig):
        return  # expand says what is wrong
    methods = at_scale(OmegaConf.to_container(cfg.experiment.methods, resolve=True), cfg.scale)
    for method, params in methods.items():
        if not isinstance(params, dict) or "filter" not in params:
            continue  # expand says what is wrong
        declared = _declared_types(builder(params["filter"]))
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
    if cfg.get("claims_dir"):  # a user's own claims: read now, so a broken file stops nothing half-run
        from replication.evidence.claims import load_own_papers

        load_own_papers(resolve(str(cfg.claims_dir)))
    check_scenes(cfg)
    skipped: list[str] = []
    runs = expand(cfg, skipped)
    if not runs:
        why = "; ".join(s.removeprefix(f"{cfg.experiment.name}: ").removesuffix(": skipped") for s in skipped)
        why = f": {why}" if why else ""
        raise ConfigError(f"{cfg.experiment.name}: nothing to run (every condition was skipped{why})")
    return runs, skipped + tables_without_runs(cfg, runs), settings


def tables_without_runs(cfg: DictConfig, runs: list[Run]) -> list[str]:
    """A line for each report table whose conditions (the keys of its ``match:``) no run of this request
    has (bis_pf run without its 3123 scene): said before any work, the page then leaves the table out."""
    tables = OmegaConf.to_container(cfg.experiment, resolve=True).get("report", {}).get("tables", [])
    ran = {str(run.condition) for run in runs}
    return [f"{cfg.experiment.name}: table {spec['name']} needs {' or '.join(spec['match'])}, which no run of "
            f"this request has: its page will leave it out" for spec in tables
            if spec.get("match") and not ran & set(spec["match"])]
