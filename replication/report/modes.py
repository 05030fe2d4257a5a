"""Does a hidden target's posterior keep every hypothesis?  bis_pf's multimodality claim, scored.

While target 3 of the 3123 test is hidden it may be behind target 1 or
behind target 2: a filter that keeps both hypotheses has mass near both
targets' positions.  From the marginal strip a tracking run stores (one
weighted histogram of the hidden target's coordinate per frame), a frame
counts as two-mode when at least ``mass`` of the marginal lies within
``width`` px of each hypothesis, in the frames of ``window`` where the two
hypotheses are more than 2 ``width`` apart (before that they are one mode).
A run keeps both modes when most of those frames do; a method does when
most of its runs do (the table kind ``modes`` in :mod:`replication.report.tables`).
The hypotheses come from the video each run saw (its ``scene_seed``).
"""

import numpy as np
import pandas as pd

from replication.evidence.aggregate import scene_of
from replication.scenes.factory import cached_sequence


def two_mode_share(density: np.ndarray, hypotheses: np.ndarray, extent: float, width: float, mass: float) -> float:
    """Share of frames whose marginal (frames, bins over [0, extent)) holds ``mass`` near each of two
    hypotheses (frames, 2); frames whose hypotheses are within 2 ``width`` of each other are left out."""
    centres = (np.arange(density.shape[1]) + 0.5) * extent / density.shape[1]
    apart = np.abs(hypotheses[:, 0] - hypotheses[:, 1]) > 2 * width
    if not apart.any():
        raise ValueError("the two hypotheses never separate in the window")
    near = np.abs(centres[None, None, :] - hypotheses[:, :, None]) <= width  # (frames, 2, bins)
    held = (density[:, None, :] * near).sum(axis=-1) >= mass  # (frames, 2)
    return float(held.all(axis=1)[apart].mean())


def runs_keeping_both_modes(group: pd.DataFrame, spec: dict, experiment: dict) -> np.ndarray:
    """Per run of one (method, condition): the share of the window's frames whose marginal of the hidden
    target holds ``spec.mass`` within ``spec.width`` px of each hypothesis (``spec.hypotheses``' targets)."""
    first, last = spec["window"]
    width, mass = spec.get("width", 5.0), spec.get("mass", 0.1)
    scene = experiment["scenes"][scene_of(experiment, group)]
    shares = []
    for _, run in group.iterrows():
        seed = run.get("scene_seed")
        sequence = cached_sequence(scene if seed is None or pd.isna(seed) else {**scene, "seed": int(seed)})
        axis = "xy".index(run["strip"]["axis"])
        truth = sequence.truth[first : last + 1, spec["hypotheses"]]  # frames first..last; strips start at frame 1
        hypotheses = truth[..., axis] + truth[..., axis + 2] / 2
        density = np.asarray(run["strip"]["density"])[first - 1 : last]
        shares.append(two_mode_share(density, hypotheses, sequence.size[axis], width, mass))
    return np.array(shares)
