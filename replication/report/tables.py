"""Report tables rebuilt from run records.  A table kind is a small class named by a spec's ``kind:``.

Every kind turns records into a :class:`Table`: one row per (method,
condition) of ours, and for the kinds that compare with the paper, the
published cells each row was matched with (by :func:`match`, the one rule
for that) and a :class:`~replication.evidence.verdict.Verdict`.

Add a kind by subclassing :class:`TableKind` with a new ``kind`` name and a
``build`` method; a spec in ``report.tables`` then names it.
"""

import itertools
import math
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np
import pandas as pd

from replication.evidence.quantities import quantity
from replication.evidence.statistics import Estimate, paired_difference, proportion
from replication.evidence.verdict import TOLERANCE, Outcome, Verdict, judge_band, judge_value, stability_bands
from replication.qmc import discrepancy_table
from replication.evidence.aggregate import summarise
from replication.report.attributes import attribute_scores, carried_by
from replication.report.modes import runs_keeping_both_modes
from replication.report.published import cells
from replication.evidence.ranking import Ranking, rankings, unreliable

FLOOR_FILTER = "point_mass"
# the equivalence tolerance is our choice (the papers state none): each compared cell is also judged at
# these, so the index shows how far the cells' verdicts move with it
SENSITIVITY = (0.05, 0.20)
KEYS = ["paper", "table", "experiment", "method", "metric", "condition"]


@dataclass
class Table:
    """Rows of ours (``frame``: numbers, and a Verdict per row where compared), the published cells
    they were compared with (``cells``: one JSON-ready entry each, for the summary of every cell), and a
    line a reader must see beside it (``note``: a ranking that is not reliable)."""

    frame: pd.DataFrame
    cells: list[dict] = field(default_factory=list)
    note: str = ""

    @property
    def empty(self) -> bool:
        return self.frame.empty

    def shown(self) -> pd.DataFrame:
        """The frame as text for a page: 'mean [low, high]', the paper's value, the verdict."""
        shown = self.frame.drop(columns=["ours", "ci_low", "ci_high", "estimate", "verdict"], errors="ignore")
        for column in _estimate_columns(shown):
            shown[column] = [str(e) for e in shown[column]]
        if "estimate" in self.frame:
            shown.insert(3, "ours (95% CI)", [str(e) for e in self.frame["estimate"]])
        if "paper" in shown:
            shown["paper"] = [_printed(v) for v in shown["paper"]]
        if "verdict" in self.frame:
            shown["verdict"] = ["" if v is None else str(v) for v in self.frame["verdict"]]
        return shown

    @classmethod
    def read(cls, frame: pd.DataFrame) -> "Table":
        """A table back from the CSV :meth:`written` made (the PDF is drawn from those files)."""
        frame = frame.copy()
        if {"ours", "ci_low", "ci_high", "runs", "interval"} <= set(frame.columns):
            frame["estimate"] = [Estimate(*row[:4], "" if pd.isna(row[4]) else row[4]) for row in
                                 frame[["ours", "ci_low", "ci_high", "runs", "interval"]].itertuples(index=False)]
        if {"outcome", "why"} <= set(frame.columns):
            frame["verdict"] = [Verdict(Outcome(o), "" if pd.isna(w) else w) if isinstance(o, str) and o else None
                                for o, w in zip(frame.pop("outcome"), frame.pop("why"))]
        for column in [c for c in frame.columns if {f"{c}_low", f"{c}_high"} <= set(frame.columns)]:
            frame[column] = [Estimate(v, lo, hi, n, "") for v, lo, hi, n in
                             zip(frame[column], frame.pop(f"{column}_low"), frame.pop(f"{column}_high"), frame["runs"])]
        return cls(frame)

    def written(self) -> pd.DataFrame:
        """The frame for a CSV: numbers as numbers (a metric's interval in its ``_low`` and ``_high``
        columns), the verdict as its outcome and why."""
        frame = self.frame.drop(columns=["estimate"], errors="ignore").copy()
        for column in _estimate_columns(frame):
            estimates = frame[column]
            at = frame.columns.get_loc(column)
            frame[column] = [e.value for e in estimates]
            frame.insert(at + 1, f"{column}_low", [e.low for e in estimates])
            frame.insert(at + 2, f"{column}_high", [e.high for e in estimates])
        if "verdict" in frame:
            frame["outcome"] = [v.outcome.value if v else "" for v in frame["verdict"]]
            frame["why"] = [v.why if v else "" for v in frame["verdict"]]
            frame = frame.drop(columns=["verdict"])
        return frame


def _estimate_columns(frame: pd.DataFrame) -> list[str]:
    """The columns of a frame that hold an :class:`Estimate` per row (a summary table's metrics)."""
    return [c for c in frame.columns if len(frame) and all(isinstance(v, Estimate) for v in frame[c])]


def match(theirs: pd.DataFrame, method: str, condition: str, spec: dict) -> pd.DataFrame:
    """The published cells our row (``method``, ``condition``) is compared with.

    ``spec.match`` maps a condition of ours to the paper's: a condition
    string, or ``{experiment: scene, condition: ...}``; an unmapped condition
    is compared with the paper's of the same name.  A paper cell with no
    condition takes ``spec.paper_condition`` (the paper's unstated N, say).
    """
    wanted = spec.get("match", {}).get(condition, {"condition": condition})
    wanted = wanted if isinstance(wanted, dict) else {"condition": wanted}
    chosen = theirs["method"] == method
    if "condition" in wanted:
        chosen &= theirs["condition"].replace("", spec.get("paper_condition", "")) == wanted["condition"]
    if "experiment" in wanted:
        chosen &= theirs["experiment"] == wanted["experiment"]
    return theirs[chosen]


class TableKind:
    """One kind of report table; subclasses register themselves by ``kind``."""

    kind: ClassVar[str]
    compares: ClassVar[bool] = True  # whether its rows are matched with published cells
    registry: ClassVar[dict[str, type["TableKind"]]] = {}

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        TableKind.registry[cls.kind] = cls

    def __init__(self, spec: dict, experiment: dict, published: pd.DataFrame):
        self.spec, self.experiment, self.published = spec, experiment, published

    @classmethod
    def of(cls, spec: dict, experiment: dict, published: pd.DataFrame) -> "TableKind":
        """The table kind a spec names (``kind:``; a list of ``metrics:`` is a summary, else a comparison)."""
        name = spec.get("kind") or ("summary" if "metrics" in spec else "comparison")
        if name not in cls.registry:
            raise ValueError(f"table {spec.get('name')!r}: unknown kind {name!r}; known: {sorted(cls.registry)}")
        return cls.registry[name](spec, experiment, published)

    def build(self, records: pd.DataFrame) -> Table:
        raise NotImplementedError

    def label(self, method: str) -> str:
        return self.experiment["methods"].get(method, {}).get("label", method)

    def theirs(self) -> pd.DataFrame:
        spec = self.spec
        return cells(self.published, self.experiment["paper"], spec["paper_table"],
                     spec.get("paper_metric", spec.get("metric")))

    def entry(self, index, row: dict, verdict: Verdict | None, estimate: Estimate | None, ours=None) -> dict:
        """A matched published cell for ``summary.json``: the cell's keys and our row's numbers."""
        cell = self.published.loc[index]
        return {
            "published_index": int(index),
            **{k: str(cell[k]) for k in KEYS},
            "table_name": self.spec["name"],
            "our_method": row["method"],
            "our_condition": "" if row["condition"] == "-" else row["condition"],
            "runs": int(row["runs"]),
            "ours": ours if ours is not None else _number(estimate.value),
            "value": _number(estimate.value) if estimate else None,  # a rating's too: the proportion behind it
            "ci_low": _number(estimate.low) if estimate else None,
            "ci_high": _number(estimate.high) if estimate else None,
            "interval": estimate.method if estimate else "",
            "verdict": verdict.as_dict() if verdict else None,
        }


class Comparison(TableKind):
    """Ours (a statistic with its 95% interval) beside the paper's number, judged (Tables 1-4 of most papers)."""

    kind = "comparison"

    def build(self, records: pd.DataFrame) -> Table:
        spec, methods = self.spec, self.experiment["methods"]
        metric, paper_metric = spec["metric"], spec.get("paper_metric", spec["metric"])
        kind = quantity(paper_metric if quantity(paper_metric).machine_dependent else metric)
        kind = kind.scaled(spec.get("scale", 1.0))
        ours = summarise(records, metric, spec.get("scale", 1.0), spec.get("statistic", "mean"))
        ours = ours[ours["runs"] > 0]
        floor_runs, excess = None, {}
        if metric == "rmse":
            floor = [m for m in methods if methods[m]["filter"] == FLOOR_FILTER]
            floors = ours[ours["method"].isin(floor)]
            # the floor at the condition where it is lowest: the weakest evidence that a value lies below it
            floor_runs = floors.loc[floors["mean"].idxmin(), "values"] if len(floors) else None
            excess = excess_over_floor(records, floor)
        if spec.get("match"):  # the conditions the paper's table covers
            ours = ours[ours["condition"].isin(list(spec["match"]))]
        theirs = self.theirs()
        rows, entries = [], []
        for _, row in ours.iterrows():
            estimate = Estimate(row["mean"], row["ci_low"], row["ci_high"], row["runs"], row["interval"])
            hit = match(theirs, row["method"], row["condition"], spec)
            paper = float(hit["number"].iloc[0]) if len(hit) else math.nan
            def judged(tolerance: float) -> Verdict | None:
                return judge_value(paper, row["values"], kind, spec.get("statistic", "mean"), spec.get("paper_runs"),
                                   floor_runs, tolerance)

            verdict = judged(spec.get("tolerance", TOLERANCE))
            shown = {"method": self.label(row["method"]), "condition": row["condition"] or "-",
                     "runs": row["runs"], "estimate": estimate, "ours": row["mean"], "ci_low": row["ci_low"],
                     "ci_high": row["ci_high"], "interval": row["interval"]}
            if excess:
                shown["excess over the floor (paired, 95% CI)"] = str(
                    excess.get((row["method"], row["condition"]), ""))
            if spec.get("show_variance"):
                shown["variance over runs"] = row["variance"]
            shown.update(paper=paper, verdict=verdict)
            rows.append(shown)
            moved = {f"{t:g}": judged(t).outcome.value for t in SENSITIVITY} if verdict else {}
            entries += [{**self.entry(i, shown, verdict, estimate), "at_tolerance": moved} for i in hit.index]
        return Table(pd.DataFrame(rows), entries)


class Rating(TableKind):
    """Failed runs per method and condition, the rating they give, and the paper's (bis_pf Table 3)."""

    kind = "rating"

    def build(self, records: pd.DataFrame) -> Table:
        theirs, bands = self.theirs(), stability_bands()
        rows, entries = [], []
        for (method, condition), group in records.groupby(["method", "condition"], sort=False):
            failures, runs = int(group[self.spec["metric"]].sum()), len(group)
            estimate = proportion(failures, runs)
            hit = match(theirs, method, condition, self.spec)
            paper = hit["value"].iloc[0] if len(hit) else ""
            ours = next(name for name, (low, high) in bands.items() if low <= estimate.value <= high)
            verdict = judge_band(paper, failures, runs, bands) if paper else None
            row = {"method": self.label(method), "condition": condition or "-", "runs": runs,
                   "failed runs": failures, "failure rate (Clopper-Pearson 95% CI)": str(estimate), "rating": ours,
                   "paper": paper, "verdict": verdict}
            rows.append(row)
            entries += [self.entry(i, row, verdict, estimate, ours=ours) for i in hit.index]
        return Table(pd.DataFrame(rows), entries)


class Modes(TableKind):
    """Does a hidden target's posterior keep both hypotheses?  Runs that do, per method (bis_pf's 3123 text)."""

    kind = "modes"
    BANDS = {"success": (0.5, 1.0), "failure": (0.0, 0.5)}  # most runs keep both modes, or most do not

    def build(self, records: pd.DataFrame) -> Table:
        theirs = self.theirs()
        stripped = records[records["strip"].notna()] if "strip" in records else records.iloc[:0]
        rows, entries = [], []
        for (method, condition), group in stripped.groupby(["method", "condition"], sort=False):
            shares = runs_keeping_both_modes(group, self.spec, self.experiment)
            keeping = int((shares > 0.5).sum())
            estimate = proportion(keeping, len(shares))
            hit = match(theirs, method, condition, self.spec)
            paper = hit["value"].iloc[0] if len(hit) else ""
            ours = "success" if estimate.value > 0.5 else "failure"
            verdict = judge_band(paper, keeping, len(shares), self.BANDS) if paper else None
            row = {"method": self.label(method), "condition": condition or "-", "runs": len(shares),
                   "two-mode frames (mean share)": round(float(shares.mean()), 3),
                   "runs keeping both modes (Clopper-Pearson 95% CI)": str(estimate), "ours": ours, "paper": paper,
                   "verdict": verdict}
            rows.append(row)
            entries += [self.entry(i, row, verdict, estimate, ours=ours) for i in hit.index]
        return Table(pd.DataFrame(rows), entries)


class Improvement(TableKind):
    """A paper's relative claim, 100 (metric[baseline] - metric[method]) / mean metric[baseline] in %,
    from paired runs (both methods filter the same data at a repetition): hspf's 1.8 %."""

    kind = "improvement"

    def build(self, records: pd.DataFrame) -> Table:
        spec = self.spec
        metric, baseline, method = spec["metric"], spec["baseline"], spec["method"]
        paired = pair(records, metric, baseline, method)
        if paired.empty:
            return Table(pd.DataFrame())
        scale = 100.0 / paired["baseline"].mean()
        improvements = (paired["baseline"] - paired["method"]).to_numpy() * scale
        estimate = paired_difference(paired["baseline"], paired["method"]).scaled(scale)
        theirs = self.theirs()
        paper = float(theirs["number"].iloc[0]) if len(theirs) else math.nan
        # equivalence within an absolute margin in percentage points (the config's ``tolerance_pp``): a
        # relative margin of a 1.8 % improvement would be a hair's breadth
        margin = spec["tolerance_pp"]
        verdict = judge_value(paper, improvements, quantity("improvement"),
                              tolerance=margin / abs(paper) if paper else TOLERANCE)
        row = {"method": f"{self.label(method)} vs {self.label(baseline)}", "condition": "-",
               "runs": estimate.runs, "estimate": estimate, "ours": estimate.value, "ci_low": estimate.low,
               "ci_high": estimate.high, "interval": estimate.method, "paper": paper, "verdict": verdict}
        return Table(pd.DataFrame([row]), [self.entry(i, row, verdict, estimate) for i in theirs.index])


class Summary(TableKind):
    """Ours only: one row per method and condition, one column per metric: its mean and 95% interval
    (shown 'mean [low, high]'; in the CSV as the metric's column and its ``_low`` and ``_high``)."""

    kind = "summary"
    compares = False

    def build(self, records: pd.DataFrame) -> Table:
        columns = {metric: summarise(records, metric) for metric in self.spec["metrics"]}
        first = columns[self.spec["metrics"][0]]
        table = pd.DataFrame({"method": [self.label(m) for m in first["method"]],
                              "condition": [c or "-" for c in first["condition"]], "runs": first["runs"]})
        for metric, summary in columns.items():
            table[metric] = [Estimate(*values, "") for values in
                             zip(summary["mean"], summary["ci_low"], summary["ci_high"], summary["runs"])]
        return Table(table)


class Attributes(TableKind):
    """OTB's per-attribute view: precision at 20 px and success AUC per attribute and method, each the
    mean over the sequences that carry the attribute (:mod:`replication.report.attributes`)."""

    kind = "otb_attributes"
    compares = False

    def build(self, records: pd.DataFrame) -> Table:
        scores = attribute_scores(records, self.experiment)
        return Table(pd.DataFrame({
            "attribute": [f"{code} ({meaning})" for code, meaning in zip(scores["attribute"], scores["meaning"])],
            "sequences": [carried_by(sequences) for sequences in scores["sequences"]],
            "method": [self.label(method) for method in scores["method"]],
            "condition": [series or "-" for series in scores["series"]],
            "runs": scores["runs"],  # the fewest on one sequence
            "precision20": scores["precision20"],
            "success_auc": scores["success_auc"],
        }))


class Discrepancy(TableKind):
    """gps_qmcpf Figures 1-3's point sets: centred L2 discrepancy of random, Halton and good points."""

    kind = "discrepancy"
    compares = False

    def build(self, records: pd.DataFrame) -> Table:
        spec = self.spec
        return Table(discrepancy_table(n=int(spec.get("n", 400)), dims=tuple(spec.get("dims", (2, 3, 5))),
                                       method=spec.get("method", "CD")))


def _note(found: dict[str, Ranking], experiment: dict) -> str:
    """The lines under a ranking: why it is not reliable (if so), and how its rank sets fare on a sequence
    left out."""
    said = "; ".join(dict.fromkeys(filter(None, (unreliable(r, experiment) for r in found.values()))))
    caveat = f"{said[:1].upper()}{said[1:]}: the probabilities describe these runs and decide no claim. " if said else ""
    return caveat + _held_out(list(found.values()))


def _held_out(found: list[Ranking]) -> str:
    """'Leaving one sequence out, ...': how many orders the other sequences show hold on the one left out
    (summed over the table's rankings of three sequences or more)."""
    found = [r for r in found if len(r.sequences) >= 3]
    if not found:
        return ""
    held, shown = (sum(counts) for counts in zip(*(r.out_of_sample for r in found)))
    sequences = max(len(r.sequences) for r in found)
    if not shown:
        return (f"Leaving one of the {sequences} sequences out, the others show no order between two methods: "
                "the rank sets are as wide as so few sequences leave them.")
    return (f"Leaving one of the {sequences} sequences out, {held} of the {shown} orders the others show between "
            "two methods hold on the sequence left out.")


class RankingTable(TableKind):
    """Methods ranked by their mean ``metric`` over the sequences, best first, with how stable that is
    (:mod:`replication.evidence.ranking`): the mean over the sequences (95% percentile interval of the
    two-level bootstrap), the probability of ranking first, and the mean rank with its 95% interval."""

    kind = "ranking"
    compares = False

    def build(self, records: pd.DataFrame) -> Table:
        found = rankings(records, self.spec)
        rows = [{"condition": group or "-", "method": self.label(method), "sequences": len(ranked.sequences),
                 "runs": ranked.runs, self.spec["metric"]: ranked.score(i),
                 "P(best)": round(float(ranked.p_best[i]), 3), "rank": ranked.rank(i)}
                for group, ranked in found.items() for i, method in enumerate(ranked.methods)]
        return Table(pd.DataFrame(rows), note=_note(found, self.experiment))


class Pairwise(TableKind):
    """Every pair of ranked methods, the better-ranked first: the probability that A's mean over the
    sequences beats B's (two-level bootstrap), the mean of the paired per-sequence differences A - B
    with its BCa interval over the sequences, and on how many sequences A is ahead."""

    kind = "pairwise"
    compares = False

    def build(self, records: pd.DataFrame) -> Table:
        found, metric = rankings(records, self.spec), self.spec["metric"]
        rows = [{"condition": group or "-", "A": self.label(ranked.methods[a]),
                 "B": self.label(ranked.methods[b]), "sequences": len(ranked.sequences), "runs": ranked.runs,
                 "P(A beats B)": round(float(ranked.beats[a, b]), 3),
                 f"{metric} A - B": ranked.difference(a, b), "A ahead on (sequences)": ranked.wins(a, b)}
                for group, ranked in found.items()
                for a, b in itertools.combinations(range(len(ranked.methods)), 2)]
        return Table(pd.DataFrame(rows), note=_note(found, self.experiment))


def pair(records: pd.DataFrame, metric: str, baseline: str, method: str, condition: str | None = None):
    """``metric`` of two methods run on the same data (same data condition and repetition), side by side:
    columns ``baseline``, ``method`` and ``repetition``, one row per shared repetition (at ``condition`` if
    given)."""
    columns = ["data_condition", "repetition", metric]
    chosen = records if condition is None else records[records["condition"] == condition]
    left = chosen[chosen["method"] == baseline][columns]
    right = chosen[chosen["method"] == method][columns]
    paired = left.merge(right, on=["data_condition", "repetition"], suffixes=("_baseline", "_method"))
    return pd.DataFrame({"baseline": paired[f"{metric}_baseline"].astype(float),
                         "method": paired[f"{metric}_method"].astype(float), "repetition": paired["repetition"]})


def excess_over_floor(records: pd.DataFrame, floor_methods: list[str]) -> dict:
    """Paired RMSE minus the point-mass filter's RMSE on the same trajectory: an Estimate per (method,
    condition).  Every method filters the same data at a repetition, so the paired difference isolates
    the filter's own error from the run-to-run spread."""
    floor = records[records["method"].isin(floor_methods)][["data_condition", "repetition", "rmse"]]
    if floor.empty:
        return {}
    paired = records.merge(floor, on=["data_condition", "repetition"], suffixes=("", "_floor"))
    paired = paired[~paired["method"].isin(floor_methods)]
    return {key: paired_difference(group["rmse"], group["rmse_floor"])
            for key, group in paired.groupby(["method", "condition"], sort=False)}


def _printed(value) -> str:
    if isinstance(value, str):
        return value
    return "" if value is None or not np.isfinite(value) else f"{value:g}"


def _number(value) -> float | None:
    try:
        value = float(value)
    except (TypeError, ValueError):
        return None
    return value if math.isfinite(value) else None
