"""The paper-scale record: every stored run of every experiment at the papers' scale, shipped as tidy
data with its provenance, so that a reader gets the verdicts without hours of runs and any machine can
re-check them.

Layout (``record/`` in a clone, the ``record`` setting of ``conf/config.yaml``)::

    record/manifest.json               what made it: commit, libraries, CPU, date, wall time, and the
                                       SHA-256 of every file below
    record/<experiment>/runs.parquet   one row per run (failed runs too, with their ``failure``)
    record/<experiment>/curves/<figure>.parquet   what each curve figure draws (per-frame means and
                                       bands, OTB curves: :mod:`replication.runner.curves`)

A runs table (:mod:`.runs`) holds a run's identity (``experiment``, ``method``, ``repetition``,
``run_key``, ``base_seed``), each condition variable (``condition.N``, ``condition.scene``) and each
method and model parameter (``method.n_particles``, ``model.scene_spec.frames``) as its own typed column,
every metric, and the provenance of the process that computed it; per-frame series only where one of the
experiment's tables reads them (:attr:`~replication.evidence.tables.table.TableKind.reads`).  Figures that
show single runs' frames (snapshots, strips, tracks) are not drawn from the record.

``pf-replicate record`` writes it from the store (:mod:`.write`), ``pf-replicate verify``
re-computes a sample of its runs in the code and environment at hand (:mod:`.verify`), and
``pf-replicate report record=record`` draws every page from it (:class:`.runs.Record` stands in for
the store).  This package computes no run: it is outside every run's code key.
"""
