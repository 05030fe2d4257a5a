"""``record/manifest.json``: what made the record, and the SHA-256 of each of its files.

One :class:`Entry` per experiment, read off its runs' own provenance: how many runs (and failed), the
commits and code digests that computed them, the libraries and CPU and the code paths the libraries took
on it (``machine_details``, :class:`~replication.runner.machine.Machine`: ``null`` where the runs were
computed before they said, as every run of the record at f29efe1 was), when the first and last were
computed, their summed wall and CPU times and the machine's load as they ended; and of its files, the SHA-256 of each and their size
(:meth:`Manifest.damaged` names a file that no longer matches).  An entry that replaces another keeps
what the one it replaced took (:class:`Before`), so that a change of code shows its cost beside the old.
"""

import datetime
import hashlib
import json
from dataclasses import asdict, dataclass, replace
from pathlib import Path

from replication import atomic
from replication.runner.machine import Machine

MANIFEST = "manifest.json"
PROFILE = "profile.json"  # where the time of the record's slowest experiments goes (benchmarks/profile_run.py)
PAGES = "record"  # <reports>/record/: the record's pages (pf-replicate report source=record)
RECOMPUTED = "recomputed.json"  # in <reports>/record/: the store's runs that are recorded ones, compared (verify)
LIBRARIES = ("python_version", "numpy_version", "scipy_version", "opencv_version", "numba_version")


@dataclass(frozen=True)
class Before:
    """What an experiment's previous recording took: its commits and code, runs, summed wall time and
    minutes from its first run to its last (None for a multiverse), and when it was written."""

    commits: tuple[str, ...]
    code_digests: tuple[str, ...]
    runs: int
    wall_s: float
    minutes: float | None
    written: str


@dataclass(frozen=True)
class Entry:
    files: dict[str, str]  # path inside the record -> SHA-256: the runs table first, then the curve tables
    bytes: int
    runs: int
    failed: int
    wall_s: float  # summed over the runs (one core each)
    first_computed: str | None
    last_computed: str | None
    commits: tuple[str, ...]
    dirty: bool  # a run was computed from a tree with uncommitted changes to the package
    code_digests: tuple[str, ...]
    libraries: tuple[str, ...]  # "python 3.11.2, numpy 2.1.3, ..." per distinct set
    machines: tuple[str, ...]
    written: str  # the date the file was written
    universes: int = 0  # a multiverse's universes recorded (0: an experiment)
    before: Before | None = None  # the recording this entry replaced
    machine_details: tuple[Machine, ...] | None = None  # the code paths of its runs' machines (None: not recorded)
    # summed over the runs: each run's thread CPU time; the machine's 1-minute load as they ended, median and
    # max; the median time of the reference work on their workers (stopwatch.reference_ms: the machine's speed)
    # (None: runs recorded before they said)
    cpu_s: float | None = None
    load_1m: tuple[float, float] | None = None
    reference_ms: float | None = None

    @property
    def minutes(self) -> float | None:
        """Minutes between the completion of the first and last runs: the experiment's wall time on the
        machine that made it, less its first run (runs in parallel; None without times).  None for a
        multiverse, whose universes reuse runs its experiments made at other times."""
        if self.universes or self.first_computed is None:
            return None
        first, last = (datetime.datetime.fromisoformat(t) for t in (self.first_computed, self.last_computed))
        return round((last - first).total_seconds() / 60, 1)

    def damaged(self, record: Path) -> list[str]:
        """Its files whose bytes no longer have the SHA-256 it gives them (or that are gone)."""
        return [file for file, digest in self.files.items()
                if not (Path(record) / file).exists() or sha256(Path(record) / file) != digest]

    def replacing(self, earlier: "Entry") -> "Entry":
        """This entry, keeping what ``earlier`` (the recording it replaces) took."""
        return replace(self, before=Before(earlier.commits, earlier.code_digests, earlier.runs, earlier.wall_s,
                                           earlier.minutes, earlier.written))

    @classmethod
    def of(cls, paths: list[Path], record: Path, rows: list[dict], universes: int = 0) -> "Entry":
        """The entry of ``paths`` holding ``rows`` (a run several universes share counts once in ``wall_s``)."""
        computed = sorted(r["computed_at"] for r in rows if r.get("computed_at"))
        distinct = {(r["experiment"], r["method"], r["run_key"], r["repetition"]): r for r in rows}.values()
        return cls(
            files={path.relative_to(record).as_posix(): sha256(path) for path in paths},
            bytes=sum(path.stat().st_size for path in paths),
            runs=len(rows), failed=sum(1 for r in rows if r.get("failure")),
            wall_s=round(sum(r.get("wall_s") or 0.0 for r in distinct), 1),
            first_computed=computed[0] if computed else None, last_computed=computed[-1] if computed else None,
            commits=_distinct(rows, "git_commit"), dirty=any(bool(r.get("git_dirty")) for r in rows),
            code_digests=_distinct(rows, "code_digest"),
            libraries=tuple(sorted({", ".join(f"{k.removesuffix('_version')} {r.get(k)}" for k in LIBRARIES)
                                    for r in rows if not r.get("failure")})),
            machines=_distinct(rows, "machine"), written=datetime.date.today().isoformat(), universes=universes,
            machine_details=_machines(rows), cpu_s=_summed(distinct, "cpu_s"), load_1m=_load(rows),
            reference_ms=_median(rows, "reference_ms"))


@dataclass(frozen=True)
class Manifest:
    experiments: dict[str, Entry]
    scale: str = "paper"

    @classmethod
    def read(cls, record: Path) -> "Manifest":
        """The record's manifest; an empty one where there is none yet."""
        path = Path(record) / MANIFEST
        if not path.exists():
            return cls({})
        data = json.loads(path.read_text())
        entries = {name: Entry(**{**_tuples(entry),
                                  "before": entry.get("before") and Before(**_tuples(entry["before"])),
                                  "machine_details": _read_machines(entry.get("machine_details"))})
                   for name, entry in data["experiments"].items()}
        return cls(entries, data["scale"])

    def with_entry(self, name: str, entry: Entry) -> "Manifest":
        """The manifest with ``entry`` for ``name``, keeping what the entry it replaces took; unless its file
        is the same bytes as before (the earlier entry, and its date, stay)."""
        earlier = self.experiments.get(name)
        if earlier is not None and earlier.files == entry.files:
            return self
        return replace(self, experiments={**self.experiments,
                                          name: entry if earlier is None else entry.replacing(earlier)})

    def write(self, record: Path) -> Path:
        path = Path(record) / MANIFEST
        data = {"scale": self.scale, "experiments": {k: asdict(v) for k, v in sorted(self.experiments.items())}}
        atomic.write_text(path, json.dumps(data, indent=1) + "\n")
        return path

    def damaged(self, record: Path) -> list[str]:
        """The files whose bytes no longer have the manifest's SHA-256 (or that are gone)."""
        return [file for entry in self.experiments.values() for file in entry.damaged(record)]


def read_profile(record: Path) -> dict | None:
    """The record's :data:`PROFILE` (None where none was made): where its slowest experiments' time goes."""
    path = Path(record) / PROFILE
    return json.loads(path.read_text()) if path.exists() else None


def sha256(path: Path) -> str:
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def _tuples(data: dict) -> dict:
    """JSON's lists back to the tuples written."""
    return {k: tuple(v) if isinstance(v, list) else v for k, v in data.items()}


def _machines(rows: list[dict]) -> tuple[Machine, ...] | None:
    """The distinct machines the rows name (None where none does: runs computed before they said)."""
    found = {Machine.of(r["machine_detail"]) for r in rows if r.get("machine_detail")}
    return tuple(sorted(found, key=str)) or None


def _read_machines(data: list[dict] | None) -> tuple[Machine, ...] | None:
    return None if data is None else tuple(Machine.of(d) for d in data)


def _present(rows: list[dict], key: str) -> list:
    """The values of ``key`` in the rows that have one."""
    return [r[key] for r in rows if r.get(key) is not None]


def _summed(rows, key: str) -> float | None:
    """The sum of ``key`` over ``rows`` (None where no row has it)."""
    values = _present(rows, key)
    return round(sum(values), 1) if values else None


def _median(rows: list[dict], key: str) -> float | None:
    """The median of ``key`` over the rows that have it (None where none does)."""
    values = sorted(_present(rows, key))
    return values[len(values) // 2] if values else None


def _load(rows: list[dict]) -> tuple[float, float] | None:
    """The median and maximum of the rows' ``load_1m`` (None where no row has it)."""
    median = _median(rows, "load_1m")
    return None if median is None else (median, max(_present(rows, "load_1m")))


def _distinct(rows: list[dict], key: str) -> tuple:
    return tuple(sorted({str(r[key]) for r in rows if r.get(key) is not None}))
