"""Where the project's folders are: relative paths in configs are taken from the project root."""

from pathlib import Path

PROJECT_ROOT = Path(__file__).resolve().parent.parent
CONF_DIR = PROJECT_ROOT / "conf"


def resolve(path: str | Path) -> Path:
    path = Path(path)
    return path if path.is_absolute() else PROJECT_ROOT / path


def experiment_names(*config_dirs: Path) -> list[str]:
    """The experiments of ``conf/experiment/`` and of each extra Hydra config dir's ``experiment/``."""
    return sorted({p.stem for folder in (CONF_DIR, *config_dirs) for p in (Path(folder) / "experiment").glob("*.yaml")})
