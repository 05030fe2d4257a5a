"""A figure kind: a function of (records, spec, experiment, path) registered under the name a spec's ``kind:``
gives it, and :func:`draw`, the one way a page draws a figure."""

from collections.abc import Callable
from pathlib import Path

import pandas as pd

from replication.evidence.published import COLUMNS
from replication.report.figures.style import NothingToDraw

KINDS: dict[str, Callable[..., Path]] = {}


def figure(kind: str) -> Callable:
    """Register the decorated function as the figure kind ``kind``."""
    def register(draw_kind: Callable[..., Path]) -> Callable[..., Path]:
        KINDS[kind] = draw_kind
        return draw_kind
    return register


def draw(records: pd.DataFrame, spec: dict, experiment: dict, path: Path,
         published: pd.DataFrame | None = None) -> Path:
    """Draw the figure ``spec`` (its ``kind`` names the function) from run records into ``path``.

    A spec that names a ``paper_table`` gets the published values ``published``: the file the report was
    asked to judge against, passed down once (none: no paper values on the figure).
    A spec with ``conditions: [..]`` draws the runs of those conditions only.
    """
    if spec["kind"] not in KINDS:
        raise ValueError(f"unknown figure kind {spec['kind']!r}; choose one of {sorted(KINDS)}")
    if "conditions" in spec:
        records = records[records["condition"].isin(spec["conditions"])]
        if records.empty:  # a scene the figure needs was not run (dropped by an override, say)
            raise NothingToDraw(f"figure {spec.get('name', spec['kind'])!r}: no runs at conditions "
                                f"{spec['conditions']}")
    if "paper_table" not in spec:
        return KINDS[spec["kind"]](records, spec, experiment, path)
    if published is None:
        published = pd.DataFrame(columns=COLUMNS + ["number"])
    return KINDS[spec["kind"]](records, spec, experiment, path, published=published)
