"""Our bootstrap PF on the UNGM as a library user calls it: ``bootstrap(N, "systematic", 1.0).run(model,
observations, rng)`` from a plain script, in whatever environment ``benchmarks/peers.py`` gives the
process (the library's defaults, or the runner's: one BLAS thread and glibc's raised allocator thresholds).
Systematic resampling at every step, the weighted mean, variance and ESS recorded at every step, no history.

The project is imported from this checkout (the folder above ``benchmarks/``), with the project's python.
The generator is seeded from ``--seed`` through numpy's global one (the harness seeds it).
"""

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

import numpy as np  # noqa: E402
from harness import main  # noqa: E402

from replication import bootstrap  # noqa: E402
from replication.models import UNGM  # noqa: E402


def filtering_means(observations, n, model):
    rng = np.random.default_rng(np.random.randint(2**31))
    return bootstrap(n, "systematic", 1.0).run(UNGM(**model, steps=len(observations)), observations, rng).means


if __name__ == "__main__":
    main({"bootstrap PF step": filtering_means}, ("numpy", "numba"), per_step=True)
