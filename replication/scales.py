"""The two scales an experiment runs at, a config read at one of them, and where each scale's reports live.

A config writes ``{paper: a, quick: b}`` wherever the scale matters (run counts, a scene's frames, the
last frame of a real sequence); :func:`at_scale` keeps the entry for the scale asked for.  The default
scale is ``conf/config.yaml``'s (:func:`default_scale`).  The two scales' reports live apart
(:func:`report_folder`), so that running one never replaces the other's page or verdict; what a scale changes
from the paper's is :func:`scale_changes`.  A low module (no
numerical stack): the preflight checks, the runner, the report and the scenes command all read it.
"""

from pathlib import Path
from typing import Any

import yaml

from replication.paths import CONF_DIR

SCALES = ("paper", "quick")
QUICK_REPORTS = "quick"  # <reports>/quick/<name>/: the quick scale's reports, beside the paper scale's
SCALED = ("runs", "scenes", "model", "methods")  # where a config's scale takes effect (not its YAML anchors)


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


def scale_changes(paper: dict, scaled: dict, path: str = "") -> list[str]:
    """What ``scaled`` (an experiment's config at a scale, as run: its real sequences located, a user's own in
    place of the shipped ones) changes from ``paper`` (the same at the paper's scale), as ``'<where>: a -> b'``
    (``all`` for a null: every frame)."""
    if isinstance(paper, dict) and isinstance(scaled, dict):
        return [change for key in paper if key in scaled and (path or key in SCALED)
                for change in scale_changes(paper[key], scaled[key], f"{path}.{key}")]
    if isinstance(paper, list) and isinstance(scaled, list) and len(paper) == len(scaled) \
            and any(isinstance(value, dict) for value in paper):
        return [change for i, (a, b) in enumerate(zip(paper, scaled))
                for change in scale_changes(a, b, f"{path}[{i}]")]
    if paper == scaled:
        return []
    shown = ["all" if v is None else str(v) for v in (paper, scaled)]
    return [f"{_where(path)}: {shown[0]} -> {shown[1]}"]


def _where(path: str) -> str:
    """A config path as a reader says it: 'runs', 'scene exp2_16_targets frames', 'scene Girl last frame'."""
    parts = path.strip(".").split(".")
    if parts[0] == "scenes" and len(parts) >= 3:
        what = {"frames": "frames", "last": "last frame"}.get(parts[-1], parts[-1])
        return f"scene {parts[1]} {what}"
    return " ".join(parts)
