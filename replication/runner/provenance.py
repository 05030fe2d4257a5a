"""Which code, libraries and machine computed a run.

:func:`run_code_digest` is part of every run key: the source of the modules
the run executes, found from its task and its filter through their imports,
so a change to a module that can change a run's numbers gives new runs, and
a change to one filter recomputes that filter's runs only.  A module that
gathers others by name (:data:`GATHERING`: the package's top level, the
filters' and tasks' registries) counts with its own source but not with every
module it gathers.  :func:`code_digest` hashes every module that computes
runs (all but :data:`READ_ONLY`: the evidence and report layers, the command
line, the reader of stored records, the export of results for other
toolkits): it goes into every record's provenance.
:func:`provenance` is written into every record, and the report shows it: beside the CPU's name, the code
paths its libraries took on it (:class:`~replication.runner.machine.Machine`).
"""

import ast
import datetime
import hashlib
import importlib.metadata
import importlib.util
import inspect
import platform
import subprocess
from dataclasses import asdict
from functools import lru_cache
from pathlib import Path

from replication.runner.machine import machine

PACKAGE = Path(__file__).resolve().parent.parent
# what never computes a run (prefixes of paths inside the package): the evidence and report layers (deciding
# and drawing), the command line and its checks, the reader of stored runs, what the judge and the figures read
# of the runs' video and series, the export of results for other toolkits, and the paper-scale record
READ_ONLY = ("evidence/", "report/", "record/", "cli.py", "__main__.py", "scenes/__main__.py", "runner/preflight.py",
             "runner/results.py", "runner/footage.py", "runner/curves.py", "export.py")
# modules that gather others by name (re-exports, registries): their source counts for a run that imports them,
# the modules they gather do not (the run's own task and filter are its entries)
GATHERING = ("__init__.py", "filters/__init__.py", "tasks/__init__.py")
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


@lru_cache(maxsize=256)
def run_code_digest(entries: tuple[str, ...], package: Path = PACKAGE) -> str:
    """SHA-256 (12 hex digits) of the path and bytes of each source file a run executes: ``entries`` (paths
    inside ``package``: its task's module, its filter's) and every module they import, transitively, with
    the packages around them (a module in :data:`GATHERING` counts, the modules it imports do not)."""
    found, todo = set(), list(entries)
    while todo:
        relative = todo.pop()
        if relative in found:
            continue
        found.add(relative)
        if relative not in GATHERING:
            todo.extend(_imports(relative, package))
    digest = hashlib.sha256()
    for relative in sorted(found):
        digest.update(relative.encode() + b"\0" + (package / relative).read_bytes() + b"\0")
    return digest.hexdigest()[:12]


def method_code_digest(task, builder) -> str:
    """The code a run of ``builder`` (a method's filter) under ``task`` executes, as 12 hex digits: for a
    built-in, :func:`run_code_digest` of the two; for a user's builder from outside the package (a plugin),
    also the bytes of its own source files (its module and the modules of its own top-level package that it
    imports, transitively, each by its path inside that package) and its distribution's name and version
    where one is installed, so an edit of the plugin gives its runs new keys and leaves the others'."""
    source = Path(inspect.getsourcefile(builder)).resolve()
    if source.is_relative_to(PACKAGE):
        return run_code_digest((source_of(task), source.relative_to(PACKAGE).as_posix()))
    top = builder.__module__.split(".")[0]
    single = builder.__module__ == top and source.name != "__init__.py"  # a module of its own, not a package
    base = source.parent if single else _package_base(top)
    files, entries, todo = set(), {source_of(task)}, [source] if single else [source, base / "__init__.py"]
    while todo:
        path = todo.pop()
        if path in files:
            continue
        files.add(path)
        within = "" if single else ".".join((top, *path.relative_to(base).with_suffix("").parts)[:-1])
        names = _imported_names(ast.parse(path.read_text(), str(path)), within)
        entries |= _module_files({n for n in names if n.split(".")[0] == PACKAGE.name}, PACKAGE)
        todo.extend(base / relative for relative in _module_files({n for n in names if n.split(".")[0] == top}, base))
    digest = hashlib.sha256(run_code_digest(tuple(sorted(entries))).encode())
    for path in sorted(files):
        digest.update(path.relative_to(base).as_posix().encode() + b"\0" + path.read_bytes() + b"\0")
    for distribution in sorted(importlib.metadata.packages_distributions().get(top, [])):
        digest.update(f"{distribution}=={importlib.metadata.version(distribution)}".encode() + b"\0")
    return digest.hexdigest()[:12]


def source_of(code) -> str:
    """The path inside the package of the file that defines ``code`` (a module, class or function): an entry
    of :func:`run_code_digest`."""
    return Path(inspect.getsourcefile(code)).resolve().relative_to(PACKAGE).as_posix()


@lru_cache(maxsize=1024)
def _imports(relative: str, package: Path) -> frozenset[str]:
    """The package's source files that importing ``relative`` runs: the modules it imports (anywhere in it,
    functions included) and the ``__init__.py`` of every package on their way."""
    modules = _imported_names(ast.parse((package / relative).read_text(), relative))
    parts = Path(relative).with_suffix("").parts
    modules.update(".".join((package.name, *parts[:i])) for i in range(len(parts)))  # its own packages
    return frozenset(_module_files({m for m in modules if m.split(".")[0] == package.name}, package) | {"__init__.py"})


def _imported_names(tree: ast.AST, within: str = "") -> set[str]:
    """Every module name a source imports, and ``module.name`` for each name imported from a module (a
    submodule, if it is one); a relative import is resolved against ``within``, the source's own package."""
    modules = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            modules.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and (node.module or node.level):
            up = within.split(".")[: len(within.split(".")) - node.level + 1] if node.level else []
            module = ".".join([*up, *([node.module] if node.module else [])])
            modules.add(module)
            modules.update(f"{module}.{alias.name}" for alias in node.names)
    return modules


def _module_files(modules: set[str], package: Path) -> set[str]:
    """The files inside ``package`` (its folder, named as its top-level module) that importing each of
    ``modules`` runs: the module's own and the ``__init__.py`` of every package on its way."""
    files = set()
    for module in modules:
        names = module.split(".")
        for i in range(2, len(names) + 1):  # every package on the way runs its __init__.py
            path = Path(*names[1:i])
            for candidate in (path.with_suffix(".py"), path / "__init__.py"):
                if (package / candidate).is_file():
                    files.add(candidate.as_posix())
    return files


def _package_base(top: str) -> Path:
    """The folder of a user's top-level package ``top`` (its files are named inside it)."""
    spec = importlib.util.find_spec(top)
    return Path(next(iter(spec.submodule_search_locations))).resolve()


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
        "machine": f"{platform.machine()} {machine().cpu}".strip(),
    }


def provenance() -> dict:
    """What a record says of where it came from: code digest, git commit and dirtiness (of the
    package's tree), library versions, machine (its CPU's name, and in ``machine_detail`` the code paths
    the libraries took on it), and the UTC time it was computed."""
    return {**_environment(), "machine_detail": asdict(machine()),
            "computed_at": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds")}
