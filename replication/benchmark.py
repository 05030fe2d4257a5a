"""``python -m replication.benchmark`` (``make benchmark``): how the core's cost grows with N.

Times, on this machine, one resampling call of each scheme and one bootstrap
PF step on the UNGM, for N from 10^2 to 10^6 particles, and one point-mass
filter step; writes ``reports/benchmark/`` (CSV, figure, page) which the
report index links.  A script, not a test: timings vary with the machine.
"""

import platform
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from replication.filters import PointMassFilter, bootstrap  # noqa: E402
from replication.models import UNGM  # noqa: E402
from replication.paths import resolve  # noqa: E402
from replication.report.index import write_index  # noqa: E402
from replication.report.render import html_table, render  # noqa: E402
from replication.smc.resampling import RESAMPLERS  # noqa: E402

SIZES = (100, 1_000, 10_000, 100_000, 1_000_000)


def best_of(call, repeats: int = 5) -> float:
    """Seconds of the fastest of ``repeats`` calls (the least disturbed by the rest of the machine)."""
    times = []
    for _ in range(repeats):
        started = time.perf_counter()
        call()
        times.append(time.perf_counter() - started)
    return min(times)


def measure() -> pd.DataFrame:
    rng = np.random.default_rng(0)
    model = UNGM(steps=20)
    observations = model.simulate(rng)[1]
    rows = []
    for n in SIZES:
        weights = rng.dirichlet(np.ones(n))
        for scheme, resample in RESAMPLERS.items():
            seconds = best_of(lambda: resample(weights, rng))
            rows.append({"what": f"resample ({scheme})", "N": n, "us_per_call": 1e6 * seconds})
        pf = bootstrap(n, "systematic", 1.0)
        seconds = best_of(lambda: pf.run(model, observations, rng), repeats=3) / model.steps
        rows.append({"what": "bootstrap PF step (UNGM)", "N": n, "us_per_call": 1e6 * seconds})
    for points in (801, 1601, 3201):
        seconds = best_of(lambda: PointMassFilter(points).run(model, observations), repeats=3) / model.steps
        rows.append({"what": "point-mass filter step (UNGM)", "N": points, "us_per_call": 1e6 * seconds})
    table = pd.DataFrame(rows)
    table["ns_per_particle"] = 1e3 * table["us_per_call"] / table["N"]
    return table


def main() -> None:
    out = resolve("reports") / "benchmark"
    out.mkdir(parents=True, exist_ok=True)
    table = measure()
    table.to_csv(out / "benchmark.csv", index=False)
    fig, ax = plt.subplots(figsize=(6.5, 4))
    for what, group in table.groupby("what", sort=False):
        ax.loglog(group["N"], group["us_per_call"], marker="o", label=what)
    ax.set_xlabel("N (particles, or grid points)")
    ax.set_ylabel("time per call (µs, best of repeats)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out / "benchmark.png", dpi=120)
    plt.close(fig)
    shown = table.assign(us_per_call=table["us_per_call"].map("{:.1f}".format))
    shown["ns_per_particle"] = table["ns_per_particle"].map("{:.1f}".format)
    (out / "index.html").write_text(
        render(
            "benchmark.html.j2",
            title="Benchmark: cost of the SMC core",
            machine=f"{platform.processor() or platform.machine()}, Python {platform.python_version()}, numpy {np.__version__}",
            table=html_table(shown),
        )
    )
    print(table.to_string(index=False))
    print(f"written to {out}; index: {write_index(out.parent)}")


if __name__ == "__main__":
    main()
