"""A kind's options as a typed value: the one way a spec written in YAML becomes what the code reads.

Every kind a config names with options of its own (a report table, a figure, a claim's test) declares those
options as the fields of a frozen dataclass deriving from :class:`Spec`, with their types and defaults.
:meth:`Spec.of` turns the mapping the YAML wrote into that value, or refuses it in one
:class:`~replication.errors.ConfigError` line naming where it is written, the option and the options the kind
takes: an option the kind does not declare (``logy`` for ``log_y``), one it needs and lacks, or a value of the
wrong type.  The code then reads ``spec.log_y``, never ``spec.get("log_y")``.
"""

import dataclasses
import types
import typing
from collections.abc import Mapping
from typing import Any, Self

from replication.errors import ConfigError

_SAID = {str: "a string", int: "an integer", float: "a number", bool: "true or false", type(None): "null",
         dict: "a mapping", list: "a list"}


@dataclasses.dataclass(frozen=True)
class Spec:
    """The options of one kind, as fields; a subclass is a frozen dataclass declaring its own."""

    @classmethod
    def options(cls) -> tuple[str, ...]:
        return tuple(f.name for f in dataclasses.fields(cls))

    @classmethod
    def of(cls, written: Mapping, where: str, named: tuple[str, ...] = ()) -> Self:
        """The spec ``written`` (a mapping from YAML) declares, checked against this kind's options (``named``:
        keys the caller has read already, such as ``kind:``, allowed and not passed on); ``where``: the file
        and entry, said first in an error."""
        if not isinstance(written, Mapping):
            raise ConfigError(f"{where}: a spec is a mapping of options, got {written!r}")
        declared = {f.name: f for f in dataclasses.fields(cls)}
        known = ", ".join([*named, *declared])
        for key in written:
            if key not in declared and key not in named:
                raise ConfigError(f"{where}: unknown option {key!r}; known options: {known}")
        hints = typing.get_type_hints(cls)
        values = {}
        for name, field in declared.items():
            if name not in written:
                if field.default is dataclasses.MISSING and field.default_factory is dataclasses.MISSING:
                    raise ConfigError(f"{where}: lacks the option {name!r}; known options: {known}")
                continue
            value = written[name]
            if not _fits(value, hints[name]):
                raise ConfigError(f"{where}: {name} must be {_said(hints[name])}, got {value!r}")
            values[name] = _frozen(value, hints[name])
        return cls(**values)


def kind_named(written: Any, kinds, name: Any, where: str, what: str):
    """The kind ``name`` stands for in registry ``kinds``, for a spec ``written`` that must be a mapping of
    options (``what``: how the error names it, "a figure"); refused in one line said from ``where``."""
    if not isinstance(written, Mapping):
        raise ConfigError(f"{where}: {what} is a mapping of options, got {written!r}")
    try:
        return kinds[name]
    except ConfigError as error:
        raise ConfigError(f"{where}: {error}") from None


def _members(wanted: Any) -> tuple:
    return typing.get_args(wanted) if typing.get_origin(wanted) in (typing.Union, types.UnionType) else (wanted,)


def _fits(value: Any, wanted: Any) -> bool:
    """Whether a value read from YAML fits a field's annotation (simple types, unions, lists, tuples, mappings)."""
    if wanted is Any:
        return True
    if typing.get_origin(wanted) in (typing.Union, types.UnionType):
        return any(_fits(value, member) for member in typing.get_args(wanted))
    if wanted in (None, type(None)):
        return value is None
    if wanted is float:
        return isinstance(value, (int, float)) and not isinstance(value, bool)
    if wanted is int:
        return isinstance(value, int) and not isinstance(value, bool)
    origin, args = typing.get_origin(wanted) or wanted, typing.get_args(wanted)
    if origin in (list, tuple):
        inner = args[0] if args else Any
        return isinstance(value, (list, tuple)) and all(_fits(v, inner) for v in value)
    if origin in (dict, Mapping):
        key, inner = args or (Any, Any)
        return isinstance(value, Mapping) and all(_fits(k, key) and _fits(v, inner) for k, v in value.items())
    return isinstance(value, origin)


def _frozen(value: Any, wanted: Any) -> Any:
    """A list read from YAML as the tuple a ``tuple[...]`` field declares."""
    tupled = any((typing.get_origin(m) or m) is tuple for m in _members(wanted))
    return tuple(value) if tupled and isinstance(value, list) else value


def _said(wanted: Any) -> str:
    """A type in words, for an error: 'a number or null', 'a list of strings'."""
    said = []
    for member in _members(wanted):
        origin, args = typing.get_origin(member) or member, typing.get_args(member)
        if origin in (list, tuple) and args and args[0] in _SAID:
            said.append(f"a list of {_SAID[args[0]].removeprefix('an ').removeprefix('a ')}s")
        else:
            said.append(_SAID.get(origin, getattr(origin, "__name__", str(origin))))
    return " or ".join(dict.fromkeys(said))
