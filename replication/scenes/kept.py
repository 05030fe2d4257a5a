"""Frames made once per process: the next run on the same sequence reads the same arrays.

Every run on a sequence reads every frame, and an experiment runs many times on each (seeds, methods,
particle counts), one after another: the runner's schedule goes scene by scene and, in each, repetition
by repetition (:func:`replication.runner.execute.schedule`), so a worker meets each video, a real
sequence or a synthetic scene at one seed, in one stretch.  Decoding a frame and converting its colours
took a quarter of a PETS09-S2L1 run; rendering a ball scene's frame and converting its colours a sixth
of a bis_pf run on 16 balls, where every method of a repetition sees the same video (common random
numbers).  Here a frame is made at its first read (:func:`decoded` for a file,
:meth:`replication.scenes.synthetic.SyntheticScene.frame` for a scene) and kept, read-only (so that no
run can change what the next one sees); what is computed from it alone is kept with it
(:func:`replication.vision.histogram.hsv_bin_image`).

A process keeps the frames of one sequence, the one it read last (a frame of another drops them),
and of that at most ``BUDGET_BYTES`` (the frames past it are made again at every read).  So a worker's
memory grows by its largest sequence at most, not by every sequence it meets: loky replaces a worker
that grew by 300 MB since its first task as leaking, and would take its frames with it.  A frame is the
same array whether made again or kept, so the numbers computed do not change.
"""

import threading
from collections.abc import Callable, Hashable
from pathlib import Path

import cv2
import numpy as np

BUDGET_BYTES = 3 * 2**29  # 1.5 GiB of frames (bin images add two thirds, grey levels a third): PETS09-S2L1's 795 are 1.05 GB
_kept: dict = {}  # (sequence, key) -> its frame, every key of one sequence
_lock = threading.Lock()  # the threading backend's workers share a process, and so this store


def kept(sequence: Hashable, key: Hashable, make: Callable[[], np.ndarray]) -> np.ndarray:
    """Frame ``key`` of ``sequence`` (equal for the same video: a folder, a scene object), read-only: made
    by ``make()`` at its first read in this process, and kept for the next read while it is the sequence
    read last and its frames fit in ``BUDGET_BYTES``."""
    with _lock:
        image = _kept.get((sequence, key))
    if image is not None:
        return image
    image = make()
    image.flags.writeable = False
    with _lock:
        if _kept and next(iter(_kept))[0] != sequence:  # another sequence: drop the last one's frames
            _kept.clear()
        if sum(frame.nbytes for frame in _kept.values()) + image.nbytes <= BUDGET_BYTES:
            _kept[sequence, key] = image
    return image


def decoded(path: Path) -> np.ndarray:
    """The image at ``path`` as read-only uint8 BGR, decoded at its first read in this process (its folder
    is its sequence)."""
    return kept(path.parent, path, lambda: _read(path))


def _read(path: Path) -> np.ndarray:
    image = cv2.imread(str(path), cv2.IMREAD_COLOR)
    if image is None:
        raise OSError(f"cannot read {path}")
    return image
