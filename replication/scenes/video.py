"""Any video file OpenCV decodes (``cv2.VideoCapture``) as a sequence, with optional OTB-style ground truth.

Frames are decoded in order: reading frame k after frame k - 1 costs one decode;
an earlier frame reopens the file and skips forward (seeking to a frame index
is not exact for every codec).  The frame count is the container's; a stream
that does not state one (a raw MJPEG file) is counted once by grabbing every frame.
"""

from dataclasses import dataclass, field
from pathlib import Path

import cv2
import numpy as np

from replication.errors import ConfigError
from replication.scenes.otb import read_groundtruth


@dataclass
class VideoSequence:
    """Frames ``first`` .. ``last`` - 1 of the video at ``path`` as uint8 BGR arrays
    (the interface of :class:`replication.scenes.base.Sequence`).

    ``groundtruth`` is one target's boxes in the OTB format (a row x, y, w, h per
    frame of the whole video, 1-based, any of the separators
    :func:`replication.scenes.otb.read_groundtruth` reads); without it ``truth``
    has no target, shape (T, 0, 4).  An unreadable video is a one-line
    :class:`~replication.errors.ConfigError`.
    """

    path: str | Path
    groundtruth: str | Path | None = None
    first: int = 0
    last: int | None = None
    name: str = ""  # the file's stem when empty
    stand_in: str | None = None
    _capture: cv2.VideoCapture | None = field(default=None, init=False, repr=False)
    _next: int = field(default=0, init=False, repr=False)  # the video frame the next read decodes

    def __post_init__(self):
        self.path = Path(self.path)
        self.name = self.name or self.path.stem
        if not self.path.is_file():
            raise ConfigError(f"{self.path}: no such video file")
        self._rewind()
        if not self._capture.isOpened() or not self._capture.grab():
            raise ConfigError(f"{self.path}: OpenCV cannot read this video (not a video, or no codec for it)")
        self._rewind()
        total = self._frame_count()
        self._frames = range(total)[self.first : self.last]
        self.n_frames = len(self._frames)
        if self.groundtruth is None:
            truth = np.zeros((total, 0, 4))
        else:
            boxes = read_groundtruth(Path(self.groundtruth))
            if len(boxes) != total:
                raise ValueError(f"{self.path}: {total} frames but {len(boxes)} boxes in {self.groundtruth}")
            truth = boxes[:, None, :]
        self.truth = truth[self.first : self.last]
        self.visibility = np.ones(self.truth.shape[:2])
        height, width = self.frame(0).shape[:2]
        self.size = (width, height)

    def _rewind(self) -> None:
        if self._capture is not None:
            self._capture.release()
        self._capture, self._next = cv2.VideoCapture(str(self.path)), 0

    def _frame_count(self) -> int:
        stated = self._capture.get(cv2.CAP_PROP_FRAME_COUNT)
        if stated > 0:
            return int(stated)
        count = 0
        while self._capture.grab():
            count += 1
        self._rewind()
        return count

    def frame(self, k: int) -> np.ndarray:
        """Frame k (0-based, counted from ``first``)."""
        if not 0 <= k < self.n_frames:
            raise IndexError(f"{self.name}: frame {k} outside 0..{self.n_frames - 1}")
        index = self._frames[k]
        if index < self._next:
            self._rewind()
        while self._next < index and self._capture.grab():
            self._next += 1
        ok, image = self._capture.read()
        if not ok or self._next != index:
            raise OSError(f"{self.path}: cannot decode frame {index}")
        self._next += 1
        return image
