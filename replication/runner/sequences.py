"""Where an experiment's real sequences are read from, and a user's own list of them.

``data.otb`` and ``data.mot`` (``conf/config.yaml``; ``$REPLICATION_OTB`` / ``$REPLICATION_MOT``)
are the folders of OTB- and MOTChallenge-layout sequences; a scene's own ``root:`` wins over them.
``sequences=[A,B]`` (or ``sequences=all``: every sequence in ``data.otb``) replaces the OTB
sequences of an experiment, each read with the settings of the experiment's first (e.g. ``last:``,
the frames it reads), and the runs are on them alone.  A sequence named there must exist:
a missing one is an error, whereas a missing shipped default is skipped (the data may not be on
this machine).  An experiment with ``scenes:`` whose model names no scene runs every scene, so the
list is given once.
"""

from replication.errors import ConfigError
from replication.paths import resolve
from replication.scenes.mot import MOT_ROOT, SHIPPED_MOT_ROOT
from replication.scenes.otb import OTB_ROOT, SHIPPED_OTB_ROOT, find_otb, otb_names

DEFAULT_ROOTS = {"otb": OTB_ROOT, "mot": MOT_ROOT}  # $REPLICATION_OTB / $REPLICATION_MOT, else the shipped data
SHIPPED_ROOTS = {"otb": SHIPPED_OTB_ROOT, "mot": SHIPPED_MOT_ROOT}


def locate_sequences(experiment: dict, data: dict | None, sequences: list[str] | str | None) -> dict:
    """``experiment`` (plain data at its scale) with its real scenes' roots filled in, the user's
    ``sequences`` in place of its OTB scenes, and a scene sweep over every scene where none is named."""
    roots = {kind: (data or {}).get(kind) or default for kind, default in DEFAULT_ROOTS.items()}
    for kind, root in roots.items():
        if (data or {}).get(kind) and not resolve(root).is_dir():
            raise ConfigError(f"data.{kind}: no folder {resolve(root)}")
    scenes = {
        name: {**spec, "root": spec.get("root", roots[spec["kind"]])} if spec.get("kind") in roots else spec
        for name, spec in (experiment.get("scenes") or {}).items()
    }
    model = dict(experiment.get("model") or {})
    sweep = dict(model.get("sweep") or {})
    if sequences is not None:
        scenes = own_sequences(scenes, sequences, roots["otb"])
        sweep["scene"] = [name for name, spec in scenes.items() if spec.get("kind") == "otb"]
    elif scenes and model.get("scene") is None and "scene" not in sweep:
        sweep["scene"] = list(scenes)
    if "scene" in sweep:
        model.pop("scene", None)
    if sweep:
        model["sweep"] = sweep
    return {**experiment, "scenes": scenes, "model": model} if scenes else experiment


def own_sequences(scenes: dict, sequences: list[str] | str, root: str) -> dict:
    """``scenes`` with the user's ``sequences`` under ``root`` added, each read like the experiment's
    first OTB scene, in place of its OTB scenes (its synthetic ones stay, unswept)."""
    shipped = [spec for spec in scenes.values() if spec.get("kind") == "otb"]
    if not shipped:
        raise ConfigError("sequences= replaces the OTB sequences of an experiment that has some "
                          "(hspf, ism_pf_otb, fusion_pf_otb, gps_qmcpf_otb, ...)")
    names = otb_names(root) if sequences == "all" else sequences
    if isinstance(names, str) or not names or not all(isinstance(n, str) for n in names):
        raise ConfigError(f"sequences must be a list of OTB sequence names or all, got {sequences!r}")
    _, missing = find_otb(list(names), root)
    if missing:
        raise ConfigError(f"sequences: {missing[0].removesuffix(': skipped')}")
    template = {k: v for k, v in shipped[0].items() if k not in ("name", "stand_in")}
    kept = {name: spec for name, spec in scenes.items() if spec.get("kind") != "otb"}
    return {**kept, **{name: {**template, "name": name, "root": str(root)} for name in names}}
