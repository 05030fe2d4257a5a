"""One way in for every method: ``filter:`` in an experiment names its builder by an entry point of the
group :data:`GROUP` or by an import path, ``module:name``.

This package registers its own builders as entry points (``pyproject.toml``), exactly as an installed
distribution registers a user's (``filter: my_pf`` after ``pip install my-pf``); a builder that is not
installed is named by where it lives (``filter: mypkg.filters:MyPF``, its folder on ``PYTHONPATH``).  A
builder is a class or function whose keyword parameters are the method's config keys, annotated as the
built-ins' are (the config check reads them), and it returns an object with ``run(model, observations,
rng) -> FilterOutput`` (and ``start`` / ``step`` to track in video), as :func:`~.bootstrap.bootstrap` does,
and may declare how its methods are drawn (:func:`drawn`).  The entry points are read into :data:`FILTERS`
(a :class:`~replication.kinds.Registry`) at its first lookup.  Everything that can go wrong in finding or
building one is one :class:`~replication.errors.ConfigError` line naming the filter.
"""

import importlib
import importlib.metadata
from collections.abc import Callable
from typing import Any

from replication.errors import ConfigError
from replication.kinds import Registry

GROUP = "replication.filters"
# a method's keys its builder never sees: filter names the builder, label and look show the method
# (replication.display), sweep, only and observation plan its runs (replication.runner.config)
RESERVED = ("filter", "label", "look", "sweep", "only", "observation")


def _entry_points():
    """Every entry point of :data:`GROUP`, by name; two distributions registering one name is an error."""
    found: dict[str, importlib.metadata.EntryPoint] = {}
    for point in importlib.metadata.entry_points(group=GROUP):
        other = found.setdefault(point.name, point)
        if other.value != point.value:
            raise ConfigError(f"two filters are registered as {point.name!r}: {other.value} (by {_by(other)}) "
                              f"and {point.value} (by {_by(point)}); uninstall one")
    if not found:
        raise ConfigError(f"no filter is registered under {GROUP}: install this package (make setup, or "
                          "pip install -e .)")
    return found.items()


FILTERS: Registry[importlib.metadata.EntryPoint] = Registry("filter", load=_entry_points,
                                                            hint=" (or an import path, module:name)")


def builder(name: str) -> Callable:
    """The builder ``name`` names: an import path ``module:attribute`` or a registered entry point."""
    if not isinstance(name, str) or not name:
        raise ConfigError(f"filter must name a builder (a registered name or module:name), got {name!r}")
    module, _, attribute = (name if ":" in name else FILTERS[name].value).partition(":")
    return _callable(name, _attribute(name, _module(name, module), attribute))


def builders() -> dict[str, Callable]:
    """Every registered builder, by name."""
    return {name: builder(name) for name in sorted(FILTERS)}


def drawn(colour: str, line: str = "-", marker: str = "o") -> Callable[[Callable], Callable]:
    """Declare how the decorated builder's methods are drawn on every figure: a colour of the Okabe-Ito
    palette by name, a line style and a marker (:mod:`replication.display`, which reads it as
    ``builder.look``); a method's own ``look:`` says what differs."""
    def declare(made: Callable) -> Callable:
        made.look = {"colour": colour, "line": line, "marker": marker}
        return made
    return declare


def build_filter(method: str, params: dict[str, Any], condition: str = ""):
    """Method ``method``'s filter from its config ``params`` (``filter:`` names the builder); a parameter the
    builder refuses is a one-line :class:`~replication.errors.ConfigError` naming the method."""
    make = builder(params.get("filter"))
    try:
        return make(**{k: v for k, v in params.items() if k not in RESERVED})
    except (TypeError, ValueError) as error:
        where = f" at {condition}" if condition else ""
        raise ConfigError(f"method {method!r}{where}: {error}") from None


def _module(name: str, module: str):
    try:
        return importlib.import_module(module)
    except Exception as error:  # a plugin's import can raise anything: the user sees which, in one line
        raise ConfigError(f"filter {name!r}: module {module} does not import ({type(error).__name__}: "
                          f"{error})") from None


def _attribute(name: str, module, attribute: str):
    found = module
    for part in attribute.split("."):
        if not hasattr(found, part):
            raise ConfigError(f"filter {name!r}: module {module.__name__} has no {attribute!r}")
        found = getattr(found, part)
    return found


def _callable(name: str, found) -> Callable:
    if not callable(found):
        raise ConfigError(f"filter {name!r} is a {type(found).__name__}, not a builder (a class or function)")
    return found


def _by(point: importlib.metadata.EntryPoint) -> str:
    dist = point.dist
    return f"{dist.name} {dist.version}" if dist is not None else "an unknown distribution"
