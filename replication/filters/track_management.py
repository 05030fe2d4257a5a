"""Births and deaths of tracks on a real video, as components with one job each (Stone Soup's initiator and deleter).

Boxes here are (x, y, w, h), top-left, as MOT tables hold them.  None of the rules below
is stated by bis_pf for its Experiment 6 ("pedestrians appearing and disappearing"); each
number is a config value and our choice (``conf/experiment/bis_pf_pets.yaml`` says so).

* :func:`associate`: the frame's detections are assigned to the tracks' boxes by the
  Hungarian method maximising IoU, pairs below ``min_iou`` rejected; a track's detection
  then feeds its proposal (:mod:`replication.models.boosted`) and supports it.
* :class:`Initiator`: a detection that no track explains (its overlap with every track's box
  below ``explained_iou``: IoU, or with ``explained_by: cover`` the share of the detection's
  area inside the box, so that a track whose box is off its person still explains the person's
  detection) starts or extends a candidate; candidates are linked frame to frame by the same
  assignment, and one linked in ``frames`` consecutive frames becomes a track, born at its
  last detection.
* :class:`Deleter`: a track is supported in a frame by an associated detection or by its
  own appearance (the colour similarity rho of its estimate to its reference at least
  ``min_rho``; ``None``: by detections alone, as tracking-by-detection does); it dies after
  ``frames`` consecutive frames without support, or at once when its centre leaves the image.
* :func:`in_frames`: a patience (births', deaths') set in ``seconds`` and converted by the
  sequence's frame rate (``seqinfo.ini``), or counted in ``frames`` as given.
"""

from dataclasses import dataclass, field

import numpy as np

from replication.metrics.mot import iou_matrix, match_boxes
from replication.metrics.tracking import outside_image


def cover_matrix(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """(N, M) share of each box of ``a`` (N, 4) inside each box of ``b`` (M, 4): intersection / area of a."""
    a, b = np.asarray(a, float).reshape(-1, 4), np.asarray(b, float).reshape(-1, 4)
    left, top = np.maximum(a[:, None, 0], b[None, :, 0]), np.maximum(a[:, None, 1], b[None, :, 1])
    right = np.minimum(a[:, None, 0] + a[:, None, 2], b[None, :, 0] + b[None, :, 2])
    bottom = np.minimum(a[:, None, 1] + a[:, None, 3], b[None, :, 1] + b[None, :, 3])
    inside = np.clip(right - left, 0, None) * np.clip(bottom - top, 0, None)
    return inside / (a[:, 2] * a[:, 3])[:, None]


# How much a detection (rows) overlaps a track's box (columns): which detections a track explains (Initiator).
OVERLAPS = {"iou": iou_matrix, "cover": cover_matrix}


def in_frames(patience: dict, frame_rate: float) -> dict:
    """``patience`` (births' or deaths' settings) with ``seconds`` made ``frames``: round(seconds x frame
    rate), at least 1, so that a wait means the same time on a 7 and a 30 frame-per-second video; settings
    given in ``frames`` are kept (a key set to None is absent: a config that sets ``frames: null`` to give
    ``seconds`` instead)."""
    given = {k: v for k, v in patience.items() if v is not None or k not in ("frames", "seconds")}
    if "seconds" not in given:
        return given
    if "frames" in given:
        raise ValueError(f"give a patience in frames or in seconds, not both: {patience}")
    seconds = given.pop("seconds")
    return {**given, "frames": max(1, round(seconds * frame_rate))}


def associate(tracks: np.ndarray, detections: np.ndarray, min_iou: float) -> np.ndarray:
    """For each track (N, 4), the index of its detection in ``detections`` (M, 4), or -1."""
    assigned = np.full(len(tracks), -1)
    rows, cols = match_boxes(tracks, detections, min_iou)
    assigned[rows] = cols
    return assigned


@dataclass
class Initiator:
    """Births from detections that persist ``frames`` consecutive frames unexplained by any track."""

    frames: int = 3
    min_iou: float = 0.3  # linking a candidate's detections from frame to frame
    explained_iou: float = 0.3  # a detection overlapping a track this much is that track's, not a new target
    explained_by: str = "iou"  # the overlap above (OVERLAPS): iou, or cover (the share of the detection inside)
    candidates: np.ndarray = field(default_factory=lambda: np.zeros((0, 4)), repr=False)
    streaks: np.ndarray = field(default_factory=lambda: np.zeros(0, int), repr=False)

    def __post_init__(self):
        if self.frames < 1 or not 0 < self.min_iou <= 1 or not 0 < self.explained_iou <= 1:
            raise ValueError(f"births need frames >= 1 and IoUs in (0, 1]; got {self}")
        if self.explained_by not in OVERLAPS:
            raise ValueError(f"unknown explained_by {self.explained_by!r}; choose one of {sorted(OVERLAPS)}")

    def step(self, detections: np.ndarray, tracks: np.ndarray) -> np.ndarray:
        """The boxes of the targets born this frame, from its ``detections`` given the ``tracks``' boxes."""
        overlap = OVERLAPS[self.explained_by](detections, tracks)
        explained = overlap.max(axis=1, initial=0.0) >= self.explained_iou
        free = detections[~explained]
        previous, current = match_boxes(self.candidates, free, self.min_iou)
        streaks = np.ones(len(free), int)
        streaks[current] = self.streaks[previous] + 1
        born = streaks >= self.frames
        self.candidates, self.streaks = free[~born], streaks[~born]
        return free[born]


@dataclass
class Deleter:
    """Deaths after ``frames`` consecutive frames without support, or on leaving the image."""

    frames: int = 20
    min_rho: float | None = 0.7  # None: only detections support a track

    def __post_init__(self):
        if self.frames < 1 or not (self.min_rho is None or 0 <= self.min_rho <= 1):
            raise ValueError(f"deaths need frames >= 1 and min_rho in [0, 1] or None; got {self}")

    def supported(self, detected: np.ndarray, rho: np.ndarray) -> np.ndarray:
        """Whether each track is supported this frame: a detection, or its appearance."""
        return detected if self.min_rho is None else detected | (rho >= self.min_rho)

    def causes(self, unsupported: np.ndarray, boxes: np.ndarray, size: tuple[int, int]) -> dict[str, np.ndarray]:
        """Why each track dies (either cause kills it): ``unsupported`` frames in a row reach ``frames``; its
        box's centre is outside the image."""
        return {"unsupported": unsupported >= self.frames, "outside": outside_image(boxes, size)}
