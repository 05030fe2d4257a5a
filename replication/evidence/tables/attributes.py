"""OTB's per-attribute view as a table."""

import pandas as pd

from replication.evidence.attributes import attribute_scores, carried_by
from replication.evidence.tables.table import Table, TableKind

class Attributes(TableKind):
    """OTB's per-attribute view: precision at 20 px and success AUC per attribute and method, each the
    mean over the sequences that carry the attribute (:mod:`replication.evidence.attributes`)."""

    kind = "otb_attributes"
    compares = False

    def build(self, records: pd.DataFrame) -> Table:
        scores = attribute_scores(records, self.experiment, self.footage)
        return Table(pd.DataFrame({
            "attribute": [f"{code} ({meaning})" for code, meaning in zip(scores["attribute"], scores["meaning"])],
            "sequences": [carried_by(sequences) for sequences in scores["sequences"]],
            "method": [self.label(method) for method in scores["method"]],
            "condition": [series or "-" for series in scores["series"]],
            "runs": scores["runs"],  # the fewest on one sequence
            "precision20": scores["precision20"],
            "success_auc": scores["success_auc"],
        }))

