"""Where one run's time goes: ``python benchmarks/profile_run.py EXPERIMENT METHOD [TEXT] [--scale paper]``.

Profiles (``cProfile``) the first repetition of ``METHOD``'s first run whose condition or scene contains
``TEXT`` (``N=800``, ``pets``) and prints the functions taking the most time of their own, and the share of
the run that the project's modules, numpy, pandas, scipy and OpenCV take.  Nothing is stored.  The
profiler's overhead is mostly per Python call, so shares of code that makes many small calls read high.

    python benchmarks/profile_run.py bis_pf_cost MFMC N=800 --scale paper
"""

import argparse
import cProfile
import pstats
import sys
from collections import Counter
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from hydra import compose, initialize_config_dir  # noqa: E402

from replication.paths import CONF_DIR  # noqa: E402
from replication.runner.config import expand  # noqa: E402
from replication.runner.execute import perform  # noqa: E402

PARTS = {"replication/": "replication", "numpy": "numpy", "pandas/": "pandas", "scipy/": "scipy",
         "numba/": "numba", "llvmlite/": "numba", "cv2": "OpenCV", "trackeval/": "TrackEval"}
OPENCV = {"<imread>", "<imdecode>", "<cvtColor>", "<LUT>", "<transform>", "<resize>", "<calcHist>"}  # cProfile's names


def part(filename: str, function: str) -> str:
    """Which library a profiled function belongs to: by its file, or for a built-in (file ``~``: numpy's
    ufunc methods, OpenCV's functions) by its name; ``Python`` for the interpreter and the rest."""
    if filename == "~" and function in OPENCV:
        return "OpenCV"
    where = function if filename == "~" else filename
    return next((name for key, name in PARTS.items() if key in where), "Python")


def profiled(run) -> tuple[float, Counter, pstats.Stats]:
    """``run`` performed under cProfile: its seconds (every function's own time), those seconds per library
    (:func:`part`), and the profile.  A profile during which numba compiled a kernel (a cold compiled cache:
    :func:`perform` then computes the run twice) is taken again, so it holds one computation, compiled."""
    from numba.core import event

    with event.install_recorder("numba:compile") as compiled:
        profile = _profile(run)
    stats = pstats.Stats(_profile(run) if compiled.buffer else profile)
    shares = Counter()
    for (filename, _, function), row in stats.stats.items():
        shares[part(filename, function)] += row[2]
    return sum(shares.values()), shares, stats


def _profile(run) -> cProfile.Profile:
    profile = cProfile.Profile()
    profile.runcall(perform, run)
    return profile


def runs_of(experiment: str, scale: str) -> list:
    """The runs ``experiment`` expands to at ``scale``."""
    with initialize_config_dir(config_dir=str(CONF_DIR), version_base="1.3"):
        cfg = compose("config", overrides=[f"experiment={experiment}", f"scale={scale}"])
    return expand(cfg)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("experiment")
    parser.add_argument("method")
    parser.add_argument("text", nargs="?", default="", help="a piece of the run's condition or scene")
    parser.add_argument("--scale", default="quick")
    parser.add_argument("--top", type=int, default=20)
    args = parser.parse_args()
    runs = [run for run in runs_of(args.experiment, args.scale) if run.method == args.method and run.repetition == 0
            and args.text in f"{run.condition} {run.data_condition}"]
    if not runs:
        sys.exit(f"{args.experiment} at {args.scale} scale has no run of {args.method!r} matching {args.text!r}")
    total, shares, stats = profiled(runs[0])
    print(f"{runs[0].run_id}: {total:.1f} s under the profiler")
    print("  " + ", ".join(f"{name} {seconds / total:.0%}" for name, seconds in shares.most_common()))
    stats.sort_stats("tottime").print_stats(args.top)


if __name__ == "__main__":
    main()
