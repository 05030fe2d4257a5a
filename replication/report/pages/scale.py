"""What the quick scale changes from the paper's, said on every page and in the PDF.

The banner lists where the experiment as run differs from the same at the paper's scale
(:func:`replication.scales.scale_changes`, which the judge puts in the report's summary), so it cannot
fall out of step with the configs.
"""

from replication.evidence.inference import detectable
from replication.evidence.settings import INFERENCE


PAPER_COMMAND = "make replicate SCALE=paper"


def scale_note(scale: str, changes: list[str] | None = None) -> str | None:
    """The banner of a page at ``scale`` (None at the paper's), listing ``changes`` where given."""
    if scale == "paper":
        return None
    listed = "" if changes is None else f" ({'; '.join(changes) or 'for this experiment, nothing'})"
    runs = INFERENCE.min_runs
    return (f"Quick scale: fewer runs and shorter scenes than the papers'{listed}. Intervals are wider, "
            f"verdicts from fewer than {runs} runs are 'not testable', and a ranking over sequences cut short is "
            f"marked not reliable and decides no claim (a full-length ranking can differ). With {runs} paired runs "
            f"an exact test reaches p = 1/{2 ** runs} at best, and a paired t-test finds an effect of "
            f"{detectable(1.0, runs):.2g} standard deviations with {INFERENCE.power:.0%} power: most claims are "
            f"then inconclusive, which is what {runs} runs can say. Paper scale: {PAPER_COMMAND}.")
