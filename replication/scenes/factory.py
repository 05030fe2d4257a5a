"""Build a sequence from its config: the scene kinds (a scene's ``kind:``), one table of what each is.

``synthetic`` (the default) is drawn here (:mod:`replication.scenes.synthetic`); ``otb`` and ``mot`` are
real video in a benchmark's layout, read from a folder (``data.otb`` / ``data.mot``, else
``$REPLICATION_OTB`` / ``$REPLICATION_MOT``, else the project's own beside it).  What the rest of the
package asks of a scene's kind (is it real video, from which benchmark, do people come and go, where are its
sequences, from which number do its frames count) is an attribute of its :class:`SceneKind`.
"""

import json
from collections.abc import Callable
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

from replication.kinds import Registry
from replication.scenes.base import SequenceMissing
from replication.scenes.mot import MOT_ROOT, SHIPPED_MOT_ROOT, find_mot, load_mot, mot_names
from replication.scenes.otb import OTB_ROOT, SHIPPED_OTB_ROOT, OTBSequence, find_otb, otb_names
from replication.scenes.synthetic import SyntheticScene


@dataclass(eq=False)  # a kind is itself: compared and hashed by identity
class SceneKind:
    """A kind of scene: how a scene's spec becomes its sequence, and what that sequence is."""

    name: str  # as a scene's ``kind:`` writes it
    build: Callable[[dict], Any]  # the sequence of a scene's spec
    benchmark: str | None = None  # a real video's benchmark (its layout); None: a scene drawn here
    open_set: bool = False  # people come and go (truth as tables: task mot); else a fixed set of targets
    counts_from: int = 0  # the number ``first:`` gives a sequence's first frame
    root: str | None = None  # the folder of its sequences unless data.<name> or a scene's root says
    shipped_root: str | None = None  # the folder of the project's own
    names: Callable[[str], list[str]] | None = None  # every sequence in a folder
    find: Callable[[list[str], str], tuple[list[str], list[str]]] | None = None  # those present; a line per absent

    @property
    def real(self) -> bool:
        """Real video, read from a folder (not drawn here)."""
        return self.benchmark is not None


def _synthetic(spec: dict) -> SyntheticScene:
    scene = {k: v for k, v in spec.items() if k not in ("kind", "name", "stand_in", "track", "evaluation", "strip")}
    return SyntheticScene(scene, name=spec.get("name", "synthetic"), stand_in=spec.get("stand_in"))


def _otb(spec: dict) -> OTBSequence:
    root = spec.get("root", OTB_ROOT)
    _, missing = find_otb([spec["name"]], root)
    if missing:
        raise SequenceMissing(missing[0])
    return OTBSequence(spec["name"], root, spec.get("first", 0), spec.get("last"), spec.get("stand_in"))


def _mot(spec: dict):
    return load_mot(spec["name"], spec.get("root", MOT_ROOT))


SYNTHETIC = SceneKind("synthetic", _synthetic)
OTB = SceneKind("otb", _otb, benchmark="OTB", root=OTB_ROOT, shipped_root=SHIPPED_OTB_ROOT, names=otb_names,
                find=find_otb)
MOT = SceneKind("mot", _mot, benchmark="MOTChallenge", open_set=True, counts_from=1, root=MOT_ROOT,
                shipped_root=SHIPPED_MOT_ROOT, names=mot_names, find=find_mot)
SCENE_KINDS: Registry[SceneKind] = Registry("scene kind", {kind.name: kind for kind in (SYNTHETIC, OTB, MOT)})


def scene_kind(spec: dict) -> SceneKind:
    """The kind of the scene ``spec`` (``synthetic`` when it names none)."""
    return SCENE_KINDS[spec.get("kind", SYNTHETIC.name)]


def build_sequence(spec: dict):
    """The sequence of the scene ``spec``; :class:`~replication.scenes.base.SequenceMissing` for a real one not
    on this machine."""
    return scene_kind(spec).build(spec)


@lru_cache(maxsize=8)
def _cached(text: str):
    return build_sequence(json.loads(text))


def cached_sequence(spec: dict):
    """The same sequence object for the same spec within a process (scenes are rebuilt per worker)."""
    return _cached(json.dumps(spec, sort_keys=True))
