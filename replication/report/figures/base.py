"""A figure kind: a function of (records, spec, experiment, path) registered under the name a spec's ``kind:``
gives it, with the per-frame series of a run it reads and whether it reads the video the runs saw (``footage``),
and :func:`draw`, the one way a page draws a figure."""

from collections.abc import Callable
from pathlib import Path

import pandas as pd

from replication.evidence.curves import figure_runs
from replication.evidence.footage import Footage
from replication.evidence.named_conditions import written
from replication.evidence.published import COLUMNS
from replication.report.figures.style import NothingToDraw

KINDS: dict[str, Callable[..., Path]] = {}
READS: dict[str, tuple[str, ...]] = {}  # kind -> the record columns of per-frame series it draws from
FILMED: set[str] = set()  # the kinds drawn from the video the runs saw: given the footage


def figure(kind: str, reads: tuple[str, ...] = (), footage: bool = False) -> Callable:
    """Register the decorated function as the figure kind ``kind``, drawn from the series ``reads``
    (``per_frame``, ``tracks``, ``strip``) of each run besides its metrics, and with ``footage`` from the video
    the runs saw (its ``footage=`` argument: a :class:`~replication.evidence.footage.Footage`)."""
    def register(draw_kind: Callable[..., Path]) -> Callable[..., Path]:
        KINDS[kind], READS[kind] = draw_kind, reads
        if footage:
            FILMED.add(kind)
        return draw_kind
    return register


def draw(records: pd.DataFrame, spec: dict, experiment: dict, path: Path,
         published: pd.DataFrame | None = None, curve: pd.DataFrame | None = None, *, footage: Footage) -> Path:
    """Draw the figure ``spec`` (its ``kind`` names the function) from run records into ``path``.

    A spec that names a ``paper_table`` gets the published values ``published``: the file the report was
    asked to judge against, passed down once (none: no paper values on the figure).
    A spec with ``conditions: [..]`` draws the runs of those conditions only.
    A kind that draws a curve table (:data:`~replication.runner.curves.CURVES`) draws ``curve`` where it
    is given (the paper-scale record keeps the table, not the runs' series), else the table ``footage`` computes
    from ``records`` (:meth:`~replication.evidence.footage.Footage.curve`, below the report).
    """
    kind = spec["kind"]
    if kind not in KINDS:
        raise ValueError(f"unknown figure kind {kind!r}; choose one of {sorted(KINDS)}")
    if curve is None:
        absent = [series for series in READS.get(kind, ()) if series not in records]
        if absent:  # runs read from the paper-scale record, which keeps no per-frame series a table does not need
            raise NothingToDraw(f"figure {spec.get('name', kind)!r}: drawn from each run's {', '.join(absent)}, "
                                "which these records do not hold")
        if "conditions" in spec and not figure_runs(records, spec).any():
            # a scene the figure needs was not run (dropped by an override, say)
            shown = ", ".join(written(c) for c in spec["conditions"])
            raise NothingToDraw(f"figure {spec.get('name', kind)!r}: no runs at conditions {shown}")
        curve = footage.curve(records, spec, experiment)
        if curve is None and "conditions" in spec:
            records = records[figure_runs(records, spec)]
    drawn = records if curve is None else curve
    given = {"footage": footage} if kind in FILMED else {}
    if "paper_table" not in spec:
        return KINDS[kind](drawn, spec, experiment, path, **given)
    if published is None:
        published = pd.DataFrame(columns=COLUMNS + ["number"])
    return KINDS[kind](drawn, spec, experiment, path, published=published, **given)
