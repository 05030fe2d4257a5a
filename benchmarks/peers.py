"""``python benchmarks/peers.py`` (part of ``make benchmark``): our bootstrap PF step and resamplers
against peer libraries, each installed in its own venv, in two environments.

What is compared, on the UNGM (gps_qmcpf eqs (11)-(12), T = 20 observations simulated here):

* ours, ``bootstrap(N, "systematic", 1.0)`` (systematic resampling at every step, no history),
  against Chopin's ``particles`` (the same bootstrap PF; and SQMC, another algorithm for the same
  filtering means, far more accurate at equal N: compared both at equal N and at equal accuracy) and
  Stone Soup (``ParticlePredictor`` + ``ParticleUpdater`` + ``SystematicResampler``): seconds per step;
* our four resamplers against filterpy's (``filterpy.monte_carlo``) on the same weights: seconds
  per call.

How: every side runs as a plain script in a process of its own: ours (``benchmarks/peers/ours_*.py``,
the project's python, the library called as its README shows) and the peers (the scripts of
``benchmarks/peers/`` in venvs made once under ``.peers/<peer>/`` from the pinned
``benchmarks/peers/<peer>.txt``, remade when that file changes; a peer that cannot be installed or run
is reported in one line and skipped).  Each script times itself (no start-up or imports), after an
untimed run at the same N (two steps of a filter, or one resampling).  Two environments, each side the
same: ``library``, the defaults a user's script gets (this process's environment less the variables
below: BLAS with its own threads, glibc's allocator as it starts), and ``runner``, the experiments'
(one BLAS thread, ``replication/runner/memory.py``'s raised glibc mmap and trim thresholds, set by the
environment variables with the same effect).  For N = 10^2 .. 10^6, ours and the peer run in turn,
A B A B, for ``--rounds`` rounds; reported per environment and N: the median and range over rounds of
t_ours / t_peer.

Agreement, checked before the times are compared: for a filter, the distance is the mean over
steps of |mean over rounds of ours' filtering mean - the same of the peer's|, and the bound 4 times
the mean over steps of its standard error from the spread of the rounds; for a resampler (whose
estimate is the mean of N W_i over the indices drawn, expected N sum W_i^2), the distance is
|mean over rounds of ours - the same of the peer's|, the bound 4 times its standard error under
multinomial draws (which residual and stratified draws do not exceed).  The distance of each side
from the exact value (the grid filter, ``PointMassFilter``; N sum W_i^2) is shown beside, and each
side's RMSE against it over the rounds and steps.  A peer beyond its bound is reported as disagreeing
and its times are flagged.  SQMC at equal accuracy: the bootstrap PF's error falls as N^-1/2 and its
time grows as N, so ours would match SQMC's RMSE at (RMSE_ours / RMSE_SQMC)^2 times the N, and the
ratio at equal accuracy is t_ours / t_SQMC times that factor (an extrapolation from the measured RMSEs).

The floor of a step, under any implementation's time: max(8 N (4 d + 4) bytes / the copy bandwidth,
the time of drawing N standard normals), d = 1 (four passes over the N d-vectors of states: propose,
weigh, gather, mean; and four N-vectors of 8 bytes: log-weights, weights, cumulative weights,
ancestors).  The bandwidth is numpy's best copy of 2 x 10^8 bytes, counting the bytes read and
written.  Our step's time over its floor is printed per environment and N.

Writes ``reports/benchmark/peers.csv``, ``peers_ratios.csv``, ``peers.png`` and ``peers.html``.
A script, not a test: timings depend on the machine and its load.
"""

import argparse
import hashlib
import json
import os
import platform
import shutil
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from replication import PointMassFilter  # noqa: E402
from replication.models import UNGM  # noqa: E402
from replication.paths import resolve  # noqa: E402
from replication.report.pages.render import html_table, render  # noqa: E402
from replication.runner.memory import MMAP_THRESHOLD, TRIM_THRESHOLD, retain_freed_memory  # noqa: E402
from replication.smc.resampling import RESAMPLERS  # noqa: E402
from timing import best_of  # noqa: E402

SCRIPTS = Path(__file__).resolve().parent / "peers"
VENVS = resolve(".peers")
PEERS = {"particles": "particles_ungm.py", "stonesoup": "stonesoup_ungm.py",
         "filterpy": "filterpy_resampling.py"}
RESAMPLING_PEERS = {"filterpy"}  # the others filter the UNGM
OURS = {False: "ours_ungm.py", True: "ours_resampling.py"}  # against a filter, against a resampler
SIZES = (10**2, 10**3, 10**4, 10**5, 10**6)
TABLE_SIZES = (10**3, 10**4, 10**5, 10**6)
STEPS = 20
BOUND_SIGMAS = 4.0
PF_STEP, SQMC_STEP = "bootstrap PF step", "SQMC step"
RUNNER_VARIABLES = {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1",
                    "MALLOC_MMAP_THRESHOLD_": str(MMAP_THRESHOLD), "MALLOC_TRIM_THRESHOLD_": str(TRIM_THRESHOLD)}
PLAIN = {name: value for name, value in os.environ.items() if name not in RUNNER_VARIABLES}
ENVIRONMENTS = {"library": PLAIN, "runner": {**PLAIN, **RUNNER_VARIABLES}}  # a user's plain script; the runner's


class PeerFailed(Exception):
    """A peer that could not be installed or run: its one-line reason."""


def last_line(text: str) -> str:
    return next((line.strip() for line in reversed(text.splitlines()) if line.strip()), "no output")


def peer_python(peer: str) -> Path:
    """The python of the peer's venv, made with the project's base python from its pinned
    requirements, or remade when they (or that python) changed."""
    requirements, venv = SCRIPTS / f"{peer}.txt", VENVS / peer
    digest = hashlib.sha256(requirements.read_bytes() + sys._base_executable.encode()).hexdigest()
    stamp, python = venv / "requirements.sha256", venv / "bin" / "python"
    if stamp.exists() and stamp.read_text() == digest:
        print(f"{peer}: venv {venv} up to date")
        return python
    print(f"{peer}: installing benchmarks/peers/{requirements.name} into {venv} ...", flush=True)
    shutil.rmtree(venv, ignore_errors=True)
    pip = [str(python), "-m", "pip", "install", "--quiet", "--disable-pip-version-check", "-r",
           str(requirements)]
    for command in ([sys._base_executable, "-m", "venv", str(venv)], pip):
        done = subprocess.run(command, capture_output=True, text=True, check=False)
        if done.returncode != 0:
            raise PeerFailed(f"could not be installed ({last_line(done.stderr)})")
    stamp.write_text(digest)
    return python


def installed_peers(peers: list[str]) -> tuple[dict[str, Path], dict[str, str]]:
    """The python of each of ``peers`` that installs, and why each other one is skipped."""
    pythons, skipped = {}, {}
    for peer in peers:
        try:
            pythons[peer] = peer_python(peer)
        except PeerFailed as failure:
            skipped[peer] = str(failure)
            print(f"{peer}: {failure}; skipped")
    return pythons, skipped


@dataclass
class Inputs:
    """What ours and a peer are given at one N: the UNGM, its observations and their exact filtering
    means, the weights to resample, and the files in ``folder`` a peer script reads."""

    model: UNGM
    observations: np.ndarray
    exact_means: np.ndarray
    weights: np.ndarray
    folder: Path

    def __post_init__(self):
        np.save(self.folder / "observations.npy", self.observations)
        np.save(self.folder / "weights.npy", self.weights)

    @property
    def n(self) -> int:
        return len(self.weights)

    def file(self, resampling: bool) -> Path:
        return self.folder / ("weights.npy" if resampling else "observations.npy")

    def exact(self, resampling: bool) -> tuple[np.ndarray, float | None]:
        """The exact values of the estimates and, for a resampler, one estimate's standard error: the
        filtering means; or N sum W_i^2, the expected mean of N W_i over N indices drawn by an unbiased
        scheme, and its standard error under multinomial draws."""
        if not resampling:
            return self.exact_means, None
        n, w = self.n, self.weights
        mean = n * np.sum(w**2)
        return np.array([mean]), np.sqrt((np.sum(w * (n * w) ** 2) - mean**2) / n)


def run_script(python: Path | str, script: str, inputs: Inputs, resampling: bool, seed: int, env: dict) -> dict:
    """One call of a script of ``benchmarks/peers/`` in its own process, with ``env``: {"versions",
    "results": [{"what", "N", "seconds", "estimates"}]}."""
    n, model, out = inputs.n, inputs.model, inputs.folder / "out.json"
    command = [str(python), str(SCRIPTS / script), "--data", str(inputs.file(resampling)),
               "--n", str(n), "--seed", str(seed), "--out", str(out),
               "--model", json.dumps({"Q": model.Q, "R": model.R, "x0": model.x0, "P0": model.P0})]
    done = subprocess.run(command, capture_output=True, text=True, env=env, timeout=3600, check=False)
    if done.returncode != 0:
        raise PeerFailed(f"{script} failed at N = {n} ({last_line(done.stderr)})")
    return json.loads(out.read_text())


def interleaved(peer: str, python: Path, inputs: Inputs, rounds: int, environment: str) -> tuple[list, dict, dict]:
    """``rounds`` rounds of ours then the peer, each a plain script in ``environment``: rows of times, per
    what the estimates of ours and of the peer by round, and the peer's versions."""
    resampling, env = peer in RESAMPLING_PEERS, ENVIRONMENTS[environment]
    rows, estimates = [], {}
    for r in range(rounds):
        ours = {result["what"]: result for result in
                run_script(sys.executable, OURS[resampling], inputs, resampling, r, env)["results"]}
        output = run_script(python, PEERS[peer], inputs, resampling, r, env)
        for result in output["results"]:
            what = result["what"]
            mine = ours[what if resampling else PF_STEP]  # particles' SQMC is set against our bootstrap PF
            rows.append({"environment": environment, "peer": peer, "what": what, "N": inputs.n, "round": r,
                         "seconds": result["seconds"][0], "ours_seconds": mine["seconds"][0]})
            estimates.setdefault(what, ([], []))[0].append(mine["estimates"][0])
            estimates[what][1].append(result["estimates"][0])
    return rows, estimates, output["versions"]


def agreement(ours: np.ndarray, peer: np.ndarray, exact: np.ndarray, sd: float | None) -> dict:
    """The distance of the peer's estimates from ours (rounds x steps) against its bound (from ``sd``,
    one estimate's exact standard error, else from the spread over rounds); each side's distance
    from exact, and its RMSE against exact over the rounds and steps."""
    rounds = len(ours)
    if sd is None:
        standard_error = np.sqrt((ours.var(axis=0, ddof=1) + peer.var(axis=0, ddof=1)) / rounds)
    else:
        standard_error = np.full(ours.shape[1], np.sqrt(2 / rounds) * sd)
    distance = float(np.mean(np.abs(ours.mean(axis=0) - peer.mean(axis=0))))
    bound = BOUND_SIGMAS * float(np.mean(standard_error))
    return {"agreement": "agrees" if distance <= bound else "disagrees", "distance": distance, "bound": bound,
            "ours_from_exact": float(np.mean(np.abs(ours.mean(axis=0) - exact))),
            "peer_from_exact": float(np.mean(np.abs(peer.mean(axis=0) - exact))),
            "ours_rmse": float(np.sqrt(np.mean((ours - exact) ** 2))),
            "peer_rmse": float(np.sqrt(np.mean((peer - exact) ** 2)))}


def compare(sizes, rounds: int, peers: list[str]) -> tuple[pd.DataFrame, pd.DataFrame, dict, dict]:
    """Each of ``peers`` that runs against ours, in each environment at each N: (times per round; agreement
    per environment, peer, what and N; the peers' versions; why a peer was skipped)."""
    model = UNGM(steps=STEPS)
    observations = model.simulate(np.random.default_rng(0))[1]
    exact_means = PointMassFilter().run(model, observations).means
    pythons, skipped = installed_peers(peers)
    rows, checks, versions = [], [], {}
    with tempfile.TemporaryDirectory(prefix="peers-") as folder:
        for environment in ENVIRONMENTS:
            for n in sizes:
                weights = np.random.default_rng(n).dirichlet(np.ones(n))
                inputs = Inputs(model, observations, exact_means, weights, Path(folder))
                for peer in [p for p in PEERS if p in pythons]:
                    print(f"timing N = {n}, {environment} environment: ours against {peer}, {rounds} rounds",
                          flush=True)
                    try:
                        peer_rows, estimates, versions[peer] = interleaved(peer, pythons[peer], inputs, rounds,
                                                                           environment)
                    except (PeerFailed, subprocess.TimeoutExpired) as failure:
                        skipped[peer] = str(failure)
                        del pythons[peer]
                        print(f"{peer}: {failure}; skipped")
                        continue
                    rows += peer_rows
                    exact, sd = inputs.exact(peer in RESAMPLING_PEERS)
                    for what, (ours_estimates, peer_estimates) in estimates.items():
                        check = agreement(np.array(ours_estimates), np.array(peer_estimates), exact, sd)
                        checks.append({"environment": environment, "peer": peer, "what": what, "N": n, **check})
                        ratio = np.median([row["ours_seconds"] / row["seconds"] for row in peer_rows
                                           if row["what"] == what])
                        print(f"  {what}: {check['agreement']} (distance {check['distance']:.3g}, bound "
                              f"{check['bound']:.3g}); t_ours / t_peer median {ratio:.3g}")
    keys = ["environment", "peer", "what", "N"]
    times = pd.DataFrame(rows, columns=[*keys, "round", "seconds", "ours_seconds"])
    times["ratio"] = times["ours_seconds"] / times["seconds"]
    checks = pd.DataFrame(checks, columns=[*keys, "agreement", "distance", "bound", "ours_from_exact",
                                           "peer_from_exact", "ours_rmse", "peer_rmse"])
    return times, checks, versions, skipped


def copy_bandwidth(nbytes: int = 2 * 10**8, repeats: int = 5) -> float:
    """Bytes per second of numpy's best copy of ``nbytes`` (the bytes read plus the bytes written)."""
    source = np.ones(nbytes // 8)
    target = np.empty_like(source)
    return 2 * source.nbytes / best_of(lambda: np.copyto(target, source), repeats)


def step_bound(sizes, bandwidth: float, d: int = 1) -> pd.DataFrame:
    """Per N the two parts of a step's bound: the bytes it moves over the bandwidth, and drawing N
    normals (best of 5, from a generator made once)."""
    rng = np.random.default_rng()
    return pd.DataFrame({"N": list(sizes),
                         "bandwidth_bound_s": [8 * n * (4 * d + 4) / bandwidth for n in sizes],
                         "normal_floor_s": [best_of(lambda n=n: rng.standard_normal(n), 5)
                                            for n in sizes]})


KEYS = ["environment", "peer", "what", "N"]


def ratio_table(times: pd.DataFrame, checks: pd.DataFrame, bound: pd.DataFrame) -> pd.DataFrame:
    """Per environment, peer, what and N: the median and range of t_ours / t_peer, the agreement, the
    medians of both times; for a filter step the two parts of the bound, the floor (their larger) and our
    time over it; for SQMC the ratio at equal accuracy (t_ours / t_SQMC x (RMSE_ours / RMSE_SQMC)^2)."""
    table = times.groupby(KEYS, sort=False).agg(
        median_ratio=("ratio", "median"), min_ratio=("ratio", "min"), max_ratio=("ratio", "max"),
        ours_median_s=("ours_seconds", "median"), peer_median_s=("seconds", "median")).reset_index()
    table = table.merge(checks, on=KEYS).merge(bound, on="N", how="left")
    table.loc[table["what"].str.startswith("resample"), ["bandwidth_bound_s", "normal_floor_s"]] = np.nan
    table["floor_s"] = table[["bandwidth_bound_s", "normal_floor_s"]].max(axis=1, skipna=False)
    table["ours_over_floor"] = table["ours_median_s"] / table["floor_s"]
    accuracy = (table["ours_rmse"] / table["peer_rmse"]) ** 2
    table["equal_accuracy_ratio"] = (table["median_ratio"] * accuracy).where(table["what"] == SQMC_STEP)
    return table


def figure(times: pd.DataFrame, table: pd.DataFrame, bound: pd.DataFrame, path: Path) -> None:
    """Log-log against N, medians over rounds: seconds per step in each environment (ours, each filter
    peer, the bound's two parts) and seconds per resampling in the library's (ours and filterpy, one
    colour per scheme); a disagreeing peer is drawn with crosses and labelled so."""
    fig, axes = plt.subplots(1, len(ENVIRONMENTS) + 1, figsize=(17, 4.5))
    disagreeing = set(table.loc[table["agreement"] == "disagrees", ["environment", "peer", "what"]]
                      .itertuples(index=False))
    medians = times.groupby(KEYS, sort=False)[["seconds", "ours_seconds"]].median().reset_index()
    palette = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    colours = {f"resample ({scheme})": palette[i] for i, scheme in enumerate(RESAMPLERS)}
    resampling = axes[-1]
    for environment, steps in zip(ENVIRONMENTS, axes):
        mine = medians[medians["environment"] == environment]
        ours = mine.assign(what=mine["what"].where(mine["what"].isin(colours), PF_STEP))
        for what, line in ours.groupby(["what", "N"])["ours_seconds"].median().groupby(level="what"):
            if what in colours and environment != "library":
                continue
            (resampling if what in colours else steps).loglog(
                line.index.get_level_values("N"), line.values, "o-", color=colours.get(what, "black"),
                label=f"ours: {what}")
        for (peer, what), line in mine.groupby(["peer", "what"], sort=False):
            if what in colours and environment != "library":
                continue
            flagged = (environment, peer, what) in disagreeing
            (resampling if what in colours else steps).loglog(
                line["N"], line["seconds"], "x--" if flagged else "s:", color=colours.get(what),
                label=f"{peer}: {what}" + (" (DISAGREES)" if flagged else ""))
        steps.loglog(bound["N"], bound["bandwidth_bound_s"], "-", color="grey", lw=0.8,
                     label="bound: 8 N (4d + 4) bytes / copy bandwidth")
        steps.loglog(bound["N"], bound["normal_floor_s"], "-.", color="grey", label="bound: drawing N normals")
        steps.set_title(f"bootstrap PF step, UNGM: {environment} environment", fontsize=9)
    resampling.set_title("resampling alone: library environment", fontsize=9)
    for ax, unit in zip(axes, ["step"] * len(ENVIRONMENTS) + ["call"]):
        ax.set_xlabel("N")
        ax.set_ylabel(f"seconds per {unit} (median of rounds)")
        ax.grid(True, which="both", alpha=0.3)
        if ax.get_legend_handles_labels()[0]:  # resampling: empty when filterpy was not run
            ax.legend(fontsize=6)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def ratio_cells(table: pd.DataFrame) -> pd.DataFrame:
    """The ratios at N = 10^3 .. 10^6 as 'median [min, max]', one row per environment, peer and what; SQMC's
    labelled for what it is, with a row of its ratio at equal accuracy; and a row of our step over its floor."""
    shown = table[table["N"].isin(TABLE_SIZES)]
    cells = [f"{m:.2f} [{lo:.2f}, {hi:.2f}]" + ("" if agrees == "agrees" else " DISAGREES")
             for m, lo, hi, agrees in shown[["median_ratio", "min_ratio", "max_ratio", "agreement"]].values]
    rows = shown.assign(cell=cells)
    rows.loc[rows["what"] == SQMC_STEP, "what"] = f"{SQMC_STEP} (another algorithm), equal N"
    sqmc = shown[shown["what"] == SQMC_STEP]
    extra = [sqmc.assign(what=f"{SQMC_STEP}, equal accuracy (ours' N x (RMSE ratio)^2)",
                         cell=sqmc["equal_accuracy_ratio"].map(lambda v: f"{v:.2f}"))]
    steps = shown[shown["what"] == PF_STEP].drop_duplicates(["environment", "N"])
    extra.append(steps.assign(peer="(floor)", what="our step / its floor: max(bandwidth, N normals)",
                              cell=steps["ours_over_floor"].map(lambda v: f"{v:.2f}")))
    rows = pd.concat([rows, *extra])
    order = pd.MultiIndex.from_frame(rows[["environment", "peer", "what"]].drop_duplicates())
    wide = rows.pivot(index=["environment", "peer", "what"], columns="N", values="cell").reindex(order)
    wide.columns = [f"N = {n:,}" for n in wide.columns]
    return wide.reset_index()


def significant(table: pd.DataFrame, digits: int = 3) -> pd.DataFrame:
    """The floats as text to ``digits`` significant digits (microseconds and ratios alike), NaN as blank."""
    return table.apply(lambda column: column.map(lambda v: "" if np.isnan(v) else f"{v:.{digits}g}")
                       if column.dtype.kind == "f" else column)


def page(table: pd.DataFrame, versions: dict, skipped: dict, rounds: int, bandwidth: float, load: str) -> str:
    peers = "; ".join([f"{peer} (" + ", ".join(f"{name} {v}" for name, v in found.items()) + ")"
                       for peer, found in versions.items()]
                      + [f"{peer} {why}, skipped" for peer, why in skipped.items()])
    return render(
        "sections.html.j2",
        title="Benchmark: our bootstrap PF and resamplers against peer libraries",
        up="index.html",
        up_label="benchmark",
        meta=f"Machine: {platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}, "
        f"numpy {np.__version__}; peers, each in its own venv: {peers}. UNGM, T = {STEPS}; {rounds} "
        "interleaved rounds (ours, peer, ours, peer, ...) per N, each side a plain script in a process of its "
        "own, in two environments: library (the defaults a user's script gets) and runner (the experiments': "
        "one BLAS thread, glibc's raised allocator thresholds); ratio = t_ours / t_peer (below 1: ours is "
        f"faster). Copy bandwidth {bandwidth / 1e9:.2f} GB/s (read + written); load average when it started "
        f"{load}. Made by make benchmark (benchmarks/peers.py).",
        sections=[
            {"title": "t_ours / t_peer over the rounds: median [min, max] (DISAGREES: the peer's estimates "
                      "are beyond Monte Carlo error of ours, its times are not comparable); SQMC, a quasi-Monte "
                      "Carlo filter far more accurate at equal N, also at equal accuracy; our step over its floor",
             "figure": None, "table": html_table(ratio_cells(table))},
            {"title": "Time against N: ours, the peers, and the step's bound (memory bandwidth, random "
                      "numbers)",
             "figure": "peers.png", "table": ""},
            {"title": "Per environment, peer and N: the ratios, the agreement (distance against its bound; each "
                      "side's distance from exact and RMSE against it), the median times, the bound's two parts "
                      "and the floor (seconds)",
             "figure": None, "table": html_table(significant(table))},
        ],
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--max-n", type=int, default=SIZES[-1], help="the largest N (less for a quick check)")
    parser.add_argument("--min-n", type=int, default=SIZES[0], help="the smallest N")
    parser.add_argument("--peer", action="append", choices=list(PEERS), help="only these peers (repeatable)")
    parser.add_argument("--rounds", type=int, default=5, help="A B rounds per peer and N (at least 2)")
    args = parser.parse_args()
    if args.rounds < 2:
        parser.error("--rounds must be at least 2 (the agreement bound needs their spread)")
    retain_freed_memory()  # for the floor measured here; each side's own process gets its environment's
    load = "{:.2f} {:.2f} {:.2f}".format(*os.getloadavg())
    out = resolve("reports") / "benchmark"
    out.mkdir(parents=True, exist_ok=True)
    sizes = [n for n in SIZES if args.min_n <= n <= args.max_n]
    print("measuring the copy bandwidth and the time of N normals", flush=True)
    bandwidth = copy_bandwidth()
    bound = step_bound(sizes, bandwidth)
    times, checks, versions, skipped = compare(sizes, args.rounds, args.peer or list(PEERS))
    table = ratio_table(times, checks, bound)
    times.to_csv(out / "peers.csv", index=False)
    table.to_csv(out / "peers_ratios.csv", index=False)
    figure(times, table, bound, out / "peers.png")
    (out / "peers.html").write_text(page(table, versions, skipped, args.rounds, bandwidth, load))
    with pd.option_context("display.width", 250, "display.max_columns", 30, "display.max_colwidth", 60):
        print(table.to_string(index=False, float_format="%.3g"), end="\n\n")
        print(ratio_cells(table).to_string(index=False))
    print(f"copy bandwidth {bandwidth / 1e9:.2f} GB/s (read + written); load average at the start {load}, at the "
          "end {:.2f} {:.2f} {:.2f}; written to {}: peers.csv, peers_ratios.csv, peers.png, peers.html".format(
              *os.getloadavg(), out))


if __name__ == "__main__":
    main()
