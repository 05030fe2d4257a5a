"""Trackers following targets through an image sequence (synthetic scene or OTB): one tracker for all targets.

The first frame's true box initialises each filter and its reference
histogram (the OTB one-pass protocol); frames 1..T-1 are filtered by the
method's tracker (:mod:`replication.filters.tracker`), every
target's filter stepping through a frame before the next frame is produced,
so the frame's features are computed once for all targets.  A synthetic
scene's ``scene_seed`` says whether every run sees the configured video
(``fixed``) or the repetition draws its own (``per_run``).  Timings are per
frame for all targets together and exclude producing the frame (rendering or
JPEG decoding), which the papers' videos did not pay for.  The OTB scores
(precision at 20 px, success AUC) count the given first frame or not as
:data:`replication.metrics.tracking.COUNT_FIRST_FRAME` says; the filter's own
averages (mean CLE, shares of correct frames) are over the frames it filtered.
"""

import numpy as np
import pandas as pd

from replication.boxes import centre_boxes, centres, corner_boxes
from replication.filters.registry import build_filter
from replication.filters.tracker import Adaptation, Marginal
from replication.filters.tracker import tracker as make_tracker
from replication.metrics import multi
from replication.metrics import tracking as tm
from replication.metrics.means import fsum_mean
from replication.metrics.mot import BOX
from replication.metrics.scalar import filter_diagnostics
from replication.models.box import BoxModel
from replication.run import Run
from replication.scenes.factory import cached_sequence, scene_kind
from replication.smc.work import Counted, Work
from replication.vision.colour import ColourLikelihood
from replication.vision.fusion import FusionLikelihood
from replication.vision.histogram import ColourHistogram

OBSERVATIONS = ("colour", "fusion")  # kernel colour histogram; colour + structure (fusion_pf)
FUSION_KEYS = ("square", "alpha", "adaptive")
SCENE_SEEDS = ("fixed", "per_run")


def targets(model: dict, n_targets: int) -> list[int]:
    """The targets a run tracks: the model's ``targets``, else the scene's ``track`` (a list, or
    ``all``), else ``target`` (default 0)."""
    chosen = model.get("targets", model.get("scene_spec", {}).get("track", [model.get("target", 0)]))
    return list(range(n_targets)) if chosen == "all" else list(chosen)


def scene_spec(run: Run) -> dict:
    """The run's scene: as configured (``scene_seed: fixed``: every run sees the same video), or seeded
    from the repetition's data stream (``per_run``: bis_pf 3.2 generates its videos "on the fly"), which
    every method at that repetition shares (common random numbers)."""
    spec = run.model["scene_spec"]
    if spec.get("scene_seed", "fixed") == "fixed":
        return spec
    return {**spec, "seed": int(run.rng("data").integers(2**31))}


def check(model: dict, method: dict) -> None:
    if "scene_spec" not in model:
        raise ValueError("a tracking experiment needs model.scene naming one of experiment.scenes")
    if scene_kind(model["scene_spec"]).open_set:
        raise ValueError("a tracking experiment follows a fixed set of targets; a scene whose people come and go "
                         "is the mot task's")
    if model["scene_spec"].get("scene_seed", "fixed") not in SCENE_SEEDS:
        raise ValueError(f"unknown scene_seed {model['scene_spec']['scene_seed']!r}; choose one of {SCENE_SEEDS}")
    observation = model.get("observation", {})
    if observation.get("kind", "colour") not in OBSERVATIONS:
        raise ValueError(f"unknown observation {observation.get('kind')!r}; choose one of {OBSERVATIONS}")
    sequence = cached_sequence(model["scene_spec"])
    for target in targets(model, sequence.truth.shape[1]):
        if not 0 <= target < sequence.truth.shape[1]:
            raise ValueError(f"target {target} not in the scene's {sequence.truth.shape[1]} targets")
    ColourHistogram(**histogram_args(observation, (8, 8), np.random.default_rng(0)))  # validation only
    unknown = set(observation) - {"kind", "bins", "kernel", "grid", "samples", "sigma", *FUSION_KEYS}
    if unknown:
        raise ValueError(f"unknown observation keys {sorted(unknown)}")
    BoxModel(np.zeros(4), None, **model.get("motion", {}))


def histogram_args(observation: dict, box_size, rng) -> dict:
    grid = observation.get("grid") or tuple(max(int(round(v)), 1) for v in box_size)
    return {
        "bins": tuple(observation.get("bins", (8, 8, 4))),
        "kernel": observation.get("kernel", "epanechnikov"),
        "grid": grid,
        "samples": observation.get("samples"),
        "rng": rng,
    }


def build_model(run: Run, sequence, target: int, cache: dict) -> BoxModel:
    observation = run.model.get("observation", {})
    initial = centre_boxes(sequence.truth[0, target])
    histogram = ColourHistogram(**histogram_args(observation, initial[2:4], run.rng(f"pattern{target}")))
    first = sequence.frame(0)
    if observation.get("kind", "colour") == "fusion":
        fusion = {k: observation[k] for k in FUSION_KEYS if k in observation}
        likelihood = FusionLikelihood.from_frame(first, initial, histogram, observation.get("sigma", 1.0), **fusion)
    else:
        likelihood = ColourLikelihood.from_frame(first, initial, histogram, observation.get("sigma", 0.1))
    return BoxModel(initial, likelihood, cache=cache, first_frame=first, **run.model.get("motion", {}))


def multi_target_scores(evaluation: dict, estimates: np.ndarray, truth: np.ndarray, visibility: np.ndarray,
                        chosen: list[int]) -> dict:
    """bis_pf's numbers: mean error per target (px) with identities (the paper's), without them (optimal
    assignment per frame; OSPA cut off at ``loss_threshold``) and while tracked (each target's frames
    before its first loss), targets lost, identity switches and their rate per close encounter (two truths
    within ``loss_threshold``), and failure.

    A target is lost when its estimate stays more than ``loss_threshold`` px
    from its own truth for ``loss_patience`` frames in a row while at least half
    of it is visible, from frame ``from_frame`` on (1-based; the 3123 test judges
    only after target 3 reappears).  A swap loses both targets.  A run fails
    when any target is lost (``failed``); with ``key_target`` (a scene target,
    0-based) it also says whether that one is (``failed[target<k + 1>]``: the
    3123 test's success is target 3 picked up again, section 3.1).

    The paper never defines failure, so two other readings are recorded with the same ``loss_threshold`` and
    ``loss_patience`` K: ``failed[swap]``, an estimate that sits on another target (the frame's optimal
    assignment) for K visible frames in a row, an identity swap that persists; ``failed[drift]``, an
    estimate over the threshold from every target for K visible frames, lock lost whoever it was on.
    ``error_without_failure[lost|swap|drift]`` is the mean error per target of a run that does not fail by
    that reading (NaN where it does): Table 2 averages "runs without failure".
    """
    threshold = evaluation.get("loss_threshold", 20.0)
    start = max(int(evaluation.get("from_frame", 2)) - 1, 1)
    estimated, true = centres(estimates), centres(truth)
    errors = np.linalg.norm(estimated - true, axis=-1)[start:]
    visible = visibility[start:] >= 0.5
    patience = evaluation.get("loss_patience", 10)
    onsets = multi.loss_onsets(np.where(visible[..., None], estimated[start:], true[start:]), true[start:], threshold,
                               patience)
    lost = onsets < len(visible)
    failures = {"swap": multi.swapped(estimated[start:], true[start:], threshold),
                "drift": multi.off_every_target(estimated[start:], true[start:], threshold)}
    failed = {"lost": bool(lost.any()), **{name: bool((multi.persistent_onsets(flags & visible, patience)
                                                       < len(visible)).any()) for name, flags in failures.items()}}
    error = multi.mean_error_per_target(estimated[1:], true[1:])
    mot = multi.clear_mot(true[1:], estimated[1:], threshold, visibility[1:] >= 0.5)
    encounters = multi.close_encounters(true[1:], threshold)
    key = {}
    if "key_target" in evaluation:
        key[f"failed[target{evaluation['key_target'] + 1}]"] = float(lost[chosen.index(evaluation["key_target"])])
    return {
        "mean_error_per_target": error,
        "identity_free_error": multi.identity_free_error(estimated[1:], true[1:]),
        f"ospa[c={threshold:g}]": multi.ospa(estimated[1:], true[1:], threshold),
        "tracked_error": multi.tracked_error(estimated[start:], true[start:], onsets),
        "encounters": encounters,
        "swaps_per_encounter": mot["switches"] / encounters if encounters else float("nan"),
        "lost_targets": int(lost.sum()),
        "failed": float(lost.any()),
        **{f"failed[{name}]": float(value) for name, value in failed.items() if name != "lost"},
        **{f"error_without_failure[{name}]": float("nan") if value else error for name, value in failed.items()},
        "switches": mot["switches"],
        "mota": mot["mota"],
        "visible_error": fsum_mean(errors[visible]),
        **key,
    }


def outside_frames(estimates: np.ndarray, size) -> int:
    """How many (frame, target) estimates put the box's centre outside the image (width, height): the
    filter's own state, never clipped, so a tracker that runs off the frame shows it."""
    return int(tm.outside_image(estimates, size).sum())


def run(run: Run) -> dict:
    """Track every target of the run; numbers are averaged over targets, 'tracked to the end' needs all."""
    spec = scene_spec(run)
    sequence = cached_sequence(spec)
    chosen = targets(run.model, sequence.truth.shape[1])
    cache: dict = {}
    work = Work()  # every target's model counts into it (replication.smc.work)
    tracker = make_tracker(lambda: build_filter(run.method, run.method_params))
    tracker.start({t: Counted(build_model(run, sequence, t, cache), work) for t in chosen}, run.rng)
    strip = spec.get("strip")  # a target whose marginal over x or y is kept per frame
    collectors = {"alpha": Adaptation(0)}  # fusion_pf's alpha_k, first target
    if strip:
        axis = strip.get("axis", "x")
        collectors["strip"] = Marginal(chosen.index(strip["target"]), axis, strip.get("bins", 60), sequence.size["xy".index(axis)])
    for _ in tracker.track((sequence.frame(k) for k in range(1, sequence.n_frames)), collectors.values()):
        pass
    outputs = tracker.outputs()
    diagnostics = [filter_diagnostics(output) for output in outputs]
    boxes = [corner_boxes(output.means) for output in outputs]
    estimates = np.stack([np.vstack([sequence.truth[:1, t], b]) for t, b in zip(chosen, boxes)], axis=1)  # (T, M, 4)
    truth = sequence.truth[:, chosen]
    errors, overlaps = tm.centre_error(estimates, truth), tm.iou(estimates, truth)  # (T, M)
    deviation = tm.deviation(estimates, truth)
    filtered = slice(1, None)  # frame 0 is given
    record = {
        "frames": sequence.n_frames,
        "mean_cle": fsum_mean(errors[filtered]),
        "precision20": fsum_mean([tm.precision_at(e) for e in tm.scored_frames(errors).T]),
        "success_auc": fsum_mean([tm.success_auc(o) for o in tm.scored_frames(overlaps).T]),
        "ms_per_frame": 1000.0 * tracker.stopwatch.wall / (sequence.n_frames - 1),
        "cpu_ms_per_frame": 1000.0 * tracker.stopwatch.cpu / (sequence.n_frames - 1),
        "filter_s": tracker.stopwatch.wall,  # the whole sequence, frame production excluded
        "cpu_filter_s": tracker.stopwatch.cpu,
        "fps": (sequence.n_frames - 1) / tracker.stopwatch.wall,
        **work.record(sequence.n_frames - 1),  # per filtered frame, all targets
        "mean_ess": fsum_mean([d["mean_ess"] for d in diagnostics]),
        "resample_count": fsum_mean([d["resample_count"] for d in diagnostics]),
        "resample_rate": fsum_mean([d["resample_rate"] for d in diagnostics]),  # % of filtered frames
        "degenerate_steps": int(sum(d["degenerate_steps"] for d in diagnostics)),
        "outside_frames": outside_frames(estimates[filtered], sequence.size),
    }
    if "seed" in spec:
        record["scene_seed"] = spec["seed"]  # the video this run saw
    if len(chosen) > 1:
        evaluation = {**run.model.get("evaluation", {}), **spec.get("evaluation", {})}
        record.update(multi_target_scores(evaluation, estimates, truth, sequence.visibility[:, chosen], chosen))
    for rule in tm.CORRECT_RULES:
        correct = tm.correct_frames(errors[filtered], overlaps[filtered], rule)
        record[f"correct_frames[{rule}]"] = float(correct.mean())
        record[f"tracked_to_end[{rule}]"] = float(all(tm.tracked_to_end(c) for c in correct.T))
    if strip:
        record["strip"] = {"target": strip["target"], "axis": strip.get("axis", "x"), "density": np.round(collectors["strip"].value, 4).tolist()}
    record["per_frame"] = {
        "cle": np.round(errors.mean(axis=1), 3).tolist(),
        "iou": np.round(overlaps.mean(axis=1), 4).tolist(),
        "dx": np.round(deviation[..., 0].mean(axis=1), 3).tolist(),
        "dy": np.round(deviation[..., 1].mean(axis=1), 3).tolist(),
        "box": np.round(estimates, 2).tolist(),
        "targets": chosen,
        "ess": [None] + np.round(np.mean([o.ess for o in outputs], axis=0), 2).tolist(),
        "seconds": [None] + np.round(tracker.frame_seconds, 7).tolist(),  # per filtered frame, all targets
        "evaluations": [None] + work.per_step(range(1, sequence.n_frames)),  # likelihood evaluations, all targets
    }
    if collectors["alpha"].value is not None:  # fusion_pf's alpha_k, first target
        record["per_frame"]["alpha"] = [None] + np.round(collectors["alpha"].value, 4).tolist()
    return record


def frame_table(record: dict) -> pd.DataFrame:
    """A run's ``per_frame`` series as rows (frame, target): the target's estimated box (x, y, w, h;
    at frame 0 the true box it was given) and the frame's ``cle``, ``iou``, ``dx``, ``dy`` and
    ``ess`` (NaN at frame 0), means over the run's targets, and fusion_pf's ``alpha`` (its first
    target's), as the record holds them: the same on every target's row of a multi-target run.
    Frames count from 0, the first of the run's sequence."""
    series = record["per_frame"]
    boxes = np.asarray(series["box"], dtype=float)  # (T, M, 4)
    n_frames, n_targets = boxes.shape[:2]
    table = pd.DataFrame({"frame": np.repeat(np.arange(n_frames), n_targets),
                          "target": np.tile(series["targets"], n_frames)})
    table[BOX] = boxes.reshape(-1, 4)
    for name, values in series.items():
        if name not in ("box", "targets"):
            table[name] = np.repeat(np.asarray(values, dtype=float), n_targets)
    return table
