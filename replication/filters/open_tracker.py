"""Trackers of an open set of targets on a real video: targets are born and die (bis_pf Experiment 6).

Every such tracker has one method, ``track(sequence, frames, rng)``, which owns the time loop
over a :class:`~replication.scenes.mot.MotSequence`'s ``frames`` (MOT numbers) and yields,
per frame, the ids (from 1) and (x, y, w, h) boxes it outputs; its ``stopwatch`` adds up its
own time on both clocks (decoding the frames excluded, as bis_pf's timings exclude it).

* :class:`ParticleTracker`: a joint filter of :mod:`replication.filters.bis` (MIPF,
  BIS-PF, MFMC, DMOT, MCMC-PF) over the targets alive, with the births, deaths and
  association of :mod:`replication.filters.track_management` and each target's
  detection fed to its proposal (:mod:`replication.models.boosted`).  The filters share
  all of that machinery and differ only in their interaction.
* :class:`DetectionTracker`: a reference built from the public detections alone
  (:mod:`replication.filters.mot_baselines`), for context.

Per frame, a particle tracker: associates the detections with the tracks' boxes of the
previous frame; steps the joint filter (each target's proposal fed its detection); marks
each track supported or not and ends the dead ones; outputs the tracks alive (by
``output: supported``, in frames where they are supported; ``detected``, where a detection is
associated with them, as SORT outputs; ``alive``, every frame of a track's life), each with its box by
``box`` (``estimate``: the filter's; ``detection``: in a frame with an associated detection, that detection's, as
SORT's output sits on its detections; ``average``: the two's mean there); then starts the tracks born this frame,
each with its colour reference from its first detection's box in this frame.
"""

from collections import Counter
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from functools import partial

import numpy as np
import pandas as pd

from replication.boxes import centre_boxes, corner_boxes
from replication.filters.joint import JointFilter
from replication.filters.mot_baselines import detection_boxes, detections_only, sort
from replication.filters.registry import drawn
from replication.filters.track_management import Deleter, Initiator, associate
from replication.metrics.mot import BOX
from replication.models.box import BoxModel
from replication.stopwatch import Stopwatch

# Which of a live track's frames are output, from whether a detection is associated with it this frame and
# whether it is supported (a detection or its colour, :class:`Deleter`).
OUTPUTS: dict[str, Callable[[np.ndarray, np.ndarray], np.ndarray]] = {
    "detected": lambda detected, supported: detected,
    "supported": lambda detected, supported: supported,
    "alive": lambda detected, supported: np.ones_like(supported),
}
# Which box a shown track outputs, from the filter's estimates (K, 4), the detections associated with them (K, 4:
# NaN where none) and whether one is: the estimate, or where a detection is associated, the detection or the mean.
BOXES: dict[str, Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray]] = {
    "estimate": lambda estimates, associated, detected: estimates,
    "detection": lambda estimates, associated, detected: np.where(detected[:, None], associated, estimates),
    "average": lambda estimates, associated, detected: np.where(detected[:, None], (estimates + associated) / 2,
                                                                 estimates),
}
Frame = tuple[int, np.ndarray, np.ndarray]  # MOT frame number, ids (K,), boxes (K, 4)


EVENTS = ("births", "track_frames", "detected_frames", "colour_frames", "shown_frames", "died_unsupported",
          "died_outside")


@dataclass
class ParticleTracker:
    """A joint filter over the targets alive, with births, deaths and the detection-fused proposal.

    ``new_model(image, box)`` makes a target's model from its first detection (cx, cy, w, h)
    in ``image``.  ``counts`` adds up, over the frames tracked, the :data:`EVENTS`: tracks born, the
    frames of live tracks (a track's frame after its birth frame), those with an associated detection
    (each such frame's proposal draws ``alpha`` of its particles from the detection), those supported by
    the colour alone, those output (birth frames included), and the deaths by cause (lost support; the
    centre leaving the image).
    """

    method: JointFilter
    new_model: Callable[[np.ndarray, np.ndarray], BoxModel]
    births: Initiator
    deaths: Deleter
    association_iou: float = 0.3  # not stated: our choice, SORT's gate
    min_score: float = -np.inf  # detections below are ignored
    output: str = "supported"
    box: str = "estimate"  # the box output (BOXES)
    stopwatch: Stopwatch = field(default_factory=Stopwatch, init=False)
    born: int = field(default=0, init=False)  # tracks started
    counts: Counter = field(default_factory=Counter, init=False)  # where the tracks' frames went (EVENTS)

    def __post_init__(self):
        if self.output not in OUTPUTS:
            raise ValueError(f"unknown output {self.output!r}; choose one of {sorted(OUTPUTS)}")
        if self.box not in BOXES:
            raise ValueError(f"unknown box {self.box!r}; choose one of {sorted(BOXES)}")

    def track(self, sequence, frames, rng: np.random.Generator) -> Iterator[Frame]:
        detections = detection_boxes(sequence.detections, self.min_score)
        state = self.method.start([], rng)
        ids, boxes, unsupported = np.zeros(0, int), np.zeros((0, 4)), np.zeros(0, int)
        for frame in frames:
            image = sequence.image(frame)
            with self.stopwatch:
                found = detections.get(frame, np.zeros((0, 4)))
                assigned = associate(boxes, found, self.association_iou)
                for model, index in zip(state.models, assigned):
                    model.detection = centre_boxes(found[index]) if index >= 0 else None
                if len(ids):
                    self.method.step(state, image)
                    means = np.array([records.means[-1][:4] for records in state.records])
                    boxes = corner_boxes(means)
                    rho = np.array([model.similarity(mean[None], image, state.t)[0]
                                    for model, mean in zip(state.models, means)])
                    detected = assigned >= 0
                    supported = self.deaths.supported(detected, rho)
                    unsupported = np.where(supported, 0, unsupported + 1)
                    causes = self.deaths.causes(unsupported, boxes, sequence.size)
                    dead = causes["unsupported"] | causes["outside"]
                    shown = ~dead & OUTPUTS[self.output](detected, supported)
                    self.counts.update({"track_frames": len(ids), "detected_frames": int(detected.sum()),
                                        "colour_frames": int((supported & ~detected).sum()),
                                        "shown_frames": int(shown.sum()),
                                        "died_unsupported": int((dead & causes["unsupported"]).sum()),
                                        "died_outside": int((dead & ~causes["unsupported"]).sum())})
                    associated = np.full_like(boxes, np.nan)
                    associated[detected] = found[assigned[detected]]
                    out_ids, out_boxes = ids[shown], BOXES[self.box](boxes, associated, detected)[shown]
                    for index in np.flatnonzero(dead)[::-1]:
                        self.method.remove(state, int(index))
                    ids, boxes, unsupported = ids[~dead], boxes[~dead], unsupported[~dead]
                else:
                    out_ids, out_boxes = ids, boxes
                taken = np.isin(np.arange(len(found)), assigned)
                born = self.births.step(found[~taken], boxes)
                for box in born:
                    self.method.add(state, self.new_model(image, centre_boxes(box)))
                new_ids = np.arange(self.born + 1, self.born + len(born) + 1)
                self.counts.update({"births": len(born), "shown_frames": len(born)})
                self.born += len(born)
                ids, boxes = np.concatenate([ids, new_ids]), np.vstack([boxes, born])
                unsupported = np.concatenate([unsupported, np.zeros(len(born), int)])
            yield frame, np.concatenate([out_ids, new_ids]), np.vstack([out_boxes, born])


@dataclass
class DetectionTracker:
    """A reference tracker on the detections alone: ``link(detections)`` gives the whole track table."""

    link: Callable[[pd.DataFrame], pd.DataFrame]
    stopwatch: Stopwatch = field(default_factory=Stopwatch, init=False)
    counts: Counter = field(default_factory=Counter, init=False)  # no particles: no EVENTS

    def track(self, sequence, frames, rng: np.random.Generator) -> Iterator[Frame]:
        frames = list(frames)
        with self.stopwatch:
            table = self.link(sequence.detections[sequence.detections["frame"].isin(frames)])
        by_frame = {frame: rows for frame, rows in table.groupby("frame")}
        for frame in frames:
            rows = by_frame.get(frame, table.iloc[:0])
            yield frame, rows["id"].to_numpy(), rows[BOX].to_numpy(float)


@drawn("black")
def sort_tracker(**settings) -> DetectionTracker:
    """SORT on the public detections (:func:`replication.filters.mot_baselines.sort`)."""
    return DetectionTracker(partial(sort, **settings))


@drawn("black", ":", "x")
def detections_only_tracker(**settings) -> DetectionTracker:
    """The public detections linked frame to frame (:func:`replication.filters.mot_baselines.detections_only`)."""
    return DetectionTracker(partial(detections_only, **settings))
