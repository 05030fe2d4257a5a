"""What judging and drawing read of the video the runs saw, and of their per-frame series, where that needs
the scenes (OpenCV) or the metrics (numba): computed here, below the evidence and the report, and handed up.

:class:`SceneFootage` is the one :class:`~replication.evidence.footage.Footage` there is: the command line and
the report's command build it and pass it to :func:`replication.evidence.judge.judge_experiment` and to the
pages, so that neither ``evidence/`` nor a page or figure imports a scene, a metric or a task.
"""

from collections.abc import Mapping
from functools import lru_cache

import numpy as np
import pandas as pd

from replication.evidence.aggregate import scene_of
from replication.metrics.mot import clear_mot_matches
from replication.metrics.multi import assignments
from replication.runner.curves import curve_table
from replication.scenes.factory import OTB, cached_sequence, scene_kind
from replication.scenes.mot import MOT_ROOT, MotSequence, load_mot
from replication.scenes.otb import otb_attributes
from replication.tasks.mot import frame_table


class SceneFootage:
    """The scenes' sequences, OTB's attribute lists, the curve figures' tables, a MOT run's tracks and CLEAR MOT
    matches, and a frame's optimal assignment, as :class:`~replication.evidence.footage.Footage` names them."""

    @property
    def meanings(self) -> Mapping[str, str]:
        return otb_attributes()[0]

    def attributes(self, scene: dict) -> tuple[str, ...] | None:
        listed = otb_attributes()[1]
        return tuple(listed[scene["name"]]) if scene_kind(scene) is OTB and scene["name"] in listed else None

    def sequence(self, scene: dict):
        return cached_sequence(scene)

    def seen(self, experiment: dict, runs: pd.DataFrame):
        first = runs.sort_values("repetition").iloc[0]
        scene = experiment["scenes"][scene_of(experiment, runs)]
        seed = first.get("scene_seed")
        return cached_sequence(scene if seed is None or pd.isna(seed) else {**scene, "seed": int(seed)})

    def described(self, experiment: dict, written: dict) -> list[dict]:
        return [_described(name, spec, written) for name, spec in experiment.get("scenes", {}).items()]

    def curve(self, records: pd.DataFrame, spec: dict, experiment: dict) -> pd.DataFrame | None:
        return curve_table(records, spec, experiment, self) if spec.curved else None

    def mot_sequence(self, experiment: dict, scene_key: str) -> MotSequence:
        scene = experiment["scenes"][scene_key]
        return _mot(scene["name"], scene.get("root", MOT_ROOT))

    def tracks(self, run) -> pd.DataFrame:
        return frame_table(run)

    def matches(self, truth: pd.DataFrame, tracks: pd.DataFrame, ignored: pd.DataFrame) -> pd.DataFrame:
        return clear_mot_matches(truth, tracks, ignored)

    def assignments(self, estimates, truth):
        return assignments(estimates, truth)


@lru_cache(maxsize=4)
def _mot(name: str, root: str) -> MotSequence:
    return load_mot(name, root)


def _described(name: str, spec: dict, written: dict) -> dict:
    """What a scene of a tracking experiment is, for its page: real video, or a synthetic stand-in and for
    what; for a stand-in whose length depends on the scale, whether the quick video is the start of the
    paper's."""
    kind = scene_kind(spec)
    if kind.real:
        first = spec.get("first", kind.counts_from) - kind.counts_from + 1  # counted from 1, as people do
        frames = f"frames {first}-{spec['last']}" if spec.get("last") else "all frames"
        return {"name": name, "kind": f"real video ({kind.benchmark})",
                "what": f"{kind.benchmark} sequence {spec['name']}, {frames}"}
    size = "x".join(str(v) for v in spec.get("size", []))
    what = spec.get("stand_in") or "synthetic scene"
    return {"name": name, "kind": "synthetic stand-in",
            "what": f"{what} ({size}, {spec.get('frames')} frames){_prefix(written['scenes'][name])}"}


def _prefix(scene: dict) -> str:
    """Whether the quick scale's video of a scene is the first frames of the paper scale's (same seed)."""
    frames = scene.get("frames")
    if not isinstance(frames, dict) or not {"quick", "paper"} <= set(frames):
        return ""
    short, long = (cached_sequence({**scene, "frames": frames[s]}) for s in ("quick", "paper"))
    same = np.array_equal(short.truth, long.truth[: len(short.truth)])
    said = f"; the quick scale's {frames['quick']} frames are {'' if same else 'not '}the first {frames['quick']}"
    return f"{said} of the paper scale's {frames['paper']}" + ("" if same else " (another random walk, same seed)")
