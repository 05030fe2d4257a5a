"""How a method is shown: its label in every table and legend, its look on every figure.

A method's label is its ``label:`` in the experiment, else its key.  Its look is a colour of the
Okabe-Ito palette (safe for colour-blind readers, :data:`COLOURS`, by name), a line style and a marker:
the one its filter declares with its builder (:func:`replication.filters.registry.drawn`), with what the
method's own ``look:`` says over it (``look: {line: "--", marker: s}``, a variant of its filter).  By
convention blue is a plain particle filter, vermillion the method a paper proposes, black a reference
(the Bayes-optimal grid, the detections).  Neither ever enters a run's key.
"""

from collections.abc import Mapping
from dataclasses import dataclass

from replication.errors import ConfigError
from replication.kinds import Registry

COLOURS: Registry[str] = Registry("colour", {  # Okabe and Ito (2008), by name
    "orange": "#E69F00", "sky": "#56B4E9", "green": "#009E73", "yellow": "#F0E442",
    "blue": "#0072B2", "vermillion": "#D55E00", "purple": "#CC79A7", "black": "#000000",
})
LINES = ("-", "--", "-.", ":")
MARKERS = ("o", "s", "^", "v", "D", "P", "X", "*", "<", ">", "h")  # "x" and "" (none) may be asked for too
PARTS = ("colour", "line", "marker")


@dataclass(frozen=True)
class Look:
    """A method's colour (hex), line style and marker ("" for none)."""

    colour: str
    linestyle: str
    marker: str

    def line(self) -> dict:
        """Keyword arguments of ``Axes.plot``."""
        return {"color": self.colour, "linestyle": self.linestyle, "marker": self.marker or "None"}

    @classmethod
    def of(cls, said: Mapping, where: str) -> "Look":
        """The look ``said`` asks for (``colour`` by name, ``line`` default "-", ``marker`` default "o"); a
        wrong one is one :class:`ConfigError` line starting with ``where``."""
        if not isinstance(said, Mapping):
            raise ConfigError(f"{where}: a look is {{colour: <name>, line: <style>, marker: <marker>}}, got {said!r}")
        unknown = sorted(set(said) - set(PARTS), key=str)
        if unknown:
            raise ConfigError(f"{where}: unknown part {unknown[0]!r} of a look; a look has {', '.join(PARTS)}")
        if "colour" not in said:
            raise ConfigError(f"{where}: a look names its colour (its filter declares none)")
        line, marker = said.get("line", "-"), said.get("marker", "o")
        if line not in LINES:
            raise ConfigError(f"{where}: unknown line {line!r}; known lines: {', '.join(map(repr, LINES))}")
        if marker not in (*MARKERS, "x", ""):
            raise ConfigError(f"{where}: unknown marker {marker!r}; known markers: "
                              f"{', '.join(map(repr, (*MARKERS, 'x', '')))}")
        try:
            return cls(COLOURS[said["colour"]], line, marker)
        except ConfigError as error:
            raise ConfigError(f"{where}: {error}") from None


def asked_look(params: Mapping, declared: Mapping | None, where: str) -> Look | None:
    """The look a method asks for: the one its builder declares (``declared``), with its config's
    (``params``) own ``look:`` over it; None if neither says one."""
    own = params.get("look")
    if own is None:
        return None if declared is None else Look.of(declared, where)
    return Look.of({**(declared or {}), **own} if isinstance(own, Mapping) else own, where)


def method_label(experiment: dict, method: str) -> str:
    """A method's name in tables and legends: its config's ``label``, else its key."""
    return experiment["methods"].get(method, {}).get("label", method)
