"""Reproducible replication of five particle-filter papers on visual tracking.

``replication.load_runs(experiment, scale)``: an experiment's stored runs as one tidy table
(:mod:`replication.runner.results`), imported on first use so that ``import replication`` stays light.
"""

__version__ = "0.1.0"
__all__ = ["__version__", "load_runs"]


def __getattr__(name: str):
    if name == "load_runs":
        from replication.runner.results import load_runs

        return load_runs
    raise AttributeError(f"module 'replication' has no attribute {name!r}")
