"""Images computed from a frame alone (its HSV bin image, its grey levels), once per frame.

A read-only frame is one a sequence keeps for its next run (:mod:`replication.scenes.kept`): what is
computed from it alone is kept with it, read-only too, while the frame lives, so every run on the
sequence (every method, particle count and repetition that sees that video) reads the same array.  A
writeable frame may be changed by its owner: its images are computed at every call.
"""

import weakref
from collections.abc import Callable, Hashable

import numpy as np

_MADE: dict = {}  # id of a read-only frame -> (weak reference to it, {what: its image})


def derived(frame: np.ndarray, what: Hashable, make: Callable[[], np.ndarray]) -> np.ndarray:
    """``make()``, the image ``what`` of ``frame``: computed once per read-only frame and kept while the frame
    lives (read-only), computed every time for a writeable one."""
    if frame.flags.writeable:
        return make()
    made = _MADE.get(id(frame))
    if made is None or made[0]() is not frame:
        made = _MADE[id(frame)] = weakref.ref(frame, lambda _, key=id(frame): _MADE.pop(key, None)), {}
    image = made[1].get(what)
    if image is None:
        image = made[1][what] = make()
        image.flags.writeable = False
    return image
