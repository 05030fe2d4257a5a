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

import json
import math
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from omegaconf import DictConfig, OmegaConf

from replication.evidence.verdict import RULES, Outcome, Verdict
from replication.evidence.inference import said_p
from replication.evidence.robustness import DECISIVE, ChoiceEffect, adjust, paired_effect
from replication.evidence.statistics import Estimate
from replication.paths import resolve
from replication.evidence.claims import Claim, ClaimTest, evaluate, load_papers
from replication.evidence.published import load_published
from replication.report.pages.render import render
from replication.report.pages.scale import scale_note
from replication.report.figures.style import OUTCOME_COLOURS
from replication.evidence.tables import TableKind
from replication.runner.multiverse import Multiverse
from replication.runner.store import Store

# how close a verdict is to the claim holding: the best case for the paper has the highest
CLOSENESS = {Outcome.REPRODUCED: 3, Outcome.INCONCLUSIVE: 2, Outcome.NOT_REPRODUCED: 1, Outcome.NOT_TESTABLE: 0}
READING = "reading"  # the scoring readings, a choice of their own beside the run-level ones
SHOWN_FLIPS = 4  # in a claim's one-line summary; its page lists every case


def _alternative(choice: str, alternative: str) -> str:
    return f"scored by '{alternative}'" if choice == READING else f"{choice}={alternative}"


@dataclass(frozen=True)
class Case:
    universe: str
    picks: tuple[tuple[str, str], ...]  # (choice, alternative) of the universe, then ("reading", its name)
    verdict: Verdict
    deciding: dict | None
    checks: tuple[dict, ...]

    @property
    def held(self) -> float:
        """The share of its testable checks that hold (a tie-break between cases with one outcome)."""
        testable = [c for c in self.checks if c["verdict"]["outcome"] != Outcome.NOT_TESTABLE.value]
        return sum(c["verdict"]["outcome"] == Outcome.REPRODUCED.value for c in testable) / max(len(testable), 1)

    @property
    def label(self) -> str:
        return f"{self.universe} (scored by: {dict(self.picks)[READING]})"


@dataclass(frozen=True)
class Robustness:
    """One claim's verdicts over its cases: the default (first universe, first reading) and the rest."""

    claim: Claim
    cases: tuple[Case, ...]

    @property
    def default(self) -> Case:
        return self.cases[0]

    @property
    def testable(self) -> list[Case]:
        return [c for c in self.cases if c.verdict.outcome is not Outcome.NOT_TESTABLE]

    @property
    def deciding(self) -> str:
        """The statistic whose movement is tested: the check that decided the default case."""
        return (self.default.deciding or {}).get("what", "")

    @cached_property
    def effects(self) -> list[ChoiceEffect]:
        """Each alternative other than the default: its paired effect on the deciding statistic against its
        twin (the case that differs only in that choice, set to its default; where a design has no twins,
        Sobol points, the default case), and how many of its cases' verdicts differ from the twin's.  A
        scoring reading, and a statistic with no per-run values (a published cell, a ranking), count only
        conflicting decisive verdicts (reproduced against not reproduced)."""
        testable = self.testable
        cases = {c.picks: c for c in testable}
        default_picks = dict(self.default.picks)
        found = []
        for choice, alternative in dict.fromkeys(p for c in testable for p in c.picks):
            if default_picks.get(choice) == alternative:
                continue
            under = [c for c in testable if (choice, alternative) in c.picks]
            twins = [(c, cases.get(tuple((ch, default_picks[ch] if ch == choice else a) for ch, a in c.picks)))
                     for c in under]
            pairs = [(c, t) for c, t in twins if t is not None]
            compared = "twin" if pairs else "default"
            pairs = pairs or [(c, self.default) for c in under]
            effect, p = (None, math.nan) if choice == READING else self._paired(pairs)
            if choice == READING or effect is None:
                compared = "readings"
                flips = sum({c.verdict.outcome, t.verdict.outcome} == DECISIVE for c, t in pairs)
            else:
                flips = sum(c.verdict.outcome is not t.verdict.outcome for c, t in pairs)
            found.append((choice, alternative, effect, p, flips, len(pairs), compared))
        return adjust(found)

    def _paired(self, pairs: list[tuple[Case, Case]]) -> tuple[Estimate | None, float]:
        """The deciding statistic's paired effect in the first pair that has it per run on both sides."""
        for case, twin in pairs:
            ours, theirs = (_per_run(c, self.deciding) for c in (case, twin))
            if ours and theirs:
                return paired_effect(ours, theirs)
        return None, math.nan

    @property
    def moving(self) -> list[ChoiceEffect]:
        return [e for e in self.effects if e.moves]

    @property
    def robust(self) -> bool | None:
        """No alternative moves the verdict; None when fewer than two cases are testable."""
        return None if len(self.testable) < 2 else not self.moving

    @property
    def flipped_by(self) -> list[str]:
        """The alternatives the verdict depends on, as a reader sees them: 'bests=rescored (+0.3 [0.1, 0.5],
        Holm p = 0.01)', "scored by 'the other rule' (2 of 2 decisive verdicts conflict)"."""
        return [f"{_alternative(e.choice, e.alternative)} ({_effect(e)})" for e in self.moving]

    @property
    def best_case(self) -> Case:
        return max(self.cases, key=lambda c: (CLOSENESS[c.verdict.outcome], c.held))

    @property
    def summary(self) -> str:
        testable = self.testable
        if self.robust is None:
            return f"not testable across readings ({len(testable)} of {len(self.cases)} cases testable)"
        tested = [e for e in self.effects if e.effect is not None]
        if self.robust:
            largest = max((e for e in tested if np.isfinite(e.effect.value)), key=lambda e: abs(e.effect.value),
                          default=None)
            said = (f"; largest effect on {self.deciding}: {_alternative(largest.choice, largest.alternative)} "
                    f"{_effect(largest)}") if largest else ""
            return (f"robust: no open choice moves the verdict ({len(self.effects)} alternatives, "
                    f"{len(testable)} cases){said}")
        flips = self.flipped_by
        flips = "; ".join(flips[:SHOWN_FLIPS]) + (f"; {len(flips) - SHOWN_FLIPS} more" if len(flips) > SHOWN_FLIPS
                                                   else "")
        best = self.best_case
        number = f" ({best.deciding['number']})" if best.deciding and best.deciding.get("number") else ""
        return (f"depends on the reading: moved by {flips}; "
                f"best case for the paper: {best.verdict.outcome.value}{number} under {best.label}")

    def as_dict(self) -> dict:
        def case(c: Case) -> dict:
            return {"universe": c.universe, "label": c.label, "picks": [list(p) for p in c.picks],
                    "verdict": c.verdict.as_dict(),
                    "deciding": c.deciding, "checks": list(c.checks)}

        def effect(e: ChoiceEffect) -> dict:
            return {"choice": e.choice, "alternative": e.alternative, "effect": e.effect.value if e.effect else None,
                    "low": e.effect.low if e.effect else None, "high": e.effect.high if e.effect else None,
                    "p": None if math.isnan(e.p) else e.p, "holm": None if math.isnan(e.adjusted) else e.adjusted,
                    "flips": e.flips, "compared": e.compared, "paired": e.paired, "moves": e.moves}

        return {"robust": self.robust, "summary": self.summary, "cases": [case(c) for c in self.cases],
                "deciding": self.deciding, "effects": [effect(e) for e in self.effects],
                "flipped_by": self.flipped_by, "best_case": case(self.best_case)}


def _per_run(case: Case, what: str) -> dict[int, float]:
    check = next((c for c in case.checks if c["what"] == what), None)
    return {int(k): v for k, v in (check or {}).get("per_run", {}).items() if v is not None}


def _effect(e: ChoiceEffect) -> str:
    if e.effect is None:
        return f"{e.flips} of {e.compared} decisive verdicts conflict"
    if e.effect.method == "the same runs":
        return "no effect: the same runs"
    return f"{e.effect.value:+.3g} [{e.effect.low:.3g}, {e.effect.high:.3g}], Holm {said_p(e.adjusted)}"


def evaluate_multiverse(multiverse: Multiverse, store_of, published: pd.DataFrame) -> list[Robustness]:
    """Every claim of the paper tested in every universe with each of its readings on the multiverse's
    experiments (``store_of(experiment)``: the store its runs are in)."""
    claims = [c for paper in load_papers() if paper.key == multiverse.paper for c in paper.claims]
    cases: dict[str, list[Case]] = {c.id: [] for c in claims}
    for universe in multiverse.universes:
        results = {}
        for name in multiverse.experiments:
            experiment = multiverse.experiment_configs[universe.name, name]
            records = store_of(name).load(multiverse.runs[universe.name, name])
            tables = _tables(name, experiment, records, claims, published)
            for claim, readings in evaluate(name, experiment, records, tables, published).items():
                results.setdefault(claim, {}).update(readings)
        for claim in claims:
            for reading in claim.readings:
                stored = results.get(claim.id, {}).get(reading.name)
                if stored is not None:
                    cases[claim.id].append(Case(universe.name, universe.picks + ((READING, reading.name),),
                                                Verdict.from_dict(stored["verdict"]), stored["deciding"],
                                                tuple(stored["checks"])))
    return [Robustness(claim, tuple(cases[claim.id])) for claim in claims if cases[claim.id]]


def _tables(name: str, experiment: dict, records: pd.DataFrame, claims: list[Claim], published: pd.DataFrame):
    """The tables the claims' ``cells`` readings on ``name`` judge, built from ``records`` (only those)."""
    wanted = {t for c in claims for r in c.readings if r.experiment == name
              for t in ClaimTest.of(r.test, experiment).tables}
    specs = [s for s in experiment.get("report", {}).get("tables", []) if s["name"] in wanted]
    if records.empty:
        return {}
    return {s["name"]: TableKind.of(s, experiment, published).build(records) for s in specs}


def draw(robustness: list[Robustness], multiverse: Multiverse, path: Path) -> None:
    """A forest plot per claim: the deciding check of its default case, in every universe under the claim's
    first reading, with its 95% interval, coloured by verdict; the claim's line (the paper's value, a bound
    or zero difference) dashed."""
    path.unlink(missing_ok=True)  # a figure of runs since recomputed must not outlive them
    shown = [r for r in robustness if _headline(r)]
    if not shown:
        return
    rows = len(multiverse.universes)
    fig, axes = plt.subplots(len(shown), 1, figsize=(8, 0.6 + len(shown) * (0.9 + 0.28 * rows)), squeeze=False)
    for ax, claim in zip(axes[:, 0], shown):
        what = _headline(claim)
        first = claim.claim.readings[0].name
        reference = None  # the claim's line, from its checks (never the previous claim's)
        for y, universe in enumerate(multiverse.universes):
            case = next((c for c in claim.cases if c.universe == universe.name and dict(c.picks)[READING] == first),
                        None)
            check = next((c for c in case.checks if c["what"] == what), None) if case else None
            if check is None or check["value"] is None:
                continue
            colour = OUTCOME_COLOURS[check["verdict"]["outcome"]]
            low, high = check["low"], check["high"]
            if low is not None and high is not None:
                ax.plot([low, high], [y, y], color=colour, lw=2)
            ax.plot([check["value"]], [y], "o", color=colour)
            reference = check.get("reference")
        if reference is not None:
            ax.axvline(reference, color="0.3", ls="--", lw=1)
        ax.set_yticks(range(rows), [u.name for u in multiverse.universes], fontsize=7)
        ax.invert_yaxis()
        ax.set_title(f"{claim.claim.id}: {what}", fontsize=8, loc="left")
        ax.tick_params(axis="x", labelsize=7)
    handles = [plt.Line2D([], [], marker="o", color=colour, ls="", label=outcome)
               for outcome, colour in OUTCOME_COLOURS.items()]
    fig.legend(handles=handles, loc="lower center", ncol=len(handles), fontsize=7, frameon=False)
    fig.tight_layout(rect=(0, 0.03, 1, 1))
    fig.savefig(path, dpi=110, bbox_inches="tight")  # universes' names can be long
    plt.close(fig)


def _headline(robustness: Robustness) -> str | None:
    """The check plotted for a claim: the one that decided its default case, if it has a number."""
    deciding = robustness.default.deciding
    return deciding["what"] if deciding and deciding.get("value") is not None else None


def write_multiverse_report(cfg: DictConfig, multiverse: Multiverse) -> Path:
    """``<reports>/<paper>_readings/``: the choices, the universes run, each claim's robustness with every
    case, the forest plot, and ``summary.json`` (under ``multiverse``) for the scorecard."""
    out = resolve(cfg.reports) / multiverse.name
    out.mkdir(parents=True, exist_ok=True)
    published = load_published(str(resolve(cfg.published_values)))
    robustness = evaluate_multiverse(multiverse, lambda name: Store(resolve(cfg.store), name), published)
    draw(robustness, multiverse, out / "readings.png")
    frame = pd.DataFrame([{"claim_id": r.claim.id, "universe": c.universe, **{k: v for k, v in c.picks},
                           "verdict": c.verdict.outcome.value, "why": c.verdict.why,
                           "number": (c.deciding or {}).get("number", "")} for r in robustness for c in r.cases])
    frame.to_csv(out / "cases.csv", index=False)
    runs = {name: multiverse.runs_of(name) for name in multiverse.experiments}
    n_runs = sum(len(r) for r in runs.values())
    n_records = sum(Store(resolve(cfg.store), name).path(run).exists() for name, r in runs.items() for run in r)
    page = out / "index.html"
    page.write_text(render(
        "multiverse.html.j2", title=cfg.experiment.get("title", multiverse.name), multiverse=multiverse,
        robustness=robustness, figure=(out / "readings.png").exists(), rules=RULES, n_runs=n_runs,
        scale_note=scale_note(cfg.scale), config=OmegaConf.to_yaml(cfg.experiment),
        command=f"python -m replication experiment={multiverse.name} scale={cfg.scale}"))
    summary = {"name": multiverse.name, "title": cfg.experiment.get("title", multiverse.name),
               "paper": multiverse.paper, "scale": cfg.scale, "n_records": n_records, "n_runs": n_runs,
               "verdicts": {}, "cells": [], "claims": {}, "scale_changes": [], "tables": [],
               "figures": [{"name": "readings", "file": "readings.png",
                            "title": "Each claim's deciding number in every universe (95% CI, coloured by verdict)"}]
               if (out / "readings.png").exists() else [],
               "universes": [u.name for u in multiverse.universes],
               "multiverse": {r.claim.id: r.as_dict() for r in robustness}}
    (out / "summary.json").write_text(json.dumps(summary, indent=1))
    return page
