"""Build a sequence from its config: ``kind: synthetic`` (the default) or ``kind: otb``."""

import json
import threading
from collections import OrderedDict
from functools import lru_cache

import numpy as np

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


FRAME_CACHE_BYTES = 2**30  # rendered or decoded frames kept per process, over all sequences


class KeptFrames:
    """A sequence whose frames are kept, read-only, after their first use, the least recently used
    dropped beyond ``FRAME_CACHE_BYTES`` for the whole process: a worker's next run of the same scene
    (the next repetition, the next method) reads them back instead of rendering or decoding them again."""

    _frames: OrderedDict = OrderedDict()  # (sequence key, k) -> frame, shared by every sequence
    _bytes = 0
    _lock = threading.Lock()  # the threading backend runs several runs in this process

    def __init__(self, sequence, key: str):
        self.sequence, self.key = sequence, key

    def __getattr__(self, name):
        return getattr(self.sequence, name)

    def frame(self, k: int) -> np.ndarray:
        frames, key = KeptFrames._frames, (self.key, k)
        with KeptFrames._lock:
            if key in frames:
                frames.move_to_end(key)
                return frames[key]
        image = self.sequence.frame(k)
        image.flags.writeable = False  # shared by every later reader
        with KeptFrames._lock:
            if key not in frames:
                frames[key] = image
                KeptFrames._bytes += image.nbytes
            while KeptFrames._bytes > FRAME_CACHE_BYTES and len(frames) > 1:
                KeptFrames._bytes -= frames.popitem(last=False)[1].nbytes
        return image


@lru_cache(maxsize=8)
def _cached(text: str):
    return KeptFrames(build_sequence(json.loads(text)), text)


def cached_sequence(spec: dict):
    """The same sequence for the same spec within a process (scenes are rebuilt per worker), its frames
    kept between runs (:class:`KeptFrames`)."""
    return _cached(json.dumps(spec, sort_keys=True))
