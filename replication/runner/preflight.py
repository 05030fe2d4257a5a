"""The checks a request passes before anything heavy is imported (numpy, scipy, OpenCV, the filters).

The command line runs them on the composed config in well under a second, so a typo or a bad value
is one line naming the key (or the file and line) and exit status 2, with nothing written.  What
needs the filters (a parameter against the type its filter declares) or the data (every frame
decodable) is :mod:`replication.runner.validate`'s, after the imports but still before any work.

Numbers are checked by what their key names: every number is finite; a ``sigma`` or a variance is
positive, a standard deviation (``*_sd``, ``P0``) is not negative; counts (``n_*``, ``steps``, ...)
are positive integers; and a key that names one of these holds a number, not a word (``Q=abc``).
Names that become file names (the experiment's, its methods' and scenes', the sequences of
``sequences=``) are restricted to :data:`SAFE_NAME`; ``store`` and ``reports`` must lie inside the project
directory unless ``outside_project=true``.  What a request asks of this machine (local workers, particles
in memory) is bounded by :mod:`replication.runner.bounds`.
"""

import math
import re
import tempfile
from pathlib import Path
from typing import Any

import yaml
from omegaconf import DictConfig, ListConfig, OmegaConf

from replication.errors import ConfigError
from replication.paths import inside_project, project_dir, resolve
from replication.runner.bounds import check_particles, check_workers
from replication.scales import SCALES, at_scale

SAFE_NAME = re.compile(r"(?![.\s])[^/\\\x00-\x1f]+")  # one file name: no separator, no leading dot
POSITIVE = re.compile(r"(sigma\w*|\w+_sigma|\w*_var|variance|Q|R)")  # a scale: zero or less is meaningless
NOT_NEGATIVE = re.compile(r"(\w+_sd|P0)")  # a standard deviation: zero switches the noise off
COUNTS = re.compile(r"(n_\w+|runs|steps|frames|iterations|bins|copies|samples)")  # positive integers
NAMED_BLOCKS = ("methods", "scenes")  # their keys become file and folder names
BEYOND, MOST_RUNS = 10, 10_000  # runs per condition beyond which a request must say force=true


def check_yaml(path: Path) -> dict:
    """An experiment file parses (else its file and line) and holds a mapping: that mapping, as written
    (before Hydra applies any override)."""
    try:
        data = yaml.safe_load(path.read_text())
    except yaml.MarkedYAMLError as error:
        mark = error.problem_mark or error.context_mark
        where = f"{path}:{mark.line + 1}" if mark else str(path)
        raise ConfigError(f"{where}: {error.problem or error.context}") from None
    except yaml.YAMLError as error:
        raise ConfigError(f"{path}: {str(error).splitlines()[0]}") from None
    if not isinstance(data, dict):
        what = "is empty" if data is None else f"holds a {type(data).__name__}, not a mapping of settings"
        raise ConfigError(f"{path} {what}")
    return data


def check_settings(cfg: DictConfig) -> None:
    """The top-level settings: seed, workers, scale, and the output folders (inside the project,
    writable)."""
    seed = cfg.get("base_seed")
    if not _integer(seed) or seed < 0:
        raise ConfigError(f"base_seed must be a non-negative integer, got {seed!r}")
    n_jobs = cfg.get("n_jobs")
    if not _integer(n_jobs) or not (n_jobs >= 1 or n_jobs == -1):
        raise ConfigError(f"n_jobs must be a positive number of workers or -1 for all cores, got {n_jobs!r}")
    if cfg.get("scale") not in SCALES:
        raise ConfigError(f"scale must be one of {', '.join(SCALES)}, got {cfg.get('scale')!r}")
    for flag in ("outside_project", "skip_recorded", "dry_run", "n_jobs_beyond_cores", "draw"):
        if not isinstance(cfg.get(flag), bool):
            raise ConfigError(f"{flag} must be true or false, got {cfg.get(flag)!r}")
    record = cfg.get("record")
    if not isinstance(record, str) or not record:
        raise ConfigError(f"record must be a folder (a clone's record/), got {record!r}")
    check_sequences(cfg.get("sequences"))
    claims = cfg.get("claims_dir")
    if claims is not None and (not isinstance(claims, str) or not resolve(claims).is_dir()):
        raise ConfigError(f"claims_dir must be a folder of your claims files (*.yaml), got {claims!r}")
    for key in ("store", "reports"):
        value = cfg.get(key)
        if not isinstance(value, str) or not value:
            raise ConfigError(f"{key} must be a folder, got {value!r}")
        if not cfg.outside_project and not inside_project(value):
            raise ConfigError(
                f"{key}={value} is outside the project directory {project_dir()}; "
                f"add outside_project=true to write there"
            )
        check_writable(key, resolve(value))


def check_sequences(sequences: Any) -> None:
    """Each name of ``sequences=[...]`` is a sequence's folder name in ``data.otb`` / ``data.mot``, never a path
    (``../otb/Girl``, ``/data/Girl``): where sequences are read from is ``data.*``'s to say."""
    for name in sequences if isinstance(sequences, ListConfig) else ():
        if isinstance(name, str) and not SAFE_NAME.fullmatch(name):
            raise ConfigError(f"sequences: {name!r} is a path, not a sequence's name (no / or \\, no leading dot); "
                              "say where sequences are with data.otb= (data.mot=) and name them by folder")


def check_writable(key: str, folder: Path) -> None:
    """``folder`` exists as a writable folder, or its nearest existing parent is writable (tested by
    writing a temporary file: permission bits alone do not tell for root or on read-only mounts)."""
    existing = folder
    while not existing.exists():
        existing = existing.parent
    if not existing.is_dir():
        raise ConfigError(f"{key}: {existing} is a file, not a folder")
    try:
        with tempfile.TemporaryFile(dir=existing):
            pass
    except OSError as error:
        raise ConfigError(f"{key}: cannot write in {existing} ({error.strerror})") from None


def check_experiment(cfg: DictConfig, written_paper: Any = None) -> None:
    """The experiment's structure, names and numbers (a multiverse is checked by its own loader);
    ``written_paper``: the paper-scale run count its file gives, before any override."""
    experiment = cfg.get("experiment")
    if not isinstance(experiment, DictConfig):
        raise ConfigError("name an experiment: experiment=<name>")
    name = experiment.get("name")
    if not isinstance(name, str) or not SAFE_NAME.fullmatch(name):
        raise ConfigError(f"experiment.name must be one file name (no / or \\, no leading dot), got {name!r}")
    if "multiverse" in experiment:
        return
    for block in ("model", "methods"):
        if not isinstance(experiment.get(block), DictConfig):
            raise ConfigError(f"experiment.{block} must be a mapping, got {_kind(experiment.get(block))}")
    runs = experiment.get("runs")
    if not isinstance(runs, DictConfig) or set(runs) != set(SCALES):
        raise ConfigError(f"experiment.runs must give paper: and quick: run counts, got {_kind(runs)}")
    for block in NAMED_BLOCKS:
        for key, value in (experiment.get(block) or {}).items():
            if not SAFE_NAME.fullmatch(str(key)):
                raise ConfigError(f"experiment.{block}: the name {key!r} must be one file name (no / or \\, no leading dot)")
            if not isinstance(value, DictConfig):
                raise ConfigError(f"experiment.{block}.{key} must be a mapping, got {_kind(value)}")
    for key, method in experiment.methods.items():
        if not isinstance(method.get("filter"), str):
            raise ConfigError(f"experiment.methods.{key} names no filter (filter: <name>)")
    values = OmegaConf.to_container(experiment, resolve=True)
    for block in ("runs", "model", "methods", "scenes"):
        check_numbers(values.get(block), f"experiment.{block}", block)
    check_size(values["runs"], cfg.get("scale"), bool(cfg.get("force")), written_paper)


def check_size(runs: dict, scale: str, force: bool, written_paper: Any = None) -> None:
    """A run count far beyond the paper's (more than :data:`BEYOND` times it, or :data:`MOST_RUNS` runs per
    condition: a typo of a few zeros) is refused unless ``force=true``: its runs would be expanded and queued
    before the first is computed.  The paper's count is the experiment file's (``written_paper``), so that
    an override of ``runs.paper`` itself is measured against it; the count as composed where the file gives
    none."""
    wanted = runs.get(scale)
    paper = written_paper if _integer(written_paper) else runs.get("paper")
    if force or not _integer(wanted) or not _integer(paper):
        return
    if wanted > BEYOND * paper or wanted > MOST_RUNS:
        raise ConfigError(f"experiment.runs.{scale} = {wanted:,} runs per condition, against the paper's {paper:,}: "
                          "pass force=true to run that many")


def check_numbers(value: Any, where: str, key: str = "") -> None:
    """Every number under ``value`` finite, and in range for what its key names (module docstring)."""
    if isinstance(value, dict):
        for k, v in value.items():
            # {paper: a, quick: b} and a sweep's list are values of the key that holds them
            inner = key if k in SCALES or k == "sweep" else str(k)
            check_numbers(v, f"{where}.{k}", inner)
        return
    if isinstance(value, list):
        for v in value:
            check_numbers(v, where, key)
        return
    names_a_number = any(rule.fullmatch(key) for rule in (POSITIVE, NOT_NEGATIVE, COUNTS))
    if names_a_number and (isinstance(value, (bool, str)) or not isinstance(value, (int, float, type(None)))):
        raise ConfigError(f"{where} must be {'an integer' if COUNTS.fullmatch(key) else 'a number'}, got {value!r}")
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return
    if not math.isfinite(value):
        raise ConfigError(f"{where} must be a finite number, got {value!r}")
    if POSITIVE.fullmatch(key) and value <= 0:
        raise ConfigError(f"{where} must be positive, got {value!r}")
    if NOT_NEGATIVE.fullmatch(key) and value < 0:
        raise ConfigError(f"{where} must not be negative, got {value!r}")
    if COUNTS.fullmatch(key) and (not _integer(value) or value < 1):
        raise ConfigError(f"{where} must be a positive integer, got {value!r}")


def check_machine(cfg: DictConfig) -> None:
    """What a request computed here asks of this machine (:mod:`replication.runner.bounds`): its local workers
    within the cores, and its largest particle count in memory in each of them.  A cluster's address
    (``parallel.address``) sends the runs elsewhere: nothing to bound here."""
    parallel = cfg.get("parallel")
    if isinstance(parallel, DictConfig) and parallel.get("address"):
        return
    check_workers(cfg.n_jobs, cfg.n_jobs_beyond_cores)
    if "multiverse" not in cfg.experiment:  # a multiverse's universes are shipped experiments' variants
        check_particles(at_scale(OmegaConf.to_container(cfg.experiment, resolve=True), cfg.scale), cfg.n_jobs)


def preflight(cfg: DictConfig, written: dict | None = None) -> None:
    """Every check of this module, in the order a user would fix them; ``written``: the experiment's file
    as written (:func:`check_yaml`), whose run counts overrides are measured against."""
    runs = (written or {}).get("runs")
    check_experiment(cfg, runs.get("paper") if isinstance(runs, dict) else None)
    check_settings(cfg)
    check_machine(cfg)


def _integer(value: Any) -> bool:
    return isinstance(value, int) and not isinstance(value, bool)


def _kind(value: Any) -> str:
    if value is None:
        return "nothing"
    if isinstance(value, (list, ListConfig)):
        return "a list"
    return repr(OmegaConf.to_container(value) if isinstance(value, DictConfig) else value)

