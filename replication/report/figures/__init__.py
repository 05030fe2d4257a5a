"""Figures drawn from run records, one module per family of kinds; importing the package registers them."""

from replication.report.figures import cost, metric, mot, qmc, ranking, tracking  # noqa: F401  (each registers its kinds)
from replication.report.figures.base import KINDS, draw

__all__ = ["KINDS", "draw"]
