"""What each per-run metric is: its range, which way is better, its interval, its human label.

A record's metric names are the compute side's (``rmse``,
``correct_frames[iou>=0.5]``); this is the one place that names and labels them (tables, claims and the
figures' axes: :func:`label`) and reads a ``metric[rule]`` name, and says what kind of number each is, so
that an interval fits its quantity:

* ``binary``: a per-run yes/no outcome (a run failed, a target was tracked to
  the end); its mean over runs is a proportion: Clopper-Pearson interval.
* ``bounded``: a per-run share or score with a range (share of correct frames,
  precision, AUC, MOTA <= 1): t interval over runs, clipped to the range.
* ``positive``: non-negative and usually skewed (errors, counts, ESS): t
  interval over runs, clipped at 0.
* ``real``: a signed number (a deviation, an improvement).
* ``timing``: machine-dependent; a published timing is shown with the ratio
  ours / theirs, never judged.

The papers' own names for the numbers their tables print are declared too (a
published cell's metric), and a metric declared nowhere is an error.
"""

import math
import re
from dataclasses import dataclass, replace

from replication.errors import ConfigError


@dataclass(frozen=True)
class Quantity:
    kind: str  # binary | bounded | positive | real | timing
    low: float = 0.0
    high: float = math.inf
    lower_is_better: bool = True
    label: str = ""

    def scaled(self, factor: float) -> "Quantity":
        """The same quantity in other units (a share as a percentage: factor 100)."""
        return replace(self, low=self.low * factor, high=self.high * factor)

    @property
    def proportion(self) -> bool:
        return self.kind == "binary"

    @property
    def machine_dependent(self) -> bool:
        return self.kind == "timing"


_BINARY = Quantity("binary", 0.0, 1.0)
_SHARE = Quantity("bounded", 0.0, 1.0, lower_is_better=False)

QUANTITIES = {
    "rmse": Quantity("positive", label="RMSE"),
    "mean_cle": Quantity("positive", label="mean centre location error (px)"),
    "visible_error": Quantity("positive", label="mean error while visible (px)"),
    "mean_error_per_target": Quantity("positive", label="mean error per target (px)"),
    "identity_free_error": Quantity("positive", label="identity-free error per target (px)"),
    "tracked_error": Quantity("positive", label="error per target while tracked (px)"),
    "encounters": Quantity("positive", label="close encounters"),
    "swaps_per_encounter": Quantity("positive", label="identity switches per close encounter"),
    "lost_targets": Quantity("positive", label="targets lost"),
    "switches": Quantity("positive", label="identity switches"),
    "degenerate_steps": Quantity("positive", label="degenerate steps"),
    "outside_frames": Quantity("positive", label="estimates outside the image (target-frames)"),
    "resample_count": Quantity("positive", label="resamplings"),
    "mean_ess": Quantity("positive", lower_is_better=False, label="mean ESS (particles)"),
    "resample_rate": Quantity("bounded", 0.0, 100.0, label="resampling rate (%)"),
    "precision20": replace(_SHARE, label="precision at 20 px"),
    "success_auc": replace(_SHARE, label="success AUC"),
    "mota": Quantity("bounded", -math.inf, 1.0, lower_is_better=False, label="MOTA"),
    "motp": Quantity("bounded", 0.0, 1.0, label="MOTP (mean 1 - IoU of matches)"),
    "idf1": replace(_SHARE, label="IDF1"),
    "hota": replace(_SHARE, label="HOTA"),
    "deta": replace(_SHARE, label="DetA"),
    "assa": replace(_SHARE, label="AssA"),
    "fragmentations": Quantity("positive", label="fragmentations"),
    "misses": Quantity("positive", label="missed boxes"),
    "false_positives": Quantity("positive", label="false positive boxes"),
    "tracks_started": Quantity("positive", label="tracks started"),
    "tracks_per_person": Quantity("positive", label="tracks started per person"),
    "detected_share": replace(_SHARE, label="share of live tracks' frames with a detection"),
    "proposal_detection_share": replace(_SHARE, label="share of particles drawn from the detections"),
    "colour_share": Quantity("bounded", 0.0, 1.0, label="share of live tracks' frames kept by colour alone"),
    "deaths_unsupported": Quantity("positive", label="deaths on lost support"),
    "deaths_outside": Quantity("positive", label="deaths on leaving the image"),
    "detection_iou": Quantity("bounded", 0.0, 1.0, label="mean IoU of an output box with its nearest detection"),
    "fp_off_person": Quantity("positive", label="false positives: a box off its person (IoU < 0.5)"),
    "off_person_detected": Quantity("positive", label="of those, with a detection on the person"),
    "fp_duplicate": Quantity("positive", label="false positives: a second box on a matched person"),
    "fp_background": Quantity("positive", label="false positives: a box on no person"),
    "miss_box_off": Quantity("positive", label="misses: a box near the person but off it"),
    "miss_detected": Quantity("positive", label="misses: no box, a detection on the person"),
    "miss_undetected": Quantity("positive", label="misses: no box and no detection"),
    "duplicate_births": Quantity("positive", label="tracks born on a person another track holds"),
    "scale_log_ratio": Quantity("real", -math.inf, math.inf, label="mean log(box area / person's area) of matches"),
    "failed": replace(_BINARY, label="runs failed"),
    "ms_per_frame": Quantity("timing", label="time per frame (ms)"),
    "cpu_ms_per_frame": Quantity("timing", label="CPU time per frame (ms)"),
    "likelihood_evaluations": Quantity("positive", label="likelihood evaluations (run)"),
    "evaluations_per_step": Quantity("positive", label="likelihood evaluations per step"),
    "propagations_per_step": Quantity("positive", label="particles propagated per step"),
    "transition_densities_per_step": Quantity("positive", label="transition densities per step"),
    "ms_per_step": Quantity("timing", label="time per step (ms)"),
    "cpu_ms_per_step": Quantity("timing", label="CPU time per step (ms)"),
    "filter_s": Quantity("timing", label="filtering time (s)"),
    "cpu_filter_s": Quantity("timing", label="filtering CPU time (s)"),
    "wall_s": Quantity("timing", label="wall time (s)"),
    "cpu_s": Quantity("timing", label="CPU time (s)"),
    "load_1m": Quantity("positive", label="machine load (1-minute average)"),
    "reference_ms": Quantity("timing", label="reference work (ms): the machine's speed"),
    "fps": Quantity("timing", lower_is_better=False, label="frames per second"),
    # the papers' own names for what their tables print (a published cell's metric)
    "time": Quantity("timing", label="time per step (ms)"),
    "run_time": Quantity("timing", label="run time (s)"),
    "time_per_frame": Quantity("timing", label="time per frame (ms)"),
    "success_rate": Quantity("bounded", 0.0, 100.0, lower_is_better=False, label="success rate (%)"),
    "correct_tracking_rate": Quantity("bounded", 0.0, 100.0, lower_is_better=False,
                                      label="correct tracking rate (%)"),
    "improvement": Quantity("real", -math.inf, math.inf, lower_is_better=False, label="improvement (%)"),
}
RULES = {  # a rule in a metric's name, in words
    "iou>=0.5": "IoU ≥ 0.5",
    "iou>0": "IoU > 0",
    "cle<=20": "centre error ≤ 20 px",
    "cle<=10": "centre error ≤ 10 px",
}
_PATTERNS = (  # metrics named after a rule: correct_frames[iou>=0.5], tracked_to_end[cle<=20]
    (re.compile(r"correct_frames\[(.+)\]"),
     lambda rule: replace(_SHARE, label=f"share of frames with {RULES.get(rule, rule)}")),
    (re.compile(r"tracked_to_end\[(.+)\]"), lambda rule: replace(_BINARY, lower_is_better=False,
                                                                 label=f"runs tracked to the end ({RULES.get(rule, rule)})")),
    (re.compile(r"ospa\[c=(.+)\]"), lambda cutoff: Quantity("positive", label=f"OSPA, cut off at {cutoff} px")),
    (re.compile(r"failed\[(.+)\]"), lambda reading: replace(_BINARY, label=f"runs failed ({reading})")),
    (re.compile(r"error_without_failure\[(.+)\]"),
     lambda reading: Quantity("positive", label=f"mean error per target, runs without failure ({reading}) (px)")),
)


def quantity(metric: str) -> Quantity:
    """The quantity a metric is.  An unknown metric is an error: which way is better sets the direction of
    every claim on it, and nothing here guesses it."""
    if metric in QUANTITIES:
        return QUANTITIES[metric]
    for pattern, make in _PATTERNS:
        found = pattern.fullmatch(metric)
        if found:
            return make(found[1])
    raise ConfigError(f"unknown metric {metric!r}: declare what it is (range, which way is better) in "
                      f"replication/evidence/quantities.py; known: {', '.join(sorted(QUANTITIES))}")


def label(metric: str) -> str | None:
    """A metric's words (its quantity's label); None for a name that is no metric declared here."""
    try:
        return quantity(metric).label or None
    except ConfigError:
        return None
