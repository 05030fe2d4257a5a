"""What a request may ask of this machine, checked before anything is allocated: workers and memory.

Workers.  A local backend (loky, threading, a local dask or ray cluster) runs ``n_jobs`` processes or
threads here, each computing one run at a time on one core: more than :data:`CORES_MULTIPLE` times the
cores this process may use adds memory and no speed (``n_jobs=100000`` started about a hundred workers,
2.8 GB, before the first run), so it is refused unless ``n_jobs_beyond_cores=true``.

Memory.  Two lower bounds, so that a refusal never stops a request that would fit: a filter holds at
least :data:`PARTICLE_BYTES` per particle (or grid point) while it runs, in each worker at once; and each
run of a request takes at least :data:`RUN_BYTES` in the runner, its run in the run list and its row in the
report's table.  A request whose bound exceeds the memory available now (``MemAvailable``, within a
cgroup's limit) is refused in one line naming the setting, before a particle or a run is allocated.

Light: no numerical module, so the command line checks a request with it in well under a second.
"""

import os
import re
from pathlib import Path

from replication.errors import ConfigError

CORES_MULTIPLE = 2  # n_jobs up to twice the usable cores: room for a worker waiting on its disk or its data
# the least any shipped filter holds per particle, measured (tracemalloc, N = 1e5 to 4e5): 80 B for the
# bootstrap filter on the UNGM (one state variable), 100-130 B for the QMC filters, far more for tracking
# filters (histograms per particle) and for HSPF's and GPS-QMCPF's pairwise steps (N x N)
PARTICLE_BYTES = 64
# the least one run takes in the runner, measured on hspf_ungm: its Run in the run list, scheduled and
# indexed (about 330 B), and its row in the report's table (about 700 B)
RUN_BYTES = 1024
PARTICLE_COUNTS = re.compile(r"n_(particles|joint|points)")  # a filter's particles, joint samples, grid points
MANY_RUNS = 100_000  # a request of more runs says so, and shows its progress while its runs are listed


def usable_cores() -> int:
    """The cores this process may run on (its CPU affinity, where the system has one)."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # macOS, Windows
        return os.cpu_count() or 1


def available_memory() -> int | None:
    """The bytes that can be allocated now without swapping: the kernel's ``MemAvailable``, within the
    memory cgroup's limit where one is set; None where neither is known (not Linux)."""
    found = []
    try:
        meminfo = Path("/proc/meminfo").read_text()
    except OSError:
        meminfo = ""
    match = re.search(r"^MemAvailable:\s+(\d+) kB", meminfo, re.MULTILINE)
    if match:
        found.append(int(match[1]) * 1024)
    try:
        limit = Path("/sys/fs/cgroup/memory.max").read_text().strip()
        used = Path("/sys/fs/cgroup/memory.current").read_text().strip()
        if limit.isdigit() and used.isdigit():
            found.append(max(int(limit) - int(used), 0))
    except OSError:
        pass
    return min(found) if found else None


def check_workers(n_jobs: int, beyond_cores: bool) -> None:
    """``n_jobs`` local workers fit this machine's cores (:data:`CORES_MULTIPLE` times them), unless
    ``beyond_cores``; ``-1`` is every core."""
    most = CORES_MULTIPLE * usable_cores()
    if n_jobs > most and not beyond_cores:
        raise ConfigError(f"n_jobs={n_jobs:,} local workers on {usable_cores()} cores (at most {most}: more add memory, "
                          "not speed); pass n_jobs_beyond_cores=true to start that many")


def workers(n_jobs: int) -> int:
    """How many runs a local backend computes at once: ``n_jobs``, every core for -1."""
    return usable_cores() if n_jobs < 0 else n_jobs


def largest_particle_count(value, where: str) -> tuple[int, str] | None:
    """The largest particle count (a key :data:`PARTICLE_COUNTS` names, a swept list's values included) in
    ``value``, plain data at one scale, and the setting that gives it; None if there is none."""
    found = []
    if isinstance(value, dict):
        for key, inner in value.items():
            path = f"{where}.{key}"
            if PARTICLE_COUNTS.fullmatch(str(key)):
                counts = inner if isinstance(inner, list) else [inner]
                found += [(count, path) for count in counts if isinstance(count, int) and not isinstance(count, bool)]
            else:
                found.append(largest_particle_count(inner, path))
    elif isinstance(value, list):
        found += [largest_particle_count(inner, where) for inner in value]
    found = [item for item in found if item is not None]
    return max(found, key=lambda item: item[0]) if found else None


def check_particles(experiment: dict, n_jobs: int) -> None:
    """The experiment's largest particle count (``experiment``: its config as plain data at the request's
    scale) fits in memory in every local worker at once (:data:`PARTICLE_BYTES` each, a lower bound)."""
    largest = largest_particle_count({k: experiment.get(k) for k in ("model", "methods")}, "experiment")
    if largest is None:
        return
    count, setting = largest
    at_once = workers(n_jobs)
    check_memory(f"{setting} = {count:,}", count * PARTICLE_BYTES * at_once,
                 f"{PARTICLE_BYTES} bytes a particle at least, in each of {at_once} worker(s) at once")


def check_runs(setting: str, runs: int) -> None:
    """``runs`` runs fit in the runner's memory (:data:`RUN_BYTES` each, a lower bound)."""
    check_memory(f"{setting}: {runs:,} runs", runs * RUN_BYTES, f"{RUN_BYTES:,} bytes a run at least")


def check_memory(what: str, needed: int, basis: str) -> None:
    """``needed`` bytes fit in the memory available now, else one line: ``what`` needs at least so much
    (``basis``: how that was estimated), against what is available."""
    available = available_memory()
    if available is not None and needed > available:
        raise ConfigError(f"{what}: at least {size(needed)} needed ({basis}); {size(available)} of memory is available")


def size(n: float) -> str:
    """Bytes in the unit a reader wants: ``74.5 GiB``."""
    units = iter(("KiB", "MiB", "GiB", "TiB"))
    unit = "B"
    while n >= 1024 and unit != "TiB":
        n, unit = n / 1024, next(units)
    return f"{n:.0f} B" if unit == "B" else f"{n:.1f} {unit}"
