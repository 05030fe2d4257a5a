"""A paper's claims under every reading: each claim's verdict in every universe of its multiverse.

A *case* is one universe (an alternative for each open choice, see
:mod:`replication.runner.multiverse`) tested with one of the claim's scoring
readings (``conf/claims/<paper>.yaml``).  A claim is *robust* when every
testable case gives the same verdict; otherwise it *depends on the reading*,
and :class:`Robustness` says which alternatives flip it (the share of their
cases whose verdict differs from the default's) and the best case for the
paper: the case that comes closest to the claim holding, with its number.
"""

import json
from dataclasses import dataclass
from pathlib import Path

import matplotlib.pyplot as plt
import pandas as pd
from omegaconf import DictConfig, OmegaConf

from replication.paths import resolve
from replication.report.claims import Claim, ClaimTest, evaluate, load_papers
from replication.report.published import load_published
from replication.report.render import render
from replication.report.scale import scale_note
from replication.report.style import OUTCOME_COLOURS
from replication.report.tables import TableKind
from replication.report.verdict import RULES, Outcome, Verdict
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
    def robust(self) -> bool | None:
        """The same verdict in every testable case; None when fewer than two cases are testable."""
        testable = self.testable
        return None if len(testable) < 2 else len({c.verdict.outcome for c in testable}) == 1

    @property
    def flips(self) -> list[tuple[str, str, int, int]]:
        """(choice, alternative, flipped, compared) for each alternative other than the default under which
        the verdict changes, most often first.

        A case under the alternative is compared with its twin: the case that differs from it only in
        that choice, set to its default (same universe otherwise, same scoring reading), so a flip is
        the alternative's own doing.  Where a design has no twins (Sobol points), every case under the
        alternative is compared with the default case instead."""
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
            pairs = [(c, t) for c, t in twins if t is not None] or [(c, self.default) for c in under]
            flipped = sum(c.verdict.outcome is not t.verdict.outcome for c, t in pairs)
            if flipped:
                found.append((choice, alternative, flipped, len(pairs)))
        return sorted(found, key=lambda f: -f[2] / f[3])

    @property
    def flipped_by(self) -> list[str]:
        """The flips as a reader sees them: 'bests=rescored (4 of 8)', "scored by 'the other rule' (2 of 2)"."""
        return [f"{_alternative(choice, alternative)} ({n} of {m})" for choice, alternative, n, m in self.flips]

    @property
    def best_case(self) -> Case:
        return max(self.cases, key=lambda c: (CLOSENESS[c.verdict.outcome], c.held))

    @property
    def summary(self) -> str:
        testable = self.testable
        if self.robust is None:
            return f"not testable across readings ({len(testable)} of {len(self.cases)} cases testable)"
        if self.robust:
            return f"robust: {testable[0].verdict.outcome.value} in all {len(testable)} cases"
        flips = self.flipped_by
        flips = "; ".join(flips[:SHOWN_FLIPS]) + (f"; {len(flips) - SHOWN_FLIPS} more" if len(flips) > SHOWN_FLIPS
                                                   else "")
        best = self.best_case
        number = f" ({best.deciding['number']})" if best.deciding and best.deciding.get("number") else ""
        return (f"depends on the reading: {self.default.verdict.outcome.value} by default, flipped under {flips}; "
                f"best case for the paper: {best.verdict.outcome.value}{number} under {best.label}")

    def as_dict(self) -> dict:
        def case(c: Case) -> dict:
            return {"universe": c.universe, "label": c.label, "picks": [list(p) for p in c.picks],
                    "verdict": c.verdict.as_dict(),
                    "deciding": c.deciding, "checks": list(c.checks)}

        return {"robust": self.robust, "summary": self.summary, "cases": [case(c) for c in self.cases],
                "flips": [list(f) for f in self.flips], "flipped_by": self.flipped_by,
                "best_case": case(self.best_case)}


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
            for claim, readings in evaluate(name, experiment, records, _tables(name, experiment, records,
                                                                               claims, published)).items():
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
