"""An experiment's stored runs as one tidy table: a row per run, a column per metric and per parameter.

``load_runs("ism_pf", scale="quick")`` expands the experiment as the runner does and reads the
records the store holds for it.  Every parameter of a run gets its own column, swept or fixed:
``method.<key>`` for the method's (``method.n_particles``), ``model.<key>`` for the model's and
its scene's, nested keys joined by dots (``model.scene_spec.frames``).  Per-frame series
(``per_frame``, ``strip``, a MOT run's ``tracks``) stay out of the table, in the JSON records.

    import seaborn as sns
    runs = load_runs("ism_pf", scale="quick")
    sns.pointplot(runs, x="method.n_particles", y="mean_cle", hue="method")
"""

import pandas as pd
from hydra import compose, initialize_config_dir

from replication.paths import CONF_DIR, resolve
from replication.run import Run
from replication.runner.config import expand
from replication.runner.store import Store

SERIES = ("per_frame", "strip", "tracks")  # per-frame data, kept in the records


def parameters(run: Run) -> dict:
    """A run's parameters as flat columns ``method.<key>`` and ``model.<key>`` (nested keys joined by dots)."""
    flat = pd.json_normalize({"method": run.method_params, "model": run.model}, sep=".")
    return {"run_key": run.key, **flat.iloc[0].to_dict()}


def load_runs(experiment: str, scale: str = "paper", *overrides: str) -> pd.DataFrame:
    """Every stored run of ``experiment`` at ``scale``, one row each, with its parameters and metrics.

    ``overrides`` are the command line's (``"store=/path"``, ``"experiment.runs.quick=3"``); runs not
    yet stored are absent (run the experiment first), and so are runs that failed
    (:mod:`replication.runner.failures`).
    """
    with initialize_config_dir(config_dir=str(CONF_DIR), version_base="1.3"):
        cfg = compose("config", overrides=[f"experiment={experiment}", f"scale={scale}", *overrides])
    runs = expand(cfg)
    records = Store(resolve(cfg.store), cfg.experiment.name).load(runs)
    if records.empty:
        return records
    table = pd.DataFrame([parameters(run) for run in runs]).drop_duplicates("run_key")
    records = records.drop(columns=[c for c in SERIES if c in records])
    return records.merge(table, on="run_key", how="left", validate="many_to_one")
