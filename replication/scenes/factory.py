"""Build a sequence from its config: ``kind: synthetic`` (the default) or ``kind: otb``."""

import json
from functools import lru_cache

from replication.scenes.otb import OTB_ROOT, OTBSequence, find_otb
from replication.scenes.synthetic import SyntheticScene

KINDS = ("synthetic", "otb")


class SequenceMissing(LookupError):
    """A real sequence that is not on this machine: skip it, do not fail."""


def build_sequence(spec: dict):
    kind = spec.get("kind", "synthetic")
    if kind not in KINDS:
        raise ValueError(f"unknown scene kind {kind!r}; choose one of {KINDS}")
    if kind == "otb":
        root = spec.get("root", OTB_ROOT)
        present, missing = find_otb([spec["name"]], root)
        if missing:
            raise SequenceMissing(missing[0])
        return OTBSequence(spec["name"], root, spec.get("first", 0), spec.get("last"), spec.get("stand_in"))
    scene = {k: v for k, v in spec.items() if k not in ("kind", "name", "stand_in", "track", "evaluation", "strip")}
    return SyntheticScene(scene, name=spec.get("name", "synthetic"), stand_in=spec.get("stand_in"))


@lru_cache(maxsize=8)
def _cached(text: str):
    return build_sequence(json.loads(text))


def cached_sequence(spec: dict):
    """The same sequence object for the same spec within a process (scenes are rebuilt per worker)."""
    return _cached(json.dumps(spec, sort_keys=True))
