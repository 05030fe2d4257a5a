"""Tracking an open set of people through a real MOT sequence (bis_pf Experiment 6, PETS 2009).

The scene is ``kind: mot`` (a MOTChallenge folder, :mod:`replication.scenes.mot`) with the
frames ``first`` to ``last`` (MOT numbers, inclusive; ``last`` empty: to the end).  The
method is a joint particle filter run by :class:`~replication.filters.open_tracker.ParticleTracker`
(births, deaths, the detection-fused proposal: the model's ``births``, ``deaths``,
``association`` and ``proposal`` settings) or a reference on the detections alone.
A target's colour model (the kernel histogram of ``observation``) is taken from its first
detection's box; its motion is ``motion`` (a random walk).

The record holds the MOT metrics of its track table against the ground truth of those
frames (CLEAR MOT and IDF1 at IoU 0.5, flag-0 boxes ignored: :mod:`replication.metrics.mot`;
HOTA by TrackEval: :mod:`replication.metrics.hota`),
bis_pf's error (the distance from a person's box centre to the centre of the track matched
to it, in px, averaged over every match), where the false positives and misses come from
(:func:`~replication.metrics.mot_errors.error_sources`), tracks started per person, where a particle tracker's
frames went (:func:`breakdown`), how close its boxes are to the detections it was given (the mean
IoU of each output box with its frame's nearest detection: 1 for the detections themselves), the
time per frame (frame decoding excluded) and the track table itself (``tracks``: rows frame, id,
x, y, w, h) for the pictures.
"""

from functools import lru_cache

import numpy as np
import pandas as pd

from replication.filters.registry import build_filter
from replication.filters.joint import JointFilter
from replication.filters.open_tracker import DetectionTracker, ParticleTracker
from replication.filters.track_management import Deleter, Initiator, in_frames
from replication.metrics.hota import hota
from replication.metrics.mot_errors import error_sources
from replication.metrics.mot import (
    BOX, clear_mot_matches, detection_overlap, drop_ignored, matched_centre_error, mot_metrics,
)
from replication.models.boosted import BoostedBoxModel
from replication.run import Run
from replication.scenes.factory import scene_kind
from replication.scenes.mot import MOT_ROOT, load_mot
from replication.smc.work import Counted, Work
from replication.tasks.tracking import histogram_args
from replication.vision.colour import ColourLikelihood
from replication.vision.histogram import ColourHistogram

SCENE_KEYS = {"kind", "name", "root", "first", "last", "stand_in"}
MODEL_KEYS = {"scene", "scene_spec", "motion", "size_steps", "observation", "births", "deaths", "association",
              "proposal", "detection_term", "min_iou"}
TRACK_COLUMNS = ["frame", "id", *BOX]  # a row of the record's ``tracks``


@lru_cache(maxsize=4)
def sequence_of(name: str, root: str):
    return load_mot(name, root)


def frames_of(spec: dict, sequence) -> range:
    """The MOT frame numbers a run covers: ``first`` (default 1) to ``last`` (default the last)."""
    first, last = spec.get("first", 1), spec.get("last") or sequence.n_frames
    if not 1 <= first <= last <= sequence.n_frames:
        raise ValueError(f"{sequence.name}: frames {first}..{last} outside 1..{sequence.n_frames}")
    return range(first, last + 1)


def _tracker(run_model: dict, method, new_model, frame_rate: float) -> ParticleTracker | DetectionTracker:
    """The open-set tracker of a configured method: a joint filter gets the births, deaths and association,
    patience given in seconds converted at the sequence's ``frame_rate``."""
    if isinstance(method, DetectionTracker):
        return method
    if not isinstance(method, JointFilter):
        raise TypeError(f"{type(method).__name__} tracks a fixed set of targets; a real video needs a joint filter "
                         "(mipf, bis, mfmc, dmot, mcmc) or a detection tracker (sort, detections_only)")
    association = run_model.get("association", {})
    return ParticleTracker(
        method, new_model, Initiator(**in_frames(run_model.get("births", {}), frame_rate)),
        Deleter(**in_frames(run_model.get("deaths", {}), frame_rate)),
        association_iou=association.get("min_iou", 0.3), min_score=association.get("min_score", -np.inf),
        output=association.get("output", "supported"), box=association.get("box", "estimate"),
    )


def box_motion(run_model: dict) -> dict:
    """The random walk of a person's box: ``motion`` with its ``step_sd`` the centre's steps (cx, cy) and
    ``size_steps`` the size's (w, h), px per frame.  The size steps are the multi-target pipeline's own key,
    so that a reading of them leaves the balls' experiments alone (``motion.step_sd`` is a key they share in
    the readings multiverse)."""
    motion = dict(run_model.get("motion", {}))
    centre = list(motion.get("step_sd", ()))
    if len(centre) != 2 or "size_steps" not in run_model:
        raise ValueError("a mot experiment gives motion.step_sd as the centre's steps [cx, cy] and size_steps as "
                         f"the size's [w, h]; got step_sd {centre} and size_steps {run_model.get('size_steps')}")
    return {**motion, "step_sd": [*centre, *run_model["size_steps"]]}


def _model_builder(run_model: dict, rng: np.random.Generator, work: Work):
    """``new_model(image, box)``: a target's model with its colour reference from ``box`` (cx, cy, w, h) in
    ``image``, its work counted into ``work``."""
    observation, cache = run_model.get("observation", {}), {}

    def new_model(image: np.ndarray, box: np.ndarray) -> Counted:
        histogram = ColourHistogram(**histogram_args(observation, box[2:4], rng))
        likelihood = ColourLikelihood.from_frame(image, box, histogram, observation.get("sigma", 0.1))
        return Counted(BoostedBoxModel(box, likelihood, cache=cache, detection_term=run_model.get("detection_term"),
                                       **box_motion(run_model), **run_model.get("proposal", {})), work)

    return new_model


def check(model: dict, method: dict) -> None:
    spec = model.get("scene_spec")
    if spec is None or not scene_kind(spec).open_set:
        raise ValueError("a mot experiment needs model.scene naming a scene whose people come and go (kind: mot)")
    unknown = (set(spec) - SCENE_KEYS) | (set(model) - MODEL_KEYS)
    if unknown:
        raise ValueError(f"unknown keys {sorted(unknown)}")
    sequence = sequence_of(spec["name"], spec.get("root", MOT_ROOT))
    frames_of(spec, sequence)
    ColourHistogram(**histogram_args(model.get("observation", {}), (8, 8), np.random.default_rng(0)))
    BoostedBoxModel(np.ones(4), None, detection_term=model.get("detection_term"), **box_motion(model),
                    **model.get("proposal", {}))
    method_object = build_filter("check", method)
    _tracker(model, method_object, None, sequence.frame_rate)


def breakdown(counts: dict, alpha: float) -> dict:
    """Where a particle tracker's frames went (:class:`ParticleTracker`'s ``counts``): the share of its live
    tracks' frames with an associated detection, ``alpha`` times that (the share of its particles drawn
    from the detections), the share kept alive by the colour alone, its deaths by cause.  None without a
    live track's frame (a detection reference, or no track born)."""
    live = counts.get("track_frames", 0)
    if not live:
        return {}
    detected = counts["detected_frames"] / live
    return {"detected_share": detected, "proposal_detection_share": alpha * detected,
            "colour_share": counts["colour_frames"] / live, "deaths_unsupported": counts["died_unsupported"],
            "deaths_outside": counts["died_outside"]}


def run(run: Run) -> dict:
    spec = run.model["scene_spec"]
    sequence = sequence_of(spec["name"], spec.get("root", MOT_ROOT))
    frames = frames_of(spec, sequence)
    work = Work()  # every target's model counts into it (replication.smc.work); none for a detection reference
    new_model = _model_builder(run.model, run.rng("pattern"), work)
    tracker = _tracker(run.model, build_filter(run.method, run.method_params), new_model, sequence.frame_rate)
    rows = [
        (frame, int(i), *box)
        for frame, ids, boxes in tracker.track(sequence, frames, run.rng("filter"))
        for i, box in zip(ids, boxes)
    ]
    tracks = pd.DataFrame(rows, columns=TRACK_COLUMNS).round(1).astype({"frame": int, "id": int})  # as stored
    truth, ignored = (table[table["frame"].isin(frames)] for table in (sequence.truth, sequence.ignored))
    min_iou = run.model.get("min_iou", 0.5)
    kept = drop_ignored(tracks, truth, ignored, min_iou)  # once, for every metric below
    matches = clear_mot_matches(truth, kept, min_iou=min_iou)
    given = sequence.detections
    used = given[given["frame"].isin(frames) & (given["score"] >= run.model.get("association", {}).get("min_score", -np.inf))]
    scores = {
        **mot_metrics(truth, kept, min_iou=min_iou),
        "ignored_hypotheses": len(tracks) - len(kept),
        **hota(truth, kept, min_iou=min_iou),
        "mean_error_per_target": matched_centre_error(truth, kept, matches),
        **error_sources(truth, kept, used, matches, min_iou=min_iou),
    }
    people = int(truth["id"].nunique())
    return {
        "sequence": sequence.name,
        "first_frame": frames.start,
        "last_frame": frames.stop - 1,
        "frames": len(frames),
        **scores,
        "tracks_started": int(tracks["id"].nunique()),
        "people": people,
        "tracks_per_person": tracks["id"].nunique() / people if people else float("nan"),
        **breakdown(tracker.counts, run.model.get("proposal", {}).get("alpha", 0.5)),
        **({"detection_iou": detection_overlap(tracks, used)} if len(tracks) else {}),
        "ms_per_frame": 1000.0 * tracker.stopwatch.wall / len(frames),
        "cpu_ms_per_frame": 1000.0 * tracker.stopwatch.cpu / len(frames),
        **work.record(len(frames)),
        "fps": len(frames) / tracker.stopwatch.wall if tracker.stopwatch.wall > 0 else float("inf"),
        "tracks": tracks.to_numpy(float).tolist(),
    }


def frame_table(record: dict) -> pd.DataFrame:
    """A run's ``tracks`` as rows (frame, id): the MOT frame number (from 1), the track's id (from 1)
    and its box (x, y, w, h, top-left from 0)."""
    return pd.DataFrame(list(record["tracks"]), columns=TRACK_COLUMNS).astype({"frame": int, "id": int})
