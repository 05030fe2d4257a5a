"""A report table: rows of ours, the published cells they were matched with, and a verdict per cell.

Every kind turns records into a :class:`Table`: one row per (method,
condition) of ours, and for the kinds that compare with the paper, the
published cells each row was matched with (by :func:`match`, the one rule
for that) and a :class:`~replication.evidence.verdict.Verdict`.

Add a kind by subclassing :class:`TableKind` in a module of this package with a
new ``kind`` name, its options (a ``Spec`` dataclass deriving from :class:`TableSpec`, or from
:class:`Compared` where it matches published cells) and a ``build`` method; a spec in ``report.tables`` then
names it, and the config check holds the spec to the options before any run (:func:`table_specs`).
"""

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np
import pandas as pd

from replication.display import method_label
from replication.errors import ConfigError
from replication.evidence.footage import Footage
from replication.evidence.named_conditions import as_mapping, holds, instead_of, written
from replication.evidence.published import cells
from replication.evidence.statistics import Estimate, said_level
from replication.evidence.verdict import Outcome, Verdict
from replication.kinds import Registry
from replication.specs import Spec, kind_named

# the equivalence tolerance is our choice (the papers state none): each compared cell is also judged at
# these, so the index shows how far the cells' verdicts move with it
SENSITIVITY = (0.05, 0.20)
KEYS = ("paper", "table", "experiment", "method", "metric", "condition")  # a published cell's identity


@dataclass(frozen=True)
class CellResult:
    """A published cell one of our tables matched: the cell's keys, our row, its estimate and verdict, and
    the verdict at each other equivalence tolerance (``at_tolerance``: '0.05' -> outcome)."""

    published_index: int
    paper: str
    table: str
    experiment: str
    method: str
    metric: str
    condition: str
    table_name: str
    our_method: str
    our_condition: str
    runs: int
    paper_number: float | None = None  # the published value as a number (None: a rating, a word)
    estimate: Estimate | None = None  # a rating's too: the proportion behind it
    rating: str = ""  # ours as a word (a rating, 'success'), where the paper's cell is one
    verdict: Verdict | None = None
    at_tolerance: dict[str, Outcome] = field(default_factory=dict)

    @property
    def key(self) -> tuple[str, ...]:
        return tuple(getattr(self, k) for k in KEYS)

    @property
    def ours(self) -> str:
        """Ours as a reader sees it: the word, or 'mean [low, high]'."""
        return self.rating or ("" if self.estimate is None else str(self.estimate))


def number(value) -> str:
    """A number as a reader is told it: 4 significant digits, thousands whole; '' when not finite."""
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return ""
    if isinstance(value, str):
        return value
    return f"{value:,.0f}" if abs(value) >= 1e4 else f"{value:.4g}"


def interval(value, low, high, level=None) -> str:
    """'value [low, high]', with the interval's level where given ('value [low, high] (90% CI)'), or the
    value alone where the interval is not defined."""
    if any(v is None or not math.isfinite(v) for v in (low, high)):
        return number(value)
    return f"{number(value)} [{number(low)}, {number(high)}]" + (f" ({said_level(level)})" if level else "")


def cell_value(value):
    """A table cell's value as a reader takes it: None where it is missing (NaN)."""
    return None if isinstance(value, float) and math.isnan(value) else value


@dataclass(frozen=True)
class Row:
    """One row of a table as its CSV writes it: columns by name, numbers shown as :func:`number` shows them."""

    where: str
    values: dict

    def __getitem__(self, column: str) -> str:
        if column not in self.values:
            raise LookupError(f"{self.where} has no column {column!r}; it has {', '.join(self.values)}")
        return number(cell_value(self.values[column]))

    def __getattr__(self, column: str) -> str:
        if column.startswith("_"):
            raise AttributeError(column)
        return self[column]

    @property
    def estimate(self) -> str:
        v = self.values
        return interval(*(cell_value(v.get(k)) for k in ("ours", "ci_low", "ci_high")))


@dataclass
class Table:
    """Rows of ours (``frame``: numbers, and a Verdict per row where compared), the published cells
    they were compared with (``cells``: one JSON-ready entry each, for the summary of every cell), a
    line a reader must see beside it (``note``: a ranking that is not reliable), and where it was read from
    (``where``: ``bis_pf/table2_error``, named in a reader's errors)."""

    frame: pd.DataFrame
    cells: list[CellResult] = field(default_factory=list)
    note: str = ""
    where: str = ""

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

    @property
    def rows(self) -> list[Row]:
        """Its rows as :meth:`written` writes them."""
        return [Row(f"{self.where} row {i}", row) for i, row in enumerate(self.written().to_dict("records"))]

    def at(self, **match) -> Row:
        """The one row (as :meth:`written` writes it) whose columns equal ``match``."""
        picked = self.written()
        for column, value in match.items():
            if column not in picked:
                raise LookupError(f"{self.where} has no column {column!r}")
            picked = picked[picked[column].astype(str) == str(value)]
        where = f"{self.where} at {', '.join(f'{k}={v}' for k, v in match.items())}"
        if len(picked) != 1:
            raise LookupError(f"{where}: {len(picked)} rows, not one")
        return Row(where, picked.iloc[0].to_dict())

    @classmethod
    def read(cls, frame: pd.DataFrame, where: str = "") -> "Table":
        """A table back from the CSV :meth:`written` made, to print or quote (the PDF, the findings), never to
        decide: the verdicts are the summary's."""
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
        return cls(frame, where=where)

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


def match(theirs: pd.DataFrame, method: str, ours: Mapping, spec: "Compared") -> pd.DataFrame:
    """The published cells our row (``method``, at the condition of ``ours``: a row with its label
    ``condition`` and its ``condition.<variable>`` columns) is compared with.

    ``spec.match`` lists conditions of ours, each with the paper's cells it is
    compared with (:func:`matched`); a condition it does not list is compared
    with the paper's of the same label.  A paper cell with no condition takes
    ``spec.paper_condition`` (the paper's unstated N, say).
    """
    wanted = next((paper for condition, paper in matched(spec) if holds(ours, condition)),
                  {"condition": ours["condition"]})
    chosen = theirs["method"] == method
    if "condition" in wanted:
        chosen &= theirs["condition"].replace("", spec.paper_condition) == wanted["condition"]
    if "experiment" in wanted:
        chosen &= theirs["experiment"] == wanted["experiment"]
    return theirs[chosen]


def matched(spec: "Compared") -> list[tuple[dict, dict]]:
    """A table's ``match:``, each entry ``{ours: {scene: Girl}, paper: {experiment: single_object, condition:
    "N=10;runs=100"}}``: a condition of ours (a mapping of values,
    :mod:`~replication.evidence.named_conditions`) and the paper's cells it is compared with, by their
    experiment and their condition as ``published_values.csv`` writes it (the paper's, not ours)."""
    entries = spec.match or []
    where = f"table {spec.name!r}: match"
    if isinstance(entries, Mapping):  # keyed by our condition's label
        label, paper = next(iter(entries.items()))
        paper = written(paper if isinstance(paper, Mapping) else {"condition": paper})
        raise ConfigError(f"{where} is a list: write {label!r} as - {{ours: {instead_of(str(label))}, paper: {paper}}}")
    for entry in entries:
        if not isinstance(entry, Mapping) or not isinstance(entry.get("paper"), Mapping):
            raise ConfigError(f"{where}: an entry is {{ours: {{scene: Girl}}, paper: {{experiment: girl, condition: "
                              f"N=10}}}}, got {entry!r}")
    return [(as_mapping(entry.get("ours"), where), dict(entry["paper"])) for entry in entries]


@dataclass(frozen=True, kw_only=True)
class TableSpec(Spec):
    """What every table spec names: the table (its CSV's and HTML's file name), its title, its kind."""

    name: str
    title: str = ""
    kind: str = ""


@dataclass(frozen=True, kw_only=True)
class Compared(TableSpec):
    """A table matched with the paper's cells: those of ``paper_table`` (one or a list; none: a user's own
    table) and ``paper_metric`` (default: the table's metric), matched by ``match`` (:func:`matched`), a cell
    stated without its condition taking ``paper_condition``."""

    paper_table: str | list[str] | None = None
    paper_metric: str | None = None
    match: Any = None
    paper_condition: str = ""

    @property
    def published_metric(self) -> str | None:
        """The metric of the paper's cells this table compares with."""
        return self.paper_metric

    @property
    def paper_tables(self) -> list[str]:
        table = self.paper_table
        return [] if table is None else [str(t) for t in table] if isinstance(table, list) else [str(table)]


TABLE_KINDS: Registry[type["TableKind"]] = Registry("table kind")


def table_spec(written: Mapping | TableSpec, where: str = "") -> TableSpec:
    """A table spec as its kind declares it (``kind:``; a list of ``metrics:`` is a summary, else a comparison),
    checked (:meth:`~replication.specs.Spec.of`); ``where``: the file it is written in."""
    if isinstance(written, TableSpec):
        return written
    name = written.get("name") if isinstance(written, Mapping) else None
    where = f"{where}: table {name!r}" if where else f"table {name!r}"
    kind = (written.get("kind") or ("summary" if "metrics" in written else "comparison")
            if isinstance(written, Mapping) else None)
    made = kind_named(written, TABLE_KINDS, kind, where, "a table")
    return made.Spec.of({**written, "kind": kind}, f"{where} ({kind})")


def table_specs(experiment: Mapping, where: str = "") -> tuple[TableSpec, ...]:
    """The experiment's report tables as typed specs (``where``: its file, said in an error)."""
    return tuple(table_spec(written, where) for written in (experiment.get("report") or {}).get("tables") or ())


class TableKind:
    """One kind of report table; subclasses register themselves by ``kind`` and declare their options
    (``Spec``)."""

    kind: ClassVar[str]
    Spec: ClassVar[type[TableSpec]] = TableSpec
    compares: ClassVar[bool] = True  # whether its rows are matched with published cells
    reads: ClassVar[tuple[str, ...]] = ()  # the per-frame series of a run it is built from (the record keeps them)

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        TABLE_KINDS.register(cls.kind, cls)

    def __init__(self, spec: TableSpec, experiment: dict, published: pd.DataFrame, footage: Footage | None = None):
        self.spec, self.experiment, self.published, self.footage = spec, experiment, published, footage

    @classmethod
    def of(cls, spec: Mapping | TableSpec, experiment: dict, published: pd.DataFrame,
           footage: Footage | None = None) -> "TableKind":
        """The table kind a spec names, built on its typed spec (a mapping is checked first: :func:`table_spec`);
        ``footage``: the video the runs saw, for a kind that reads it (the caller's)."""
        spec = table_spec(spec)
        return TABLE_KINDS[spec.kind](spec, experiment, published, footage)

    def build(self, records: pd.DataFrame) -> Table:
        raise NotImplementedError

    def label(self, method: str) -> str:
        return method_label(self.experiment, method)

    def theirs(self) -> pd.DataFrame:
        return cells(self.published, self.experiment["paper"], self.spec.paper_table,  # none: a user's own table
                     self.spec.published_metric)

    def entry(self, index, row: dict, verdict: Verdict | None, estimate: Estimate | None, rating: str = ""
              ) -> CellResult:
        """A matched published cell for ``summary.json``: the cell's keys and our row's numbers."""
        cell = self.published.loc[index]
        return CellResult(int(index), *(str(cell[k]) for k in KEYS), table_name=self.spec.name,
                          our_method=row["method"], our_condition="" if row["condition"] == "-" else row["condition"],
                          runs=int(row["runs"]),
                          paper_number=None if pd.isna(cell["number"]) else float(cell["number"]),
                          estimate=estimate, rating=rating, verdict=verdict)


def pair(records: pd.DataFrame, metric: str, baseline: str, method: str, condition: str | None = None,
         baseline_condition: str | None = None):
    """``metric`` of two methods run on the same data (same data condition and repetition), side by side:
    columns ``baseline``, ``method`` and ``repetition``, one row per shared repetition (at ``condition`` if
    given; the baseline at ``baseline_condition`` instead if given: another N on the same data)."""
    columns = ["data_condition", "repetition", metric]

    def at(name: str, where: str | None) -> pd.DataFrame:
        chosen = records["method"] == name
        if where is not None:
            chosen &= records["condition"] == where
        return records.loc[chosen, columns]  # the three columns taken, not the record's every one

    left = at(baseline, baseline_condition or condition)
    right = at(method, condition)
    paired = left.merge(right, on=["data_condition", "repetition"], suffixes=("_baseline", "_method"))
    return pd.DataFrame({"baseline": paired[f"{metric}_baseline"].astype(float),
                         "method": paired[f"{metric}_method"].astype(float), "repetition": paired["repetition"]})


def _printed(value) -> str:
    if isinstance(value, str):
        return value
    return "" if value is None or not np.isfinite(value) else f"{value:g}"

