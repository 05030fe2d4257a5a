"""``make benchmark`` (``python benchmarks/benchmark.py``): what the core costs on this machine.

1. The colour likelihood: particles per second for N = 10, 100, 1000 boxes of
   40 x 40 px on a 480 x 410 frame, our one-call vectorised histograms against
   a per-particle loop of ``cv2.calcHist`` (unweighted: cheaper than the kernel
   histogram it stands for) and a per-particle numpy loop of the same kernel histogram.
2. Resampling and a bootstrap PF step on the UNGM, N = 10^2 .. 10^6.
3. Rendering a 480 x 410 synthetic frame with 36 targets.
4. BIS-PF on 36 balls (N = 400, K = 4000), one process: frames per second
   against the paper's 5.52, and a profile of where the time goes.

Writes ``reports/benchmark/`` (CSV, figures, a page the report index links).
A script, not a test: timings depend on the machine and its load.
"""

import platform
import time

import cv2
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
from replication.runner.memory import retain_freed_memory  # noqa: E402
from replication.scenes import SyntheticScene  # noqa: E402
from replication.smc.resampling import RESAMPLERS  # noqa: E402
from replication.vision.colour import ColourLikelihood  # noqa: E402
from replication.vision.histogram import ColourHistogram  # noqa: E402

BINS = (8, 8, 4)


def best_of(call, repeats: int = 5) -> float:
    """Seconds of the fastest of ``repeats`` calls (the least disturbed by the rest of the machine)."""
    times = []
    for _ in range(repeats):
        started = time.perf_counter()
        call()
        times.append(time.perf_counter() - started)
    return min(times)


def likelihood_throughput() -> pd.DataFrame:
    rng = np.random.default_rng(0)
    scene = SyntheticScene(
        {"size": [480, 410], "frames": 1, "background": {"kind": "noise", "colour": [90, 120, 90]},
         "targets": [{"shape": "ball", "size": [40, 40], "colour": [40, 60, 200],
                      "motion": {"kind": "scripted", "keyframes": [[0, 240, 205]]}}]}
    )
    frame, box = scene.frame(0), np.array([240.0, 205.0, 40.0, 40.0])
    hsv = cv2.cvtColor(frame, cv2.COLOR_BGR2HSV)
    rows = []
    for n in (10, 100, 1000):
        boxes = box + np.column_stack([rng.normal(0, 8, (n, 2)), np.zeros((n, 2))])
        for name, histogram in (
            ("vectorised, all 40x40 pixels", ColourHistogram(BINS, grid=(40, 40))),
            ("vectorised, 100 sampled pixels", ColourHistogram(BINS, samples=100, rng=rng)),
        ):
            likelihood = ColourLikelihood.from_frame(frame, box, histogram, sigma=0.1)
            prepared = likelihood.prepare(frame)  # once per frame, whatever N: timed on its own below
            seconds = best_of(lambda: likelihood.log_likelihood(boxes, prepared))
            rows.append({"method": name, "N": n, "seconds": seconds})
        seconds = best_of(lambda: [_calchist(hsv, b) for b in boxes], repeats=3)
        rows.append({"method": "per-particle cv2.calcHist loop (no kernel)", "N": n, "seconds": seconds})
        kernel = ColourHistogram(BINS, grid=(40, 40))
        bin_image = ColourLikelihood.from_frame(frame, box, kernel, 0.1).prepare(frame)
        seconds = best_of(lambda: [kernel.of_boxes(bin_image, b[None]) for b in boxes], repeats=3)
        rows.append({"method": "per-particle loop of the same kernel histogram", "N": n, "seconds": seconds})
    likelihood = ColourLikelihood.from_frame(frame, box, ColourHistogram(BINS), sigma=0.1)
    rows.append({"method": "per frame: HSV bin image (once, any N)", "N": 1, "seconds": best_of(lambda: likelihood.prepare(frame))})
    rows.append({"method": "per frame: cv2.cvtColor to HSV (baseline's share)", "N": 1,
                 "seconds": best_of(lambda: cv2.cvtColor(frame, cv2.COLOR_BGR2HSV))})
    table = pd.DataFrame(rows)
    table["particles_per_s"] = table["N"] / table["seconds"]
    return table


def _calchist(hsv, box):
    cx, cy, w, h = box
    x0, y0 = int(cx - w / 2), int(cy - h / 2)
    roi = hsv[max(y0, 0) : y0 + int(h), max(x0, 0) : x0 + int(w)]
    return cv2.calcHist([roi], [0, 1, 2], None, list(BINS), [0, 180, 0, 256, 0, 256])


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
        seconds = best_of(lambda: pf.run(model, observations, rng), repeats=3) / model.steps
        rows.append({"what": "bootstrap PF step (UNGM)", "N": n, "us_per_call": 1e6 * seconds})
    for points in (801, 1601, 3201):
        seconds = best_of(lambda: PointMassFilter(points).run(model, observations), repeats=3) / model.steps
        rows.append({"what": "point-mass filter step (UNGM)", "N": points, "us_per_call": 1e6 * seconds})
    return pd.DataFrame(rows)


def rendering() -> pd.DataFrame:
    targets = [{"shape": "ball", "size": [20, 20], "colour": [40, 200, 220], "depth": i,
                "motion": {"kind": "random_walk", "noise_var": 0.4, "max_speed": 2}} for i in range(36)]
    scene = SyntheticScene({"size": [480, 410], "frames": 50, "seed": 1, "camera_noise": 2.0,
                            "background": {"kind": "noise", "colour": [60, 120, 60]}, "targets": targets})
    seconds = best_of(lambda: [scene.frame(k) for k in range(50)], repeats=3) / 50
    return pd.DataFrame([{"scene": "480x410, 36 targets, camera noise", "ms_per_frame": 1e3 * seconds,
                          "ms_per_target": 1e3 * seconds / 36}])


def bis_pf_36() -> tuple[pd.DataFrame, pd.DataFrame]:
    """BIS-PF's frame rate on the bis_pf 36-ball scene, and its profile by function."""
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
    frames = [scene.frame(k) for k in range(1, 41)]

    class Run:  # what build_model reads of a run
        model = {**experiment["model"], "scene_spec": experiment["scenes"]["exp3_36_targets"]}

        @staticmethod
        def rng(stream):
            return np.random.default_rng(0)

    cache: dict = {}
    models = [build_model(Run, scene, m, cache) for m in range(36)]
    bis = BISPF(n_particles=400, n_joint=4000, beta=4.0)
    state = bis.start(models, np.random.default_rng(1))
    started = time.perf_counter()
    for frame in frames[:20]:
        bis.step(state, frame)
    fps = 20 / (time.perf_counter() - started)
    profile = cProfile.Profile()
    profile.enable()
    for frame in frames[20:]:
        bis.step(state, frame)
    profile.disable()
    stats = pstats.Stats(profile).stats
    rows = sorted(
        ({"function": f"{name[2]} ({name[0].rsplit('/', 1)[-1]}:{name[1]})", "seconds (self)": tt, "calls": nc}
         for name, (cc, nc, tt, ct, callers) in stats.items()),
        key=lambda r: -r["seconds (self)"],
    )[:12]
    speed = pd.DataFrame([{"scene": "36 balls, 480x410", "N": 400, "K": 4000, "frames_per_s": fps, "paper_frames_per_s": 5.52}])
    return speed, pd.DataFrame(rows)


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


def main() -> None:
    retain_freed_memory()  # as every experiment's run does
    out = resolve("reports") / "benchmark"
    out.mkdir(parents=True, exist_ok=True)
    likelihood, core, render_cost = likelihood_throughput(), smc_core(), rendering()
    bis_speed, bis_profile = bis_pf_36()
    for name, table in (("likelihood", likelihood), ("smc_core", core), ("rendering", render_cost),
                        ("bis_pf_speed", bis_speed), ("bis_pf_profile", bis_profile)):
        table.to_csv(out / f"{name}.csv", index=False)
        print(table.to_string(index=False), end="\n\n")
    per_particle = likelihood[~likelihood["method"].str.startswith("per frame")]
    _loglog(per_particle, "N", "particles_per_s", "method", out / "likelihood.png", "particles per second")
    _loglog(core, "N", "us_per_call", "what", out / "smc_core.png", "µs per call (best of repeats)")
    (out / "index.html").write_text(
        render(
            "sections.html.j2",
            title="Benchmark: cost of the likelihood, the SMC core and scene rendering",
            up="../index.html",
            up_label="all experiments",
            meta=f"Machine: {platform.machine()}, Python {platform.python_version()}, numpy {np.__version__}, "
            f"OpenCV {cv2.__version__}. Best of several calls, single process. Made by make benchmark.",
            sections=[
                {"title": "Colour likelihood throughput (480x410 frame, 40x40 boxes, 8x8x4 bins)",
                 "figure": "likelihood.png", "table": html_table(likelihood.round(5))},
                {"title": "SMC core", "figure": "smc_core.png", "table": html_table(core.round(2))},
                {"title": "Scene rendering", "figure": None, "table": html_table(render_cost.round(3))},
                {"title": "BIS-PF on 36 balls (N = 400, K = 4000), one process: frames per second",
                 "figure": None, "table": html_table(bis_speed.round(2))},
                {"title": "BIS-PF profile over 20 frames: where the time goes (self time per function)",
                 "figure": None, "table": html_table(bis_profile.round(4))},
            ],
        )
    )
    print(f"written to {out}; index: {write_index(out.parent)}")


if __name__ == "__main__":
    main()
