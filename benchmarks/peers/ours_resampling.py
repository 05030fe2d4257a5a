"""Our four resamplers (``replication.smc.resampling``) on the same normalised weights as filterpy's, one
call per repeat, from a plain script in the environment ``benchmarks/peers.py`` gives the process; the
estimate is filterpy_resampling.py's (the mean of N W_i over the indices drawn).  The project is imported
from this checkout, with the project's python."""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

import numpy as np  # noqa: E402
from harness import main  # noqa: E402

from replication.smc.resampling import RESAMPLERS  # noqa: E402


GENERATOR = []  # made by the untimed first call, seeded through numpy's global generator (the harness seeds it)


def resampled(resample):
    def run(weights, n, model):
        if not GENERATOR:
            GENERATOR.append(np.random.default_rng(np.random.randint(2**31)))
        return resample(weights, GENERATOR[0])

    return run


def mean_weight(indices, weights):
    return [len(weights) * weights[indices].mean()]


if __name__ == "__main__":
    main({f"resample ({scheme})": resampled(resample) for scheme, resample in RESAMPLERS.items()},
         ("numpy", "numba"), per_step=False, estimates=mean_weight)
