"""The checks a request passes before any work starts.

Each raises :class:`ConfigError` with one line naming the bad key: a value of
the wrong type for the filter it goes to, a look no figure can draw, an unknown
``parallel.*`` key or backend, a scene of an unknown kind or a real one whose folder
does not exist or whose frames and ground truth do not pair up (the missing frames named), a table, figure
or claim's test of an unknown kind or with an option its kind does not take, a condition a
table, a figure or a claim names that no run of the experiment has.  :func:`prepare`
runs them all and expands the experiment into its runs.
"""

import inspect
import types
import typing
from pathlib import Path

from omegaconf import DictConfig, OmegaConf

from replication.condition import Condition
from replication.errors import ConfigError
from replication.evidence.curves import figure_conditions
from replication.evidence.figures import FigureSpec, figure_specs
from replication.evidence.named_conditions import holds, written
from replication.evidence.tables import Compared, TableSpec, matched, table_specs
from replication.display import asked_look
from replication.filters.registry import RESERVED, builder
from replication.paths import experiment_names, resolve
from replication.run import Run
from replication.runner.config import expand, experiment_at_scale, planned
from replication.scales import at_scale
from replication.runner.backends import BackendError, check_backend
from replication.runner.variant import as_shipped

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
    so that ``n_particles=abc`` names the key instead of failing inside ``int()``, and the
    method's look (its own over its filter's, :mod:`replication.display`)."""
    if not isinstance(cfg.experiment.get("methods"), DictConfig):
        return  # expand says what is wrong
    methods = at_scale(OmegaConf.to_container(cfg.experiment.methods, resolve=True), cfg.scale)
    for method, params in methods.items():
        if not isinstance(params, dict) or "filter" not in params:
            continue  # expand says what is wrong
        made = builder(params["filter"])
        where = f"experiment.methods.{method}.look" if "look" in params else f"filter {params['filter']!r}: drawn"
        asked_look(params, getattr(made, "look", None), where)
        declared = _declared_types(made)
        values = [(f"experiment.methods.{method}.{k}", k, v) for k, v in params.items() if k not in RESERVED]
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
    """Every scene is of a known kind, and a real one names its sequence and exists at a ``root:`` given.

    (A sequence absent from the shared folder is not an error: its
    conditions are skipped, so the suite runs on machines without the data.)
    """
    from replication.scenes.factory import scene_kind

    if not isinstance(cfg.experiment.get("scenes"), DictConfig):
        return
    scenes = at_scale(OmegaConf.to_container(cfg.experiment.scenes, resolve=True), cfg.scale)
    for name, spec in scenes.items():
        if not isinstance(spec, dict):
            continue
        try:
            kind = scene_kind(spec)
        except ConfigError as error:
            raise ConfigError(f"experiment.scenes.{name}.kind: {error}") from None
        if not kind.real:
            continue
        if not isinstance(spec.get("name"), str) or not spec["name"]:
            raise ConfigError(f"experiment.scenes.{name}.name: a scene of kind {kind.name} names its "
                              f"{kind.benchmark} sequence")
        if "root" in spec:
            root = resolve(str(spec["root"]))
            if not root.is_dir():
                raise ConfigError(
                    f"experiment.scenes.{name}.root: no folder {root} (leave root out for the shared {kind.root})"
                )


def check_frames(cfg: DictConfig) -> None:
    """Each OTB sequence the request reads has a frame for each ground-truth box, else one line naming the
    frames missing (:func:`unpaired`).  The sequence's reader checks the counts too (its line names none):
    this check, outside the code that computes runs, names them before it is reached.  A sequence that is
    absent, or whose ground truth does not read, is left to the reader, which skips or names it."""
    from replication.scenes.otb import GROUNDTRUTH_FILES, read_groundtruth

    for spec in (experiment_at_scale(cfg).get("scenes") or {}).values():
        if spec.get("kind") != "otb" or not isinstance(spec.get("name"), str):
            continue
        folder, name = GROUNDTRUTH_FILES.get(spec["name"], (spec["name"], "groundtruth_rect.txt"))
        directory = resolve(str(spec["root"])) / folder
        try:
            boxes = len(read_groundtruth(directory / name))
        except (OSError, ValueError):
            continue
        frames = sorted((directory / "img").glob("*.jpg"))
        if frames and len(frames) != boxes:
            raise ConfigError(unpaired(directory, frames, boxes))


def unpaired(directory: Path, frames: list[Path], boxes: int) -> str:
    """The line for frames and ground-truth boxes that do not pair up, naming the frames beyond the last box, or
    those missing: the gaps in the frames' numbering, then those past its end where it starts at 1 (as OTB's
    does; one that starts later may lack frames at either end)."""
    said = f"{directory}: {len(frames)} frames but {boxes} ground-truth boxes"
    if len(frames) > boxes:
        return f"{said}: {listed([f'img/{p.name}' for p in frames[boxes:]])} beyond the last box"
    numbers = sorted(int(p.stem) for p in frames if p.stem.isdigit())
    if not numbers:
        return said
    missing = sorted(set(range(numbers[0], numbers[-1] + 1)) - set(numbers))
    ends = boxes - len(frames) - len(missing)  # missing at the ends of the numbering
    if ends > 0 and numbers[0] == 1:
        missing, ends = missing + list(range(numbers[-1] + 1, numbers[-1] + 1 + ends)), 0
    width, suffix = len(frames[0].stem), frames[0].suffix
    names = [f"img/{n:0{width}d}{suffix}" for n in missing]
    at_ends = f"{ends} before img/{frames[0].name} or after img/{frames[-1].name}" if ends > 0 else ""
    return f"{said}: missing " + "; ".join(filter(None, [listed(names), at_ends]))


def listed(names: list[str], shown: int = 3) -> str:
    """The first ``shown`` of ``names``, and how many in all where there are more."""
    return ", ".join(names[:shown]) + (f" ... ({len(names)} in all)" if len(names) > shown else "")


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
    check_frames(cfg)
    check_report(cfg)
    check_conditions(cfg)
    skipped: list[str] = []
    runs = expand(cfg, skipped)
    if not runs:
        why = "; ".join(s.removeprefix(f"{cfg.experiment.name}: ").removesuffix(": skipped") for s in skipped)
        why = f": {why}" if why else ""
        raise ConfigError(f"{cfg.experiment.name}: nothing to run (every condition was skipped{why})")
    return runs, skipped + tables_without_runs(cfg, runs), settings


REPORT_KEYS = ("tables", "figures", "sequence_pages")


def report_specs(cfg: DictConfig) -> tuple[tuple[TableSpec, ...], tuple[FigureSpec, ...]]:
    """The experiment's report tables and figures as typed specs, each checked against its kind
    (:func:`~replication.evidence.tables.table_specs`, :func:`~replication.evidence.figures.figure_specs`):
    an unknown kind, key or option is one line naming the file, the entry and the options known."""
    file = f"experiment/{cfg.experiment.name}.yaml"
    experiment = experiment_at_scale(cfg)
    report = experiment.get("report") or {}
    unknown = sorted(set(report) - set(REPORT_KEYS)) if isinstance(report, dict) else []
    if unknown:
        raise ConfigError(f"{file}: unknown key report.{unknown[0]}; report takes {', '.join(REPORT_KEYS)}")
    return table_specs(experiment, file), figure_specs(experiment, file)


def check_report(cfg: DictConfig) -> None:
    """The report's specs (:func:`report_specs`), and the figures its ``sequence_pages`` name among them."""
    if "multiverse" in cfg.experiment:
        return  # its universes' reports are their experiments', checked as shipped
    _, figures = report_specs(cfg)
    pages = (experiment_at_scale(cfg).get("report") or {}).get("sequence_pages") or []
    unknown = sorted(set(pages) - {figure.name for figure in figures})
    if unknown:
        raise ConfigError(f"experiment/{cfg.experiment.name}.yaml: report.sequence_pages names no figure "
                          f"{unknown[0]!r}; figures: {', '.join(figure.name for figure in figures)}")


def tables_without_runs(cfg: DictConfig, runs: list[Run]) -> list[str]:
    """A line for each report table whose conditions (those its ``match:`` lists) no run of this request
    has (bis_pf run without its 3123 scene): said before any work, the page then leaves the table out."""
    tables, _ = report_specs(cfg)
    ran = list({str(run.condition): run.condition for run in runs}.values())
    lines = []
    for spec in tables:
        wanted = [condition for condition, _ in matched(spec)] if isinstance(spec, Compared) else []
        if wanted and not _held(ran, wanted):
            lines.append(f"{cfg.experiment.name}: table {spec.name} needs {' or '.join(map(written, wanted))}, "
                         "which no run of this request has: its page will leave it out")
    return lines


def named_conditions(cfg: DictConfig) -> list[tuple[str, dict]]:
    """Each condition the experiment's report tables (``match:``) and figures (``conditions:``) name, and the
    claims' readings of it (the papers', and a user's own in ``claims_dir``), with where it is written."""
    from replication.evidence.claim_tests import named
    from replication.evidence.claims import load_own_papers, load_papers

    name = cfg.experiment.name
    file = f"experiment/{name}.yaml"
    tables, figures = report_specs(cfg)
    try:  # a label is refused here, in the file's name
        found = [(f"{file}: table {spec.name!r}: match", condition)
                 for spec in tables if isinstance(spec, Compared) for condition, _ in matched(spec)]
        found += [(f"{file}: figure {spec.name!r}: conditions", condition)
                  for spec in figures for condition in figure_conditions(spec)]
    except ConfigError as error:
        raise ConfigError(f"{file}: {error}") from None
    papers = load_papers() + (load_own_papers(resolve(str(cfg.claims_dir))) if cfg.get("claims_dir") else ())
    return found + [(f"{paper.path}: claim {claim.id}, reading {reading.name}", condition)
                    for paper in papers for claim in paper.claims for reading in claim.readings
                    if reading.experiment == name for condition in named(reading.test)]


def check_conditions(cfg: DictConfig) -> None:
    """Every condition :func:`named_conditions` gives holds for some run of the experiment: at this
    request's scale or at paper scale, as requested or as shipped (a narrowed sweep, the quick scale or a
    sequence not on this machine may leave a named condition without runs: its table, figure or check is
    then left out, and said).  One that holds for none (a typo, a value no sweep takes) is one line naming
    where it is written and the values each variable takes."""
    named = named_conditions(cfg)
    scales = dict.fromkeys([cfg.scale, "paper"])
    known = [c for scale in scales for _, c, *_ in planned(experiment_at_scale(cfg, scale))]
    missing = [(where, wanted) for where, wanted in named if not _held(known, [wanted])]
    if missing and cfg.experiment.name in experiment_names():  # as shipped: a request may narrow its sweeps
        known += [c for _, c, *_ in planned(experiment_at_scale(as_shipped(cfg.experiment.name, "paper")))]
        missing = [(where, wanted) for where, wanted in missing if not _held(known, [wanted])]
    if missing:
        where, wanted = missing[0]
        raise ConfigError(f"{where}: {written(wanted)} matches no run of {cfg.experiment.name}; {_values(known)}")


def _held(conditions: list[Condition], wanted: list[dict]) -> bool:
    """Whether one of ``wanted`` holds for one of ``conditions``."""
    return any(holds(c.columns(), w) for c in conditions for w in wanted)


def _values(conditions: list[Condition]) -> str:
    """The values each variable takes in ``conditions``, for a message."""
    taken: dict[str, list] = {}
    for condition in conditions:
        for variable, value in condition.values:
            if value not in taken.setdefault(variable, []):
                taken[variable].append(value)
    if not taken:
        return "it sweeps nothing: name no condition"
    return "its runs take " + "; ".join(f"{v}: {', '.join(map(str, values))}" for v, values in taken.items())
