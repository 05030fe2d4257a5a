"""One parser for every command's ``key=value`` arguments (``python -m replication.report``, ``scenes``,
``export``, ``record``, ``verify``, the PDF and calibration pages).

A command declares its settings as a frozen dataclass: each field a key, its type (``str``, ``bool`` written
``true``/``false``, ``int``, ``tuple[str, ...]`` written ``a,b``, each optional with ``| None``) and its
default.  :func:`parse` reads ``argv`` into that value, and hands on the arguments the command passes to
Hydra (``handed``: keys, prefixes ending in ``.``, or ``*`` for any other key); a bare word, a key it neither
declares nor hands on, or a value of the wrong type is one :class:`~replication.errors.ConfigError` line
naming the known keys (:func:`read`: said, and the command stops with status 2).
"""

import dataclasses
import types
import typing
from typing import Any, TypeVar

from replication.errors import ConfigError, fail

T = TypeVar("T")


def parse(argv: list[str], settings: type[T], command: str, handed: tuple[str, ...] = ()) -> tuple[T, list[str]]:
    """``argv`` as ``settings`` (a later ``key=`` over an earlier one), and the arguments ``handed`` names (by
    their key, ``+`` and ``~`` stripped), in their order, for Hydra."""
    fields = [f.name for f in dataclasses.fields(settings)]
    hints = typing.get_type_hints(settings)
    values, passed = {}, []
    for arg in argv:
        key, equals, value = arg.partition("=")
        if not equals and not (arg.startswith("~") and "*" in handed):  # Hydra's ~key: a deletion
            raise ConfigError(f"arguments are key=value; got {arg}")
        if key in fields and equals:
            values[key] = _typed(key, value, hints[key])
        elif any(_hands(name, key.lstrip("+~")) for name in handed):
            passed.append(arg)
        else:
            known = [f"{k}=" for k in fields] + [f"{k}<key>=" if k.endswith(".") else f"{k}=" for k in handed]
            raise ConfigError(f"unknown option {key!r} for {command}; known: {', '.join(known)}")
    return settings(**values), passed


def read(argv: list[str], settings: type[T], command: str, handed: tuple[str, ...] = ()) -> tuple[T, list[str]]:
    """:func:`parse`, a bad argument said in one line and the command stopped (status 2)."""
    try:
        return parse(argv, settings, command, handed)
    except ConfigError as error:
        fail(str(error))


def _hands(name: str, key: str) -> bool:
    return name == "*" or key == name or (name.endswith(".") and key.startswith(name))


def names(value: str) -> tuple[str, ...]:
    """A list written ``a,b`` (``experiment=gps_qmcpf,hspf``): its names."""
    return tuple(value.split(","))


def _typed(key: str, value: str, wanted: Any) -> Any:
    members = typing.get_args(wanted) if typing.get_origin(wanted) in (typing.Union, types.UnionType) else (wanted,)
    wanted = next(m for m in members if m is not type(None))
    if wanted is bool:
        if value.lower() not in ("true", "false"):
            raise ConfigError(f"{key} must be true or false, got {value!r}")
        return value.lower() == "true"
    if wanted is int:
        try:
            return int(value)
        except ValueError:
            raise ConfigError(f"{key} must be an integer, got {value!r}") from None
    if typing.get_origin(wanted) is tuple:
        return names(value)
    return value
