"""How every figure of the report looks and is written: one look per method, human axis labels, diverged
runs clipped, the figure saved (or, where the runs cannot make it, :class:`NothingToDraw`).

A method (its config key) has the same colour, line style and marker on every
figure of every experiment.  The colours are the Okabe-Ito palette, safe for
colour-blind readers; line style and marker keep more methods than colours
apart, and in print.  By convention blue is a plain particle filter and
vermillion the method a paper proposes; black is the Bayes-optimal reference.
A paper's own values are hollow diamonds in the method's colour.
"""

import re
import zlib
from dataclasses import dataclass
from itertools import product
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.colors import to_rgb

from replication import atomic
ORANGE, SKY, GREEN, YELLOW = "#E69F00", "#56B4E9", "#009E73", "#F0E442"
BLUE, VERMILLION, PURPLE, BLACK = "#0072B2", "#D55E00", "#CC79A7", "#000000"
PALETTE = (ORANGE, SKY, GREEN, YELLOW, BLUE, VERMILLION, PURPLE, BLACK)  # Okabe and Ito (2008)
# a verdict's colour in figures, as on the report's pages (base.html.j2): keyed by Outcome's value
OUTCOME_COLOURS = {"reproduced": "#1a7f37", "inconclusive": "#8a5a00", "not reproduced": "#b42318",
                   "not testable": "#999999"}
LINESTYLES = ("-", "--", "-.", ":")
MARKERS = ("o", "s", "^", "v", "D", "P", "X", "*", "<", ">", "h")


@dataclass(frozen=True)
class Look:
    """A method's colour, line style and marker ("" for none)."""

    colour: str
    linestyle: str
    marker: str

    def line(self) -> dict:
        """Keyword arguments of ``Axes.plot``."""
        return {"color": self.colour, "linestyle": self.linestyle, "marker": self.marker or "None"}


METHODS = {  # config key -> look; every method of conf/experiment/*.yaml
    # plain particle filters
    "PF": Look(BLUE, "-", "o"),
    # the baselines over an N sweep, for error against cost (hspf, gps_qmcpf, fusion_pf)
    "PF-N": Look(BLUE, ":", "<"),
    "NQMCPF-N": Look(SKY, ":", "<"),
    "TR-SQMC-N": Look(GREEN, ":", "<"),
    "colour-only-N": Look(BLUE, ":", "s"),
    "MIPF": Look(BLUE, "-", "s"),
    "color-only PF": Look(BLUE, "--", "s"),
    "colour-sigma-0.1": Look(SKY, "--", "s"),
    # what each paper proposes
    "ISM-PF": Look(VERMILLION, "-", "^"),
    "GPS-QMCPF": Look(VERMILLION, "-", "D"),
    "BIS-PF": Look(VERMILLION, "-", "*"),
    "HSPF": Look(VERMILLION, "-", "P"),
    "color+structure fusion PF": Look(VERMILLION, "-", "X"),
    # variants of a proposal
    "ISM-PF-literal": Look(PURPLE, "--", "v"),
    "GPS-QMCPF-fixed": Look(ORANGE, "--", "D"),
    "BIS-PF-beta": Look(VERMILLION, "--", "s"),
    "BIS-PF-K": Look(VERMILLION, ":", "D"),
    "fusion-sigma-0.1": Look(ORANGE, "--", "X"),
    "PSO-GPS": Look(PURPLE, "-.", "P"),
    # the papers' competitors
    "NQMCPF": Look(SKY, "-", "s"),
    "TR-SQMC": Look(GREEN, "-", "v"),
    "PSO-PF": Look(ORANGE, "-", "s"),
    "MRF-JPF": Look(GREEN, "-", "h"),
    "MCMC": Look(ORANGE, "-", "v"),
    "MFMC": Look(PURPLE, "-", "<"),
    "DMOT": Look(SKY, "-", ">"),
    "HS": Look(GREEN, "--", "^"),
    "MS": Look(ORANGE, "-", "<"),
    "MSPF": Look(SKY, "--", ">"),
    "DFT": Look(PURPLE, "-", "h"),
    "MIL": Look(YELLOW, "-", "*"),
    # references on the public detections alone (bis_pf_pets)
    "SORT": Look(BLACK, "-", "o"),
    "Detections": Look(BLACK, ":", "x"),
    # the Bayes-optimal reference (point-mass filter)
    "grid": Look(BLACK, "--", ""),
    # ablations: ISM-PF's c1, fusion_pf's fixed alpha
    "ISM-c1-0.2": Look(SKY, "-", "^"),
    "ISM-c1-0.5": Look(GREEN, "-", "^"),
    "ISM-c1-0.8": Look(VERMILLION, "--", "^"),
    "ISM-c1-1.0": Look(PURPLE, "-", "^"),
    "alpha-0": Look(GREEN, "-", "o"),
    "alpha-0.25": Look(SKY, "-", "o"),
    "alpha-0.5": Look(PURPLE, "-", "o"),
    "alpha-0.75": Look(YELLOW, "-", "o"),
    "alpha-1": Look(BLUE, ":", "o"),
}
SPARE = [look for look in (Look(c, s, m) for c, s, m in product(PALETTE[:-1], LINESTYLES, MARKERS))
         if look not in METHODS.values()]
PAPER = {"marker": "D", "markersize": 8, "markerfacecolor": "none", "markeredgewidth": 1.6,  # a published value
         "linestyle": "None"}


def method_look(method: str) -> Look:
    """A method's look: its own if :data:`METHODS` names it, else a spare one chosen by a stable
    hash of its name (a user's own method looks the same on every figure and every run)."""
    return METHODS.get(method) or SPARE[zlib.crc32(method.encode()) % len(SPARE)]


def method_label(experiment: dict, method: str) -> str:
    """A method's name in legends: its config's ``label``, else its key."""
    return experiment["methods"].get(method, {}).get("label", method)


def shades(colour: str, n: int) -> list[tuple]:
    """``n`` shades of ``colour``, dark to light: one method's several series (one per value of
    another parameter) keep the method's hue."""
    if n == 1:
        return [to_rgb(colour)]
    rgb = np.array(to_rgb(colour))
    return [tuple(rgb * (1 + t) if t < 0 else rgb + (1 - rgb) * t) for t in np.linspace(-0.45, 0.55, n)]


LABELS = {  # metric, per-frame series or swept variable -> axis label
    "rmse": "RMSE",
    "ms_per_step": "time per step (ms)",
    "ms_per_frame": "time per frame (ms)",
    "evaluations_per_step": "likelihood evaluations per step",
    "filter_s": "filtering time (s)",
    "fps": "frames per second",
    "mean_ess": "mean effective sample size",
    "resample_count": "resamplings",
    "resample_rate": "resampling rate (% of steps)",
    "mean_cle": "mean centre location error (px)",
    "precision20": "precision at 20 px",
    "success_auc": "success AUC",
    "mean_error_per_target": "mean error per target (px)",
    "lost_targets": "lost targets",
    "failed": "share of failed runs",
    "switches": "identity switches",
    "mota": "MOTA",
    "correct_frames": "share of frames with {rule}",
    "tracked_to_end": "share of runs tracked to the end ({rule})",
    "cle": "centre location error (px)",
    "iou": "overlap (IoU)",
    "dx": "column deviation from the truth (px)",
    "dy": "row deviation from the truth (px)",
    "alpha": r"fusion coefficient $\alpha_k$",
    "ess": "effective sample size",
    "N": "number of particles N",
    "n_particles": "number of particles N",  # a sweep of a method's value names it in full
    "steps": "number of steps T",
    "n_joint": "joint draws K",
    "T": "number of steps T",
    "K": "joint draws K",
    "beta": r"interaction strength $\beta$",
    "ni": "improvisations NI",
    "hms": "harmony memory size HMS",
    "tau1": r"position-matrix step $\tau_1$",
    "ess_threshold": "ESS threshold (share of N)",
    "resampling": "resampling scheme",
    "iou>=0.5": "IoU ≥ 0.5",
    "iou>0": "IoU > 0",
    "cle<=20": "centre error ≤ 20 px",
    "cle<=10": "centre error ≤ 10 px",
}


def axis_label(name: str) -> str:
    """The words for a metric, series or swept variable; ``metric[rule]`` reads its rule; else the name."""
    base, rule = re.fullmatch(r"([^\[]*)(?:\[(.*)\])?", name).groups()
    if rule is None:
        return LABELS.get(name, name)
    return LABELS[base].format(rule=LABELS.get(rule, rule)) if base in LABELS else name


def clipped_note(diverged: int, runs: int) -> str:
    """What a legend says of the diverged runs of a line (nothing when none did)."""
    return f" ({diverged} of {runs} runs diverged, clipped)" if diverged else ""


class NothingToDraw(ValueError):
    """The runs at hand cannot make this figure (a ranking of one method, say): the page leaves it out."""


def save(fig, path: Path, dpi: int = 110) -> Path:
    """Lay out, write and close a figure; the image takes in what lies outside the axes (a legend below)."""
    fig.tight_layout()
    atomic.save_figure(fig, path, dpi=dpi, bbox_inches="tight", pad_inches=0.1)
    plt.close(fig)
    return path
