"""Validate an experiment config and expand it into independent runs.

A value written ``{paper: a, quick: b}`` anywhere in the model, scenes or
methods takes the entry of the current scale (e.g. a scene's frame count).
The ``sweep:`` block of ``model`` or of a method lists the values a parameter
takes (``sweep: {n_particles: [500, 200, 100]}``): the runs are the product
method x swept values x repetition.  A model sweep may name a key inside a block
by its path (``sweep: {deaths.frames: [5, 10]}`` sets ``model.deaths.frames``).  Everything else is a parameter, lists
included (a velocity clamp, histogram bins).  A method's ``only:`` block
(``only: {scene: [a]}``) keeps it to the conditions with those values; its
``observation:`` block overrides keys of ``model.observation`` (fusion_pf's two
filters differ only there); its ``label:`` and ``look:`` show it (:mod:`replication.display`)
and are no part of its runs' keys.  Everything is checked
before any work starts, and errors are one line that names the bad key.
"""

import hashlib
import itertools
import json
from collections.abc import Iterator
from typing import Any

from omegaconf import DictConfig, OmegaConf
from tqdm.auto import tqdm

from replication.condition import Condition
from replication.errors import ConfigError
from replication.filters.registry import build_filter, builder
from replication.run import Run
from replication.runner.bounds import MANY_RUNS, check_runs
from replication.runner.provenance import method_code_digest
from replication.scales import SCALES, at_scale
from replication.runner.sequences import locate_sequences
from replication.tasks import TASKS, DataMissing

def _sweeps(params: dict[str, Any], on_model: bool, where: str) -> list[tuple[bool, str, list]]:
    """The (on_model, name, values) of a block's ``sweep:``, removed from ``params``."""
    sweep = params.pop("sweep", None) or {}
    if not isinstance(sweep, dict):
        raise ConfigError(f"{where}.sweep must map parameter names to lists of values")
    for name, values in sweep.items():
        if not isinstance(values, list) or not values:
            raise ConfigError(f"{where}.sweep.{name} must be a non-empty list of values, got {values!r}")
    return [(on_model, name, list(values)) for name, values in sweep.items()]


def _set(params: dict[str, Any], name: str, value: Any) -> None:
    """``params[name] = value``, a dotted ``name`` (``deaths.frames``) setting a key inside a block, which is
    copied first so the experiment's own block is left as it is."""
    *blocks, key = name.split(".")
    for block in blocks:
        inner = params.get(block)
        if inner is not None and not isinstance(inner, dict):
            raise ConfigError(f"sweep {name}: {block} is {inner!r}, not a block of keys")
        params[block] = dict(inner or {})
        params = params[block]
    params[key] = value


def _get(params: dict[str, Any], name: str, default: Any = None) -> Any:
    """``params.get(name, default)``, a dotted ``name`` (``deaths.seconds``) reading a key inside a block."""
    *blocks, key = name.split(".")
    for block in blocks:
        params = params.get(block)
        if not isinstance(params, dict):
            return default
    return params.get(key, default)


def _run_key(task: str, model: dict, method: dict, base_seed: int, code: str) -> str:
    """Hash of everything that can change a run's numbers (not its repetition): the config and ``code``, the
    digest of the code the run executes (:func:`~replication.runner.provenance.method_code_digest`)."""
    numeric = {k: v for k, v in method.items() if k != "label"}
    blob = json.dumps({"task": task, "model": model, "method": numeric, "seed": base_seed, "code": code},
                      sort_keys=True)
    return hashlib.sha256(blob.encode()).hexdigest()[:10]


def experiment_at_scale(cfg: DictConfig, scale: str | None = None) -> dict:
    """``cfg.experiment`` as plain data at ``scale`` (by default ``cfg.scale``), its real sequences located
    (``data.*``, ``sequences=``: :mod:`replication.runner.sequences`): what the runs and the report both read."""
    experiment = at_scale(OmegaConf.to_container(cfg.experiment, resolve=True), scale or cfg.scale)
    return locate_sequences(experiment, cfg.get("data"), cfg.get("sequences"))


def n_runs(cfg: DictConfig) -> int:
    scale = cfg.scale
    if scale not in SCALES:
        raise ConfigError(f"scale must be one of {SCALES}, got {scale!r}")
    runs = cfg.experiment.runs[scale]
    if not isinstance(runs, int) or runs <= 0:
        raise ConfigError(f"experiment.runs.{scale} must be a positive integer, got {runs!r}")
    return runs


def expand(cfg: DictConfig, skipped: list[str] | None = None) -> list[Run]:
    """All runs of ``cfg.experiment`` at ``cfg.scale``, validated.

    Conditions whose data are absent (a real sequence not on this machine) are
    left out, with a message appended to ``skipped``.  The runs are counted before any is built, and a
    count that cannot fit in memory is refused (:func:`~replication.runner.bounds.check_runs`); a count of
    :data:`~replication.runner.bounds.MANY_RUNS` or more shows its progress while it is listed.
    """
    exp = cfg.experiment
    repetitions = n_runs(cfg)
    task = TASKS[exp.get("task")]
    name, kind, seed = exp.name, exp.task, int(cfg.base_seed)  # read once: each lookup costs more than a run
    experiment = experiment_at_scale(cfg)
    scenes = experiment.get("scenes", {})
    # counted in a pass of their own: the runs' blocks are built as they are listed, after the conditions
    # before them (a check may fill in a block some share), exactly as their keys were always computed
    conditions = sum(1 for _ in planned(experiment))
    check_runs(f"experiment.runs.{cfg.scale} = {repetitions:,} per condition x {conditions:,} conditions",
               repetitions * conditions)
    listed = tqdm(total=repetitions * conditions, desc=f"{name}: listing its runs", unit="run",
                  disable=not cfg.get("progress") or repetitions * conditions < MANY_RUNS, mininterval=1.0)
    runs, skipped = [], [] if skipped is None else skipped
    codes: dict[str, str] = {}  # filter name -> the digest of the code its runs execute
    for method, condition, data_condition, run_model, run_params in planned(experiment):
        builder(run_params["filter"])
        if "scene" in run_model:
            if run_model["scene"] not in scenes:
                raise ConfigError(f"model.scene {run_model['scene']!r} is not in experiment.scenes {sorted(scenes)}")
            run_model["scene_spec"] = scenes[run_model["scene"]]
        try:
            task.check(run_model, run_params)
        except DataMissing as missing:
            message = f"{exp.name}: {missing}"
            if message not in skipped:
                skipped.append(message)
            continue
        except (TypeError, ValueError, KeyError) as error:
            where = f" ({condition})" if condition else ""
            raise ConfigError(f"model{where}: {error}") from None
        build_filter(method, run_params, str(condition))
        if run_params["filter"] not in codes:  # a filter's code is digested once, not once per swept value
            codes[run_params["filter"]] = method_code_digest(task, builder(run_params["filter"]))
        key = _run_key(kind, run_model, run_params, seed, codes[run_params["filter"]])
        runs.extend(
            Run(name, kind, method, condition, r, run_model, run_params, seed, key, data_condition)
            for r in range(repetitions)
        )
        listed.update(repetitions)
    listed.close()
    return runs


def planned(experiment: dict) -> Iterator[tuple[str, Condition, Condition, dict, dict]]:
    """Each method's conditions as ``experiment`` (plain data at a scale) sweeps them, before any data or
    filter is looked at: ``(method, condition, data condition, model, parameters)`` for each product of the
    model's and the method's swept values that the method's ``only:`` keeps."""
    model = dict(experiment["model"])
    model_sweeps = _sweeps(model, True, "model")
    methods = experiment["methods"]
    if not methods:
        raise ConfigError("experiment.methods is empty")
    for method, params in methods.items():
        if "filter" not in params:
            raise ConfigError(f"method {method!r}: no 'filter:' key (a registered name or module:name)")
        params = dict(params)
        sweeps = model_sweeps + _sweeps(params, False, f"methods.{method}")
        only = params.pop("only", None) or {}  # e.g. {scene: [exp1_3123]}: a method run on some conditions only
        observation = params.pop("observation", None) or {}  # e.g. fusion_pf's colour-only filter: {alpha: 1}
        params.pop("look", None)  # how its figures draw it (replication.display): no part of a run
        for values in itertools.product(*(values for _, _, values in sweeps)):
            run_model, run_params = dict(model), dict(params)
            if observation:
                run_model["observation"] = {**model.get("observation", {}), **observation}
            for (on_model, name, _), value in zip(sweeps, values):
                _set(run_model if on_model else run_params, name, value)
            if any(_get(run_model, k, _get(run_params, k)) not in allowed for k, allowed in only.items()):
                continue
            condition = Condition.of((name, value) for (_, name, _), value in zip(sweeps, values))
            data_condition = Condition.of((name, value) for (on_model, name, _), value in zip(sweeps, values)
                                          if on_model)
            yield method, condition, data_condition, run_model, run_params
