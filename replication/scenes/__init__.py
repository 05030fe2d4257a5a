"""Image sequences with per-frame ground truth: synthetic scenes, real OTB and MOT sequences, video files.

Synthetic, OTB and video-file sequences give one interface (:class:`replication.scenes.base.Sequence`):
frames as uint8 BGR arrays, ``truth`` boxes (x, y, w, h; 0-based, pixels) and ``visibility``
fractions for every target.  MOT sequences (:mod:`replication.scenes.mot`) are multi-target
with births and deaths: their ground truth and detections are tables.
"""

from replication.scenes.base import Sequence
from replication.scenes.mot import MotSequence, load_mot
from replication.scenes.otb import OTBSequence, find_otb
from replication.scenes.synthetic import SyntheticScene
from replication.scenes.video import VideoSequence

__all__ = ["MotSequence", "OTBSequence", "Sequence", "SyntheticScene", "VideoSequence", "find_otb", "load_mot"]
