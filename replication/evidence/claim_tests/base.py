"""What every claim test shares: its options' base (:class:`ClaimSpec`), the registry of tests by name
(:data:`CLAIM_TESTS`), the conditions a reading names (:func:`named`) and :class:`ClaimTest`."""

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar

import pandas as pd

from replication.evidence.checks import Check
from replication.evidence.named_conditions import as_mappings, matching
from replication.evidence.tables import Table
from replication.kinds import Registry
from replication.specs import Spec, kind_named


@dataclass(frozen=True, kw_only=True)
class ClaimSpec(Spec):
    """What every reading's test names: the test, and the ``conditions`` it is checked at (each a mapping of
    values, :func:`named`; none: each condition of the runs)."""

    test: str
    conditions: Any = None

    @property
    def naming(self) -> tuple:
        """The options that name conditions, as written (:func:`named` reads them)."""
        return (self.conditions,)

    @property
    def reads(self) -> tuple[str, ...]:
        """The run columns its test reads (a metric, a cost): on runs that recorded none of one, the reading
        is not testable (runs computed before the column was measured)."""
        return ()

    @property
    def basis(self) -> str:
        """What the methods are compared at: "" where at the paper's own settings (equal N), else the budget
        they are given in common (its label: "likelihood evaluations per step", "time per frame (ms)")."""
        return ""

    @property
    def sized(self) -> bool:
        """Whether it tests the paper's own size (its checks then carry the replication criteria's effects)."""
        return False


@dataclass(frozen=True, kw_only=True)
class Measured(ClaimSpec):
    """A test of one run ``metric`` (the spec of every test that reads one)."""

    metric: str

    @property
    def reads(self) -> tuple[str, ...]:
        return (self.metric,)


CLAIM_TESTS: Registry[type["ClaimTest"]] = Registry("claim test")
READING_KEYS = ("name", "experiment", "ours")  # a reading's own keys, beside its test's options


def claim_spec(written: Mapping | ClaimSpec, where: str = "a claim's reading") -> ClaimSpec:
    """A reading's test as its kind declares it (``test:``), checked (:meth:`~replication.specs.Spec.of`)."""
    if isinstance(written, ClaimSpec):
        return written
    made = kind_named(written, CLAIM_TESTS, written.get("test") if isinstance(written, Mapping) else None, where,
                      "a reading")
    return made.Spec.of({k: v for k, v in written.items() if k not in READING_KEYS}, f"{where} ({made.name})",
                        READING_KEYS)


def named(spec: ClaimSpec, where: str = "a claim's reading") -> list[dict]:
    """The conditions a reading names (``conditions:``, a threshold's ``condition:``, a pareto's ``chosen:``),
    each a mapping of variables to values that picks every condition taking them
    (:mod:`~replication.evidence.named_conditions`): each condition picked is a check of its own, as each
    condition is where the reading names none."""
    return [condition for value in spec.naming for condition in as_mappings(value, where)]


class ClaimTest:
    """How a reading tests its claim; subclasses register by ``name``, declare their options (``Spec``) and
    turn records into checks."""

    name: ClassVar[str]
    Spec: ClassVar[type[ClaimSpec]] = ClaimSpec
    needs_runs: ClassVar[bool] = True  # False for a test of something computed, not run (point sets)

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        CLAIM_TESTS.register(cls.name, cls)

    def __init__(self, spec: ClaimSpec, experiment: dict, published: pd.DataFrame | None = None):
        self.spec, self.experiment, self.published = spec, experiment, published

    @classmethod
    def of(cls, spec: Mapping | ClaimSpec, experiment: dict, published: pd.DataFrame | None = None) -> "ClaimTest":
        """The test a reading names, on its typed spec (a mapping is checked first: :func:`claim_spec`)."""
        spec = claim_spec(spec)
        return CLAIM_TESTS[spec.test](spec, experiment, published)

    def checks(self, records: pd.DataFrame, tables: dict[str, Table]) -> list[Check]:
        raise NotImplementedError

    @property
    def tables(self) -> list[str]:
        """The names of the experiment's tables the test judges (none: it judges the records)."""
        return []

    def conditions(self, records: pd.DataFrame) -> list[str]:
        """The labels of the conditions of ``records`` that the reading names (:func:`named`), each once, in the
        order named; every condition of ``records`` where it names none."""
        wanted = named(self.spec)
        if not wanted:
            return list(dict.fromkeys(records["condition"]))
        return list(dict.fromkeys(label for w in wanted for label in records.loc[matching(records, w), "condition"]))


def listed(value) -> list:
    """One name or a list of them, as a list."""
    return [] if value is None else list(value) if isinstance(value, (list, tuple)) else [value]
