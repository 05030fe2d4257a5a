"""What a report stores in its ``summary.json``, as typed values, and the one serialiser that writes and reads them.

A page builds a :class:`Summary` (its published cells as :class:`CellResult`, its claims' readings as
:class:`~replication.evidence.checks.Result`, a multiverse's claims as :class:`RobustnessResult`);
:func:`dump` turns any such value into JSON and :func:`load` rebuilds it from its type hints, so the
index, the scorecard and the PDF read the values a page decided, never text parsed back.
"""

import dataclasses
import json
import math
import types
import typing
from collections import Counter
from enum import Enum
from pathlib import Path

from replication import atomic
from replication.evidence.checks import Result
from replication.evidence.tables import CellResult
from replication.evidence.verdict import Verdict

@dataclasses.dataclass(frozen=True)
class RobustnessResult:
    """A claim across its paper's multiverse, as the scorecard shows it."""

    robust: bool | None  # None: fewer than two cases testable
    summary: str
    deciding: str  # the statistic whose movement was tested
    cases: int
    flipped_by: tuple[str, ...]
    best_case: str  # the universe and reading closest to the paper's claim
    best_case_verdict: Verdict
    best_case_number: str


@dataclasses.dataclass(frozen=True)
class Summary:
    """One report folder's results: an experiment's (cells and claims) or a multiverse's (``multiverse``)."""

    name: str
    title: str
    paper: str
    scale: str
    n_records: int
    n_runs: int
    failed: dict[str, int] = dataclasses.field(default_factory=dict)
    cells: tuple[CellResult, ...] = ()
    claims: dict[str, dict[str, Result]] = dataclasses.field(default_factory=dict)
    scale_changes: tuple[str, ...] = ()
    tables: tuple[dict[str, str], ...] = ()  # name, title, csv, note
    figures: tuple[dict[str, str], ...] = ()  # name, title, file (and link, beside)
    multiverse: dict[str, RobustnessResult] = dataclasses.field(default_factory=dict)
    own: tuple[str, ...] = ()  # what a user's request changed in the shipped experiment (empty: as shipped)

    @property
    def verdicts(self) -> dict[str, int]:
        """How many compared cells have each outcome."""
        return dict(Counter(c.verdict.outcome.value for c in self.cells if c.verdict))

    def write(self, folder: Path) -> Path:
        path = Path(folder) / "summary.json"
        atomic.write_text(path, json.dumps(dump(self), indent=1))
        return path

    @classmethod
    def read(cls, path: Path) -> "Summary":
        return load(cls, json.loads(Path(path).read_text()))


def dump(value):
    """A typed value as JSON: dataclasses by their fields, enums by value, non-finite floats as null."""
    if dataclasses.is_dataclass(value):
        return {f.name: dump(getattr(value, f.name)) for f in dataclasses.fields(value)}
    if isinstance(value, Enum):
        return value.value
    if isinstance(value, dict):
        return {str(k): dump(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [dump(v) for v in value]
    if isinstance(value, float) or hasattr(value, "dtype"):  # numpy scalars too
        value = value.item() if hasattr(value, "item") else value
        return value if not isinstance(value, float) or math.isfinite(value) else None
    return value


def load(kind, data):
    """``data`` (as :func:`dump` wrote it) rebuilt as ``kind``: a dataclass from its type hints, recursively."""
    origin, arguments = typing.get_origin(kind), typing.get_args(kind)
    if origin in (typing.Union, types.UnionType):
        if data is None and type(None) in arguments:
            return None
        arms = [a for a in arguments if a is not type(None)]
        return load(arms[0], data) if len(arms) == 1 else data
    if data is None:
        return math.nan if kind is float else None
    if dataclasses.is_dataclass(kind):
        hints = typing.get_type_hints(kind)
        return kind(**{f.name: load(hints[f.name], data[f.name]) for f in dataclasses.fields(kind)
                       if f.init and f.name in data})
    if isinstance(kind, type) and issubclass(kind, Enum):
        return kind(data)
    if origin is tuple:
        return tuple(load(arguments[0], v) for v in data)
    if origin is list:
        return [load(arguments[0], v) for v in data]
    if origin is dict:
        return {load(arguments[0], k): load(arguments[1], v) for k, v in data.items()}
    if kind in (int, float):
        return kind(data)
    return data

