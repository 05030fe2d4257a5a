"""Where one run's time goes: ``python benchmarks/profile_run.py EXPERIMENT METHOD [TEXT] [--scale paper]``.

Profiles (``cProfile``) the first repetition of ``METHOD``'s first run whose condition or scene contains
``TEXT`` (``N=800``, ``pets``) and prints the functions taking the most time of their own, and the share of
the run that the project's modules, numpy, pandas, scipy and OpenCV take.  Nothing is stored.  The
profiler's overhead is mostly per Python call, so shares of code that makes many small calls read high.

    python benchmarks/profile_run.py bis_pf_cost MFMC N=800 --scale paper

It also prints the run's time by part (:func:`staged`: drawing or reading the frames, the likelihood, the
filter, scoring, the rest).

``python benchmarks/profile_run.py --record`` (``make record`` runs it) profiles every method of the
record's three experiments with the most CPU on its recorded run of median time (:func:`slowest_profiles`)
and writes ``record/profile.json`` (:func:`write_profile`), from which ``pf-replicate findings`` renders
where the record's time goes; ``make benchmark`` shows the same profiles in its report.
"""

import argparse
import cProfile
import json
import pstats
import sys
from collections import Counter
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import pandas as pd  # noqa: E402
from hydra import compose, initialize_config_dir  # noqa: E402

from replication.paths import CONF_DIR, PACKAGE_DIR, resolve  # noqa: E402
from replication.record.manifest import PROFILE  # noqa: E402
from replication.runner.config import expand  # noqa: E402
from replication.runner.execute import perform  # noqa: E402
from replication.runner.provenance import provenance  # noqa: E402

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


def slowest_profiles(record: Path, count: int = 3, top: int = 6) -> pd.DataFrame:
    """The ``count`` experiments of the record with the most CPU (the sum of their runs' times), costliest
    first, and in each every method, costliest first, on its recorded run of median time, performed here
    once and then under cProfile: the method's share of the experiment's CPU, the run's seconds, their
    shares by part of the run (``part: frames`` ...) and by library (``library: numpy`` ...), and its
    ``top`` functions by own time.  A run this code does not make (an older record's key) is named, not
    profiled."""
    spent = {folder.name: pd.read_parquet(folder / "runs.parquet", columns=["method", "run_key", "repetition", "wall_s"])
             for folder in sorted(record.iterdir()) if (folder / "runs.parquet").exists()}
    rows = []
    for name in sorted(spent, key=lambda n: -spent[n]["wall_s"].sum())[:count]:
        runs, keys = spent[name], {(r.key, r.repetition): r for r in runs_of(name, "paper")}
        by_method = runs.groupby("method")["wall_s"].sum().sort_values(ascending=False)
        for method, cpu in by_method.items():
            mine = runs[runs["method"] == method].sort_values("wall_s", kind="stable")
            median = mine.iloc[(len(mine) - 1) // 2]  # the lower of two middles
            row = {"experiment": name, "record CPU-minutes": runs["wall_s"].sum() / 60, "method": method,
                   "share of the experiment's CPU": cpu / runs["wall_s"].sum(), "recorded s": median["wall_s"]}
            run = keys.get((median["run_key"], median["repetition"]))
            if run is None:  # the record was made by other code: its run is not this code's
                rows.append({**row, "run": f"{median['run_key']}: not in this code's runs (the record is older)"})
                continue
            perform(run)  # a worker's state after its first run: frames decoded, kernels compiled
            seconds, shares, stats = profiled(run)
            own = sorted(stats.stats.items(), key=lambda item: -item[1][2])[:top]
            rows.append({**row, "run": run.run_id, "profiled s": seconds,
                         **{f"part: {part}": t / seconds for part, t in staged(stats).most_common()},
                         **{f"library: {part}": t / seconds for part, t in shares.most_common()},
                         "costliest functions (own s)": "; ".join(f"{f} ({Path(file).name}:{line}) {v[2]:.2f}"
                                                                  for (file, line, f), v in own)})
    return pd.DataFrame(rows)


def write_profile(profiles: pd.DataFrame, record: Path) -> Path:
    """``record/profile.json``: the profiles of :func:`slowest_profiles` (each experiment's CPU, each method's
    share of it and its run's split by part) and what made them, for ``pf-replicate findings`` to render."""
    made = provenance()
    methods = [{"experiment": row["experiment"], "method": row["method"],
                "cpu_minutes": round(row["record CPU-minutes"] * row["share of the experiment's CPU"], 1),
                "share": round(row["share of the experiment's CPU"], 3), "run": row["run"],
                "parts": {c.removeprefix("part: "): round(row[c], 3) for c in profiles.columns
                          if c.startswith("part: ") and pd.notna(row[c])}}
               for _, row in profiles.iterrows()]
    path = record / PROFILE
    path.write_text(json.dumps({"made": {k: made[k] for k in ("git_commit", "code_digest", "machine", "computed_at")},
                                "stages": list(dict.fromkeys([*STAGES.values(), REST])), "methods": methods},
                               indent=1) + "\n")
    return path


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("experiment", nargs="?")
    parser.add_argument("method", nargs="?")
    parser.add_argument("text", nargs="?", default="", help="a piece of the run's condition or scene")
    parser.add_argument("--scale", default="quick")
    parser.add_argument("--top", type=int, default=20)
    parser.add_argument("--record", action="store_true", help="profile the record's costliest experiments into it")
    args = parser.parse_args()
    if args.record:
        print(f"profile: {write_profile(slowest_profiles(resolve('record')), resolve('record'))}")
        return
    if args.method is None:
        sys.exit("give EXPERIMENT METHOD, or --record")
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
