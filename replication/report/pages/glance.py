"""Every claim at a glance: one line per claim of the five papers, its verdict at the papers' scale (the
record) and in this report, whether it survives every reading, and its deciding number on one common scale.

The common scale is ours / paper's: the deciding check's estimate and interval over the paper's own value
of the same number (:attr:`~replication.evidence.checks.Check.paper`: a sized claim's gap, a cell's
published value, a threshold's bound), so 1 is what the paper says, 0 no effect and a negative number the
other way round.  A check for which the paper quotes no number (a sign-only claim) gets no mark: its line
still gives its verdicts.  The figure heads the index page and the PDF.
"""

import math
import textwrap
from dataclasses import dataclass
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.transforms import blended_transform_factory  # noqa: E402

from replication import atomic  # noqa: E402
from replication.evidence.checks import Check  # noqa: E402
from replication.evidence.claims import Paper  # noqa: E402
from replication.evidence.scorecard import ClaimRow  # noqa: E402
from replication.evidence.statistics import Estimate, said_level  # noqa: E402
from replication.evidence.verdict import Outcome  # noqa: E402
from replication.report.figures.style import OUTCOME_COLOURS  # noqa: E402
from replication.report.pages.recorded import recorded  # noqa: E402

FIGURE = "glance.png"
LIMIT = 30.0  # the axis runs over [-LIMIT, LIMIT] on a symmetric log scale, linear within [-1, 1]
ROW = 0.24  # inches a line takes


def relative(check: Check | None) -> Estimate | None:
    """The check's estimate and interval in units of the paper's own value (None where either is missing)."""
    if check is None or check.estimate is None or check.paper is None:
        return None
    paper, e = check.paper, check.estimate
    if not (math.isfinite(paper) and paper != 0 and math.isfinite(e.value)):
        return None
    ends = sorted([e.low / paper, e.high / paper]) if e.defined else [math.nan, math.nan]
    return Estimate(e.value / paper, *ends, e.runs, "ours / paper's", e.level)


@dataclass(frozen=True)
class Side:
    """One claim at one scale: its verdict, its deciding number over the paper's, and its robustness."""

    scale: str
    outcome: Outcome
    relative: Estimate | None
    robust: bool | None

    @classmethod
    def of(cls, row: ClaimRow) -> "Side":
        return cls(row.primary.scale, row.verdict.outcome, relative(row.primary.deciding), row.robust)


@dataclass(frozen=True)
class Line:
    """A claim's line: here (this report's runs) and, where a record was drawn, the record's."""

    id: str
    text: str
    here: Side
    recorded: Side | None

    @property
    def robust(self) -> bool | None:
        """Robust across the paper's multiverse: the record's judgement where it has one, else this report's."""
        return self.recorded.robust if self.recorded and self.recorded.robust is not None else self.here.robust


def lines(papers: list[Paper], rows: dict[str, list[ClaimRow]],
          recorded: dict[str, ClaimRow] | None = None) -> dict[str, list[Line]]:
    """Per paper, one :class:`Line` per claim (``recorded``: the record's rows by claim id, where drawn)."""
    recorded = recorded or {}
    return {paper.key: [Line(row.claim.id, row.claim.text, Side.of(row),
                             Side.of(recorded[row.claim.id]) if row.claim.id in recorded else None)
                        for row in rows[paper.key]] for paper in papers}


def write(reports: Path, papers: list[Paper], rows: dict[str, list[ClaimRow]]) -> Path:
    """``reports/glance.png`` from this report's claim rows and the record drawn under ``reports``, if any."""
    record = recorded(reports, tuple(papers))
    return draw(lines(papers, rows, record["claims"] if record else None), Path(reports) / FIGURE)


def _position(value: float) -> float:
    """A value on the axis: clipped to its ends (an arrow marks a clipped end)."""
    return max(-LIMIT, min(LIMIT, value))


def _mark(ax, side: Side | None, y: float, filled: bool) -> None:
    if side is None or side.relative is None:
        return
    colour, r = OUTCOME_COLOURS[side.outcome.value], side.relative
    if math.isfinite(r.low):
        ax.plot([_position(r.low), _position(r.high)], [y, y], color=colour, lw=2, solid_capstyle="butt")
    beyond = abs(r.value) > LIMIT
    marker = (">" if r.value > 0 else "<") if beyond else "o"
    ax.plot([_position(r.value)], [y], marker, ms=6, color=colour, mfc=colour if filled else "white", mew=1.5)


def draw(by_paper: dict[str, list[Line]], path: Path) -> Path:
    """The glance figure: a line per claim (grouped by paper) with its verdicts and readings as text and its
    deciding number over the paper's on a shared axis, the record's filled and this report's hollow."""
    entries = [e for paper, claims in by_paper.items() for e in [(paper, None)] + [(paper, c) for c in claims]]
    recorded = any(c.recorded for claims in by_paper.values() for c in claims)
    here = next((c.here.scale for claims in by_paper.values() for c in claims if c.here.scale), "")
    fig = plt.figure(figsize=(13, 1.4 + ROW * len(entries)))
    top = 1 - 0.6 / fig.get_figheight()
    bottom = 0.8 / fig.get_figheight()  # the ticks, the axis label and the caption below them
    ax = fig.add_axes((0.6, bottom, 0.26, top - bottom))
    ax.set_xscale("symlog", linthresh=1.0, linscale=1.0)
    ax.set_xlim(-LIMIT, LIMIT)
    ax.set_ylim(len(entries) - 0.5, -0.5)
    ax.set_yticks([])
    ax.axvline(0, color="0.55", lw=1)
    ax.axvline(1, color="0.3", lw=1, ls="--")
    ax.set_xticks([-10, -1, 0, 1, 10], ["-10", "-1", "0", "1", "10"])
    ax.tick_params(axis="x", labelsize=8)
    ax.set_xlabel("ours / paper's  (1: as the paper says; 0: no effect; < 0: the other way)", fontsize=8)
    text = blended_transform_factory(fig.transFigure, ax.transData)
    columns = {"claim": 0.01, "recorded": 0.34, "here": 0.435, "readings": 0.53, "number": 0.87}
    heads = {"claim": "claim", "recorded": "paper scale\n(recorded)" if recorded else "",
             "here": f"{here} scale\n(this report)", "readings": "every\nreading", "number": "ours / paper's"}
    for key, x in columns.items():
        fig.text(x, top + 0.1 / fig.get_figheight(), heads[key], fontsize=8, weight="bold", va="bottom")
    for y, (paper, line) in enumerate(entries):
        if line is None:
            fig.text(columns["claim"], y, paper, transform=text, fontsize=9, weight="bold", va="center")
            ax.axhline(y - 0.5, color="0.85", lw=0.8)
            continue
        said = textwrap.shorten(f"{line.id.split('.', 1)[1]}: {line.text}", 62, placeholder="...")
        fig.text(columns["claim"] + 0.01, y, said, transform=text, fontsize=8, va="center")
        for key, side in (("recorded", line.recorded), ("here", line.here)):
            if side is not None:
                fig.text(columns[key], y, side.outcome.value, transform=text, fontsize=8, va="center",
                         color="white", weight="bold",
                         bbox={"boxstyle": "round,pad=0.2", "fc": OUTCOME_COLOURS[side.outcome.value], "ec": "none"})
        robust = {True: "robust", False: "depends", None: "-"}[line.robust]
        fig.text(columns["readings"], y, robust, transform=text, fontsize=8, va="center",
                 style="normal" if line.robust is not None else "italic")
        shown = line.recorded if line.recorded and line.recorded.relative else line.here
        if shown.relative is not None:
            r = shown.relative
            interval = f" [{r.low:.3g}, {r.high:.3g}] {said_level(r.level)}" if math.isfinite(r.low) else ""
            fig.text(columns["number"], y, f"{r.value:.3g}{interval}", transform=text, fontsize=8, va="center")
        else:
            fig.text(columns["number"], y, "no number quoted", transform=text, fontsize=7, va="center", color="0.45")
        _mark(ax, line.recorded, y - 0.17, filled=True)
        _mark(ax, line.here, y + (0.17 if line.recorded else 0.0), filled=False)
    fig.text(0.01, 0.12 / fig.get_figheight(), "Filled: the record's runs at the papers' scale; hollow: this report's. "
             "The bar is the deciding check's interval, at the level beside its number; an arrow, a value beyond the axis. "
             "\"every reading\": robust when no open choice of the paper's multiverse moves the verdict.",
             fontsize=7, color="0.3")
    path = Path(path)
    atomic.save_figure(fig, path, dpi=100)
    plt.close(fig)
    return path
