"""OTB's per-attribute view: each method's score on the sequences that carry an attribute (occlusion,
scale variation, ...), as the OTB toolkit's attribute plots show it.

For an attribute, a method's score is the mean over the sequences carrying it
of the sequence's mean over runs: every sequence weighs the same, whatever its
length or run count (the toolkit averages the sequences' curves).  Precision at
20 px and the success AUC are linear in those curves, so this is the value the
toolkit's plots give.  The sequences are the ones at hand, not a sample: an
interval (where each sequence has at least :data:`INFERENCE.min_runs` runs) is over runs
only, and an attribute carried by one sequence is that sequence's score.
The attributes of a sequence come from OTB-100's list
(:func:`replication.scenes.otb.otb_attributes`), read by the caller's
:class:`~replication.evidence.footage.Footage`; a scene without one (a
synthetic scene, a sequence not in the list) is left out.
"""

from collections.abc import Mapping

import pandas as pd

from replication.condition import label_of, values_of
from replication.evidence.footage import Footage
from replication.evidence.quantities import quantity
from replication.evidence.settings import INFERENCE
from replication.evidence.statistics import stratified_mean

METRICS = ("precision20", "success_auc")  # OTB's two scores


def sequence_attributes(records: pd.DataFrame, experiment: dict, footage: Footage) -> pd.DataFrame:
    """``records`` with ``sequence`` (the scene's name), ``series`` (the condition without the scene:
    ``n_particles=10``, or "") and ``attributes`` (OTB codes), for the runs on an OTB sequence listed."""
    fixed = experiment.get("model", {}).get("scene")  # an experiment of one scene does not sweep it
    rows = []
    for index, scene, series in zip(records.index, values_of(records, "scene"), label_of(records, ("scene",))):
        spec = experiment.get("scenes", {}).get(scene or fixed, {})
        codes = footage.attributes(spec) if spec else None
        if codes is not None:
            rows.append((index, spec["name"], series, codes))
    index, sequences, series, attributes = zip(*rows) if rows else ((), (), (), ())
    known = records.loc[list(index)].copy()
    known["sequence"], known["series"], known["attributes"] = sequences, series, attributes
    return known


def attribute_scores(records: pd.DataFrame, experiment: dict, footage: Footage, metrics=METRICS) -> pd.DataFrame:
    """One row per attribute carried by a sequence here and per (method, series), in OTB's attribute
    order: ``attribute`` (code), ``meaning``, ``sequences`` (those carrying it, sorted), ``runs`` (the
    fewest on one of them), and an :class:`~replication.evidence.statistics.Estimate` per metric."""
    meanings = footage.meanings
    known = sequence_attributes(records, experiment, footage)
    rows = []
    for code, meaning in meanings.items():
        carrying = known[pd.Series([code in codes for codes in known["attributes"]], index=known.index, dtype=bool)]
        for (method, series), group in carrying.groupby(["method", "series"], sort=False):
            by_sequence = group.groupby("sequence")
            row = {"attribute": code, "meaning": meaning, "sequences": tuple(by_sequence.groups),
                   "method": method, "series": series, "runs": int(by_sequence.size().min())}
            for metric in metrics:
                kind = quantity(metric)
                row[metric] = stratified_mean([values.astype(float) for _, values in by_sequence[metric]],
                                              kind.low, kind.high, INFERENCE.min_runs)
            rows.append(row)
    return pd.DataFrame(rows, columns=["attribute", "meaning", "sequences", "method", "series", "runs",
                                       *metrics])


def absent(scores: pd.DataFrame, meanings: Mapping[str, str]) -> list[str]:
    """The attributes (of ``meanings``, OTB's) no sequence here carries, in OTB's order."""
    return [code for code in meanings if code not in set(scores["attribute"])]


def carried_by(sequences: tuple[str, ...]) -> str:
    """How many sequences carry an attribute and which; one sequence is said to be one."""
    if len(sequences) == 1:
        return f"{sequences[0]} only (one sequence, not a population)"
    return f"{len(sequences)}: {', '.join(sequences)}"
