"""Does a hidden target's posterior keep every hypothesis?  bis_pf's multimodality claim, scored.

While target 3 of the 3123 test is hidden it may be behind target 1 or
behind target 2: a filter that keeps both hypotheses has mass near both
targets' positions.  From the marginal strip a tracking run stores (one
weighted histogram of the hidden target's coordinate per frame), a frame
counts as two-mode when at least ``mass`` of the marginal lies within
``width`` px of each hypothesis, in the frames of ``window`` where the two
hypotheses are more than 2 ``width`` apart (before that they are one mode).
A run keeps both modes when most of those frames do; a method does when
most of its runs do (the table kind :class:`Modes`).
The hypotheses come from the video each run saw (its ``scene_seed``), read through the caller's
:class:`~replication.evidence.footage.Footage`.
"""

from dataclasses import dataclass

import numpy as np
import pandas as pd

from replication.evidence.footage import Footage
from replication.evidence.statistics import proportion
from replication.evidence.tables.table import Compared, Table, TableKind, match
from replication.evidence.verdict import judge_band


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


def runs_keeping_both_modes(group: pd.DataFrame, spec: "Modes.Spec", experiment: dict, footage: Footage) -> np.ndarray:
    """Per run of one (method, condition): the share of the window's frames whose marginal of the hidden
    target holds ``spec.mass`` within ``spec.width`` px of each hypothesis (``spec.hypotheses``' targets)."""
    first, last = spec.window
    width, mass = spec.width, spec.mass
    shares = []
    for index, run in group.iterrows():
        sequence = footage.seen(experiment, group.loc[[index]])
        axis = "xy".index(run["strip"]["axis"])
        truth = sequence.truth[first : last + 1, list(spec.hypotheses)]  # frames first..last; strips start at frame 1
        hypotheses = truth[..., axis] + truth[..., axis + 2] / 2
        density = np.asarray(run["strip"]["density"])[first - 1 : last]
        shares.append(two_mode_share(density, hypotheses, sequence.size[axis], width, mass))
    return np.array(shares)


class Modes(TableKind):
    """Does a hidden target's posterior keep both hypotheses?  Runs that do, per method (bis_pf's 3123 text)."""

    kind = "modes"
    reads = ("strip",)
    BANDS = {"success": (0.5, 1.0), "failure": (0.0, 0.5)}  # most runs keep both modes, or most do not

    @dataclass(frozen=True, kw_only=True)
    class Spec(Compared):
        """The hidden target's frames ``window`` (first, last), the targets of its two ``hypotheses``, and
        the ``mass`` within ``width`` px of each that keeps a mode."""

        window: tuple[int, int]
        hypotheses: tuple[int, ...]
        width: float = 5.0
        mass: float = 0.1

    def build(self, records: pd.DataFrame) -> Table:
        theirs = self.theirs()
        stripped = records[records["strip"].notna()] if "strip" in records else records.iloc[:0]
        rows, entries = [], []
        for (method, condition), group in stripped.groupby(["method", "condition"], sort=False):
            shares = runs_keeping_both_modes(group, self.spec, self.experiment, self.footage)
            keeping = int((shares > 0.5).sum())
            estimate = proportion(keeping, len(shares))
            hit = match(theirs, method, group.iloc[0], self.spec)
            paper = hit["value"].iloc[0] if len(hit) else ""
            ours = "success" if estimate.value > 0.5 else "failure"
            verdict = judge_band(paper, keeping, len(shares), self.BANDS) if paper else None
            row = {"method": self.label(method), "condition": condition or "-", "runs": len(shares),
                   "two-mode frames (mean share)": round(float(shares.mean()), 3),
                   "runs keeping both modes (Clopper-Pearson 95% CI)": str(estimate), "ours": ours, "paper": paper,
                   "verdict": verdict}
            rows.append(row)
            entries += [self.entry(i, row, verdict, estimate, rating=ours) for i in hit.index]
        return Table(pd.DataFrame(rows), entries)

