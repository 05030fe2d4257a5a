"""What the distribution declares is what the code needs: the papers' numbers ship inside it, every library
it imports is declared, and the lowest versions it allows (its floors) pass the suite."""

import ast
import os
import re
import subprocess
import sys
import tomllib
import warnings
from importlib.metadata import packages_distributions
from pathlib import Path

import pytest

from replication.evidence.published import PACKAGED, load_published, published_path

ROOT = Path(__file__).resolve().parent.parent
SHARED = ROOT.parent / "shared" / "reference" / "published_values.csv"
PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]


def _name(requirement: str) -> str:
    """A requirement's distribution name, normalised (PEP 503): ``"scipy>=1.15"`` -> ``scipy``."""
    return re.sub(r"[-_.]+", "-", re.match(r"[A-Za-z0-9._-]+", requirement).group()).lower()


def _floor(requirement: str) -> str | None:
    """The lowest version a requirement allows (its ``>=``), or None."""
    found = re.search(r">=\s*([0-9][0-9a-z.]*)", requirement)
    return found.group(1) if found else None


@pytest.mark.skipif(not SHARED.exists(), reason="../shared is not beside this clone")
def test_the_packaged_published_values_are_the_shared_ones():
    assert PACKAGED.read_bytes() == SHARED.read_bytes(), (
        f"{PACKAGED.relative_to(ROOT)} differs from {SHARED}: copy the shared file over it")


def test_no_configured_published_values_means_the_packaged_ones(tmp_path):
    assert published_path(None) == PACKAGED
    assert published_path(tmp_path / "mine.csv") == tmp_path / "mine.csv"
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the packaged file is there: no "published values not found"
        table = load_published(str(PACKAGED))
    assert set(table["paper"]) == {"bis_pf", "fusion_pf", "gps_qmcpf", "hspf", "ism_pf"}


def _imported_distributions() -> dict[str, set[str]]:
    """Each third-party distribution the package imports (anywhere, functions included) -> the modules importing it."""
    providers, found = packages_distributions(), {}
    for path in (ROOT / "replication").rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                names = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
                names = [node.module]
            else:
                continue
            for top in {name.split(".")[0] for name in names} - set(sys.stdlib_module_names) - {"replication"}:
                for distribution in providers.get(top, [top]):
                    found.setdefault(_name(distribution), set()).add(path.relative_to(ROOT).as_posix())
    return found


def test_every_library_the_package_imports_is_declared():
    declared = {_name(r) for r in PYPROJECT["dependencies"]}
    cluster = {_name(r) for r in PYPROJECT["optional-dependencies"]["cluster"]}
    imported = _imported_distributions()
    # cv2 is provided by either OpenCV wheel; the project declares the headless one (pyproject.toml's comment)
    imported.pop("opencv-python", None)
    assert "opencv-python-headless" in imported
    undeclared = {name: sorted(where) for name, where in imported.items() if name not in declared | cluster}
    assert not undeclared, f"imported but not declared in pyproject.toml: {undeclared}"
    # the cluster backends are imported by the runner alone, when parallel.backend names them (and by its
    # starter of a cluster on the loopback, when one is started)
    assert {name for name in imported if name in cluster} == cluster
    runner = {"replication/runner/backends.py", "replication/runner/loopback.py"}
    assert all("replication/runner/backends.py" in where and where <= runner
               for name, where in imported.items() if name in cluster), imported


@pytest.mark.e2e
def test_an_installed_package_judges_the_papers_claims_from_an_empty_folder(tmp_path):
    """Built and installed as pip does (no ``../shared`` beside it, no clone): the configs, the claims and
    the published values come with it."""
    site, empty = tmp_path / "site", tmp_path / "empty"
    empty.mkdir()
    subprocess.run([sys.executable, "-m", "pip", "install", "--quiet", "--no-deps", "--target", str(site), str(ROOT)],
                   check=True, capture_output=True, cwd=tmp_path)
    script = ("import warnings; warnings.simplefilter('error'); import replication\n"
              "from replication.evidence.published import load_published, published_path\n"
              "from replication.evidence.claims import load_papers\n"
              "print(replication.__file__); print(len(load_published(str(published_path(None)))))\n"
              "print(sum(len(p.claims) for p in load_papers()))")
    environment = {k: v for k, v in os.environ.items() if k not in ("REPLICATION_HOME", "PYTHONPATH")}
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, cwd=empty,
                          env={**environment, "PYTHONPATH": str(site)})
    assert done.returncode == 0, done.stderr
    where, cells, claims = done.stdout.split()
    assert Path(where).is_relative_to(site)  # the installed copy, not this clone's
    assert int(cells) == len(load_published(str(PACKAGED)))
    assert int(claims) > 0


def _lowest(name: str, floor: str, python: Path) -> str:
    """The lowest released version of ``name`` at or above ``floor`` (``pip index versions``; a listed version
    that is not PEP 440, such as an old upload's ``0.7.0d``, pip cannot install by that name either: left out)."""
    from packaging.version import InvalidVersion, Version

    def parsed(text: str) -> Version | None:
        try:
            return Version(text)
        except InvalidVersion:
            return None

    listed = subprocess.run([str(python), "-m", "pip", "index", "versions", name], capture_output=True, text=True,
                            check=True).stdout
    versions = [v for v in map(parsed, re.search(r"Available versions: (.*)", listed).group(1).split(", ")) if v]
    return str(min(v for v in versions if v >= Version(floor) and not v.is_prerelease))


@pytest.mark.slow
@pytest.mark.e2e
def test_the_declared_floors_pass_the_fast_tests(tmp_path):
    """Every dependency at the lowest version pyproject.toml allows (its own, the cluster extra's and the test
    extra's), in a fresh venv, passes the tests ``make test`` and ``make test-e2e`` run: a floor that lies fails here.  Twenty
    minutes and the network: ``-m slow``."""
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
    python = venv / "bin" / "python"
    requirements = PYPROJECT["dependencies"] + [r for r in PYPROJECT["optional-dependencies"]["test"]
                                                if not r.startswith(PYPROJECT["name"])]
    requirements += PYPROJECT["optional-dependencies"]["cluster"]
    pins = [f"{_name(r)}=={_lowest(_name(r), _floor(r), python)}" if _floor(r) else _name(r) for r in requirements]
    (tmp_path / "floors.txt").write_text("\n".join(pins) + "\n")
    install = [str(python), "-m", "pip", "install", "--quiet"]
    subprocess.run(install + ["-c", str(tmp_path / "floors.txt"), *pins], check=True)
    headless = next(p for p in pins if p.startswith("opencv-python-headless"))  # as make setup: the headless cv2 last
    subprocess.run(install + ["--force-reinstall", "--no-deps", headless], check=True)
    subprocess.run(install + ["--no-deps", "-e", str(ROOT)], check=True)
    done = subprocess.run([str(python), "-m", "pytest", "-q", "--maxfail=20", "-m", "not slow", "-p", "no:cacheprovider",
                           "-n", "2", "--dist", "loadgroup"], cwd=ROOT, capture_output=True, text=True)
    assert done.returncode == 0, f"at the floors {pins}:\n{done.stdout[-3000:]}"
