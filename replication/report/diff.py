"""``pf-replicate diff A B``: every claim and published cell whose verdict or estimate differs between two
sets of results, before and after.

A and B are each a record folder (``record/``, or any folder holding its ``manifest.json``: its pages are
drawn first, as ``report source=record`` draws them, unless ``reports/record`` holds them drawn from that
very record by this code), a drawn report folder (one holding the experiments' ``summary.json`` files:
``reports``, ``reports/record``), or ``store``: the runs in the store at the paper scale.  What is compared is
what the summaries decide, read through their schema (:class:`~replication.evidence.scorecard.Scorecard`, against
the package's published values): the claims and cells ``claims.csv`` and ``summary.csv`` export, never those
files read back.  Each is named as it
was given, with what is done with it (drawing a record's pages shows a bar of its experiments); the scratch
folders pages are drawn into are never named, since they are gone when the command ends.  Then one line per
changed claim (verdict, deciding number and interval, runs, each replication criterion's count of its sized
effects meeting it and its relative effect size) and per changed cell (our estimate, its verdict),
and the totals.  Exit status 0 when nothing differs, 1 when a claim or a cell does (as ``diff`` does), 2
when A or B is none of the above.

:func:`verdicts` compares the verdicts alone, of some experiments of two records: ``pf-replicate verify``'s
judgement of the runs it re-computed.
"""

import io
import sys
import tempfile
from contextlib import ExitStack, redirect_stdout
from pathlib import Path

import pandas as pd

from replication.errors import fail
from replication.evidence.criteria import CRITERIA
from replication.evidence.scorecard import Scorecard
from replication.paths import resolve
from replication.record.manifest import MANIFEST, PAGES, Manifest
from replication.scales import SCALES, report_folder

CLAIM = ("claim_id",)
CLAIM_FIELDS = ("verdict", "number", "runs", "robustness", "at_equal_cost",  # and each replication criterion's
                *(f"criterion_{c.key}" for c in CRITERIA), "relative_effect")  # count of effects meeting it
CELL = ("paper", "table", "experiment", "method", "metric", "condition")
CELL_FIELDS = ("ours", "runs", "verdict", "reason")
VERDICTS = {CLAIM: ("verdict", "robust", "at_equal_cost"), CELL: ("verdict",)}  # what must not move, by key
NO_RECORD = ("a record is a folder holding manifest.json, such as the repository's record/ (a clone has it; an "
             "installed copy ships none)")


def drawn(source: str, scratch: Path, experiments: tuple[str, ...] = (), n_jobs: int | None = None,
          side: str = "") -> Path:
    """The report folder holding ``source``'s summaries (:func:`is_drawn`), drawing it into ``scratch``
    first if need be (of a record, only its ``experiments`` where named, on ``n_jobs`` workers where given).
    The drawing shows a bar of the experiments drawn.  With ``side`` (A or B), say first what ``source`` is and
    what is done with it; of a whole record, read ``reports/record`` where it holds that record's pages as this
    code draws them."""
    from replication.report.__main__ import drawn_pages
    from replication.report.__main__ import main as report

    def say(what: str) -> None:
        if side:
            print(f"{side}: {source}: {what}", flush=True)

    path = resolve(source) if source != "store" else Path(source)
    # the scratch folder's pages, named nowhere; no findings (only the claims and cells are compared)
    settings = [f"reports={scratch}", "pdf=false", f"findings={scratch / 'no-findings'}"]
    if is_drawn(path):
        say("a drawn report, read as it is")
        return path
    if (path / MANIFEST).exists():
        ready = None if experiments else drawn_pages(path, [])
        if ready is not None:
            say(f"a record whose pages {ready} holds, drawn from it by this code: read as they are")
            return ready
        say(f"a record of {len(Manifest.read(path).experiments)} experiments and multiverses: drawing its pages")
        only = [f"experiment={','.join(experiments)}"] if experiments else []
        workers = [f"n_jobs={n_jobs}"] if n_jobs else []
        with redirect_stdout(io.StringIO()):
            report(["source=record", f"record={path}", *settings, *only, *workers])
        return scratch / PAGES
    if source == "store":
        say("the store's runs at the paper scale: drawing their pages")
        with redirect_stdout(io.StringIO()):
            report(["scale=paper", *settings])
        return scratch
    if not path.exists():
        fail(f"{source}: no such folder ({path}); {NO_RECORD}")
    fail(f"{source}: neither a record (no {MANIFEST}), a drawn report (no <experiment>/summary.json) nor 'store'; "
         f"{NO_RECORD}")


def is_drawn(folder: Path) -> bool:
    """Whether ``folder`` holds drawn reports: an experiment's ``summary.json`` at either scale."""
    return any(any(report_folder(folder, "", scale).glob("*/summary.json")) for scale in SCALES)


def decided(folder: Path) -> dict[tuple[str, ...], pd.DataFrame]:
    """What the summaries in a drawn report ``folder`` decide, keyed as compared: the claims (by :data:`CLAIM`)
    and the published cells (by :data:`CELL`), as ``claims.csv`` and ``summary.csv`` export them."""
    card = Scorecard.read(folder)
    return {CLAIM: card.claims, CELL: card.cell_table}


def changes(before: pd.DataFrame, after: pd.DataFrame, key: tuple[str, ...],
            fields: tuple[str, ...]) -> list[tuple[str, dict[str, tuple[str, str]]]]:
    """Each row (by ``key``, named by its key's values) whose ``fields`` differ, with each differing field's
    (before, after), or that only one side has (its one field ``only in``: (the side, ''))."""
    joined = before.merge(after, on=list(key), how="outer", suffixes=("_a", "_b"), indicator=True)
    found = []
    for row in joined.astype(object).fillna("").astype(str).to_dict("records"):
        name = " ".join(row[k] for k in key if row[k])
        if row["_merge"] != "both":
            found.append((name, {"only in": ("A" if row["_merge"] == "left_only" else "B", "")}))
            continue
        moved = {f: (row[f + "_a"], row[f + "_b"]) for f in fields
                 if f + "_a" in row and row[f + "_a"] != row[f + "_b"]}
        if moved:
            found.append((name, moved))
    return found


def line(name: str, moved: dict[str, tuple[str, str]]) -> str:
    if "only in" in moved:
        return f"{name}: only in {moved['only in'][0]}"
    return f"{name}: " + "; ".join(f"{f} {a or '-'!r} -> {b or '-'!r}" for f, (a, b) in moved.items())


def verdicts(before: Path, after: Path, experiments: list[str], n_jobs: int = 2) -> list[str]:
    """Each claim and published cell whose verdict differs between two records judged on their entries
    ``experiments`` (each drawn as ``report source=record`` draws it), a line each; printed after the counts,
    with how many estimates moved though their verdict held."""
    if not experiments:  # drawn() reads no experiments as the whole record: never what a caller naming them means
        raise ValueError("verdicts: name the experiments to judge; none were named")
    with ExitStack() as stack:
        folders = [drawn(str(source), Path(stack.enter_context(tempfile.TemporaryDirectory(prefix="verdicts-"))),
                         tuple(experiments), n_jobs) for source in (before, after)]
        sides = [decided(folder) for folder in folders]
    tables = {key: [side[key] for side in sides] for key in (CLAIM, CELL)}
    moved = [line(*change) for key, fields in VERDICTS.items() for change in changes(*tables[key], key, fields)]
    estimates = [len(changes(*tables[key], key, (field,))) for key, field in ((CLAIM, "number"), (CELL, "ours"))]
    judged = [int((tables[key][1][column].fillna("") != "").sum()) for key, column in ((CLAIM, "scale"),
                                                                                    (CELL, "verdict"))]
    print(f"verdicts: {judged[0]} claims and {judged[1]} published cells judged from them: {len(moved)} verdicts "
          f"changed ({estimates[0]} claims' and {estimates[1]} cells' estimates moved)")
    print(*moved, sep="\n", end="\n" if moved else "")
    return moved


def main(argv: list[str]) -> None:
    if {"--help", "-h"} & set(argv) or len(argv) != 2:
        print(__doc__.strip())
        if len(argv) != 2 and not {"--help", "-h"} & set(argv):
            sys.exit(2)
        return
    with ExitStack() as stack:
        folders = [drawn(source, Path(stack.enter_context(tempfile.TemporaryDirectory(prefix="diff-"))), side=side)
                   for side, source in zip("AB", argv)]
        sides = [decided(folder) for folder in folders]
    claims, cells = ([side[key] for side in sides] for key in (CLAIM, CELL))
    claim_changes = changes(*claims, CLAIM, CLAIM_FIELDS)
    claim_lines = [line(*change) for change in claim_changes]
    cell_lines = [line(*change) for change in changes(*cells, CELL, CELL_FIELDS)]
    for title, lines in (("claims", claim_lines), ("published cells", cell_lines)):
        print(f"\n{title}: {len(lines)} changed")
        print(*lines, sep="\n", end="\n" if lines else "")
    verdicts = sum("verdict" in moved for _, moved in claim_changes)
    print(f"\n{len(claims[1])} claims: {verdicts} changed verdict, {len(claim_lines)} changed at all; "
          f"{len(cells[1])} cells: {len(cell_lines)} changed")
    if claim_lines or cell_lines:
        sys.exit(1)
