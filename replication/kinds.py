"""One registry type for every kind a config names: a name written in YAML -> the code it stands for.

The tasks (:data:`replication.tasks.TASKS`), the resampling schemes (:data:`replication.smc.resampling.RESAMPLERS`),
the scene kinds (:data:`replication.scenes.kinds.SCENE_KINDS`) and the filters (fed from the entry points of
``replication.filters``: :data:`replication.filters.registry.FILTERS`) are each a :class:`Registry`.  A kind is
registered by a table (``Registry("task", {"scalar": scalar, ...})``), by decorating it
(``@KINDS.register("name")``), by a base class's ``__init_subclass__`` calling :meth:`Registry.register`, or
by a loader read at the first lookup (entry points); however it came in, a name the registry does not
know is one :class:`~replication.errors.ConfigError` line naming the known ones.
"""

from collections.abc import Callable, Iterable, Iterator, Mapping
from typing import Generic, TypeVar

from replication.errors import ConfigError

T = TypeVar("T")
_UNSET = object()


class Registry(Generic[T]):
    """The kinds of one sort (``what``: ``"task"``, ``"scene kind"``) by name, in the order registered.

    ``load`` (a function giving ``(name, kind)`` pairs) fills the registry at its first use, and again after
    :meth:`forget`; ``hint`` ends the message of an unknown name (another way to name a kind)."""

    def __init__(self, what: str, kinds: Mapping[str, T] | Iterable[tuple[str, T]] = (), *,
                 load: Callable[[], Iterable[tuple[str, T]]] | None = None, hint: str = ""):
        self.what, self.hint, self._load = what, hint, load
        self._kinds: dict[str, T] | None = None
        for name, kind in (kinds.items() if isinstance(kinds, Mapping) else kinds):
            self.register(name, kind)

    def register(self, name: str, kind=_UNSET):
        """Register ``kind`` as ``name`` and return it; without ``kind``, a decorator that does.  Two kinds
        under one name is an error (one name, one meaning)."""
        if kind is _UNSET:
            return lambda decorated: self.register(name, decorated)
        known = self._known()
        if known.setdefault(name, kind) is not kind:
            raise ValueError(f"two {self.what}s are registered as {name!r}: {known[name]!r} and {kind!r}")
        return kind

    def forget(self) -> None:
        """Read the kinds from ``load`` again at the next use (a distribution installed meanwhile)."""
        self._kinds = None

    def __getitem__(self, name: str) -> T:
        known = self._known()
        try:
            return known[name]
        except (KeyError, TypeError):  # TypeError: not a name at all (a list or mapping from YAML)
            raise ConfigError(f"unknown {self.what} {name!r}; known {self.what}s: {', '.join(sorted(known))}"
                              f"{self.hint}") from None

    def __contains__(self, name: object) -> bool:
        try:
            return name in self._known()
        except TypeError:
            return False

    def __iter__(self) -> Iterator[str]:
        return iter(list(self._known()))

    def __len__(self) -> int:
        return len(self._known())

    def items(self) -> list[tuple[str, T]]:
        return list(self._known().items())

    def values(self) -> list[T]:
        return list(self._known().values())

    def __repr__(self) -> str:
        return f"Registry({self.what!r}: {', '.join(self._known())})"

    def _known(self) -> dict[str, T]:
        if self._kinds is None:
            self._kinds = {}
            if self._load is not None:
                try:
                    for name, kind in self._load():
                        self.register(name, kind)
                except BaseException:
                    self._kinds = None  # a loader that failed is asked again, not remembered as empty
                    raise
        return self._kinds
