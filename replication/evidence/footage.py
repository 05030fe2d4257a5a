"""What the evidence and the report read of the video the runs saw and of their per-frame series, where that
needs the scenes (OpenCV) or the metrics (compiled code): a :class:`Footage`, given by the caller
(:class:`replication.runner.footage.SceneFootage`), so that ``evidence/`` opens no video and imports no
compiled code, and a page or figure imports no scene, metric or task."""

from collections.abc import Mapping
from typing import Any, Protocol

import pandas as pd


class Footage(Protocol):
    """The scenes of an experiment and what is computed from a run's series, as the judge and the report ask."""

    @property
    def meanings(self) -> Mapping[str, str]:
        """OTB's attributes: code -> meaning, in the benchmark's order."""

    def attributes(self, scene: dict) -> tuple[str, ...] | None:
        """The OTB attributes of a scene's sequence; None for a scene not in OTB's list (a synthetic one)."""

    def sequence(self, scene: dict) -> Any:
        """A scene's sequence (``truth``, ``size``, ``n_frames``, ``frame(k)``), the same object per spec."""

    def seen(self, experiment: dict, runs: pd.DataFrame) -> Any:
        """The sequence the first repetition of ``runs`` (one condition) saw: its scene at the run's own seed
        where each run has its own video (``scene_seed``), else as configured; every method at that repetition
        saw it."""

    def described(self, experiment: dict, written: dict) -> list[dict]:
        """What each scene of the experiment is (``name``, ``kind``, ``what``), for its page; ``written``: the
        experiment as its YAML writes it (both scales' values)."""

    def curve(self, records: pd.DataFrame, spec, experiment: dict) -> pd.DataFrame | None:
        """The table a curve figure ``spec`` (a typed figure spec) draws from ``records`` (:mod:`replication.runner.curves`); None
        for a figure kind that draws the runs themselves."""

    def mot_sequence(self, experiment: dict, scene_key: str) -> Any:
        """The MOTChallenge sequence of a scene (``truth``, ``ignored``, ``image(frame)``, ``size``, ...)."""

    def tracks(self, run) -> pd.DataFrame:
        """A MOT run's ``tracks`` as rows: frame, id, x, y, w, h."""

    def matches(self, truth: pd.DataFrame, tracks: pd.DataFrame, ignored: pd.DataFrame) -> pd.DataFrame:
        """The CLEAR MOT matches of ``tracks`` against ``truth``, as the metrics count them: frame, truth_id,
        hypothesis_id, switch."""

    def assignments(self, estimates, truth) -> tuple:
        """Per frame, the target each estimate is given by the optimal assignment, and its distance to it."""
