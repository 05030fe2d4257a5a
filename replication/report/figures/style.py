"""How every figure of the report looks and is written: one look per method, human axis labels, diverged
runs clipped, the figure saved (or, where the runs cannot make it, :class:`NothingToDraw`).

A method has the same colour, line style and marker on every figure of every experiment: the look its
filter declares, with its own ``look:`` over it (:mod:`replication.display`); a method that has neither
takes a spare look, chosen by a stable hash of its key among those no other method of its experiment has.
Line style and marker keep more methods than colours apart, and in print.  A paper's own values are
hollow diamonds in the method's colour.
"""

import zlib
from itertools import product
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.colors import to_rgb

from replication import atomic
from replication.display import COLOURS, LINES, MARKERS, Look, asked_look
from replication.errors import ConfigError
from replication.evidence.quantities import label as metric_label
from replication.filters.registry import builder

PALETTE = tuple(COLOURS.values())
BLACK = COLOURS["black"]
# a verdict's colour in figures, as on the report's pages (base.html.j2): keyed by Outcome's value
OUTCOME_COLOURS = {"reproduced": "#1a7f37", "inconclusive": "#8a5a00", "not reproduced": "#b42318",
                   "not testable": "#999999"}
SPARE = [Look(c, s, m) for c, s, m in product(PALETTE[:-1], LINES, MARKERS)]
PAPER = {"marker": "D", "markersize": 8, "markerfacecolor": "none", "markeredgewidth": 1.6,  # a published value
         "linestyle": "None"}


def method_look(experiment: dict, method: str) -> Look:
    """A method's look: the one it asks for (:func:`replication.display.asked_look`), else a spare one
    chosen by a stable hash of its name, skipping those the experiment's other methods have (a user's own
    method looks the same on every figure and every run, and unlike its neighbours)."""
    asked = _asked(experiment, method)
    if asked is not None:
        return asked
    taken = {_asked(experiment, other) for other in experiment.get("methods", {}) if other != method}
    start = zlib.crc32(method.encode())
    return next(look for look in (SPARE[(start + i) % len(SPARE)] for i in range(len(SPARE))) if look not in taken)


def _asked(experiment: dict, method: str) -> Look | None:
    params = experiment.get("methods", {}).get(method) or {}
    try:
        declared = getattr(builder(params["filter"]), "look", None) if "filter" in params else None
    except ConfigError:  # its filter does not import here (a plugin not installed): its own look: alone
        declared = None
    return asked_look(params, declared, f"experiment.methods.{method}.look")


def shades(colour: str, n: int) -> list[tuple]:
    """``n`` shades of ``colour``, dark to light: one method's several series (one per value of
    another parameter) keep the method's hue."""
    if n == 1:
        return [to_rgb(colour)]
    rgb = np.array(to_rgb(colour))
    return [tuple(rgb * (1 + t) if t < 0 else rgb + (1 - rgb) * t) for t in np.linspace(-0.45, 0.55, n)]


LABELS = {  # per-frame series and swept variables -> axis label (a metric's are evidence's: quantities.label)
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
}


def axis_label(name: str) -> str:
    """The words for a metric (:func:`replication.evidence.quantities.label`, which reads ``metric[rule]``),
    a per-frame series or a swept variable; else the name."""
    return LABELS.get(name) or metric_label(name) or name


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
