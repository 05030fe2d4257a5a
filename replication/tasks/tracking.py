"""One filter tracking one target through an image sequence (synthetic scene or OTB).

The first frame's true box initialises the filter and the reference
histogram (the OTB one-pass protocol); frames 1..T-1 are filtered.  Timings
exclude producing the frames (rendering or JPEG decoding), which the papers'
videos did not pay for.
"""

import time

import numpy as np

from replication.metrics import tracking as tm
from replication.metrics.scalar import filter_diagnostics
from replication.models.box import BoxModel
from replication.runner.config import Run, build_filter
from replication.scenes.factory import cached_sequence
from replication.vision.colour import ColourLikelihood
from replication.vision.histogram import ColourHistogram

OBSERVATIONS = ("colour",)


def check(model: dict, method: dict) -> None:
    if "scene_spec" not in model:
        raise ValueError("a tracking experiment needs model.scene naming one of experiment.scenes")
    observation = model.get("observation", {})
    if observation.get("kind", "colour") not in OBSERVATIONS:
        raise ValueError(f"unknown observation {observation.get('kind')!r}; choose one of {OBSERVATIONS}")
    sequence = cached_sequence(model["scene_spec"])
    target = model.get("target", 0)
    if not 0 <= target < sequence.truth.shape[1]:
        raise ValueError(f"target {target} not in the scene's {sequence.truth.shape[1]} targets")
    ColourHistogram(**_histogram_args(observation, (8, 8), None))
    BoxModel(np.zeros(4), None, **model.get("motion", {}))


def _histogram_args(observation: dict, box_size, rng) -> dict:
    grid = observation.get("grid") or tuple(max(int(round(v)), 1) for v in box_size)
    return {
        "bins": tuple(observation.get("bins", (8, 8, 4))),
        "kernel": observation.get("kernel", "epanechnikov"),
        "grid": grid,
        "samples": observation.get("samples"),
        "rng": rng,
    }


def build_model(run: Run, sequence) -> BoxModel:
    observation = run.model.get("observation", {})
    x, y, w, h = sequence.truth[0, run.model.get("target", 0)]
    initial = np.array([x + w / 2, y + h / 2, w, h])
    histogram = ColourHistogram(**_histogram_args(observation, (w, h), run.rng("pattern")))
    likelihood = ColourLikelihood.from_frame(sequence.frame(0), initial, histogram, observation.get("sigma", 0.1))
    return BoxModel(initial, likelihood, **run.model.get("motion", {}))


class _TimedFrames:
    """Frames 1..T-1 of a sequence, counting the time spent producing them."""

    def __init__(self, sequence):
        self.sequence, self.seconds = sequence, 0.0

    def __iter__(self):
        for k in range(1, self.sequence.n_frames):
            started = time.perf_counter()
            frame = self.sequence.frame(k)
            self.seconds += time.perf_counter() - started
            yield frame


def run(run: Run) -> dict:
    sequence = cached_sequence(run.model["scene_spec"])
    truth = sequence.truth[:, run.model.get("target", 0)]
    model = build_model(run, sequence)
    method = build_filter(run.method, run.method_params)
    frames = _TimedFrames(sequence)
    started = time.perf_counter()
    output = method.run(model, frames, run.rng("filter"))
    elapsed = time.perf_counter() - started - frames.seconds
    estimates = np.vstack([truth[:1], BoxModel.boxes(output.means)])
    errors, overlaps = tm.centre_error(estimates, truth), tm.iou(estimates, truth)
    deviation = tm.deviation(estimates, truth)
    scored = slice(1, None)  # frame 0 is given
    record = {
        "frames": sequence.n_frames,
        "mean_cle": float(errors[scored].mean()),
        "precision20": tm.precision_at(errors[scored]),
        "success_auc": tm.success_auc(overlaps[scored]),
        "ms_per_frame": 1000.0 * elapsed / (sequence.n_frames - 1),
        **filter_diagnostics(output),
    }
    for rule in tm.CORRECT_RULES:
        correct = tm.correct_frames(errors[scored], overlaps[scored], rule)
        record[f"correct_frames[{rule}]"] = float(correct.mean())
        record[f"tracked_to_end[{rule}]"] = float(tm.tracked_to_end(correct))
    record["per_frame"] = {
        "cle": np.round(errors, 3).tolist(),
        "iou": np.round(overlaps, 4).tolist(),
        "dx": np.round(deviation[:, 0], 3).tolist(),
        "dy": np.round(deviation[:, 1], 3).tolist(),
        "box": np.round(estimates, 2).tolist(),
        "ess": [None] + np.round(output.ess, 2).tolist(),
    }
    return record
