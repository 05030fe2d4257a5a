"""Where one run's time goes: ``python benchmarks/profile_run.py EXPERIMENT METHOD [TEXT] [--scale paper]``.

Profiles (``cProfile``) the first repetition of ``METHOD``'s first run whose condition or scene contains
``TEXT`` (``N=800``, ``pets``) and prints the functions taking the most time of their own, and the share of
the run that the project's modules, numpy, pandas, scipy and OpenCV take.  Nothing is stored.  The
profiler's overhead is mostly per Python call, so shares of code that makes many small calls read high.

    python benchmarks/profile_run.py bis_pf_cost MFMC N=800 --scale paper

It also prints the run's time by part (:func:`staged`: drawing or reading the frames, the likelihood, the
filter, scoring, the rest), which ``make benchmark`` records for the record's slowest experiments.
"""

import argparse
import cProfile
import pstats
import sys
from collections import Counter
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from hydra import compose, initialize_config_dir  # noqa: E402

from replication.paths import CONF_DIR, PACKAGE_DIR  # noqa: E402
from replication.runner.config import expand  # noqa: E402
from replication.runner.execute import perform  # noqa: E402

# the parts of a run, by the project's subpackage (or module) whose function spent the time
STAGES = {"scenes": "frames", "vision": "likelihood", "filters": "filter", "smc": "filter", "models": "filter",
          "qmc.py": "filter", "metrics": "scoring"}
REST = "rest"  # the task's set-up, the runner, and time no project function called

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


def stage(filename: str) -> str | None:
    """The part of a run (:data:`STAGES`, else :data:`REST`) a project file's functions do; None for a
    library's or the interpreter's."""
    path = Path(filename)
    if not path.is_absolute() or not path.is_relative_to(PACKAGE_DIR):
        return None
    return STAGES.get(path.relative_to(PACKAGE_DIR).parts[0], REST)


def staged(stats: pstats.Stats) -> Counter:
    """Seconds per part of the run (:func:`stage`): a project function's own time goes to its part; a
    library's (numpy, OpenCV, built-ins) to its callers' parts, in proportion to the time it spent for each
    (followed up through library callers to the project's)."""
    entries = stats.stats
    shares: dict = {}

    def share(function) -> dict:
        if function in shares:
            return shares[function]
        own = stage(function[0])
        if own is not None:
            shares[function] = {own: 1.0}
            return shares[function]
        shares[function] = {REST: 1.0}  # while its callers are followed: a cycle ends here
        callers = entries[function][4] if function in entries else {}
        spent = sum(edge[2] for edge in callers.values())
        if spent > 0:
            found = Counter()
            for caller, edge in callers.items():
                for part, fraction in share(caller).items():
                    found[part] += fraction * edge[2] / spent
            shares[function] = dict(found)
        return shares[function]

    seconds = Counter()
    for function, (_, _, own_time, _, _) in entries.items():
        for part, fraction in share(function).items():
            seconds[part] += own_time * fraction
    return seconds


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
    print("  by part: " + ", ".join(f"{name} {seconds / total:.0%}" for name, seconds in staged(stats).most_common()))
    stats.sort_stats("tottime").print_stats(args.top)


if __name__ == "__main__":
    main()
