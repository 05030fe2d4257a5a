"""The two scales an experiment runs at, a config read at one of them, and where each scale's reports live.

A config writes ``{paper: a, quick: b}`` wherever the scale matters (run counts, a scene's frames, the
last frame of a real sequence); :func:`at_scale` keeps the entry for the scale asked for.  The default
scale is ``conf/config.yaml``'s (:func:`default_scale`).  The two scales' reports live apart
(:func:`report_folder`), so that running one never replaces the other's page or verdict.  A low module (no
numerical stack): the preflight checks, the runner, the report and the scenes command all read it.
"""

from pathlib import Path
from typing import Any

import yaml

from replication.paths import CONF_DIR

SCALES = ("paper", "quick")
QUICK_REPORTS = "quick"  # <reports>/quick/<name>/: the quick scale's reports, beside the paper scale's


def at_scale(value: Any, scale: str) -> Any:
    """Replace every ``{paper: a, quick: b}`` inside ``value`` by the entry for ``scale``."""
    if isinstance(value, dict):
        if set(value) == set(SCALES):
            return at_scale(value[scale], scale)
        return {k: at_scale(v, scale) for k, v in value.items()}
    if isinstance(value, list):
        return [at_scale(v, scale) for v in value]
    return value


def default_scale() -> str:
    """The scale a request runs at when it names none: ``conf/config.yaml``'s ``scale``."""
    return yaml.safe_load((CONF_DIR / "config.yaml").read_text())["scale"]


def report_folder(reports: str | Path, name: str, scale: str) -> Path:
    """Where report ``name`` at ``scale`` lives: ``<reports>/<name>/`` at the paper scale, ``<reports>/quick/<name>/``
    at the quick one."""
    return Path(reports) / name if scale == "paper" else Path(reports) / QUICK_REPORTS / name


def page_link(name: str, scale: str) -> str:
    """The page of report ``name`` at ``scale`` as a link from the reports' folder (the index's)."""
    return f"{report_folder('', name, scale).as_posix()}/index.html"


def index_from(name: str, scale: str) -> str:
    """The reports' index (``<reports>/index.html``) as a link from the page of report ``name`` at ``scale``."""
    return "../" * len(report_folder("", name, scale).parts) + "index.html"
