"""A figure kind's drawing: a function of (records, spec, experiment, path) registered for the kind it draws
(``@draws(PerFrameCurve)``: a kind of :mod:`replication.evidence.figures`, with its options, the series it
reads and whether it is drawn on the video the runs saw), and :func:`draw`, the one way a page draws a figure."""

from collections.abc import Callable, Mapping
from pathlib import Path

import pandas as pd

from replication.evidence.curves import figure_runs
from replication.evidence.figures import FigureSpec, figure_spec
from replication.evidence.footage import Footage
from replication.evidence.named_conditions import written
from replication.evidence.published import COLUMNS
from replication.report.figures.style import NothingToDraw

DRAWINGS: dict[type[FigureSpec], Callable[..., Path]] = {}  # a figure kind -> the function drawing it


def draws(kind: type[FigureSpec]) -> Callable:
    """Register the decorated function as the drawing of the figure kind ``kind``."""
    def register(draw_kind: Callable[..., Path]) -> Callable[..., Path]:
        DRAWINGS[kind] = draw_kind
        return draw_kind
    return register


def draw(records: pd.DataFrame, spec: Mapping | FigureSpec, experiment: dict, path: Path,
         published: pd.DataFrame | None = None, curve: pd.DataFrame | None = None, *, footage: Footage) -> Path:
    """Draw the figure ``spec`` (its kind names the drawing; a mapping is checked first) from run records into
    ``path``.

    A spec that draws the paper's values (``paper_table``) gets the published values ``published``: the file
    the report was asked to judge against, passed down once (none: no paper values on the figure).
    A spec with ``conditions: [..]`` draws the runs of those conditions only.
    A kind that draws a curve table (``curved``) draws ``curve`` where it is given (the paper-scale record
    keeps the table, not the runs' series), else the table ``footage`` computes from ``records``
    (:meth:`~replication.evidence.footage.Footage.curve`, below the report); a kind drawn on the video the runs
    saw (``filmed``) is given ``footage``.
    """
    spec = figure_spec(spec)
    if curve is None:
        absent = [series for series in spec.reads if series not in records]
        if absent:  # runs read from the paper-scale record, which keeps no per-frame series a table does not need
            raise NothingToDraw(f"figure {spec.name!r}: drawn from each run's {', '.join(absent)}, "
                                "which these records do not hold")
        if spec.conditions is not None and not figure_runs(records, spec).any():
            # a scene the figure needs was not run (dropped by an override, say)
            shown = ", ".join(written(c) for c in spec.conditions)
            raise NothingToDraw(f"figure {spec.name!r}: no runs at conditions {shown}")
        if spec.curved:
            curve = footage.curve(records, spec, experiment)
        elif spec.conditions is not None:
            records = records[figure_runs(records, spec)]
    drawn = curve if spec.curved else records
    given = {"footage": footage} if spec.filmed else {}
    if not spec.paper:
        return DRAWINGS[type(spec)](drawn, spec, experiment, path, **given)
    if published is None:
        published = pd.DataFrame(columns=COLUMNS + ["number"])
    return DRAWINGS[type(spec)](drawn, spec, experiment, path, published=published, **given)
