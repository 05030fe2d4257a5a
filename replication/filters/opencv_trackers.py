"""The hspf paper's non-PF baselines, MIL and DFT, driven like our filters: ``start(model, rng)``,
``step(state, frame)``, ``state.output()`` (one box per frame, ESS 1, never resampled).

Both initialise on the first frame, which ``start`` reads from ``model.first_frame`` (the frame of
``model.initial_box``).  A step where a tracker reports failure keeps the previous box.

* MIL (Babenko, Yang and Belongie, CVPR 2009): OpenCV's ``cv2.TrackerMIL`` as is, default parameters
  (hspf ran "the authors' code").  It draws from two generators: its Haar features from the C library's
  ``rand()`` (``tracking_feature.cpp``) and its image samples from a copy of OpenCV's ``theRNG()`` taken
  when the tracker is made (``TrackerSamplerCSC``).  ``cv2.setRNGSeed`` alone seeds only the second, so
  the features followed from whatever the worker process had run before.  Both are seeded from the
  run's stream before the tracker is made: a run repeats (any process, any order), and runs with other
  seeds differ as MIL's own randomness makes them.
* DFT (Sevilla-Lara and Learned-Miller, CVPR 2012): a distribution field is a per-pixel one-hot over
  ``bins`` grey levels, smoothed by a spatial Gaussian and a Gaussian across bins; the target is the box
  whose field has the least L1 distance to the template field.  As in the authors' code (``run_DFT.m`` in
  the OTB benchmark): 16 bins; two levels searched coarse to fine (spatial kernels 15 px / sigma 2, then
  9 px / sigma 1; across bins 5 bins / sigma 0.625); at each level a greedy descent over the 4-neighbour
  shifts from the previous box moved by the last motion, within ``max_shift`` = 30 px; template
  T <- 0.95 T + 0.05 F(new box) per level; the size is fixed.  Our choices: the grey image is OpenCV's
  luma; every field, the template's too, is smoothed over the frame around the box (reflected at the
  image border), not over the box crop alone; the last motion is the last frame-to-frame displacement
  (the authors' code keeps the displacement from the predicted start, which alternates between v and 0
  under constant velocity v).
"""

import ctypes
import dataclasses
import threading
from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import Any

import cv2
import numpy as np

from replication.boxes import centre_boxes, corner_boxes
from replication.filters.registry import drawn
from replication.smc.loop import FilterOutput, Summaries

NEIGHBOURS = np.array([[-1, 0], [0, 1], [1, 0], [0, -1]])  # (row, col) steps of the DFT descent
C_LIBRARY = ctypes.CDLL(None)  # the process's C library (POSIX), whose rand() OpenCV's Haar features use
SEEDING = threading.Lock()  # rand() is one per process: seeding and drawing the features go together


@dataclass
class BoxState:
    """A one-box tracker between frames: its box (cx, cy, w, h), what it keeps (``memory``) and what it
    has recorded (one box per frame, as a filter's summaries with ESS 1, never resampled)."""

    model: Any
    rng: np.random.Generator
    box: np.ndarray
    memory: Any = None
    t: int = 0
    records: Summaries = dataclasses.field(default_factory=Summaries)

    def output(self) -> FilterOutput:
        return self.records.output(0.0)

    def posterior(self) -> tuple[np.ndarray, np.ndarray]:
        """A point mass at the box: what a one-box tracker states about the target."""
        return self.box[None], np.zeros(1)


def corner_box(box: np.ndarray) -> tuple[int, int, int, int]:
    """Integer (x, y, w, h) of a (cx, cy, w, h) box."""
    x, y, w, h = corner_boxes(box)
    return int(round(x)), int(round(y)), int(round(w)), int(round(h))


class BoxTracker(ABC):
    """A tracker that keeps one box, driven as a single-target filter: ``start(model, rng)``, ``step(state, frame)``."""

    @abstractmethod
    def initialise(self, frame: np.ndarray, box: np.ndarray) -> Any:
        """What the tracker keeps between frames, learnt from ``box`` (cx, cy, w, h) in the first frame."""

    @abstractmethod
    def update(self, memory: Any, frame: np.ndarray) -> np.ndarray | None:
        """The box (cx, cy, w, h) in ``frame``, or None when the tracker reports failure."""

    def start(self, model, rng: np.random.Generator) -> BoxState:
        frame = getattr(model, "first_frame", None)
        if frame is None:
            raise ValueError(f"{type(self).__name__} initialises on model.first_frame, which is not set")
        box = np.asarray(model.initial_box, dtype=float)[:4]
        return BoxState(model, rng, box, memory=self.initialise(frame, box))

    def step(self, state: BoxState, frame: np.ndarray) -> None:
        state.t += 1
        box = self.update(state.memory, frame)
        if box is not None:
            state.box = np.asarray(box, dtype=float)
        state.records.add(state.box[None], np.ones(1), False)
        state.records.resampled.append(False)

    def run(self, model, observations, rng: np.random.Generator) -> FilterOutput:
        """Track through ``observations`` (frames 1..T; frame 0 is ``model.first_frame``)."""
        state = self.start(model, rng)
        for frame in observations:
            self.step(state, frame)
        return state.output()


class MILTracker(BoxTracker):
    """OpenCV's MIL tracker (``cv2.TrackerMIL``, default parameters), its generators seeded from ``rng``."""

    def start(self, model, rng: np.random.Generator) -> BoxState:
        seed = int(rng.integers(2**31))
        with SEEDING:  # under a thread backend, no other run's tracker draws features in between
            cv2.setRNGSeed(seed)
            C_LIBRARY.srand(seed)
            return super().start(model, rng)

    def initialise(self, frame, box):
        tracker = cv2.TrackerMIL.create()
        tracker.init(frame, corner_box(box))
        return tracker

    def update(self, tracker, frame):
        found, corner = tracker.update(frame)
        return centre_boxes(corner) if found else None


@dataclass
class DFTMemory:
    """DFT between frames: a template field per level, the box's top-left (row, col), size and last motion."""

    templates: list
    corner: np.ndarray
    size: np.ndarray
    motion: np.ndarray


@dataclass
class DFTTracker(BoxTracker):
    """Distribution fields tracking (Sevilla-Lara and Learned-Miller 2012); levels run coarse to fine."""

    bins: int = 16
    spatial_widths: tuple[int, ...] = (15, 9)  # px, odd
    spatial_sigmas: tuple[float, ...] = (2.0, 1.0)
    feature_width: int = 5  # bins, odd
    feature_sigma: float = 0.625
    max_shift: int = 30  # px per frame
    learning_rate: float = 0.05

    def __post_init__(self):
        if int(self.bins) != self.bins or not 2 <= self.bins <= 256:
            raise ValueError(f"bins must be an integer in [2, 256], got {self.bins}")
        widths = [*self.spatial_widths, self.feature_width]
        if len(self.spatial_widths) != len(self.spatial_sigmas) or not self.spatial_widths:
            raise ValueError("give one spatial sigma per spatial width, at least one level")
        if any(int(w) != w or w < 1 or w % 2 == 0 for w in widths):
            raise ValueError(f"kernel widths must be odd positive integers, got {widths}")
        if min(*self.spatial_sigmas, self.feature_sigma) <= 0:
            raise ValueError("kernel sigmas must be positive")
        if int(self.max_shift) != self.max_shift or self.max_shift < 1:
            raise ValueError(f"max_shift must be a positive integer, got {self.max_shift}")
        if not 0.0 <= self.learning_rate <= 1.0:
            raise ValueError(f"learning_rate must lie in [0, 1], got {self.learning_rate}")
        offsets = np.arange(self.bins)
        across = np.abs(offsets[:, None] - offsets[None, :])
        gauss = np.exp(-0.5 * (np.arange(self.feature_width // 2 + 1) / self.feature_sigma) ** 2)
        gauss /= 2 * gauss.sum() - gauss[0]  # the full kernel sums to 1; mass beyond the end bins is lost
        near = across <= self.feature_width // 2
        self._across = np.where(near, gauss[np.minimum(across, len(gauss) - 1)], 0.0).astype(np.float32)
        self._pad = max(self.spatial_widths) // 2

    def fields(self, grey: np.ndarray) -> list[np.ndarray]:
        """The smoothed distribution field (H, W, bins) of a grey image at every level."""
        one_hot = np.eye(self.bins, dtype=np.float32)[grey.astype(np.intp) * self.bins // 256]
        return [
            cv2.GaussianBlur(one_hot, (width, width), sigma, borderType=cv2.BORDER_REFLECT) @ self._across
            for width, sigma in zip(self.spatial_widths, self.spatial_sigmas)
        ]

    def _region(self, grey: np.ndarray, corner: np.ndarray, size: np.ndarray, reach: int):
        """Fields of the part of the frame within ``reach`` + the kernel radius of the box, and its origin."""
        top = np.maximum(corner - reach - self._pad, 0)
        bottom = np.minimum(corner + size + reach + self._pad, grey.shape[:2])
        return self.fields(grey[top[0] : bottom[0], top[1] : bottom[1]]), top

    def initialise(self, frame, box):
        grey = _grey(frame)
        x, y, w, h = corner_box(box)
        size = np.array([h, w])
        if np.any(size < 1) or np.any(size > grey.shape[:2]):
            raise ValueError(f"the box {box} does not fit in the {grey.shape[1]}x{grey.shape[0]} frame")
        corner = np.clip([y, x], 0, np.array(grey.shape[:2]) - size)
        fields, top = self._region(grey, corner, size, 0)
        templates = [_window(f, corner - top, size) for f in fields]
        return DFTMemory(templates, corner, size, np.zeros(2, dtype=int))

    def update(self, memory, frame):
        grey = _grey(frame)
        size, highest = memory.size, np.array(grey.shape[:2]) - memory.size
        start = np.clip(memory.corner + memory.motion, 0, highest)
        fields, top = self._region(grey, start, size, self.max_shift)
        lower = np.maximum(start - self.max_shift, 0) - top
        upper = np.minimum(start + self.max_shift, highest) - top
        corner = start - top
        for field, template in zip(fields, memory.templates):
            corner = _descend(field, template, corner, lower, upper)
        rate = self.learning_rate
        memory.templates = [
            (1 - rate) * template + rate * _window(field, corner, size)
            for template, field in zip(memory.templates, fields)
        ]
        corner = corner + top
        memory.motion, memory.corner = corner - memory.corner, corner
        return centre_boxes([corner[1], corner[0], size[1], size[0]])  # (row, col) -> (x, y)


def _grey(frame: np.ndarray) -> np.ndarray:
    return cv2.cvtColor(frame, cv2.COLOR_BGR2GRAY) if frame.ndim == 3 else frame


def _window(field: np.ndarray, corner: np.ndarray, size: np.ndarray) -> np.ndarray:
    return field[corner[0] : corner[0] + size[0], corner[1] : corner[1] + size[1]]


def _descend(field, template, corner, lower, upper) -> np.ndarray:
    """Greedy descent of the L1 distance ||template - field(box)||_1 over 4-neighbour shifts of the box's
    corner (row, col), kept in [lower, upper] (``findTarget.m``); stops when no neighbour is closer."""
    size = np.array(template.shape[:2])
    best = np.abs(_window(field, corner, size) - template).sum()
    while True:
        candidates = corner + NEIGHBOURS
        candidates = candidates[np.all((candidates >= lower) & (candidates <= upper), axis=1)]
        if len(candidates) == 0:
            return corner
        windows = np.stack([_window(field, c, size) for c in candidates])
        distances = np.abs(windows - template).sum(axis=(1, 2, 3))
        if distances.min() >= best:
            return corner
        corner, best = candidates[distances.argmin()], distances.min()


@drawn("yellow", "-", "*")
def mil() -> MILTracker:
    """The hspf paper's MIL baseline."""
    return MILTracker()


@drawn("purple", "-", "h")
def dft(**params) -> DFTTracker:
    """The hspf paper's DFT baseline; ``params`` are :class:`DFTTracker` fields."""
    return DFTTracker(**params)
