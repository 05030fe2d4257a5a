"""Filter variants.  Each is a small builder that returns an object with
``run(model, observations, rng) -> FilterOutput``; particle filters are the one
loop of :mod:`replication.smc.loop` with their own proposal or move.

A method in an experiment config names its builder with ``filter:`` and passes
the rest of its keys to it; :mod:`replication.filters.registry` finds the
builder, a built-in or a user's, by the one mechanism of entry points and
import paths.  A task tracking targets in video drives every method through
:func:`replication.filters.tracker.tracker`: one interface for one or many
targets, the multi-target filters of :mod:`replication.filters.bis` stepping
all targets together, any other filter one per target.
"""
