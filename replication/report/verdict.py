"""How our number is compared with the paper's.  The rules, as the report states them."""

import math

RULES = (
    "agrees: the published value lies inside the 95% interval a published mean should fall in if it "
    "estimates what ours does: ours ± t·sd·sqrt(1/our runs + 1/their runs), their spread estimated by ours "
    "(their run count where the paper states it, otherwise the published value is taken as exact and this is "
    "our own 95% interval). "
    "differs: it lies outside; the signed difference is ours minus theirs, relative to theirs. "
    "below the Bayes floor: a published error lower than the same interval's lower bound for the "
    "point-mass filter's RMSE, which no filter can beat on average under the model as we read it. "
    "machine-dependent: timings are shown with the ratio ours/theirs and not judged. "
    "reference: a row of ours with no published counterpart."
)

TIMING_METRICS = {"ms_per_step", "time", "time_per_frame", "run_time", "fps"}


def verdict(paper: float, mean: float, low: float, high: float, metric: str, floor_low: float | None = None) -> str:
    """Judge ``paper`` against our ``mean`` and comparison interval [low, high] (see RULES)."""
    if paper is None or (isinstance(paper, float) and math.isnan(paper)):
        return "reference"
    if metric in TIMING_METRICS:
        return f"machine-dependent (ours/theirs = {mean / paper:.2f})"
    if floor_low is not None and paper < floor_low:
        return f"below the Bayes floor ({floor_low:.3g})"
    if low <= paper <= high:
        return "agrees"
    return f"differs ({(mean - paper) / abs(paper):+.0%})"
