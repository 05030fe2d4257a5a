"""Where an experiment's real sequences are read from, and a user's own list of them.

``data.otb`` and ``data.mot`` (``conf/config.yaml``; ``$REPLICATION_OTB`` / ``$REPLICATION_MOT``)
are the folders of OTB- and MOTChallenge-layout sequences; a scene's own ``root:`` wins over them.
``sequences=[A,B]`` (or ``sequences=all``: every sequence in ``data.otb``, or ``data.mot`` for a
MOTChallenge experiment) replaces the real sequences of an experiment, each read with the settings of
the experiment's first (e.g. ``last:``, the frames it reads), and the runs are on them alone; figures
and tables that named a replaced scene are drawn for each of them.  A sequence named there must exist:
a missing one is an error, whereas a missing shipped default is skipped (the data may not be on
this machine).  An experiment with ``scenes:`` whose model names no scene runs every scene, so the
list is given once.
"""

from replication.errors import ConfigError
from replication.paths import resolve
from replication.scenes.factory import SCENE_KINDS, SceneKind, scene_kind


def locate_sequences(experiment: dict, data: dict | None, sequences: list[str] | str | None) -> dict:
    """``experiment`` (plain data at its scale) with its real scenes' roots filled in, the user's
    ``sequences`` in place of its real ones (and in its report's figures and tables), and a scene sweep over
    every scene where none is named."""
    roots = {kind: (data or {}).get(kind.name) or kind.root for kind in SCENE_KINDS.values() if kind.real}
    for kind, root in roots.items():
        if (data or {}).get(kind.name) and not resolve(root).is_dir():
            raise ConfigError(f"data.{kind.name}: no folder {resolve(root)}")
    scenes = {
        name: {**spec, "root": spec.get("root", roots[kind])} if (kind := scene_kind(spec)).real else spec
        for name, spec in (experiment.get("scenes") or {}).items()
    }
    model = dict(experiment.get("model") or {})
    sweep = dict(model.get("sweep") or {})
    if sequences is not None:
        shipped = set(scenes)
        scenes = own_sequences(scenes, sequences, roots)
        sweep["scene"] = [name for name, spec in scenes.items() if scene_kind(spec).real]
        report = follow_sequences(experiment.get("report") or {}, shipped - set(scenes), sweep["scene"])
        experiment = {**experiment, "report": report}
    elif scenes and model.get("scene") is None and "scene" not in sweep:
        sweep["scene"] = list(scenes)
    if "scene" in sweep:
        model.pop("scene", None)
    if sweep:
        model["sweep"] = sweep
    return {**experiment, "scenes": scenes, "model": model} if scenes else experiment


def own_sequences(scenes: dict, sequences: list[str] | str, roots: dict[SceneKind, str]) -> dict:
    """``scenes`` with the user's ``sequences`` in place of its real ones (of the first real kind it has, in
    the order of :data:`~replication.scenes.factory.SCENE_KINDS`: OTB, else MOTChallenge), each read like the
    experiment's first real scene of that kind (its synthetic ones stay, unswept)."""
    kinds = {name: scene_kind(spec) for name, spec in scenes.items()}
    kind = next((k for k in roots if k in kinds.values()), None)
    if kind is None:
        raise ConfigError("sequences= replaces the real sequences of an experiment that has some (OTB: hspf, "
                          "ism_pf_otb, fusion_pf_otb, gps_qmcpf_otb; MOTChallenge: bis_pf_pets)")
    names = kind.names(roots[kind]) if sequences == "all" else sequences
    if isinstance(names, str) or not names or not all(isinstance(n, str) for n in names):
        raise ConfigError(f"sequences must be a list of {kind.benchmark} sequence names or all, got {sequences!r}")
    _, missing = kind.find(list(names), roots[kind])
    if missing:
        raise ConfigError(f"sequences: {missing[0].removesuffix(': skipped')}")
    shipped = [scenes[name] for name, of in kinds.items() if of is kind]
    template = {k: v for k, v in shipped[0].items() if k not in ("name", "stand_in")}
    kept = {name: spec for name, spec in scenes.items() if kinds[name] is not kind}
    return {**kept, **{name: {**template, "name": name, "root": str(roots[kind])} for name in names}}


def follow_sequences(report: dict, replaced: set[str], scenes: list[str]) -> dict:
    """A report spec whose figures and tables named a replaced scene drawn for the user's ``scenes`` instead:
    ``conditions: [{scene: ...}]`` for each of them, a one-scene figure's ``scene:`` (a video) for the first;
    one naming only kept scenes stays as it is."""
    def moved(spec: dict) -> dict:
        if spec.get("scene") in replaced:
            spec = {**spec, "scene": scenes[0]}
        named = [c for c in spec.get("conditions", []) if isinstance(c, dict) and c.get("scene") in replaced]
        if not named:
            return spec
        return {**spec, "conditions": [{"scene": name} for name in scenes]}

    return {**report, **{part: [moved(spec) for spec in report.get(part, [])] for part in ("tables", "figures")
                         if part in report}}
