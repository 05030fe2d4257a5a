"""Which code, libraries and machine computed a run.

:func:`code_digest` is part of every run key, so a change to any module that
can change a run's numbers gives new runs rather than stale ones.  It hashes
the source of every module of the package except those that never compute a run
(:data:`READ_ONLY`: the evidence and report layers, the command line, the reader of stored records,
the export of results for other toolkits).
:func:`provenance` is written into every record, and the report shows it.
"""

import datetime
import hashlib
import importlib.metadata
import platform
import subprocess
from functools import lru_cache
from pathlib import Path

PACKAGE = Path(__file__).resolve().parent.parent
# what never computes a run (prefixes of paths inside the package): the evidence and report layers (deciding
# and drawing), the command line and its checks, the reader of stored runs and the export of results for
# other toolkits
READ_ONLY = ("evidence/", "report/", "cli.py", "__main__.py", "scenes/__main__.py", "runner/preflight.py",
             "runner/results.py", "export.py")
LIBRARIES = {"numpy": "numpy", "scipy": "scipy", "opencv": "opencv-python-headless", "numba": "numba"}  # column: distribution


@lru_cache(maxsize=4)
def code_digest(package: Path = PACKAGE) -> str:
    """SHA-256 (12 hex digits) of the path and bytes of each source file of ``package`` that computes runs."""
    digest = hashlib.sha256()
    for path in sorted(package.rglob("*.py")):
        relative = path.relative_to(package)
        if relative.as_posix().startswith(READ_ONLY):
            continue
        digest.update(relative.as_posix().encode() + b"\0" + path.read_bytes() + b"\0")
    return digest.hexdigest()[:12]


@lru_cache(maxsize=1)
def _git() -> dict:
    """The checkout's commit and whether its tree had changes; None for both outside a git checkout."""
    def git(*args: str) -> str | None:
        try:
            done = subprocess.run(["git", "-C", str(PACKAGE.parent), *args], capture_output=True, text=True,
                                  timeout=10)
        except (OSError, subprocess.SubprocessError):
            return None
        return done.stdout.strip() if done.returncode == 0 else None

    commit = git("rev-parse", "HEAD")
    status = git("status", "--porcelain", "--untracked-files=no", "--", "replication") if commit else None
    return {"git_commit": commit, "git_dirty": None if status is None else bool(status)}


@lru_cache(maxsize=1)
def _environment() -> dict:
    versions = {}
    for column, distribution in LIBRARIES.items():
        try:
            versions[f"{column}_version"] = importlib.metadata.version(distribution)
        except importlib.metadata.PackageNotFoundError:
            versions[f"{column}_version"] = None
    return {
        "code_digest": code_digest(),
        **_git(),
        "python_version": platform.python_version(),
        **versions,
        "machine": f"{platform.machine()} {_cpu()}".strip(),
    }


def _cpu() -> str:
    """The CPU's model name (Linux), else what the platform module knows."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor()


def provenance() -> dict:
    """What a record says of where it came from: code digest, git commit and dirtiness (of the
    package's tree), library versions, machine, and the UTC time it was computed."""
    return {**_environment(), "computed_at": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")}
