"""``pf-replicate verify [N=200|all] [experiment=a,b] [cheapest=true] [n_jobs=2] [experiment.<key>=...]``:
re-compute recorded runs in the code and environment at hand, grade each against the record, and
re-judge the verdicts with them (``experiment.*`` settings compose the experiments as a record of
changed ones was made).

``pf-replicate verify against=store scale=quick`` computes nothing: the store's runs that are recorded
runs (the same identity, config, seed and code: the first repetitions of a quick cell whose scene does
not change with the scale) are graded against the record, into ``<reports>/record/recomputed.json``,
which the report's index shows.

A sample of ``N`` recorded runs, stratified by experiment and by universe of a multiverse (each gives at
least one, the rest in proportion to its runs, drawn with a fixed seed; ``cheapest=true`` takes each
one's quickest recorded runs instead, as the test suite does), is computed again by the runner into a
scratch store, a run several universes share once.  Its columns are compared with the record's: every
metric and kept series, a failure by its reason; not timings, provenance or parameters (timings depend
on the machine; the others are the run's identity).  Each run is graded:

* *identical*: every column the same bits;
* *within tolerance*: every column that differs within its kind's declared tolerance
  (:data:`TOLERANCES`: a count exactly, a score to a relative 1e-5, the strip rounded to 4 decimals to
  one step of its rounding), as a machine whose numpy, BLAS, OpenCV or numba took other code paths
  rounds (docs/reproducibility.md says how the tolerances were chosen);
* *diverged*: a column beyond its tolerance: a resampling or proposal decision flipped on a rounding
  difference and the filter's path split, so the run is another draw of the same experiment.  It is
  named with the first column (and the first frame of a kept series) where it parts, and it must lie
  within the run-to-run spread: each of its scalar columns beyond tolerance within the range or the t
  prediction interval at :data:`LEVEL` (Bonferroni over its columns) of the other recorded runs of its
  cell (experiment, universe, method and condition).  One that does not is *beyond* and fails.

A run computed here on the record's own machine (the same :class:`~replication.runner.machine.Machine`
and library versions) must be identical, and fails otherwise.  Then the verdicts: every claim and
published cell of the experiments and multiverses holding a run that is not identical is judged again
from a copy of the record with those runs in place of the recorded ones, and compared with the record's
own (:func:`replication.report.diff.verdicts`, which the command line passes in).  One line per diverged
or failing run, the counts of each grade with the largest relative difference, then the verdicts; exit
status 1 if a run is beyond the spread, a run of the record's machine is not identical, or a verdict
changed.
"""

import json
import math
import shutil
import sys
import tempfile
from collections.abc import Callable
from dataclasses import dataclass
from enum import Enum
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
from scipy import stats
from tqdm.auto import tqdm

from replication import atomic
from replication.condition import PREFIX
from replication.arguments import read
from replication.errors import ConfigError, fail
from replication.evidence.statistics import Estimate
from replication.record.manifest import LIBRARIES, PAGES, RECOMPUTED, Manifest
from replication.record.runs import (
    CURVES_DIR, FAILURE, LABELS, PARAMETERS, UNIVERSE, Record, read_rows, row_identity, runs_table, write_table,
)
from replication.run import Run
from replication.runner.execute import TIMING_COLUMNS, duration, execute
from replication.runner.machine import Machine
from replication.runner.results import SERIES
from replication.runner.store import Store

NOT_COMPARED = (*TIMING_COLUMNS, *LIBRARIES, "code_digest", "git_commit", "git_dirty", "machine", "machine_detail",
                "replication_version", "experiment", "method", "repetition", "run_key", "base_seed")


@dataclass(frozen=True)
class Settings:
    """The command's own settings (store=, reports=, record= and experiment.* compose the config)."""

    N: str = "200"  # a number of recorded runs, or all
    experiment: tuple[str, ...] | None = None  # every experiment the record holds by default
    cheapest: bool = False
    n_jobs: int = 2
    progress: bool = True
    against: str | None = None
    scale: str = "paper"


SAMPLE_SEED = 20261126  # the sample's own stream: the same N gives the same runs
LEVEL = 0.99  # a diverged run's columns against its cell's recorded runs: the prediction interval's level
START = 5.0  # seconds per experiment re-computed, beside its runs' own: loading its scenes and compiled kernels
DRAW = (10.0, 0.0025)  # seconds to judge an experiment's or multiverse's verdicts: fixed, and per recorded run


def prediction(values, level: float) -> Estimate:
    """Where one more run of the same experiment falls, at ``level``: Student's t prediction interval
    mean +- t(n - 1) s sqrt(1 + 1/n), or the range of ``values`` where that is wider (skewed runs).  One
    value, or every value equal: that value alone (no spread to allow another)."""
    values = np.asarray(values, dtype=float)
    values = values[np.isfinite(values)]
    if len(values) == 0:
        return Estimate(math.nan, math.nan, math.nan, 0, "t prediction", level)
    centre, n = float(values.mean()), len(values)
    half = float(stats.t.ppf((1 + level) / 2, n - 1) * values.std(ddof=1) * math.sqrt(1 + 1 / n)) if n > 1 else 0.0
    return Estimate(centre, min(centre - half, float(values.min())), max(centre + half, float(values.max())), n,
                    "t prediction", level)

@dataclass(frozen=True)
class Tolerance:
    """How far a re-computed value may lie from the recorded one: a ``relative`` difference (of the larger
    magnitude) or an ``absolute`` one, whichever allows more; neither, exactly."""

    relative: float = 0.0
    absolute: float = 0.0

    def admits(self, a: float, b: float) -> bool:
        return a == b or abs(a - b) <= max(self.relative * max(abs(a), abs(b)), self.absolute)


EXACT = Tolerance()
# per kind of metric (docs/reproducibility.md, "Verifying the record"): a count moves only where a decision
# flipped; a score (double precision, or through OpenCV's single-precision image filters) stays within 1e-5,
# ten times the largest difference other code paths of numpy, OpenBLAS, OpenCV and numba made in it; the
# strip's density, rounded to 4 decimals, by one step of its rounding where a value sat on its edge
TOLERANCES = {"count": EXACT, "score": Tolerance(relative=1e-5), "rounded": Tolerance(absolute=1.5e-4)}
ROUNDED = ("strip",)  # series rounded before they are stored


class Grade(Enum):
    IDENTICAL = "identical"
    WITHIN = "within tolerance"
    DIVERGED = "diverged"


@dataclass(frozen=True)
class Recomputed:
    """A recorded run computed again here: its recorded ``row`` and its record ``now`` (a failure as
    ``{"failure": reason}``), the strata that hold it, and how they differ."""

    run: Run
    strata: tuple[str, ...]  # the experiment and the universes whose recorded runs hold it
    row: dict
    now: dict
    columns: tuple[tuple[str, object, object], ...]  # (column, recorded, now) of each column that differs
    beyond: tuple[str, ...]  # of those, the columns beyond their kind's tolerance
    frame: tuple[str, int] | None = None  # its first kept series beyond tolerance, and the frame where it parts
    outside: tuple[str, ...] = ()  # diverged: its columns outside its cell's run-to-run spread
    peers: int = 0  # diverged: the other recorded runs of its cell it was held against

    @property
    def grade(self) -> Grade:
        return Grade.IDENTICAL if not self.columns else Grade.WITHIN if not self.beyond else Grade.DIVERGED

    @property
    def same_machine(self) -> bool:
        """Computed here by the code paths and libraries that computed the recorded run (both known)."""
        recorded, here = self.row.get("machine_detail"), self.now.get("machine_detail")
        return (recorded is not None and here is not None and set(recorded) == set(here)
                and Machine.of(recorded) == Machine.of(here)
                and all(self.row.get(k) == self.now.get(k) for k in LIBRARIES))

    @property
    def fails(self) -> bool:
        """Beyond the run-to-run spread, or not identical though computed on the record's machine."""
        return bool(self.outside) or (self.same_machine and self.grade is not Grade.IDENTICAL)

    @property
    def largest(self) -> tuple[float, str]:
        """The largest relative difference of its differing scalar columns, and that column's name."""
        return max(((relative(a, b), c) for c, a, b in self.columns if _number(a) and _number(b)), default=(0.0, ""))

    def line(self) -> str:
        where = f" (held by {len(self.strata)} experiments and universes)" if len(self.strata) > 1 else ""
        said = f"{self.run.experiment} {self.run.run_id}{where}: {self.grade.value}"
        if self.grade is Grade.WITHIN:
            value, column = self.largest
            said += f", {column} by {value:.2g} relative"
        elif self.grade is Grade.DIVERGED:
            column = self.beyond[0]
            recorded, now = next((a, b) for c, a, b in self.columns if c == column)
            more = f" and {len(self.beyond) - 1} more columns" if len(self.beyond) > 1 else ""
            frame = f", {self.frame[0]} from frame {self.frame[1]}" if self.frame else ""
            said += f" at {column} (recorded {_short(recorded)}, now {_short(now)}{more}{frame})"
        if self.same_machine and self.grade is not Grade.IDENTICAL:
            return f"{said}: computed on the record's own machine and libraries, it should be identical"
        if self.outside:
            return (f"{said}: beyond the run-to-run spread of its cell's {self.peers} other recorded runs in "
                    f"{', '.join(self.outside)}")
        if self.grade is Grade.DIVERGED:
            return f"{said}: another draw, within the run-to-run spread of its cell's {self.peers} other recorded runs"
        return said


def sample(recorded: dict[str, list[tuple[Run, dict]]], n: int | None, cheapest: bool) -> list[tuple[Run, dict]]:
    """About ``n`` of the recorded (run, row) pairs (all for None), each stratum (an experiment, a universe)
    at least one and the rest in proportion to its runs: drawn at random with :data:`SAMPLE_SEED`, or its
    quickest with ``cheapest``."""
    total = sum(len(pairs) for pairs in recorded.values())
    rng = np.random.default_rng(SAMPLE_SEED)
    chosen = []
    for name, pairs in sorted(recorded.items()):
        k = len(pairs) if n is None else min(len(pairs), max(1, round(n * len(pairs) / total)))
        if cheapest:
            order = sorted(range(len(pairs)), key=lambda i: pairs[i][1].get("wall_s") or 0.0)[:k]
        else:
            order = sorted(rng.choice(len(pairs), size=k, replace=False))
        chosen += [pairs[i] for i in order]
    return chosen


def compared(column: str) -> bool:
    """Whether a column is a run's result, compared with the record (not its identity, timing or provenance)."""
    return column not in (*NOT_COMPARED, *LABELS, FAILURE) and not column.startswith((*PARAMETERS, PREFIX, UNIVERSE))


def compare(row: dict, now: dict, other_code: bool = False) -> tuple[tuple[str, object, object], ...]:
    """The columns in which a recomputed record ``now`` differs from the recorded ``row`` in any bit (a value
    one has and the other lacks differs too; a series the record does not keep is not compared).  A run the
    record holds from ``other_code`` (its key is not this code's) is compared on what the record says: a
    result this code adds is new, not a difference."""
    if row.get(FAILURE) is not None or "failure" in now:
        same = row.get(FAILURE) == now.get("failure")
        return () if same else ((FAILURE, row.get(FAILURE), now.get("failure")),)
    added = (k for k in now if k not in SERIES and not (other_code and k not in row))
    columns = [k for k in dict.fromkeys([*row, *added]) if compared(k)]
    return tuple((k, row.get(k), now.get(k)) for k in columns if not same_value(row.get(k), now.get(k)))


def tolerance(column: str, value) -> Tolerance:
    """The declared tolerance of ``column``'s kind: a rounded series, a count (an integer) or a score."""
    if column in ROUNDED:
        return TOLERANCES["rounded"]
    return TOLERANCES["count" if isinstance(value, int) and not isinstance(value, bool) else "score"]


def same_value(a, b, within: Tolerance = EXACT) -> bool:
    """Equal as a record holds values: numbers exactly (or ``within`` a tolerance), NaN equal to NaN, lists
    and mappings element by element (a key one mapping lacks is None in it, as a Parquet struct reads back)."""
    if isinstance(a, dict) and isinstance(b, dict):
        return all(same_value(a.get(k), b.get(k), within) for k in {*a, *b})
    if isinstance(a, (list, tuple)) and isinstance(b, (list, tuple)):
        return len(a) == len(b) and all(same_value(x, y, within) for x, y in zip(a, b))
    if _number(a) and _number(b):
        if math.isnan(a) or math.isnan(b):
            return math.isnan(a) and math.isnan(b)
        return within.admits(a, b)
    return a == b


def relative(a: float, b: float) -> float:
    """|a - b| over the larger magnitude (0 where equal, NaN equal to NaN)."""
    if a == b or (math.isnan(a) and math.isnan(b)):
        return 0.0
    return abs(a - b) / max(abs(a), abs(b)) if math.isfinite(a) and math.isfinite(b) else math.inf


def first_frame(a, b, within: Tolerance) -> int | None:
    """Where two per-frame series (lists by frame, or mappings of them) first differ beyond ``within``,
    counting frames from 1; None where they do not, or are no series."""
    if isinstance(a, dict) and isinstance(b, dict):
        found = [f for k in {*a, *b} if (f := first_frame(a.get(k), b.get(k), within)) is not None]
        return min(found, default=None)
    if isinstance(a, list) and isinstance(b, list):
        return next((i + 1 for i, (x, y) in enumerate(zip(a, b)) if not same_value(x, y, within)),
                    None if len(a) == len(b) else min(len(a), len(b)) + 1)
    return None


def graded(run: Run, strata: tuple[str, ...], row: dict, now: dict, peers: list[dict]) -> Recomputed:
    """``run`` graded against its recorded ``row``; ``peers`` are the recorded rows of its cell, whose spread
    (``row`` left out: the draw it replaces) a diverged run is held against."""
    columns = compare(row, now, other_code=run is not None and row.get("run_key") != run.key)
    peers = [peer for peer in peers if (peer.get("run_key"), peer.get("repetition")) != (row.get("run_key"),
                                                                                        row.get("repetition"))]
    beyond = tuple(c for c, a, b in columns if not same_value(a, b, tolerance(c, a if a is not None else b)))
    if not beyond:
        return Recomputed(run, strata, row, now, columns, ())
    parts = ((c, first_frame(row.get(c), now.get(c), tolerance(c, None))) for c in beyond)
    frame = next(((c, f) for c, f in parts if f is not None), None)
    return Recomputed(run, strata, row, now, columns, beyond, frame, outside(now, beyond, peers), len(peers))


def outside(now: dict, beyond: tuple[str, ...], peers: list[dict]) -> tuple[str, ...]:
    """Of a diverged run's columns beyond tolerance, those outside the run-to-run spread of ``peers``: a
    scalar whose value here lies outside their range and their t prediction interval at :data:`LEVEL`
    (Bonferroni over the scalar columns), or a failure on one side only.  A series is not held against
    the spread (its frames are not independent draws)."""
    if FAILURE in beyond:
        return (FAILURE,)
    scalars = [c for c in beyond if _number(now.get(c))]
    level = 1 - (1 - LEVEL) / max(len(scalars), 1)
    return tuple(c for c in scalars if not prediction([p[c] for p in peers if _number(p.get(c))], level)
                 .contains(now[c]))


def strata(cfg, record: Record) -> dict[str, list[tuple[Run, dict]]]:
    """The recorded (run, row) pairs of an experiment, or of each universe of a multiverse (its runs of
    every experiment it re-runs), by the name of the stratum."""
    from replication.runner.config import expand
    from replication.runner.multiverse import load

    if "multiverse" not in cfg.experiment:
        return {cfg.experiment.name: record.found(expand(cfg))}
    multiverse = load(cfg)
    return {f"{multiverse.name} {universe.name}":
            [pair for name in multiverse.experiments
             for pair in record.universe(multiverse.name, universe.name).found(multiverse.runs[universe.name, name])]
            for universe in multiverse.universes}


def cells(pairs: list[tuple[Run, dict]]) -> dict[tuple, list[dict]]:
    """The recorded rows of ``pairs`` by cell: experiment, method and condition."""
    found: dict[tuple, list[dict]] = {}
    for run, row in pairs:
        found.setdefault((run.experiment, run.method, str(run.condition)), []).append(row)
    return found


@dataclass(frozen=True)
class Verification:
    runs: tuple[Recomputed, ...]  # each distinct run once
    sampled: int  # runs drawn, a run several universes share once per universe
    strata: int
    stale: int  # sampled runs other code made

    def count(self, grade: Grade) -> int:
        return sum(r.grade is grade for r in self.runs)

    @property
    def failing(self) -> list[Recomputed]:
        return [r for r in self.runs if r.fails]

    def summary(self) -> str:
        value, column, run = max(((*r.largest, r) for r in self.runs if r.grade is Grade.WITHIN),
                                 default=(0.0, "", None), key=lambda found: found[0])
        largest = f" (largest relative difference {value:.2g}: {column}, {run.run.experiment})" if run else ""
        beyond = f"; {len(self.failing)} beyond (named above)" if self.failing else ""
        stale = f" ({self.stale} made by other code than this)" if self.stale else ""
        return (f"verified {self.sampled} recorded runs ({len(self.runs)} distinct) of {self.strata} experiments "
                f"and universes{stale}: {self.count(Grade.IDENTICAL)} identical, {self.count(Grade.WITHIN)} within "
                f"tolerance{largest}, {self.count(Grade.DIVERGED)} diverged{beyond}")


def verify(cfgs: list, record: Record, n: int | None, cheapest: bool, n_jobs: int, progress: bool = True,
           then: str = "") -> Verification:
    """Re-compute a sample of the record's runs of ``cfgs`` (composed at the paper scale: experiments, and
    multiverses, each universe a stratum), each distinct run once, and grade them; first say how many and
    roughly how long (their recorded times, and :data:`START` per experiment), and ``then`` what follows."""
    reading = tqdm(cfgs, desc="reading the record", unit="experiment", disable=not progress, mininterval=1.0)
    recorded = {name: pairs for cfg in reading for name, pairs in strata(cfg, record).items() if pairs}
    chosen = sample(recorded, n, cheapest)
    distinct = {(run.experiment, run.run_id, row["run_key"]): (run, row) for run, row in chosen}
    held: dict[tuple[str, str, str], list[str]] = {}  # each distinct run: the strata whose recorded runs hold it
    for name, pairs in recorded.items():
        for run, row in pairs:
            if (run.experiment, run.run_id, row["run_key"]) in distinct:
                held.setdefault((run.experiment, run.run_id, row["run_key"]), []).append(name)
    experiments = {run.experiment for run, _ in distinct.values()}
    seconds = (sum(row.get("wall_s") or 0.0 for _, row in distinct.values()) + START * len(experiments)) / n_jobs
    print(f"re-computing {len(distinct)} recorded runs ({len(chosen)} sampled from {len(recorded)} experiments and "
          f"universes, a run several share once), about {duration(seconds)} on {n_jobs} worker(s){then}", flush=True)
    spread = {name: cells(pairs) for name, pairs in recorded.items()}
    found = []
    with tempfile.TemporaryDirectory(prefix="verify-") as scratch:
        for name in dict.fromkeys(run.experiment for run, _ in distinct.values()):
            pairs = [(run, row) for run, row in distinct.values() if run.experiment == name]
            store = Store(scratch, name)
            execute([run for run, _ in pairs], store, n_jobs=n_jobs, progress=progress)
            for run, row in pairs:
                now = store.read(run)
                now = now if now is not None else {"failure": store.failure_path(run).read_text().strip()}
                names = tuple(held[run.experiment, run.run_id, row["run_key"]])
                peers = spread[names[0]][run.experiment, run.method, str(run.condition)]
                found.append(graded(run, names, row, now, peers))
                if found[-1].grade is Grade.DIVERGED or found[-1].fails:
                    print(found[-1].line(), flush=True)
    stale = sum(row["run_key"] != run.key for run, row in chosen)
    return Verification(tuple(found), len(chosen), len(recorded), stale)


def machines(verification: Verification) -> str:
    """The machines that computed the sampled runs, in the record and here (runs made before records named
    their machine's code paths: not recorded)."""
    def named(rows) -> str:
        found = {str(Machine.of(r["machine_detail"])) for r in rows if r.get("machine_detail")}
        return "; ".join(sorted(found)) or "not recorded (these runs were computed before records said)"
    return (f"recorded on: {named(r.row for r in verification.runs)}\n"
            f"computed here on: {named(r.now for r in verification.runs)}")


def substituted(record: Path, runs: list[Recomputed], out: Path) -> list[str]:
    """A copy of ``record`` in ``out`` with each of ``runs`` in place of its recorded row, in every file that
    holds it (its experiment's, each universe's); the names of the entries whose files changed.  Only the
    compared columns are replaced: timings and provenance stay the record's."""
    shutil.copytree(record, out)
    by_key = {(r.run.experiment, row_identity(r.row), r.row["run_key"]): r for r in runs}
    changed = []
    for path in sorted(p for p in out.rglob("*.parquet") if CURVES_DIR not in p.parts):
        names = [c for c in pq.read_schema(path).names if c in ("experiment", "method", "repetition", "run_key")
                 or c.startswith(PREFIX)]
        held = pq.read_table(path, columns=names).to_pylist()
        keys = [(r["experiment"], row_identity(r), r["run_key"]) for r in held]
        if not by_key.keys() & set(keys):
            continue
        rows = [_in_place(r, by_key[key]) if key in by_key else r for r, key in zip(read_rows(path), keys)]
        write_table(runs_table(rows), path)
        changed.append(path.relative_to(out).parts[0])
    return sorted(set(changed))


def _in_place(row: dict, recomputed: Recomputed) -> dict:
    """``row`` with the results of its run as computed here (a failure, or every compared column)."""
    if "failure" in recomputed.now:
        return {**row, FAILURE: recomputed.now["failure"]}
    kept = {k: v for k, v in recomputed.now.items() if compared(k) and (k not in SERIES or k in row)}
    return {**row, **kept, FAILURE: None}


def recomputed(cfgs: list, store_root: Path, record: Record) -> dict[str, dict]:
    """Per experiment of ``cfgs`` (at any scale), its stored runs that are recorded runs (the same identity
    and key: the same resolved config, seed and code), graded against the record: how many of each grade,
    the largest relative difference, a line per diverged run and per run beyond.  Nothing is computed."""
    from replication.runner.config import expand

    found = {}
    for cfg in (cfg for cfg in cfgs if "multiverse" not in cfg.experiment):  # a quick universe is no paper one
        store, name = Store(store_root, cfg.experiment.name), cfg.experiment.name
        pairs = record.found(expand(cfg))
        spread = cells(pairs)
        runs = [graded(run, (name,), row, now, spread[run.experiment, run.method, str(run.condition)])
                for run, row in pairs if row["run_key"] == run.key and (now := store.read(run)) is not None]
        verification = Verification(tuple(runs), len(runs), 1, 0)
        found[name] = {"compared": len(runs), **{g.name.lower(): verification.count(g) for g in Grade},
                       "largest": max((r.largest[0] for r in runs if r.grade is Grade.WITHIN), default=0.0),
                       "lines": [r.line() for r in runs if r.grade is Grade.DIVERGED or r.fails],
                       "beyond": [r.line() for r in runs if r.fails]}
    return found


def write_recomputed(found: dict[str, dict], out: Path) -> None:
    """Write :func:`recomputed`'s finding for the index and print it: a line per diverged run and the counts.
    A run beyond the spread is a finding the index shows at its top, not a failed command (make replicate
    goes on)."""
    atomic.write_text(out, json.dumps(found, indent=1) + "\n")
    lines = [line for entry in found.values() for line in entry["lines"]]
    print(*lines, sep="\n", end="\n" if lines else "")
    compared = sum(entry["compared"] for entry in found.values())
    counts = {g: sum(entry[g.name.lower()] for entry in found.values()) for g in Grade}
    largest = max((entry["largest"] for entry in found.values()), default=0.0)
    beyond = sum(len(entry["beyond"]) for entry in found.values())
    outcome = (f"{counts[Grade.IDENTICAL]} identical, {counts[Grade.WITHIN]} within tolerance (largest relative "
               f"difference {largest:.2g}), {counts[Grade.DIVERGED]} diverged" + (f", {beyond} beyond the run-to-run "
                                                                                 "spread" if beyond else ""))
    print((f"this machine re-computed {compared} recorded runs: {outcome}" if compared
           else "no stored run is a recorded run (other configs or code)") + f" ({out})")


def main(argv: list[str], verdicts: Callable[[Path, Path, list[str], int], list[str]] | None = None) -> None:
    """The command; ``verdicts(record, substituted, names, n_jobs)`` re-judges the verdicts of the entries
    ``names`` of the record and of its copy with the re-computed runs, and returns a line per verdict that
    changed (the report's: the command line passes :func:`replication.report.diff.verdicts`)."""
    if {"--help", "-h"} & set(argv):
        print(__doc__.strip())
        return
    from hydra import compose, initialize_config_dir

    from replication.paths import CONF_DIR, resolve

    options, handed = read(argv, Settings, "verify", handed=("store", "reports", "record", "experiment."))
    changes = [arg for arg in handed if arg.lstrip("+~").startswith("experiment.")]  # the experiments' own settings
    paths = [arg for arg in handed if arg not in changes]
    try:
        n = None if options.N == "all" else _positive(options.N, "N")
        n_jobs = _positive(str(options.n_jobs), "n_jobs")
    except ValueError as error:
        fail(f"verify: {error}")
    with initialize_config_dir(config_dir=str(CONF_DIR), version_base="1.3"):
        cfg = compose("config", overrides=paths)
        folder = resolve(cfg.record)
        manifest = Manifest.read(folder)
        if not manifest.experiments:
            fail(f"{folder}: no record here (make record writes one from a paper-scale store)")
        damaged = manifest.damaged(folder)
        if damaged:
            fail(f"{folder}: {', '.join(damaged)} no longer match the manifest's SHA-256")
        names = options.experiment or sorted(manifest.experiments)
        missing = sorted(set(names) - set(manifest.experiments))
        if missing:
            fail(f"the record holds no {missing[0]!r}; it holds {', '.join(sorted(manifest.experiments))}")
        if options.against is None:
            print(sampling(manifest, names, n), flush=True)
        scale = options.scale
        cfgs = [compose("config", overrides=[f"experiment={name}", f"scale={scale}", *paths, *changes])
                for name in names]
    touched = set(names) | {name for name, entry in manifest.experiments.items() if entry.universes}  # may hold them
    judging = 2 * sum(DRAW[0] + DRAW[1] * manifest.experiments[name].runs for name in touched) / n_jobs
    then = f", then up to about {duration(judging)} judging the verdicts again where a run is not identical"
    try:
        if options.against == "store":  # the store's runs that are recorded ones, graded
            found = recomputed(cfgs, resolve(cfg.store), Record(folder))
            return write_recomputed(found, resolve(cfg.reports) / PAGES / RECOMPUTED)
        elif options.against is not None:
            fail(f"against= takes store (compare the store's runs with the record), got {options.against!r}")
        verification = verify(cfgs, Record(folder), n, options.cheapest, n_jobs, progress=options.progress,
                              then=then if verdicts else "")
    except ConfigError as error:
        fail(str(error))
    print(machines(verification))
    print(verification.summary(), flush=True)
    moved = rejudged(folder, verification, n_jobs, verdicts) if verdicts else []
    if verification.failing or moved:
        sys.exit(1)


def sampling(manifest: Manifest, names: list[str], n: int | None) -> str:
    """The line verify says before it reads the record: how many runs it samples of how many, from how many
    strata (each gives at least one, so a small ``N`` samples one run per experiment and universe)."""
    strata_count = sum(manifest.experiments[name].universes or 1 for name in names)
    total = sum(manifest.experiments[name].runs for name in names)
    size = "all" if n is None else f"about {max(n, strata_count):,}"
    return (f"verify: {size} of the record's {total:,} runs of {len(names)} experiments and multiverses, each of "
            f"their {strata_count} experiments and universes at least one (experiment=a,b for fewer); reading them "
            "from the record first")


def rejudged(folder: Path, verification: Verification, n_jobs: int,
             verdicts: Callable[[Path, Path, list[str], int], list[str]], multiverses: bool = True) -> list[str]:
    """The verdicts that change when the runs that are not identical replace the recorded ones, in every
    experiment (and, with ``multiverses``, every multiverse) holding one; none to re-judge where every run
    is identical (the same numbers give the same verdicts) or every one that is not sits in a multiverse left
    out."""
    differing = [r for r in verification.runs if r.grade is not Grade.IDENTICAL]
    if not differing:
        print("verdicts: every re-computed run is identical, so are the verdicts")
        return []
    universes = {name: entry.universes for name, entry in Manifest.read(folder).experiments.items()}
    with tempfile.TemporaryDirectory(prefix="verify-record-") as scratch:
        copy = Path(scratch) / "record"
        names = [name for name in substituted(folder, differing, copy) if multiverses or not universes[name]]
        if not names:  # nothing to judge (verdicts() refuses an empty list)
            print(f"verdicts: the {len(differing)} runs that are not identical are all in multiverses, not "
                  f"re-judged here")
            return []
        print(f"verdicts: re-judging {len(names)} experiments and multiverses with the {len(differing)} runs that "
              f"are not identical in place of the recorded ({', '.join(names)})", flush=True)
        return verdicts(folder, copy, names, n_jobs)


def _positive(text: str, name: str) -> int:
    if not text.isdigit() or int(text) <= 0:
        raise ValueError(f"{name} must be a positive integer, got {text!r}")
    return int(text)


def _number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _short(value) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."
