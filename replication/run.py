"""A run: the pure input of a task (an experiment's method at one condition and repetition) and its
random streams, keyed by its identity."""

from dataclasses import dataclass
from typing import Any

import numpy as np

from replication.condition import Condition
from replication.seeding import seed_sequence


@dataclass(frozen=True)
class Run:
    """One independent run: the pure input of a task."""

    experiment: str
    task: str
    method: str
    condition: Condition
    repetition: int
    model: dict[str, Any]
    method_params: dict[str, Any]
    base_seed: int
    key: str
    data_condition: Condition = Condition()  # the model's swept values alone: what the data depend on

    @property
    def run_id(self) -> str:
        condition = str(self.condition) or "default"
        return f"{self.method}__{condition}__{self.key}__r{self.repetition:03d}"

    def rng(self, stream: str) -> np.random.Generator:
        """Independent generators: ``data`` is shared by every method at the same model
        condition and repetition (common random numbers); ``filter`` is the method's own."""
        if stream == "data":
            identity = ("data", str(self.data_condition), self.repetition)
        else:
            identity = (stream, self.method, str(self.condition), self.repetition)
        return np.random.default_rng(seed_sequence(self.base_seed, *identity))

    def identity(self) -> dict[str, Any]:
        return {
            "experiment": self.experiment,
            "method": self.method,
            "condition": str(self.condition),
            "data_condition": str(self.data_condition),
            "repetition": self.repetition,
            "run_key": self.key,
            "run_id": self.run_id,
        }
