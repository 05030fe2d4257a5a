"""Video frames decoded once per process: the next run on the same sequence reads the same arrays.

Every run on a real sequence (OTB, MOTChallenge) reads every frame, and an experiment runs many
times on each (seeds, methods, particle counts), one after another (the runner's schedule goes scene
by scene).  Decoding a frame and converting its colours took a quarter of a PETS09-S2L1 run; here the
decoded frame is kept, read-only (so that no run can change what the next one sees), and what is
computed from it alone is kept with it (:func:`replication.vision.histogram.hsv_bin_image`).

A process keeps the frames of one sequence, the one it read last (a frame of another drops them),
and of that at most ``BUDGET_BYTES`` (the frames past it are decoded at every read).  So a worker's
memory grows by its largest sequence at most, not by every sequence it meets: loky replaces a worker
that grew by 300 MB since its first task as leaking, and would take its frames with it.  The numbers
computed do not change.
"""

from pathlib import Path

import cv2
import numpy as np

BUDGET_BYTES = 3 * 2**29  # 1.5 GiB of decoded frames (their bin images add two thirds): PETS09-S2L1's 795 are 1.05 GB
_kept: dict = {}  # path -> its decoded frame, every path in one folder


def decoded(path: Path) -> np.ndarray:
    """The image at ``path`` as read-only uint8 BGR, decoded at its first read in this process."""
    image = _kept.get(path)
    if image is not None:
        return image
    image = cv2.imread(str(path), cv2.IMREAD_COLOR)
    if image is None:
        raise OSError(f"cannot read {path}")
    image.flags.writeable = False
    if _kept and next(iter(_kept)).parent != path.parent:  # another sequence: drop the last one's frames
        _kept.clear()
    if sum(kept.nbytes for kept in _kept.values()) + image.nbytes <= BUDGET_BYTES:
        _kept[path] = image
    return image
