"""Tasks bind a dataset (model or scene), a method and the metrics into one run.

A task is ``run -> dict of metrics``; the experiment config names it with ``task:``.
"""

from replication.tasks.scalar import scalar

TASKS = {"scalar": scalar}

__all__ = ["TASKS"]
