"""Whether a request runs an experiment as shipped, or on a user's own data, methods or settings.

Decided from the resolved config, never from which key was used: the experiment at its scale with its real
sequences located (:func:`~replication.runner.config.experiment_at_scale`, so ``data.otb``, ``data.mot``,
``sequences=`` and a scene's own name or root all show) against the same experiment composed from its name
and the scale alone; ``$REPLICATION_OTB`` / ``$REPLICATION_MOT`` pointing elsewhere than the shipped data
count too.  Any difference but the run count (more or fewer repetitions of the same experiment,
as the scales are) makes the runs the user's: their report is ``<experiment>@<label>`` (``label=``, else a
digest of the difference), it judges no paper claim, and the papers' scorecard never reads it.
"""

import hashlib
import json

from hydra import compose, initialize_config_dir
from hydra.core.global_hydra import GlobalHydra
from hydra.errors import HydraException
from omegaconf import DictConfig
from omegaconf.errors import OmegaConfBaseException

from replication.errors import ConfigError
from replication.paths import CONF_DIR, experiment_names
from replication.runner.config import experiment_at_scale
from replication.scenes.factory import SCENE_KINDS, scene_kind

NOT_COMPARED = ("runs", "also")  # the run count (the same experiment, repeated more or less) and the companions


def differences(cfg: DictConfig) -> list[str]:
    """What the request changes in the shipped experiment, one line per key added, removed or changed (a
    whole scene or method once), in key order; empty for the experiment as shipped.  An experiment the
    package does not ship is the user's throughout."""
    if cfg.experiment.name not in experiment_names():  # a --config-dir's (Hydra would compose it from there)
        return [f"experiment {cfg.experiment.name}: not one the package ships"]
    try:
        shipped = experiment_at_scale(as_shipped(cfg.experiment.name, cfg.scale))
    except (HydraException, OmegaConfBaseException):  # renamed inside its file: not the package's
        return [f"experiment {cfg.experiment.name}: not one the package ships"]
    ours = experiment_at_scale(cfg)
    kinds = {scene_kind(spec) for spec in (ours.get("scenes") or {}).values()}
    moved = [f"data.{kind.name}: {kind.shipped_root} -> {kind.root} (from the environment)"
             for kind in SCENE_KINDS.values() if kind in kinds and kind.real and kind.root != kind.shipped_root]
    return moved + [line for line in _diff(shipped, ours) if not line.startswith(NOT_COMPARED)]


def _diff(shipped: dict, ours: dict, prefix: str = "") -> list[str]:
    found = []
    for key in sorted(set(shipped) | set(ours), key=str):
        path, theirs, mine = f"{prefix}{key}", shipped.get(key), ours.get(key)
        if key not in ours:
            found.append(f"{path}: removed")
        elif key not in shipped:
            found.append(f"{path}: added, {_said(mine)}")
        elif isinstance(theirs, dict) and isinstance(mine, dict):
            found += _diff(theirs, mine, f"{path}.")
        elif _said(theirs) != _said(mine):
            found.append(f"{path}: {_said(theirs)} -> {_said(mine)}")
    return found


def report_name(cfg: DictConfig, changes: list[str]) -> str:
    """``<experiment>`` as shipped, else ``<experiment>@<label>``: the user's ``label=`` or the difference's digest."""
    name = cfg.experiment.name
    if not changes:
        return name
    label = cfg.get("label") or hashlib.sha256("\n".join(changes).encode()).hexdigest()[:8]
    if not str(label).replace("-", "").replace("_", "").isalnum():
        raise ConfigError(f"label must be letters, digits, - or _ (a folder name), got {label!r}")
    return f"{name}@{label}"


def as_shipped(name: str, scale: str) -> DictConfig:
    """The config of the shipped experiment ``name`` at ``scale``, composed without the request's overrides."""
    overrides = [f"experiment={name}", f"scale={scale}"]
    if GlobalHydra.instance().is_initialized():  # inside the run command or the report's composition
        return compose("config", overrides=overrides)
    with initialize_config_dir(config_dir=str(CONF_DIR), version_base="1.3"):
        return compose("config", overrides=overrides)


def _said(value) -> str:
    return json.dumps(value, sort_keys=True, default=str)
