"""The two scales an experiment runs at, and a config read at one of them.

A config writes ``{paper: a, quick: b}`` wherever the scale matters (run counts, a scene's frames, the
last frame of a real sequence); :func:`at_scale` keeps the entry for the scale asked for.  A low module
(no numerical stack): the preflight checks, the runner and the scenes command all read it.
"""

from typing import Any

SCALES = ("paper", "quick")


def at_scale(value: Any, scale: str) -> Any:
    """Replace every ``{paper: a, quick: b}`` inside ``value`` by the entry for ``scale``."""
    if isinstance(value, dict):
        if set(value) == set(SCALES):
            return at_scale(value[scale], scale)
        return {k: at_scale(v, scale) for k, v in value.items()}
    if isinstance(value, list):
        return [at_scale(v, scale) for v in value]
    return value
