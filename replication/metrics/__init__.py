"""Numbers computed from (estimates, truth) and from a filter's diagnostics; no filter code here."""

from replication.metrics.scalar import filter_diagnostics, rmse

__all__ = ["filter_diagnostics", "rmse"]
