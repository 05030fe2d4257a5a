"""A paper's multiverse: its experiments re-run under every defensible reading of what it leaves open.

``conf/experiment/<paper>_readings.yaml`` lists the paper's *choices* (a
setting the paper does not state, or prints ambiguously), each with its
*alternatives*: the config values it sets and the paper's words it rests on.
The first alternative is the default: what the experiment configs say today.
A *universe* picks one alternative per choice; the *design* says which
universes are run: ``full`` (every combination), ``one_at_a_time`` (the
default, then each other alternative alone) or ``{sobol: n}`` (n points of a
scrambled Sobol sequence over the choices, for a product too large to run);
``{full: [a, b]}``, ``{one_at_a_time: [a, b]}`` and ``{sobol: n, over: [a, b]}`` vary only the
choices named (a smaller design for the quick scale; a Sobol design whose points stay where they were
when choices are added), and a list of designs runs the union of their universes.  Like every setting, the design,
the run count and the experiments may differ by scale (``{paper: .., quick: ..}``).

Each universe's runs are the base experiments' runs with the alternatives'
values set: they go through the same expansion, store (the base experiment's
folder), seeds and backends as any run, and the run key hashes the changed
config, so the default universe (the base experiments as they stand, at
their own run count, which the other universes share at theirs) reuses the
base experiments' stored runs and
a run shared by several universes (a method no choice touches) is computed
once.
"""

import copy
import itertools
import re
from dataclasses import dataclass
from typing import Any

import numpy as np
from hydra import compose, initialize_config_dir
from hydra.core.global_hydra import GlobalHydra
from omegaconf import DictConfig, OmegaConf
from scipy.stats import qmc

from replication.errors import ConfigError
from replication.paths import CONF_DIR, experiment_names
from replication.run import Run
from replication.runner.config import experiment_at_scale
from replication.scales import at_scale
from replication.runner.validate import prepare

NAME = re.compile(r"[a-z][a-z0-9_]*")


@dataclass(frozen=True)
class Alternative:
    name: str
    why: str
    values: dict[str, Any]  # dotted path in an experiment config -> the value this reading gives it


@dataclass(frozen=True)
class Choice:
    name: str
    label: str
    alternatives: tuple[Alternative, ...]

    @property
    def default(self) -> Alternative:
        return self.alternatives[0]


@dataclass(frozen=True)
class Universe:
    """One alternative per choice, by name; named after the alternatives that are not the default."""

    picks: tuple[tuple[str, str], ...]  # (choice, alternative), in the choices' order
    name: str

    @classmethod
    def of(cls, choices: tuple[Choice, ...], picked: list[Alternative]) -> "Universe":
        changed = [f"{c.name}={a.name}" for c, a in zip(choices, picked) if a is not c.default]
        return cls(tuple((c.name, a.name) for c, a in zip(choices, picked)), "; ".join(changed) or "default")

    @property
    def is_default(self) -> bool:
        return self.name == "default"


@dataclass(frozen=True)
class Multiverse:
    name: str
    paper: str
    experiments: tuple[str, ...]
    choices: tuple[Choice, ...]
    universes: tuple[Universe, ...]
    runs: dict[tuple[str, str], list[Run]]  # (universe, experiment) -> its runs
    experiment_configs: dict[tuple[str, str], dict]  # (universe, experiment) -> its config at the scale
    skipped: tuple[str, ...] = ()  # conditions left out (a sequence not on this machine), once each

    def runs_of(self, experiment: str) -> list[Run]:
        """Every distinct run of ``experiment`` over the universes (a run several share, once)."""
        distinct = {}
        for (_, name), runs in self.runs.items():
            if name == experiment:
                distinct.update((run.run_id, run) for run in runs)
        return list(distinct.values())


def choices_of(spec: dict) -> tuple[Choice, ...]:
    """The ``choices:`` block of a multiverse config, checked."""
    if not isinstance(spec, dict) or not spec:
        raise ConfigError("experiment.choices must map each choice's name to its label and alternatives")
    found = []
    for name, choice in spec.items():
        where = f"experiment.choices.{name}"
        if not NAME.fullmatch(str(name)):
            raise ConfigError(f"{where}: a choice's name is lower-case letters, digits and _")
        alternatives = (choice or {}).get("alternatives") if isinstance(choice, dict) else None
        if not isinstance(alternatives, dict) or len(alternatives) < 2:
            raise ConfigError(f"{where}.alternatives must map at least two alternatives to their why and set")
        parsed = []
        for alt, body in alternatives.items():
            if not NAME.fullmatch(str(alt)) or not isinstance(body, dict):
                raise ConfigError(f"{where}.alternatives.{alt}: a name (lower-case, digits, _) with why: and set:")
            if not isinstance(body.get("why"), str) or not body["why"].strip():
                raise ConfigError(f"{where}.alternatives.{alt}.why: say which words of the paper it rests on")
            if not isinstance(body.get("set"), dict) or not body["set"]:
                raise ConfigError(f"{where}.alternatives.{alt}.set must map config paths to values")
            parsed.append(Alternative(str(alt), body["why"].strip(), dict(body["set"])))
        found.append(Choice(str(name), str(choice.get("label", name)), tuple(parsed)))
    return tuple(found)


def design(choices: tuple[Choice, ...], spec: Any, seed: int) -> tuple[Universe, ...]:
    """The universes to run, the default first (see the module's docstring for the designs).

    ``{full: [a, b]}``, ``{one_at_a_time: [a, b]}`` or ``{sobol: n, over: [a, b]}`` vary only the choices
    named, the others staying at their default; a list of designs gives the union of their universes."""
    picks = [p for one in (spec if isinstance(spec, list) and spec else [spec]) for p in _picks(choices, one, seed)]
    picks = list(dict.fromkeys(picks))  # the default once, a Sobol point drawn twice once
    return tuple(Universe.of(choices, [c.alternatives[i] for c, i in zip(choices, p)]) for p in picks)


def _picks(choices: tuple[Choice, ...], spec: Any, seed: int) -> list[tuple[int, ...]]:
    """One design's universes as the index of each choice's alternative, the default first."""
    kind, varied, n = _design_of(spec, choices)
    sizes = [len(c.alternatives) if c.name in varied else 1 for c in choices]
    default = tuple(0 for _ in sizes)
    if kind == "full":
        return list(itertools.product(*(range(n) for n in sizes)))
    if kind == "one_at_a_time":
        return [default] + [tuple(i if j == k else 0 for j in range(len(sizes)))
                            for k, n in enumerate(sizes) for i in range(1, n)]
    if kind == "sobol":  # one dimension per varied choice, so that a choice added outside ``over`` moves no point
        dims = [k for k, c in enumerate(choices) if c.name in varied]
        points = qmc.Sobol(len(dims), scramble=True, seed=np.random.default_rng(seed)).random(n)
        cells = (points * np.array([sizes[k] for k in dims])).astype(int)
        return [default] + [tuple(int(row[dims.index(k)]) if k in dims else 0 for k in range(len(sizes)))
                            for row in cells]
    raise ConfigError(f"experiment.multiverse.design must be full, one_at_a_time, {{sobol: n}} (n a power of "
                      f"two: Sobol points balance only then), {{full|one_at_a_time: [choices]}}, "
                      f"{{sobol: n, over: [choices]}} or a list of these; got {spec!r}")


def _design_of(spec: Any, choices: tuple[Choice, ...]) -> tuple[str | None, list[str], int]:
    """(kind, the choices it varies, the number of Sobol points) of a design as written; kind None if
    it is not one."""
    names = [c.name for c in choices]
    if isinstance(spec, str):
        return spec, names, 0
    if not isinstance(spec, dict) or not spec:
        return None, names, 0
    if "sobol" in spec and set(spec) <= {"sobol", "over"}:
        over = spec.get("over", names)
        known = isinstance(over, list) and over and set(over) <= set(names)
        return ("sobol" if _power_of_two(spec["sobol"]) and known else None), list(over) if known else names, spec["sobol"]
    (kind, value), = spec.items() if len(spec) == 1 else ((None, None),)
    if kind in ("full", "one_at_a_time") and isinstance(value, list) and value and set(value) <= set(names):
        return kind, value, 0
    return None, names, 0


def _power_of_two(n: Any) -> bool:
    return isinstance(n, int) and not isinstance(n, bool) and n > 0 and n & (n - 1) == 0


def matches(node: Any, path: str) -> list[tuple[Any, Any]]:
    """The (container, key) pairs a dotted ``path`` reaches in ``node``; ``*`` matches every key and an
    integer indexes a list.  Only paths that exist to their last key match: an override never adds a key."""
    head, _, rest = path.partition(".")
    if isinstance(node, dict):
        keys = list(node) if head == "*" else [head] if head in node else []
    elif isinstance(node, list):
        keys = list(range(len(node))) if head == "*" else [int(head)] if head.isdigit() and int(head) < len(node) else []
    else:
        keys = []
    if not rest:
        return [(node, key) for key in keys]
    return [found for key in keys for found in matches(node[key], rest)]


def apply(experiment: dict, values: dict[str, Any]) -> tuple[dict, list[str]]:
    """``experiment`` with each path of ``values`` set where it exists, and the paths that matched."""
    changed = copy.deepcopy(experiment)
    matched = []
    for path, value in values.items():
        places = matches(changed, path)
        for container, key in places:
            container[key] = copy.deepcopy(value)
        if places:
            matched.append(path)
    return changed, matched


def load(cfg: DictConfig) -> Multiverse:
    """The multiverse ``cfg.experiment`` describes: its choices checked against its base experiments
    (every alternative sets something; the default's values are the configs' own), its universes, and
    every universe's runs, validated as the base experiments' runs are."""
    exp = cfg.experiment
    spec = at_scale(OmegaConf.to_container(exp.multiverse, resolve=True), cfg.scale)
    choices = choices_of(OmegaConf.to_container(exp.choices, resolve=True) if "choices" in exp else {})
    experiments = tuple(spec.get("experiments") or ())
    runs_per_universe = spec.get("runs")
    if not experiments:
        raise ConfigError("experiment.multiverse.experiments must list the experiments whose claims it re-tests")
    if not isinstance(runs_per_universe, int) or runs_per_universe <= 0:
        raise ConfigError(f"experiment.multiverse.runs.{cfg.scale} must be a positive integer, got {runs_per_universe!r}")
    unknown = sorted(set(experiments) - set(experiment_names()))
    if unknown:
        raise ConfigError(f"experiment.multiverse.experiments: no experiment {unknown[0]!r}")
    bases = {name: _experiment(name) for name in experiments}
    others = [name for name in named_experiments(OmegaConf.to_container(exp.multiverse, resolve=True))
              if name not in bases]
    _check_choices(choices, {**{name: _experiment(name) for name in others}, **bases}, cfg.scale)
    universes = design(choices, spec.get("design", "full"), int(cfg.base_seed))
    top = {k: v for k, v in OmegaConf.to_container(cfg, resolve=True).items() if k != "experiment"}
    runs, configs, skipped = {}, {}, {}
    for universe in universes:
        values = universe_values(choices, universe)
        for name, base in bases.items():
            experiment, _ = apply(base, values)
            if not universe.is_default:  # the default universe is the base experiments at their own run count
                experiment["runs"] = {scale: runs_per_universe for scale in ("paper", "quick")}
            derived = OmegaConf.create({**top, "experiment": experiment})
            try:
                runs[universe.name, name], missing, _ = prepare(derived)
            except ConfigError as error:
                raise ConfigError(f"{exp.name}, universe {universe.name}, {name}: {error}") from None
            skipped.update(dict.fromkeys(missing))
            configs[universe.name, name] = experiment_at_scale(derived)
    return Multiverse(exp.name, exp.paper, experiments, choices, universes, runs, configs, tuple(skipped))


def universe_values(choices: tuple[Choice, ...], universe: Universe) -> dict[str, Any]:
    """The config values ``universe`` sets: every picked alternative's, a choice's default never overriding
    another choice's reading of the same path (two readings of one setting: patience in frames or in seconds)."""
    picked = dict(universe.picks)
    chosen = [(c, a) for c in choices for a in c.alternatives if a.name == picked[c.name]]
    return {path: value for c, a in sorted(chosen, key=lambda ca: ca[1] is not ca[0].default)
            for path, value in a.values.items()}


def named_experiments(multiverse: dict) -> list[str]:
    """Every experiment a multiverse block names, at any scale (``experiments: [..]`` or ``{paper: [..],
    quick: [..]}``), sorted."""
    listed = multiverse.get("experiments") or ()
    return sorted({name for names in (listed.values() if isinstance(listed, dict) else [listed]) for name in names})


def _experiment(name: str) -> dict:
    """Experiment ``name``'s config as Hydra composes it (with what it inherits through ``defaults:``)."""
    if not GlobalHydra.instance().is_initialized():  # outside a Hydra app (the report, a test)
        with initialize_config_dir(config_dir=str(CONF_DIR), version_base="1.3"):
            return _experiment(name)
    return OmegaConf.to_container(compose("config", overrides=[f"experiment={name}"]).experiment, resolve=True)


def _check_choices(choices: tuple[Choice, ...], bases: dict[str, dict], scale: str) -> None:
    """Every alternative's every path exists in some experiment the multiverse names (at any scale: the
    quick scale's smaller multiverse may leave out experiments whose keys a choice also sets), and the
    default's values are the configs' own wherever they exist (so the default universe is the experiments
    as they stand)."""
    for choice in choices:
        for alternative in choice.alternatives:
            for path, value in alternative.values.items():
                places = [(name, container[key]) for name, base in bases.items()
                          for container, key in matches(base, path)]
                where = f"experiment.choices.{choice.name}.alternatives.{alternative.name}.set.{path}"
                if not places:
                    raise ConfigError(f"{where}: no such key in {', '.join(bases)} (write the default there first)")
                if alternative is choice.default:
                    differing = [name for name, found in places if at_scale(found, scale) != at_scale(value, scale)]
                    if differing:
                        raise ConfigError(f"{where}: the default alternative must be what {differing[0]} says today")
