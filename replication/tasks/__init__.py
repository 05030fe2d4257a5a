"""Tasks bind a dataset (model or scene), a method and the metrics into one run.

A task is a module with ``check(model, method)`` (raise ``ValueError`` for a
bad config, :class:`DataMissing` for absent data) and ``run(run) -> dict``; the
experiment config names it with ``task:``.  A task whose records hold per-frame data
also has ``frame_table(record) -> DataFrame``, a row per frame (and target or track), which
:func:`replication.runner.results.frames` gathers.
"""

from types import ModuleType

from replication.kinds import Registry
from replication.scenes.base import SequenceMissing as DataMissing
from replication.tasks import mot, scalar, tracking

TASKS: Registry[ModuleType] = Registry("task", {"scalar": scalar, "tracking": tracking, "mot": mot})

__all__ = ["TASKS", "DataMissing"]
