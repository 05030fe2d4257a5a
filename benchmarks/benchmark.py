"""``make benchmark`` (``python benchmarks/benchmark.py --instructions``): what the core costs on this machine
(``make replicate`` runs it without ``--instructions``: the counts under valgrind take minutes).

1. The colour likelihood: particles per second for N = 10, 100, 1000 boxes of
   40 x 40 px on a 480 x 410 frame, our compiled kernel histograms (every
   pixel, and 100 sampled pixels) against a per-particle loop of
   ``cv2.calcHist`` (unweighted: cheaper than the kernel histogram it stands
   for), the vectorised numpy path the kernel replaced, and a per-particle
   loop of the same kernel histogram.
2. Resampling and a bootstrap PF step on the UNGM, N = 10^2 .. 10^6 (against
   ``particles``, Stone Soup and filterpy, each in its own venv, in the
   library's and the runner's environment: ``benchmarks/peers.py``, the
   second half of ``make benchmark``).
3. Rendering a 480 x 410 synthetic frame with 36 targets.
4. BIS-PF on 36 balls (N = 400, K = 4000), one process: frames per second
   against the paper's 5.52, a profile of where the time goes, and its time
   per frame against the number of targets M (the paper claims O(M)).
6. With ``--profiles`` (``make benchmark``): where a paper-scale run's time goes in the three
   experiments that cost the shipped record the most CPU, each method profiled on its recorded run of
   median time (``profile_run.py --record``'s profiles, which ``make record`` writes into the record):
   its time by part of the run (frames, likelihood, filter, scoring, the rest) and by library, and its
   costliest functions.
5. Issue 34's two ratios, each measured ROUNDS times in this run (median and
   range): the likelihood against the calcHist loop at N = 1000, the two
   timed in turn (>= 15), and BIS-PF against the paper's frame rate (>= 15);
   beside them the likelihood's instructions per particle, ours and the
   loop's, counted by ``valgrind --tool=callgrind`` (the same whatever the
   load). The PF step's ratios against its peers are ``peers.py``'s.

Everything here is timed in this process, in the runner's environment: one
BLAS thread, as in the experiments' workers (joblib's loky limits each worker
to cpu_count // n_jobs threads: one on this two-core machine), and glibc's
raised allocator thresholds (``replication/runner/memory.py``).  The PF step
as a library user calls it, from a plain script with the defaults, is timed
by ``peers.py`` in both environments (a step calls no BLAS: its sums are
compiled, ``replication/smc/weights.py``).

Writes ``reports/benchmark/`` (CSV, figures, a page the report index links).
A script, not a test: timings depend on the machine and its load.
"""

import os

for _variable in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):  # before numpy loads BLAS
    os.environ.setdefault(_variable, "1")

import platform  # noqa: E402
from pathlib import Path  # noqa: E402
import re  # noqa: E402
import shutil  # noqa: E402
import subprocess  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402

import cv2  # noqa: E402
import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
from markupsafe import Markup  # noqa: E402

from replication import PointMassFilter, bootstrap  # noqa: E402
from replication.evidence.scorecard import Scorecard  # noqa: E402
from replication.models import UNGM  # noqa: E402
from replication.paths import resolve  # noqa: E402
from replication.report.pages.index import write_index  # noqa: E402
from replication.report.pages.render import html_table, render  # noqa: E402
from replication.runner.memory import retain_freed_memory  # noqa: E402
from profile_run import slowest_profiles  # noqa: E402  (benchmarks/: the script's own folder)
from replication.scenes import SyntheticScene  # noqa: E402
from replication.smc.resampling import RESAMPLERS  # noqa: E402
from replication.vision.colour import ColourLikelihood  # noqa: E402
from replication.vision.histogram import ColourHistogram  # noqa: E402
from likelihood_sides import BINS, CALCHIST, OURS, calchist, scene_frame, scored  # noqa: E402
from timing import best_of  # noqa: E402

PF_STEP = "bootstrap PF step (UNGM)"
PAPER_FPS = 5.52  # bis_pf, Table 1: BIS-PF on the 36 balls, 1.4 GHz Pentium 4
ROUNDS = 5  # each ratio measured this many times in one run: its median and range are reported
SIDES = Path(__file__).with_name("likelihood_sides.py")  # the child instructions() counts under callgrind


def likelihood_throughput() -> pd.DataFrame:
    rng = np.random.default_rng(0)
    frame, box = scene_frame()
    hsv = cv2.cvtColor(frame, cv2.COLOR_BGR2HSV)
    rows = []
    for n in (10, 100, 1000):
        boxes = box + np.column_stack([rng.normal(0, 8, (n, 2)), np.zeros((n, 2))])
        for name, histogram in (
            (OURS, ColourHistogram(BINS, grid=(40, 40))),
            ("compiled kernel, 100 sampled pixels", ColourHistogram(BINS, samples=100, rng=rng)),
        ):
            likelihood = ColourLikelihood.from_frame(frame, box, histogram, sigma=0.1)
            prepared = likelihood.prepare(frame)  # once per frame, whatever N: timed on its own below
            likelihood.log_likelihood(boxes, prepared)  # numba loads the compiled kernel on the first call
            seconds = best_of(lambda: likelihood.log_likelihood(boxes, prepared), repeats=9)
            rows.append({"method": name, "N": n, "seconds": seconds})
        seconds = best_of(lambda: [calchist(hsv, b) for b in boxes], repeats=5)
        rows.append({"method": CALCHIST, "N": n, "seconds": seconds})
        kernel = ColourHistogram(BINS, grid=(40, 40))
        likelihood = ColourLikelihood.from_frame(frame, box, kernel, 0.1)
        bin_image = likelihood.prepare(frame)
        seconds = best_of(lambda: kernel.bhattacharyya_numpy(bin_image, boxes, likelihood.reference))
        rows.append({"method": "vectorised numpy (cv2.remap + bincount: before issue 18), all 40x40 pixels", "N": n,
                     "seconds": seconds})
        seconds = best_of(lambda: [kernel.of_boxes(bin_image, b[None]) for b in boxes], repeats=3)
        rows.append({"method": "per-particle loop of the same kernel histogram", "N": n, "seconds": seconds})
    likelihood = ColourLikelihood.from_frame(frame, box, ColourHistogram(BINS), sigma=0.1)
    rows.append({"method": "per frame: HSV bin image (once, any N)", "N": 1, "seconds": best_of(lambda: likelihood.prepare(frame))})
    rows.append({"method": "per frame: cv2.cvtColor to HSV (baseline's share)", "N": 1,
                 "seconds": best_of(lambda: cv2.cvtColor(frame, cv2.COLOR_BGR2HSV))})
    table = pd.DataFrame(rows)
    table["particles_per_s"] = table["N"] / table["seconds"]
    return table


def likelihood_rounds(n: int = 1000, rounds: int = ROUNDS) -> pd.DataFrame:
    """The likelihood ratio timed in turn, A B A B: in each round ours (best of 3 calls), then the calcHist
    loop (best of 3), so that a change of load falls on both sides of a round's ratio."""
    sides = scored(n, np.random.default_rng(0))
    sides[OURS]()  # numba loads the compiled kernel on the first call
    rows = []
    for round_ in range(rounds):
        ours, theirs = (best_of(sides[name], repeats=3) for name in (OURS, CALCHIST))
        rows.append({"round": round_, "N": n, "ours_s": ours, "calchist_s": theirs, "ratio": theirs / ours,
                     "load_1m": os.getloadavg()[0]})
    return pd.DataFrame(rows)


def instructions(n: int = 1000, calls: int = 3) -> pd.DataFrame:
    """Instructions per particle of each side of the likelihood ratio, counted by ``valgrind --tool=callgrind``
    (the same count run after run, whatever the load): each side in a child process that prepares the
    inputs and calls it ``calls`` times, and again ``2 calls`` times; the difference over ``calls n`` is
    the count per particle, everything else (Python, imports, the first call's kernel load) cancelling.

    Numba compiles its kernels for the CPU it finds, and valgrind presents another (fewer features: no
    AVX-512, ...); compiled under valgrind, the kernels took a fresh clone about 20 minutes.  So the CPU
    LLVM finds under valgrind is read first (a child that imports llvmlite alone), the kernels are
    compiled for it natively (``NUMBA_CPU_NAME`` and ``NUMBA_CPU_FEATURES``: numba's cache is keyed by
    them) and the counted children load them from numba's cache."""
    valgrind = shutil.which("valgrind")
    if valgrind is None:
        return pd.DataFrame([{"side": "valgrind not found: no instruction counts", "instructions_per_particle": np.nan}])
    probe = subprocess.run([valgrind, "--tool=none", "-q", sys.executable, "-c",
                            "import llvmlite.binding as ll; print(ll.get_host_cpu_name()); "
                            "print(ll.get_host_cpu_features().flatten())"],
                           capture_output=True, text=True, check=True)
    name, features = probe.stdout.split()[-2:]
    env = {**os.environ, "PYTHONHASHSEED": "0", "NUMBA_CPU_NAME": name, "NUMBA_CPU_FEATURES": features}
    subprocess.run([sys.executable, str(SIDES), OURS, str(n), "0"], check=True, env=env)  # compiled natively

    def counted(side: str, times: int) -> int:
        done = subprocess.run([valgrind, "--tool=callgrind", "--callgrind-out-file=/dev/null", sys.executable,
                               str(SIDES), side, str(n), str(times)], capture_output=True, text=True, check=True, env=env)
        return int(re.search(r"Collected : (\d+)", done.stderr).group(1))

    rows = []
    for side in (OURS, CALCHIST):
        few, more = counted(side, calls), counted(side, 2 * calls)
        rows.append({"side": side, "N": n, "instructions_per_particle": (more - few) / (calls * n)})
    table = pd.DataFrame(rows)
    table.attrs["ratio"] = table["instructions_per_particle"].iloc[1] / table["instructions_per_particle"].iloc[0]
    table.attrs["cpu"] = name
    return table


def smc_core() -> pd.DataFrame:
    rng = np.random.default_rng(0)
    model = UNGM(steps=20)
    observations = model.simulate(rng)[1]
    rows = []
    for n in (100, 1_000, 10_000, 100_000, 1_000_000):
        weights = rng.dirichlet(np.ones(n))
        for scheme, resample in RESAMPLERS.items():
            rows.append({"what": f"resample ({scheme})", "N": n, "us_per_call": 1e6 * best_of(lambda: resample(weights, rng))})
        pf = bootstrap(n, "systematic", 1.0)
        pf.run(model, observations[:1], rng)  # the compiled resampler's first call
        seconds = best_of(lambda: pf.run(model, observations, rng), repeats=5) / model.steps
        rows.append({"what": PF_STEP, "N": n, "us_per_call": 1e6 * seconds})
    for points in (801, 1601, 3201):
        seconds = best_of(lambda: PointMassFilter(points).run(model, observations), repeats=3) / model.steps
        rows.append({"what": "point-mass filter step (UNGM)", "N": points, "us_per_call": 1e6 * seconds})
    return pd.DataFrame(rows)


def rendering() -> pd.DataFrame:
    targets = [{"shape": "ball", "size": [20, 20], "colour": [40, 200, 220], "depth": i,
                "motion": {"kind": "random_walk", "noise_var": 0.4, "max_speed": 2}} for i in range(36)]
    scene = SyntheticScene({"size": [480, 410], "frames": 50, "seed": 1, "camera_noise": 2.0,
                            "background": {"kind": "noise", "colour": [60, 120, 60]}, "targets": targets})
    seconds = best_of(lambda: [scene.render(k) for k in range(50)], repeats=3) / 50  # not the kept frames
    return pd.DataFrame([{"scene": "480x410, 36 targets, camera noise", "ms_per_frame": 1e3 * seconds,
                          "ms_per_target": 1e3 * seconds / 36}])



def bis_pf_36() -> tuple[pd.DataFrame, pd.DataFrame, pd.DataFrame]:
    """BIS-PF's frame rate on the bis_pf 36-ball scene, its profile by function, and its time per
    frame against the number of targets M (with a least-squares line and the log-log slope)."""
    import cProfile
    import pstats

    from omegaconf import OmegaConf

    from replication.filters.bis import BISPF
    from replication.paths import CONF_DIR
    from replication.runner.config import at_scale
    from replication.scenes.factory import build_sequence
    from replication.tasks.tracking import build_model

    experiment = at_scale(OmegaConf.to_container(OmegaConf.load(CONF_DIR / "experiment" / "bis_pf.yaml")), "quick")
    scene = build_sequence(experiment["scenes"]["exp3_36_targets"])
    frames = [scene.frame(k) for k in range(1, 42)]

    class Run:  # what build_model reads of a run
        model = {**experiment["model"], "scene_spec": experiment["scenes"]["exp3_36_targets"]}

        @staticmethod
        def rng(stream):
            return np.random.default_rng(0)

    cache: dict = {}
    models = [build_model(Run, scene, m, cache) for m in range(36)]
    bis = BISPF(n_particles=400, n_joint=4000, beta=4.0)
    state = bis.start(models, np.random.default_rng(1))
    bis.step(state, frames[0])  # numba loads the compiled kernels on the first frame: not timed
    fps, loads = [], []
    for _ in range(ROUNDS):  # the same 20 frames again from the same start: ROUNDS measures of one thing
        state = bis.start(models, np.random.default_rng(1))
        bis.step(state, frames[0])
        started = time.perf_counter()
        for frame in frames[1:21]:
            bis.step(state, frame)
        fps.append(20 / (time.perf_counter() - started))
        loads.append(os.getloadavg()[0])
    profile = cProfile.Profile()
    profile.enable()
    for frame in frames[21:]:
        bis.step(state, frame)
    profile.disable()
    stats = pstats.Stats(profile).stats
    rows = sorted(
        ({"function": f"{name[2]} ({name[0].rsplit('/', 1)[-1]}:{name[1]})", "seconds (self)": tt, "calls": nc}
         for name, (cc, nc, tt, ct, callers) in stats.items()),
        key=lambda r: -r["seconds (self)"],
    )[:12]
    scaling = []
    for m in (4, 9, 16, 25, 36):  # the first M balls, the same frames
        state = bis.start(models[:m], np.random.default_rng(1))
        bis.step(state, frames[0])
        started = time.perf_counter()
        for frame in frames[1:11]:
            bis.step(state, frame)
        scaling.append({"M": m, "ms_per_frame": 1e3 * (time.perf_counter() - started) / 10})
    scaling = pd.DataFrame(scaling)
    slope, intercept = np.polyfit(scaling["M"], scaling["ms_per_frame"], 1)
    log_slope = np.polyfit(np.log(scaling["M"]), np.log(scaling["ms_per_frame"]), 1)[0]
    scaling["linear_fit_ms"] = intercept + slope * scaling["M"]
    scaling.attrs.update(slope=slope, intercept=intercept, log_slope=log_slope)
    speed = pd.DataFrame([{"scene": "36 balls, 480x410", "N": 400, "K": 4000, "round": i, "frames_per_s": f,
                           "paper_frames_per_s": PAPER_FPS, "load_1m": load} for i, (f, load) in enumerate(zip(fps, loads))])
    return speed, pd.DataFrame(rows), scaling


def _loglog(table, x, y, group, path, ylabel):
    fig, ax = plt.subplots(figsize=(6.5, 4))
    for name, rows in table.groupby(group, sort=False):
        ax.loglog(rows[x], rows[y], marker="o", label=name)
    ax.set_xlabel(x)
    ax.set_ylabel(ylabel)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def ratios(rounds: pd.DataFrame, bis_speed: pd.DataFrame, counted: pd.DataFrame) -> pd.DataFrame:
    """Issue 34's targets for the likelihood and BIS-PF: each ratio in one run, ROUNDS times, median and range
    (met when the median reaches the target); and the likelihood's instructions per particle (load-free)."""
    speedup = bis_speed["frames_per_s"] / PAPER_FPS
    rows = [
        {"ratio": "colour likelihood, N = 1000, every pixel of 40x40 kernel-weighted: speed / per-particle "
                  "cv2.calcHist loop (timed in turn)",
         "median": rounds["ratio"].median(), "min": rounds["ratio"].min(), "max": rounds["ratio"].max(),
         "target": ">= 15", "met": rounds["ratio"].median() >= 15,
         "ours": f"{1e3 * rounds['ours_s'].median():.2f} ms", "peer": f"{1e3 * rounds['calchist_s'].median():.2f} ms",
         "load_1m": _load_range(rounds)},
        {"ratio": "BIS-PF on the 36 balls (N = 400, K = 4000): frames/s / the paper's",
         "median": speedup.median(), "min": speedup.min(), "max": speedup.max(), "target": ">= 15",
         "met": speedup.median() >= 15, "ours": f"{bis_speed['frames_per_s'].median():.1f} frames/s",
         "peer": f"{PAPER_FPS} frames/s (bis_pf Table 1, 1.4 GHz Pentium 4)", "load_1m": _load_range(bis_speed)},
    ]
    if "ratio" in counted.attrs:
        per = counted.set_index("side")["instructions_per_particle"]
        rows.append({"ratio": "colour likelihood, N = 1000: instructions per particle of the calcHist loop / ours "
                              "(valgrind callgrind: the same whatever the load)",
                     "median": counted.attrs["ratio"], "min": counted.attrs["ratio"], "max": counted.attrs["ratio"],
                     "target": "-", "met": None, "ours": f"{per[OURS]:,.0f}", "peer": f"{per[CALCHIST]:,.0f}",
                     "load_1m": "any (a count)"})
    return pd.DataFrame(rows)


def _load_range(rounds: pd.DataFrame) -> str:
    """The machine's one-minute load over a ratio's rounds, median (min-max): beside every timed figure, since
    the same ratio reads differently on a loaded machine."""
    load = rounds["load_1m"]
    return f"{load.median():.2f} ({load.min():.2f}-{load.max():.2f})"


def throughput_plot(likelihood: pd.DataFrame, core: pd.DataFrame, path) -> None:
    """Particles per second against N: the likelihood and its peers, and the PF step (its peers: peers.py)."""
    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    per_particle = likelihood[~likelihood["method"].str.startswith("per frame")]
    steps = core[core["what"] == PF_STEP].assign(particles_per_s=lambda t: t["N"] / (t["us_per_call"] / 1e6))
    for ax, table, group, title in ((axes[0], per_particle, "method", "colour likelihood (40x40 boxes)"),
                                    (axes[1], steps, "what", "bootstrap PF step (UNGM)")):
        for name, rows in table.groupby(group, sort=False):
            ax.loglog(rows["N"], rows["particles_per_s"], marker="o", label=name)
        ax.set_xlabel("N")
        ax.set_ylabel("particles per second")
        ax.set_title(title, fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=6)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def scaling_plot(scaling: pd.DataFrame, path) -> None:
    fig, ax = plt.subplots(figsize=(6.5, 4))
    ax.plot(scaling["M"], scaling["ms_per_frame"], "o", label="BIS-PF, measured")
    ax.plot(scaling["M"], scaling["linear_fit_ms"], "-",
            label=f"least squares: {scaling.attrs['intercept']:.2f} + {scaling.attrs['slope']:.3f} M ms "
                  f"(log-log slope {scaling.attrs['log_slope']:.2f})")
    ax.set_xlabel("targets M (N = 400, K = 4000)")
    ax.set_ylabel("ms per frame")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main() -> None:
    retain_freed_memory()  # as every experiment's run does
    out = resolve("reports") / "benchmark"
    out.mkdir(parents=True, exist_ok=True)
    likelihood, core, render_cost = likelihood_throughput(), smc_core(), rendering()
    rounds = likelihood_rounds()
    counted = instructions() if "--instructions" in sys.argv[1:] else pd.DataFrame(
        [{"side": "not counted in this run (make benchmark counts them: benchmark.py --instructions: about 11 CPU-minutes, mostly Python under valgrind)",
          "instructions_per_particle": np.nan}])
    bis_speed, bis_profile, bis_scaling = bis_pf_36()
    summary = ratios(rounds, bis_speed, counted)
    profiles = slowest_profiles(resolve("record")) if "--profiles" in sys.argv[1:] and resolve("record").is_dir() \
        else pd.DataFrame([{"experiment": "not profiled in this run (make benchmark profiles them: benchmark.py "
                                          "--profiles, about 2 min)"}])
    for name, table in (("likelihood", likelihood), ("likelihood_rounds", rounds), ("instructions", counted),
                        ("smc_core", core), ("rendering", render_cost), ("bis_pf_speed", bis_speed),
                        ("bis_pf_profile", bis_profile), ("bis_pf_scaling", bis_scaling), ("ratios", summary),
                        ("profiles", profiles)):
        table.to_csv(out / f"{name}.csv", index=False)
        print(table.to_string(index=False), end="\n\n")
    print(f"BIS-PF time per frame against M: slope {bis_scaling.attrs['slope']:.3f} ms per target, "
          f"log-log slope {bis_scaling.attrs['log_slope']:.2f} (O(M): 1)\n")
    per_particle = likelihood[~likelihood["method"].str.startswith("per frame")]
    _loglog(per_particle, "N", "particles_per_s", "method", out / "likelihood.png", "particles per second")
    _loglog(core, "N", "us_per_call", "what", out / "smc_core.png", "µs per call (best of repeats)")
    throughput_plot(likelihood, core, out / "throughput.png")
    scaling_plot(bis_scaling, out / "bis_pf_scaling.png")
    (out / "index.html").write_text(
        render(
            "sections.html.j2",
            title="Benchmark: cost of the likelihood, the SMC core and scene rendering",
            up="../index.html",
            up_label="all experiments",
            meta=f"Machine: {platform.machine()}, {os.cpu_count()} cores, Python {platform.python_version()}, "
            f"numpy {np.__version__}, OpenCV {cv2.__version__}. Best of several calls, single process, in the runner's "
            "environment (one BLAS thread and glibc's raised allocator thresholds, as the experiments' workers; the "
            "PF step from a plain script with the defaults: the peers' page). Made by make benchmark.",
            sections=[
                {"title": f"Issue 34's ratios: each measured {ROUNDS} times in this run (median and range; the "
                          "likelihood timed in turn with its peer, A B A B), and the likelihood's instructions per "
                          "particle, which load does not move",
                 "figure": None, "table": html_table(summary.round(2))},
                {"title": "The likelihood ratio, round by round (N = 1000)", "figure": None,
                 "table": html_table(rounds.round(6))},
                {"title": "Instructions per particle (valgrind --tool=callgrind, N = 1000)", "figure": None,
                 "table": html_table(counted.round(1))},
                {"title": "The PF step and the resamplers against particles, Stone Soup and filterpy",
                 "figure": None,
                 "table": Markup('<p><a href="peers.html">each peer in its own venv, timed in turn with ours</a></p>')
                 if (out / "peers.html").exists() else
                 Markup("<p>Not measured on this machine yet: <code>make benchmark</code> installs the peers and times "
                        "them (<code>benchmarks/peers.py</code>).</p>")},
                {"title": "Throughput against N: ours and the peers (particles per second)",
                 "figure": "throughput.png", "table": ""},
                {"title": "Colour likelihood throughput (480x410 frame, 40x40 boxes, 8x8x4 bins)",
                 "figure": "likelihood.png", "table": html_table(likelihood.round(5))},
                {"title": "SMC core, in the runner's environment (from a plain script: the peers' page)", "figure": "smc_core.png", "table": html_table(core.round(2))},
                {"title": "Scene rendering", "figure": None, "table": html_table(render_cost.round(3))},
                {"title": "BIS-PF on 36 balls (N = 400, K = 4000), one process: frames per second",
                 "figure": None, "table": html_table(bis_speed.round(2))},
                {"title": f"BIS-PF time per frame against the number of targets M: "
                          f"{bis_scaling.attrs['slope']:.3f} ms per target, log-log slope "
                          f"{bis_scaling.attrs['log_slope']:.2f} (the paper's O(M): 1)",
                 "figure": "bis_pf_scaling.png", "table": html_table(bis_scaling.round(3))},
                {"title": "BIS-PF profile over 20 frames: where the time goes (self time per function)",
                 "figure": None, "table": html_table(bis_profile.round(4))},
                {"title": "Where a paper-scale run's time goes: the three experiments that cost the shipped record "
                          "the most CPU, each method on its recorded run of median time, under cProfile (whose "
                          "overhead is per Python call: shares of code making many small calls read high)",
                 "figure": None, "table": html_table(profiles.round(3))},
            ],
        )
    )
    print(f"written to {out}; index: {write_index(out.parent, Scorecard.read(out.parent))}")


if __name__ == "__main__":
    main()
