"""The interface every image sequence gives to trackers, metrics and figures, and the absence of a real one."""

from typing import Protocol

import numpy as np


class Sequence(Protocol):
    """Frames and exact ground truth.

    ``truth[k, m]`` is target m's box (x, y, w, h) in frame k, 0-based pixel
    coordinates of its top-left corner; ``visibility[k, m]`` the fraction of
    its pixels that can be seen (1 when unknown, as in OTB).  ``stand_in`` says
    what a synthetic scene stands in for (None for real video).
    """

    name: str
    n_frames: int
    size: tuple[int, int]
    truth: np.ndarray
    visibility: np.ndarray
    stand_in: str | None

    def frame(self, k: int) -> np.ndarray: ...


class SequenceMissing(LookupError):
    """A real sequence that is not on this machine: skip it, do not fail."""
