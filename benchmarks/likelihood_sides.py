"""The two sides of the colour likelihood's speed ratio (``benchmark.py``), and the child process that
``benchmark.instructions`` runs under ``valgrind --tool=callgrind``: ``python likelihood_sides.py SIDE N CALLS``
prepares the inputs and calls SIDE CALLS + 1 times.  It imports little (numpy, OpenCV, the vision
substrate), since under valgrind every instruction of Python's start-up is executed slowly too."""

import sys

import cv2
import numpy as np

from replication.scenes import SyntheticScene
from replication.vision.colour import ColourLikelihood
from replication.vision.histogram import ColourHistogram

BINS = (8, 8, 4)
OURS = "compiled kernel, all 40x40 pixels (the likelihood)"
CALCHIST = "per-particle cv2.calcHist loop (no kernel)"


def scene_frame() -> tuple[np.ndarray, np.ndarray]:
    """The frame every likelihood timing scores (480 x 410, one 40 x 40 ball) and the ball's box."""
    scene = SyntheticScene(
        {"size": [480, 410], "frames": 1, "background": {"kind": "noise", "colour": [90, 120, 90]},
         "targets": [{"shape": "ball", "size": [40, 40], "colour": [40, 60, 200],
                      "motion": {"kind": "scripted", "keyframes": [[0, 240, 205]]}}]}
    )
    return scene.frame(0), np.array([240.0, 205.0, 40.0, 40.0])


def scored(n: int, rng: np.random.Generator) -> dict:
    """One call of each side of the likelihood ratio on ``n`` boxes jittered about the ball: ours (the
    compiled kernel histogram of every pixel, the frame prepared once) and the per-particle calcHist loop."""
    frame, box = scene_frame()
    boxes = box + np.column_stack([rng.normal(0, 8, (n, 2)), np.zeros((n, 2))])
    likelihood = ColourLikelihood.from_frame(frame, box, ColourHistogram(BINS, grid=(40, 40)), sigma=0.1)
    prepared, hsv = likelihood.prepare(frame), cv2.cvtColor(frame, cv2.COLOR_BGR2HSV)
    return {OURS: lambda: likelihood.log_likelihood(boxes, prepared),
            CALCHIST: lambda: [calchist(hsv, b) for b in boxes]}


def calchist(hsv, box):
    cx, cy, w, h = box
    x0, y0 = int(cx - w / 2), int(cy - h / 2)
    roi = hsv[max(y0, 0) : y0 + int(h), max(x0, 0) : x0 + int(w)]
    return cv2.calcHist([roi], [0, 1, 2], None, list(BINS), [0, 180, 0, 256, 0, 256])


if __name__ == "__main__":
    side, n, calls = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
    call = scored(n, np.random.default_rng(0))[side]
    for _ in range(calls + 1):  # the first: numba loads the compiled kernel
        call()
