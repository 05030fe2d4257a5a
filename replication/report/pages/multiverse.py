"""A paper's claims under every reading: each claim's verdict in every universe of its multiverse.

A *case* is one universe (an alternative for each open choice, see
:mod:`replication.runner.multiverse`) tested with one of the claim's scoring
readings (``conf/claims/<paper>.yaml``).  Whether the claim's verdict depends
on a choice is decided by the choice's paired effect on the deciding
statistic (:mod:`replication.evidence.robustness`): *robust* unless some
alternative moves that statistic significantly (Holm across the alternatives)
and its verdict with it.  :class:`Robustness` gives each alternative's effect
with its interval and the best case for the paper: the case that comes
closest to the claim holding, with its number.
"""

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from omegaconf import DictConfig, OmegaConf

from replication import atomic
from replication.evidence.judge import MultiverseJudgement, Universes
from replication.evidence.multiverse import READING, Robustness
from replication.evidence.settings import rules
from replication.evidence.statistics import said_level
from replication.paths import resolve
from replication.report.pages.experiment import Drawn
from replication.report.pages.render import render
from replication.report.pages.scale import scale_note
from replication.scales import index_from, report_folder
from replication.report.figures.style import OUTCOME_COLOURS


def draw(robustness: list[Robustness], multiverse: Universes, path: Path) -> None:
    """A forest plot per claim: the deciding check of its default case, in every universe under the claim's
    first reading, with the interval of the test that decided it (its level in the panel's title), coloured by
    verdict; the claim's line (the paper's value, a bound, zero difference or an allowed margin) dashed."""
    path.unlink(missing_ok=True)  # a figure of runs since recomputed must not outlive them
    shown = [r for r in robustness if _headline(r)]
    if not shown:
        return
    rows = len(multiverse.universes)
    fig, axes = plt.subplots(len(shown), 1, figsize=(8, 0.6 + len(shown) * (0.9 + 0.28 * rows)), squeeze=False)
    for ax, claim in zip(axes[:, 0], shown):
        what = _headline(claim)
        first = claim.claim.readings[0].name
        reference, level = None, None  # the claim's line and interval level, from its checks (not the last claim's)
        for y, universe in enumerate(multiverse.universes):
            case = next((c for c in claim.cases if c.universe == universe.name and dict(c.picks)[READING] == first),
                        None)
            check = next((c for c in case.result.checks if c.what == what), None) if case else None
            if check is None or check.estimate is None or not np.isfinite(check.estimate.value):
                continue
            colour = OUTCOME_COLOURS[check.verdict.outcome.value]
            if check.estimate.defined:
                ax.plot([check.estimate.low, check.estimate.high], [y, y], color=colour, lw=2)
            ax.plot([check.estimate.value], [y], "o", color=colour)
            reference, level = check.reference, check.estimate.level
        if reference is not None:
            ax.axvline(reference, color="0.3", ls="--", lw=1)
        ax.set_yticks(range(rows), [u.name for u in multiverse.universes], fontsize=7)
        ax.invert_yaxis()
        title = f"{claim.claim.id}: {what}" + (f" ({said_level(level)})" if level else "")
        ax.set_title(title, fontsize=8, loc="left")
        ax.tick_params(axis="x", labelsize=7)
    handles = [plt.Line2D([], [], marker="o", color=colour, ls="", label=outcome)
               for outcome, colour in OUTCOME_COLOURS.items()]
    fig.legend(handles=handles, loc="lower center", ncol=len(handles), fontsize=7, frameon=False)
    fig.tight_layout(rect=(0, 0.03, 1, 1))
    atomic.save_figure(fig, path, dpi=110, bbox_inches="tight")  # universes' names can be long
    plt.close(fig)


def _headline(robustness: Robustness) -> str | None:
    """The check plotted for a claim: the one that decided its default case, if it has a number."""
    deciding = robustness.default.deciding
    return deciding.what if deciding and deciding.estimate is not None else None


def write_multiverse_report(cfg: DictConfig, multiverse: Universes, judged: MultiverseJudgement,
                            overrides: tuple[str, ...] = ()) -> Drawn:
    """``<reports>/<paper>_readings/`` (at the quick scale under ``<reports>/quick/``), drawn from the multiverse's
    judgement (:func:`replication.evidence.judge.judge_multiverse`): the choices, the universes run, each claim's
    robustness with every case and the forest plot; return what it drew (the caller stores the summary, whose
    ``multiverse`` the scorecard reads)."""
    out = report_folder(resolve(cfg.reports), multiverse.name, cfg.scale)
    out.mkdir(parents=True, exist_ok=True)
    robustness = judged.robustness
    draw(robustness, multiverse, out / "readings.png")
    frame = pd.DataFrame([{"claim_id": r.claim.id, "universe": c.universe, **{k: v for k, v in c.picks},
                           "verdict": c.verdict.outcome.value, "why": c.verdict.why,
                           "number": c.deciding.number if c.deciding else ""} for r in robustness for c in r.cases])
    atomic.save(out / "cases.csv", lambda tmp: frame.to_csv(tmp, index=False))
    page = out / "index.html"
    atomic.write_text(page, render(
        "multiverse.html.j2", title=judged.summary.title, multiverse=multiverse,
        robustness=robustness, figure=(out / "readings.png").exists(), rules=rules(), n_runs=judged.summary.n_runs,
        home=index_from(multiverse.name, cfg.scale),
        scale_note=scale_note(cfg.scale), config=OmegaConf.to_yaml(cfg.experiment),
        command=" ".join([f"python -m replication experiment={multiverse.name} scale={cfg.scale}",  # what made it
                          *(o for o in overrides if not o.startswith(("experiment=", "scale=")))])))
    figures = ({"name": "readings", "file": "readings.png",
                "title": "Each claim's deciding number in every universe (its test's interval, coloured by verdict)"},)
    return Drawn(page, figures if (out / "readings.png").exists() else ())
