"""The papers' claims, tested: each claim one entry of ``conf/claims/<paper>.yaml``.

A claim is a sentence of the paper with the table or page it comes from,
the published cells that belong to it, and one or more *readings*: ways of
testing it on our runs where the paper leaves a choice open (which success
rule, which sigma).  The first reading is the primary one and gives the
claim's verdict; the others say whether the verdict survives another
defensible reading.

A reading names an experiment and a *test*, a small class registered by
name (:class:`~replication.evidence.claim_tests.ClaimTest`), whose options are
checked as the file is read.  Each test returns
:class:`~replication.evidence.checks.Check` values, combined into the reading's
:class:`~replication.evidence.checks.Result`.
"""

import functools
from dataclasses import dataclass
from pathlib import Path

import pandas as pd
import yaml

from replication.errors import ConfigError
from replication.evidence.checks import Result
from replication.evidence.claim_tests import ClaimSpec, ClaimTest, claim_spec, named
from replication.evidence.tables import Table
from replication.evidence.verdict import Outcome, Verdict
from replication.paths import CONF_DIR

CLAIMS_DIR = CONF_DIR / "claims"
EQUAL_N = "equal N"  # what a reading at the paper's own settings compares at


@dataclass(frozen=True)
class Reading:
    name: str
    experiment: str
    test: ClaimSpec
    ours: str = ""  # what this reading adds to the paper's words (a sequence it did not use, equal cost): never
    # the primary reading's

    @property
    def basis(self) -> str:
        """What the methods are compared at: "" where at the paper's own settings (equal N), else the budget
        they are given in common (its label: "likelihood evaluations per step", "time per frame (ms)")."""
        return self.test.basis

    @property
    def compared_at(self) -> str:
        """The same for a reader: "equal N", or "equal <budget>"."""
        return f"equal {self.basis}" if self.basis else EQUAL_N


@dataclass(frozen=True)
class Quote:
    """The paper's own words for a claim, as its text prints them (``text``, the original language) and
    in English."""

    text: str
    english: str


@dataclass(frozen=True)
class Claim:
    id: str
    paper: str
    text: str  # the claim in plain words, saying no more than its quote
    quote: Quote
    where: str  # section, table or figure (and page) as the paper's text gives them
    cells: dict  # which published cells belong to it: {column: [values]}, every column matching
    readings: tuple[Reading, ...]
    note: str = ""
    untestable: str = ""  # why no reading tests it here (a private video with no stand-in, a lost table)

    def owns(self, cell: pd.Series) -> bool:
        """Whether a published cell (a row of ``published_values.csv``) belongs to this claim."""
        return cell["paper"] == self.paper and bool(self.cells) and all(
            str(cell[column]) in [str(v) for v in _listed(values)] for column, values in self.cells.items())


@dataclass(frozen=True)
class Paper:
    key: str
    title: str
    authors: str
    venue: str
    claims: tuple[Claim, ...]
    path: Path | None = None  # its claims file


@functools.cache
def load_papers(directory: Path = CLAIMS_DIR) -> tuple[Paper, ...]:
    """Every paper's claims, in the order the papers are numbered (``order:`` in each file); read once
    per process (every experiment's report asks for them)."""
    papers = [_paper(path) for path in sorted(Path(directory).glob("*.yaml"))]
    return tuple(paper for _, paper in sorted(papers, key=lambda item: item[0]))


def load_own_papers(directory: Path) -> tuple[Paper, ...]:
    """A user's claims files (the ``claims_dir`` setting) in the papers' format, judged on the user's own
    reports only; a folder without one, a file lacking a key or a reading naming an unknown test or option
    is one :class:`~replication.errors.ConfigError` line naming the file."""
    paths = sorted(Path(directory).glob("*.yaml"))
    if not paths:
        raise ConfigError(f"claims_dir={directory}: no claims file (*.yaml) there")
    papers = []
    for path in paths:
        try:
            order, paper = _paper(path)
        except (KeyError, TypeError, AttributeError, yaml.YAMLError) as error:
            what = f"lacks the key {error}" if isinstance(error, KeyError) else f"is not in the claims format ({error})"
            raise ConfigError(f"{path} {what}; see conf/claims/*.yaml") from None
        papers.append((order, paper))
    return tuple(paper for _, paper in sorted(papers, key=lambda item: item[0]))


def _paper(path: Path) -> tuple[int, Paper]:
    """One claims file: its paper's ``order`` and the paper with its claims, each reading's test checked
    against the options its kind declares (:func:`claim_spec`), in the file's name."""
    data = yaml.load(path.read_text(), Loader=getattr(yaml, "CSafeLoader", yaml.SafeLoader))
    claims = tuple(
        Claim(id=c["id"], paper=data["paper"], text=c["claim"], quote=Quote(**c.get("quote", {"text": "", "english": ""})),
              where=c.get("where", ""), cells=c.get("cells") or {},
              readings=tuple(_reading(r, f"{path}: claim {c['id']}, reading {r['name']}")
                             for r in c.get("readings") or ()),
              note=c.get("note", ""), untestable=c.get("untestable", ""))
        for c in data["claims"]
    )
    for claim in claims:  # a condition written as a label is refused here, in its file's name
        for reading in claim.readings:
            named(reading.test, f"{path}: claim {claim.id}, reading {reading.name}")
    return data["order"], Paper(data["paper"], data["title"], data["authors"], data["venue"], claims, path)


def _reading(written: dict, where: str) -> Reading:
    """One reading of a claims file: its name, experiment and test (:func:`claim_spec`)."""
    return Reading(written["name"], written["experiment"], claim_spec(written, where), written.get("ours", ""))


def evaluate(name: str, experiment: dict, records: pd.DataFrame, tables: dict[str, Table],
             published: pd.DataFrame | None = None,
             papers: tuple[Paper, ...] | None = None) -> dict[str, dict[str, "Result"]]:
    """The results of every reading that names experiment ``name``: {claim id: {reading name: result}}
    (``published``: the paper's numbers, whose sizes the ``order`` tests compare with ours; ``papers``:
    whose claims, the five papers' unless a user's own are given)."""
    results = {}
    for paper in load_papers() if papers is None else papers:
        for claim in paper.claims:
            for reading in claim.readings:
                if reading.experiment != name:
                    continue
                test = ClaimTest.of(reading.test, experiment, published)
                absent = [column for column in reading.test.reads if len(records) and column not in records]
                if absent:  # runs computed before the column was measured (the record's older runs, say)
                    why = f"no run recorded {absent[0]}: computed by code that did not measure it"
                    results.setdefault(claim.id, {})[reading.name] = Result(Verdict(Outcome.NOT_TESTABLE, why))
                    continue
                checks = test.checks(records, tables) if len(records) or not test.needs_runs else []
                results.setdefault(claim.id, {})[reading.name] = Result.of(checks)
    return results


def _listed(value) -> list:
    return [] if value is None else list(value) if isinstance(value, (list, tuple)) else [value]
