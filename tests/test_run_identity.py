"""The invariant typed conditions must keep: every run of every shipped experiment has the identity and
seed streams it had when conditions were strings (tests/data/run_identities.json, written before the
change), so common random numbers and the stored runs' names hold."""

import hashlib
import json
from pathlib import Path

import pytest
from hydra import compose, initialize_config_dir

from replication.condition import Condition
from replication.paths import CONF_DIR
from replication.runner.config import expand

RECORDED = json.loads((Path(__file__).parent / "data" / "run_identities.json").read_text())


def _fingerprint(run) -> str:
    streams = [run.rng(stream).integers(0, 2**63, 2).tolist() for stream in ("data", "filter")]
    return f"{run.method}|{run.condition}|{run.data_condition}|{run.repetition}|{streams}"


@pytest.mark.parametrize("experiment_scale", sorted(RECORDED))
def test_every_run_keeps_its_identity_and_seeds(experiment_scale):
    name, scale = experiment_scale.split("@")
    with initialize_config_dir(config_dir=str(CONF_DIR), version_base="1.3"):
        runs = expand(compose("config", overrides=[f"experiment={name}", f"scale={scale}"]))
    assert all(isinstance(run.condition, Condition) for run in runs)
    blob = "\n".join(sorted(_fingerprint(run) for run in runs))
    assert [len(runs), hashlib.sha256(blob.encode()).hexdigest()] == RECORDED[experiment_scale]


def test_a_condition_is_values_and_its_label_is_derived():
    condition = Condition.of([("n_particles", 100), ("scene", "Girl")])
    assert str(condition) == "N=100;scene=Girl" and condition.get("N") == 100
    assert condition.columns() == {"condition.N": 100, "condition.scene": "Girl"}
    assert str(condition.without("scene")) == "N=100" and not Condition() and str(Condition()) == ""
