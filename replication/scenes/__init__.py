"""Image sequences with per-frame ground truth: synthetic scenes and real OTB sequences.

Both give the same interface (:class:`replication.scenes.base.Sequence`): frames
as uint8 BGR arrays, ``truth`` boxes (x, y, w, h; 0-based, pixels) and
``visibility`` fractions for every target.
"""

from replication.scenes.base import Sequence
from replication.scenes.otb import OTBSequence, find_otb
from replication.scenes.synthetic import SyntheticScene

__all__ = ["OTBSequence", "Sequence", "SyntheticScene", "find_otb"]
