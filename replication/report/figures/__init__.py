"""Figures drawn from run records, one module per family of kinds; importing the package registers their
drawings."""

from replication.report.figures import cost, metric, mot, qmc, ranking, tracking  # noqa: F401  (each registers its drawings)
from replication.report.figures.base import DRAWINGS, draw

__all__ = ["DRAWINGS", "draw"]
