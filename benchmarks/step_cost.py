"""The most one compiled step over all targets of a frame could save: ``python benchmarks/step_cost.py``.

From the record alone (nothing is run).  On ``bis_pf_cost`` (16 balls, 10 runs at each N) a multi-target
filter's time in its frame steps, ``ms_per_frame`` x ``frames``, is fitted by least squares as a + b N
(N particles per target; MCMC: its chain's samples; MFMC on N <= 400, past which its pair tables grow as
N^2).  a is what the steps cost whatever N: the Python around the compiled kernels (a call chain per
target and frame: propose, likelihood, weights, summaries, resampling), the part a whole-frame compiled
step could remove, and at most all of it.  Every recorded run of such a filter on the balls then saves at
most a / (a + b N) of its step time (the share at its N on the 16 balls; its scene's targets scale a and
b alike).  The script prints that bound for the experiments and for ``bis_pf_readings``, against what the
record took, and the workers the record's CPU needs for 30 minutes and for 2 hours.
"""

import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from replication.paths import resolve  # noqa: E402
from replication.record.manifest import MANIFEST, Manifest  # noqa: E402
from replication.record.runs import UNIVERSES_DIR  # noqa: E402

BALLS = ("exp1_3123", "exp2_16_targets", "exp3_36_targets")
FILTERS = ("MIPF", "BIS-PF", "DMOT", "MFMC", "MCMC")  # the record's multi-target filters; BIS-PF-K and -beta are BIS-PF
QUADRATIC_FROM = {"MFMC": 400}  # the largest N fitted: past it the step is no longer linear in N
FIT_ON = "bis_pf_cost"
READINGS = "bis_pf_readings"  # the multiverse of those filters on the balls


def step_seconds(runs: pd.DataFrame) -> pd.Series:
    """A run's time in its frame steps (frame production and scoring excluded)."""
    return runs["ms_per_frame"] * runs["frames"] / 1000


def fixed_costs(runs: pd.DataFrame) -> dict[str, tuple[float, float]]:
    """Per filter, (a, b) of step seconds = a + b N over its runs (least squares)."""
    fits = {}
    for method, own in runs.groupby("method"):
        own = own[own["method.n_particles"] <= QUADRATIC_FROM.get(method, math.inf)]
        b, a = np.polyfit(own["method.n_particles"], step_seconds(own), 1)
        fits[method] = (a, b)
    return fits


def bound(runs: pd.DataFrame, fits: dict[str, tuple[float, float]]) -> float:
    """At most what removing each filter's fixed cost would save of ``runs``' CPU seconds (0 for runs that
    are no such filter's on the balls, or an experiment without scenes or frames)."""
    if not {"condition.scene", "ms_per_frame"} <= set(runs.columns):
        return 0.0
    filter_of = runs["method"].str.replace(r"^BIS-PF-.*", "BIS-PF", regex=True)
    ours = filter_of.isin(FILTERS) & runs["condition.scene"].isin(BALLS)
    a = filter_of[ours].map({m: a for m, (a, _) in fits.items()}).astype(float)
    b = filter_of[ours].map({m: b for m, (_, b) in fits.items()}).astype(float)
    share = a / (a + b * runs.loc[ours, "method.n_particles"])
    return float((share * step_seconds(runs[ours])).sum())


def main() -> None:
    record = resolve("record")
    if not (record / MANIFEST).exists():
        sys.exit(f"{record}: no record here")
    entries = Manifest.read(record).experiments
    fits = fixed_costs(pd.read_parquet(record / FIT_ON / "runs.parquet"))
    print(f"fixed cost of a frame step on the 16 balls ({FIT_ON}, a + b N):")
    for method, (a, b) in fits.items():
        per_target = a / (999 * 16)  # bis_pf_cost: 999 steps of 16 targets a run
        print(f"  {method:7s} a = {a:4.2f} s a run ({per_target * 1e6:3.0f} us a target and frame), b = {b * 1e3:5.2f} ms a particle")
    solo = [name for name, e in entries.items() if not e.universes]
    cpu = sum(entries[name].wall_s for name in solo)
    saved = sum(bound(pd.read_parquet(record / name / "runs.parquet"), fits) for name in solo)
    print(f"the {len(solo)} experiments: {cpu / 60:.1f} CPU-min; at most {saved / 60:.1f} saved: "
          f"{cpu / 120:.1f} -> {(cpu - saved) / 120:.1f} min on 2 workers")
    universes = sorted((record / READINGS / UNIVERSES_DIR).glob("*.parquet"))
    readings, saved_readings = entries[READINGS].wall_s, bound(pd.concat(pd.read_parquet(p) for p in universes), fits)
    multiverses = sum(e.wall_s for e in entries.values() if e.universes)
    print(f"{READINGS}: {readings / 3600:.2f} CPU-h; at most {saved_readings / 3600:.2f} saved; all multiverses: "
          f"{multiverses / 7200:.1f} -> {(multiverses - saved_readings) / 7200:.1f} h on 2 workers")
    print(f"workers the record's CPU needs: {math.ceil(cpu / 1800)} for the experiments in 30 min, "
          f"{math.ceil(multiverses / 7200)} for the multiverses in 2 h")


if __name__ == "__main__":
    main()
