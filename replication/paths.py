"""Where the project's folders are.

The configs ship inside the package (``replication/conf``; a clone's top-level ``conf`` is a link to
it).  Relative paths in a config (``store``, ``reports``, the data roots) are taken from the project
directory: ``$REPLICATION_HOME`` when set, else the working directory, so an installed
``pf-replicate`` writes ``experiments/`` and ``reports/`` where it is run, as a clone's ``make`` does.
The command line fixes ``REPLICATION_HOME`` at start, so its workers and companions agree with it.
"""

import os
from pathlib import Path

PACKAGE_DIR = Path(__file__).resolve().parent
CONF_DIR = PACKAGE_DIR / "conf"
HOME_VARIABLE = "REPLICATION_HOME"


def project_dir() -> Path:
    """``$REPLICATION_HOME`` if set, else the working directory."""
    return Path(os.environ.get(HOME_VARIABLE) or os.getcwd()).resolve()


def resolve(path: str | Path) -> Path:
    path = Path(path)
    return path if path.is_absolute() else project_dir() / path


def inside_project(path: str | Path) -> bool:
    """Whether ``path`` (resolved, links followed) lies in the project directory."""
    return resolve(path).resolve().is_relative_to(project_dir())


def experiment_names(*config_dirs: Path) -> list[str]:
    """The experiments of ``conf/experiment/`` and of each extra Hydra config dir's ``experiment/``."""
    return sorted({p.stem for folder in (CONF_DIR, *config_dirs) for p in (Path(folder) / "experiment").glob("*.yaml")})
