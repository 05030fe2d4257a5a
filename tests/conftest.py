import gc
import math
import os
import signal
import sys
from pathlib import Path

import pytest
from hydra import compose, initialize_config_dir

from replication.paths import CONF_DIR, HOME_VARIABLE

PROJECT_ROOT = Path(__file__).resolve().parents[1]  # the checkout: the commands run from it


def pytest_configure(config):
    """Deliver Ctrl-C as a terminal does, even when the suite was started in the background of a
    non-interactive shell, which starts it with SIGINT ignored (and every process it spawns with it):
    the reliability tests send SIGINT to the runner and to its workers."""
    if signal.getsignal(signal.SIGINT) == signal.SIG_IGN:
        signal.signal(signal.SIGINT, signal.default_int_handler)


@pytest.fixture(autouse=True)
def process_state_restored():
    """The command line sets ``$REPLICATION_HOME`` for its workers; a test that calls it in-process must not
    leave it to the tests after it in the same worker, whose subprocesses would then resolve their store in
    this checkout (a copy of the project ran its runs into this clone's ``experiments/``)."""
    saved = os.environ.get(HOME_VARIABLE)
    yield
    gc.unfreeze()  # the command line freezes the heap for its exit (lifeline.exit_uncollected); a test is no exit
    if saved is None:
        os.environ.pop(HOME_VARIABLE, None)
    else:
        os.environ[HOME_VARIABLE] = saved


@pytest.fixture
def make_cfg(tmp_path):
    """Compose a config the way the CLI does, with the store and reports in a temporary folder."""

    def make(experiment="gps_qmcpf", *overrides):
        with initialize_config_dir(config_dir=str(CONF_DIR), version_base="1.3"):
            return compose(
                "config",
                overrides=[
                    f"experiment={experiment}",
                    f"store={tmp_path / 'experiments'}",
                    f"reports={tmp_path / 'reports'}",
                    "progress=false",
                    *overrides,
                ],
            )

    return make


@pytest.fixture
def cli(tmp_path):
    """The command line as a user runs it, with its store and reports in a temporary folder."""
    import subprocess

    def run(*args, timeout=300, env=None):
        command = [
            sys.executable,
            "-m",
            "replication",
            *args,
            f"store={tmp_path / 'experiments'}",
            f"reports={tmp_path / 'reports'}",
            "outside_project=true",
            "progress=false",
        ]
        return subprocess.run(command, cwd=PROJECT_ROOT, capture_output=True, text=True, timeout=timeout, env=env)

    return run


SMALL = ("scale=quick", "experiment.runs.quick=3")


@pytest.fixture
def keep_figures(monkeypatch):
    """``keep_figures(*modules)``: the figures those report modules draw, kept as matplotlib Figures (their
    ``save`` replaced) instead of written as PNG files; returns the list they are appended to."""
    kept = []

    def keep(fig, path, dpi=110):
        kept.append(fig)
        return path

    def patch(*modules):
        for module in modules:
            monkeypatch.setattr(module, "save", keep)
        return kept

    return patch


def typed(records):
    """Hand-written records as the store gives them: each condition label's variables also as typed columns
    (``N=10;scene=a`` -> ``condition.N`` = 10, ``condition.scene`` = 'a'), the columns the report reads."""
    import pandas as pd

    from replication.condition import Condition

    def value(text: str):
        for kind in (int, float):
            try:
                return kind(text)
            except ValueError:
                pass
        return text

    conditions = [Condition(tuple((k, value(v)) for k, v in (p.split("=", 1) for p in label.split(";") if p)))
                  for label in records["condition"]]
    columns = pd.DataFrame([c.columns() for c in conditions], index=records.index, dtype=object)
    return pd.concat([records, columns], axis=1) if len(columns.columns) else records


def c_library(function):
    """``function``, one of :mod:`math`'s (the C library's, as the compiled kernels call it), element by element:
    the same bits on every CPU.  numpy's own exp and log take a vector path chosen by the CPU (AVX-512F where
    there is one) and may differ from the C library's in the last bit, so a kernel checked against a numpy
    form "to the bit" is checked against these."""
    import numpy as np

    return np.vectorize(function, otypes=[float])


libm_exp, libm_log = c_library(math.exp), c_library(math.log)
