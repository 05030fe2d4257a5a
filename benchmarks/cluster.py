"""Parallel efficiency and the scheduling overhead per run of every backend, at 1 and 2 workers (issue 59, item 5).

``python benchmarks/cluster.py [EXPERIMENT] [override ...]`` (default: ``hspf_ungm scale=quick
experiment.runs.quick=120``: 360 runs of about 0.1 s, short enough for scheduling to show).  The same runs are
computed

1. one after another in this process (``perform``), after one warm-up run of each method: the serial time
   ``T1``, the sum of the runs' own wall times;
2. by each backend, into a fresh store, with 1 and then 2 workers: ``loky`` (the default), ``dask`` (a
   ``dask scheduler`` and ``dask worker`` processes started from their command lines on the loopback, as on
   real machines) and ``ray`` (``ray start --head --num-cpus=W``), each cluster started before its clock.

For each: the wall time ``W`` of ``execute`` (the command's core: the store checked, the runs sent, every
record written), the parallel efficiency ``T1 / (workers W)``, and the overhead per run
``(workers W - the records' summed wall_s) / runs``: what scheduling, sending and storing add to each run
(a worker's first run also loads numba's compiled kernels).  Every store's records are checked equal to the
first's.  The machine's one-minute load is logged beside every figure.  Writes
``reports/benchmark/cluster.csv`` and prints it.  A script, not a test: timings depend on the machine.
"""

import os
import secrets
import tempfile

for _variable in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):  # as in the runner's workers
    os.environ.setdefault(_variable, "1")
# the ray heads' files in a folder of this script's own, and their token, in this process's environment before
# anything reads it: the heads started here and this process, which joins them, share both
RAY_ENV = {"RAY_TMPDIR": tempfile.mkdtemp(prefix="ray", dir="/tmp"), "RAY_AUTH_MODE": "token",
           "RAY_AUTH_TOKEN": secrets.token_hex(32)}
os.environ.update(RAY_ENV)

import shutil  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from contextlib import nullcontext  # noqa: E402
from pathlib import Path  # noqa: E402

import pandas as pd  # noqa: E402
from hydra import compose, initialize_config_dir  # noqa: E402

from replication.paths import CONF_DIR, resolve  # noqa: E402
from replication.runner.config import expand  # noqa: E402
from replication.runner.execute import TIMING_COLUMNS, execute, perform  # noqa: E402
from replication.runner.loopback import dask_cluster, ray_cluster  # noqa: E402
from replication.runner.store import Store  # noqa: E402

DEFAULT = ("hspf_ungm", "scale=quick", "experiment.runs.quick=120")
WORKERS = (1, 2)


CLUSTERS = {"loky": lambda workers: nullcontext(None), "dask": dask_cluster, "ray": ray_cluster}  # ray: RAY_ENV


def records(store: Store, runs) -> pd.DataFrame:
    return store.load(runs).drop(columns=list(TIMING_COLUMNS), errors="ignore").sort_values("run_id") \
        .reset_index(drop=True)


def main(arguments: list[str]) -> None:
    experiment, *overrides = arguments or DEFAULT
    with initialize_config_dir(config_dir=str(CONF_DIR), version_base="1.3"):
        cfg = compose("config", overrides=[f"experiment={experiment}", "progress=false", *overrides])
    runs = expand(cfg)
    for run in {run.method: run for run in runs}.values():  # numba's kernels loaded here before the clock
        perform(run)
    started = time.perf_counter()
    serial = sum(perform(run)["wall_s"] for run in runs)
    serial_wall = time.perf_counter() - started
    print(f"{experiment}: {len(runs)} runs, serial {serial:.1f} s of runs ({serial_wall:.1f} s wall), "
          f"load {os.getloadavg()[0]:.2f}", flush=True)
    rows, reference = [], None
    with tempfile.TemporaryDirectory() as folder:
        for backend, cluster in CLUSTERS.items():
            for workers in WORKERS:
                with cluster(workers) as address:
                    store = Store(Path(folder) / f"{backend}-{workers}", cfg.experiment.name)
                    load = os.getloadavg()[0]
                    started = time.perf_counter()
                    execute(runs, store, n_jobs=workers, backend=backend, address=address, progress=False)
                    wall = time.perf_counter() - started
                table = records(store, runs)
                if reference is None:
                    reference = table
                pd.testing.assert_frame_equal(table, reference)  # every backend: the same records
                work = store.load(runs)["wall_s"].sum()
                rows.append({"backend": backend, "workers": workers, "runs": len(runs), "wall_s": wall,
                             "serial_s": serial, "efficiency": serial / (workers * wall),
                             "overhead_ms_per_run": 1e3 * (workers * wall - work) / len(runs),
                             "runs_wall_s": work, "load_1m_before": load, "load_1m_after": os.getloadavg()[0]})
                print(pd.DataFrame(rows[-1:]).round(3).to_string(index=False, header=len(rows) == 1), flush=True)
    table = pd.DataFrame(rows)
    out = resolve("reports") / "benchmark"
    out.mkdir(parents=True, exist_ok=True)
    table.to_csv(out / "cluster.csv", index=False)
    shutil.rmtree(RAY_ENV["RAY_TMPDIR"], ignore_errors=True)
    print(f"\nevery backend stored the same records; written to {out / 'cluster.csv'}")


if __name__ == "__main__":
    main(sys.argv[1:])
