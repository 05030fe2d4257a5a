"""Video frames decoded once per process: the next run on the same sequence reads the same arrays.

Every run on a real sequence (OTB, MOTChallenge) reads every frame, and an experiment runs many
times on each (seeds, methods, particle counts), one after another in a worker (the runner's
schedule goes scene by scene).  Decoding a frame and converting its colours took a quarter of a
PETS09-S2L1 run; here the decoded frame is kept, read-only (so that no run can change what the
next one sees), and what is computed from it alone is kept with it
(:func:`replication.vision.histogram.hsv_bin_image`).  The frames kept in a process are bounded by
``BUDGET_BYTES``, the least recently read dropped first (their bin images, two thirds of a BGR
frame's bytes, go with them).  The numbers computed do not change.
"""

from collections import OrderedDict
from pathlib import Path

import cv2
import numpy as np

BUDGET_BYTES = 3 * 2**29  # 1.5 GiB of decoded frames per process: PETS09-S2L1's 795 are 1.05 GB
_kept: OrderedDict = OrderedDict()  # path -> its decoded frame, least recently read first
_size = [0]


def decoded(path: Path) -> np.ndarray:
    """The image at ``path`` as read-only uint8 BGR, decoded at its first read in this process."""
    image = _kept.get(path)
    if image is not None:
        _kept.move_to_end(path)
        return image
    image = cv2.imread(str(path), cv2.IMREAD_COLOR)
    if image is None:
        raise OSError(f"cannot read {path}")
    image.flags.writeable = False
    _kept[path] = image
    _size[0] += image.nbytes
    while _size[0] > BUDGET_BYTES and _kept:
        _size[0] -= _kept.popitem(last=False)[1].nbytes
    return image
