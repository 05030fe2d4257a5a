"""What the quick scale changes from the paper's, said on every page and in the PDF.

An experiment config writes ``{paper: a, quick: b}`` wherever the scale
matters (run counts, frames of a scene, the last frame of a real sequence);
:func:`scale_changes` lists where the experiment as run differs from the same at
the paper's scale, so the banner cannot fall out of step with the configs, and
names the sequences the page ran (a user's own, not the shipped ones they replace).
"""

from replication.evidence.inference import detectable
from replication.evidence.settings import INFERENCE


PAPER_COMMAND = "make replicate SCALE=paper"
SCALED = ("runs", "scenes", "model", "methods")  # where a config's scale takes effect (not its YAML anchors)


def scale_changes(paper: dict, scaled: dict, path: str = "") -> list[str]:
    """What ``scaled`` (an experiment's config at a scale, as run: its real sequences located, a user's own in
    place of the shipped ones) changes from ``paper`` (the same at the paper's scale), as ``'<where>: a -> b'``
    (``all`` for a null: every frame)."""
    if isinstance(paper, dict) and isinstance(scaled, dict):
        return [change for key in paper if key in scaled and (path or key in SCALED)
                for change in scale_changes(paper[key], scaled[key], f"{path}.{key}")]
    if isinstance(paper, list) and isinstance(scaled, list) and len(paper) == len(scaled) \
            and any(isinstance(value, dict) for value in paper):
        return [change for i, (a, b) in enumerate(zip(paper, scaled))
                for change in scale_changes(a, b, f"{path}[{i}]")]
    if paper == scaled:
        return []
    shown = ["all" if v is None else str(v) for v in (paper, scaled)]
    return [f"{_where(path)}: {shown[0]} -> {shown[1]}"]


def _where(path: str) -> str:
    """A config path as a reader says it: 'runs', 'scene exp2_16_targets frames', 'scene Girl last frame'."""
    parts = path.strip(".").split(".")
    if parts[0] == "scenes" and len(parts) >= 3:
        what = {"frames": "frames", "last": "last frame"}.get(parts[-1], parts[-1])
        return f"scene {parts[1]} {what}"
    return " ".join(parts)


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
