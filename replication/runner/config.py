"""Validate an experiment config and expand it into independent runs.

A value given as a list under ``model`` or under a method is a sweep: the runs
are the product method x sweep values x repetition.  Everything is checked
before any work starts, and errors are one line that names the bad key.
"""

import hashlib
import itertools
import json
from dataclasses import dataclass
from typing import Any

import numpy as np
from omegaconf import DictConfig, OmegaConf

import replication
from replication.filters import FILTERS
from replication.models import MODELS
from replication.runner.seeding import seed_sequence

SCALES = ("paper", "quick")
SHORT_NAMES = {"n_particles": "N", "steps": "T"}


class ConfigError(ValueError):
    """A config that cannot run; the message is meant for the user as is."""


@dataclass(frozen=True)
class Run:
    """One independent run: the pure input of a task."""

    experiment: str
    task: str
    method: str
    condition: str
    repetition: int
    model: dict[str, Any]
    method_params: dict[str, Any]
    base_seed: int
    key: str
    data_condition: str = ""

    @property
    def run_id(self) -> str:
        condition = self.condition or "default"
        return f"{self.method}__{condition}__{self.key}__r{self.repetition:03d}"

    def rng(self, stream: str) -> np.random.Generator:
        """Independent generators: ``data`` is shared by every method at the same model
        condition and repetition (common random numbers); ``filter`` is the method's own."""
        if stream == "data":
            identity = ("data", self.data_condition, self.repetition)
        else:
            identity = (stream, self.method, self.condition, self.repetition)
        return np.random.default_rng(seed_sequence(self.base_seed, *identity))

    def identity(self) -> dict[str, Any]:
        return {
            "experiment": self.experiment,
            "method": self.method,
            "condition": self.condition,
            "data_condition": self.data_condition,
            "repetition": self.repetition,
            "run_key": self.key,
            "run_id": self.run_id,
        }


def _label(name: str, value: Any) -> str:
    return f"{SHORT_NAMES.get(name, name)}={value}"


def _sweeps(params: dict[str, Any], on_model: bool) -> list[tuple[bool, str, list]]:
    return [(on_model, k, list(v)) for k, v in params.items() if isinstance(v, list)]


def _run_key(task: str, model: dict, method: dict, base_seed: int) -> str:
    """Hash of everything that can change a run's numbers (not its repetition)."""
    numeric = {k: v for k, v in method.items() if k != "label"}
    blob = json.dumps(
        {"task": task, "model": model, "method": numeric, "seed": base_seed, "version": replication.__version__},
        sort_keys=True,
    )
    return hashlib.sha256(blob.encode()).hexdigest()[:10]


def n_runs(cfg: DictConfig) -> int:
    scale = cfg.scale
    if scale not in SCALES:
        raise ConfigError(f"scale must be one of {SCALES}, got {scale!r}")
    runs = cfg.experiment.runs[scale]
    if not isinstance(runs, int) or runs <= 0:
        raise ConfigError(f"experiment.runs.{scale} must be a positive integer, got {runs!r}")
    return runs


def expand(cfg: DictConfig) -> list[Run]:
    """All runs of ``cfg.experiment`` at ``cfg.scale``, validated."""
    exp = cfg.experiment
    repetitions = n_runs(cfg)
    model = OmegaConf.to_container(exp.model, resolve=True)
    if model.get("name") not in MODELS:
        raise ConfigError(f"unknown model {model.get('name')!r}; known models: {', '.join(sorted(MODELS))}")
    methods = OmegaConf.to_container(exp.methods, resolve=True)
    if not methods:
        raise ConfigError("experiment.methods is empty")
    runs = []
    for method, params in methods.items():
        if params.get("filter") not in FILTERS:
            what = f"unknown filter {params['filter']!r}" if "filter" in params else "no 'filter:' key"
            raise ConfigError(f"method {method!r}: {what}; known filters: {', '.join(sorted(FILTERS))}")
        sweeps = _sweeps(model, True) + _sweeps(params, False)
        for values in itertools.product(*(values for _, _, values in sweeps)):
            run_model, run_params = dict(model), dict(params)
            labels, data_labels = [], []
            for (on_model, name, _), value in zip(sweeps, values):
                (run_model if on_model else run_params)[name] = value
                labels.append(_label(name, value))
                if on_model:
                    data_labels.append(labels[-1])
            condition = ";".join(labels)
            build_model(run_model, context=f"model ({condition or 'default'})")
            build_filter(method, run_params, condition)
            key = _run_key(exp.task, run_model, run_params, int(cfg.base_seed))
            runs.extend(
                Run(
                    exp.name, exp.task, method, condition, r, run_model, run_params,
                    int(cfg.base_seed), key, ";".join(data_labels),
                )
                for r in range(repetitions)
            )
    return runs


def build_model(params: dict[str, Any], context: str = "model"):
    kwargs = {k: v for k, v in params.items() if k != "name"}
    try:
        return MODELS[params["name"]](**kwargs)
    except (TypeError, ValueError) as error:
        raise ConfigError(f"{context}: {error}") from None


def build_filter(method: str, params: dict[str, Any], condition: str = ""):
    kwargs = {k: v for k, v in params.items() if k not in ("filter", "label")}
    try:
        return FILTERS[params["filter"]](**kwargs)
    except (TypeError, ValueError) as error:
        where = f" at {condition}" if condition else ""
        raise ConfigError(f"method {method!r}{where}: {error}") from None
