"""A target's box written two ways, and the one conversion between them.

A scene's truth and a tracker's output are *corner* boxes (x, y, w, h): the top-left corner, 0-based
pixels, and the size; a box model's state is a *centre* box (cx, cy, w, h, ...), cx = x + w / 2 and
cy = y + h / 2 (:mod:`replication.scenes.base`, :class:`replication.models.box.BoxModel`).  Every layer
converts through these functions, so a box and its centre agree to the last bit wherever they are computed.
"""

import numpy as np


def centres(boxes) -> np.ndarray:
    """The centres (x + w / 2, y + h / 2) of corner boxes (..., >= 4): (..., 2)."""
    boxes = np.asarray(boxes, dtype=float)
    return boxes[..., :2] + boxes[..., 2:4] / 2.0


def centre_boxes(boxes) -> np.ndarray:
    """Corner boxes (x, y, w, h, ...) as centre boxes (cx, cy, w, h): (..., 4)."""
    boxes = np.asarray(boxes, dtype=float)
    return np.concatenate([centres(boxes), boxes[..., 2:4]], axis=-1)


def corner_boxes(states) -> np.ndarray:
    """Centre boxes (cx, cy, w, h, ...) as corner boxes (cx - w / 2, cy - h / 2, w, h): (..., 4); the
    inverse of :func:`centre_boxes` (to rounding)."""
    states = np.asarray(states, dtype=float)
    return np.concatenate([states[..., :2] - states[..., 2:4] / 2.0, states[..., 2:4]], axis=-1)
