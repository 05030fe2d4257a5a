"""Every published cell, one row each: ours beside it where a table of ours matched it, otherwise why not.

Each experiment's ``summary.json`` lists, under ``cells``, the published cells
its tables matched (:meth:`replication.evidence.tables.TableKind.entry` builds those entries); this module
joins them with ``published_values.csv`` so that the summary at the top of
``reports/index.html`` (and the PDF's first pages) has one row per published
cell, in the file's order.  A cell that no experiment matched still has its
row, with the reason: not run yet or not at this scale, a scene or method we do
not reproduce (a private video, say), no value in the paper, or not yet
replicated at all.
"""

from collections import Counter
from dataclasses import dataclass
import sys
from pathlib import Path

import pandas as pd
import yaml

from replication.evidence.schema import Summary
from replication.evidence.tables import KEYS, CellResult, Compared, matched, table_specs
from replication.paths import CONF_DIR, experiment_names
from replication.scales import SCALES, page_link, report_folder

# -- the summary of every published cell --------------------------------------------------------------


def load_summaries(reports: Path, own: bool = False, scales: tuple[str, ...] = SCALES) -> dict[str, Summary]:
    """Each shipped experiment's ``summary.json`` under ``reports``, by experiment name (configs' order), at
    the first of ``scales`` that has one (:func:`~replication.scales.report_folder`: the paper scale's before
    the quick one's, so a quick run never hides a paper-scale verdict); with ``own``, instead the reports of
    users' own data or settings (``<experiment>@<label>``), which the scorecard and the summary of published
    cells never read.  One that an older version wrote in another schema, or at another scale than its
    folder's, is left out with one line on stderr (redraw it)."""
    summaries = {}
    folders = [report_folder(reports, "", scale) for scale in scales]  # every scale's reports
    names = sorted({p.parent.name for f in folders for p in f.glob("*@*/summary.json")}) if own else experiment_names()
    for name, scale in ((name, scale) for name in names for scale in scales):
        path = report_folder(reports, name, scale) / "summary.json"
        if name in summaries or not path.exists():
            continue
        redraw = f"redraw it: pf-replicate report experiment={name.split('@')[0]} scale={scale}"
        try:
            summary = Summary.read(path)
        except (KeyError, TypeError, ValueError) as error:
            print(f"skipped: {path} is in an older schema ({error!r}); {redraw}", file=sys.stderr)
            continue
        if summary.scale != scale:  # written before the scales' reports lived apart
            print(f"skipped: {path} is at the {summary.scale} scale, in the {scale} scale's folder; {redraw}",
                  file=sys.stderr)
            continue
        summaries[name] = summary
    return summaries


def experiment_configs() -> dict[str, dict]:
    """Every experiment config as written (``conf/experiment/*.yaml``), by name.

    As written means without what a file inherits through Hydra's ``defaults:``,
    on purpose: a derived experiment (an N sweep, an ablation, the OTB runs)
    re-draws its parent's tables on other settings, and a published cell is
    compared only with the experiment that declares its table.  Plain YAML
    (the configs use anchors, no interpolation): 20 times faster than OmegaConf here.
    A file that does not parse is left out with one line on stderr: it never breaks another's report.
    """
    loader = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
    configs = {}
    for name in experiment_names():
        path = CONF_DIR / "experiment" / f"{name}.yaml"
        try:
            configs[name] = yaml.load(path.read_text(), Loader=loader)
        except yaml.YAMLError as error:
            print(f"skipped: {path} does not parse ({str(error).splitlines()[0]})", file=sys.stderr)
            continue
        if not isinstance(configs[name], dict):
            print(f"skipped: {path} holds no experiment", file=sys.stderr)
            del configs[name]
    return configs


def summary_table(
    published: pd.DataFrame, summaries: dict[str, Summary], configs: dict[str, dict], claims: list[str] | None = None
) -> pd.DataFrame:
    """One row per published cell (the csv's order): the paper's value, ours and the verdict, or why not.

    Columns: the key columns, ``note``, ``paper_value`` (value and unit),
    ``ours`` ('mean [low, high]', or a rating), ``outcome`` and ``verdict`` (the
    outcome and its why; empty where not compared), ``tag`` (the verdict's kind: ``bayes_floor``), ``reason`` (why not
    compared; empty where compared), ``claim`` (the claim the cell belongs to), ``also``
    (further rows of ours compared with the same cell), ``link`` (the
    experiment page's section, relative to ``reports/``) and ``link_text``.
    """
    by_key = {}
    for name, summary in summaries.items():
        for entry in summary.cells:
            by_key.setdefault(entry.key, []).append((name, entry))
    scene_notes = _scene_notes(published)
    rows = []
    for index, cell in published.iterrows():
        key = tuple(str(cell[k]) for k in KEYS)
        found = by_key.get(key, [])
        row = {k: cell[k] for k in KEYS}
        row.update(note=cell["note"], paper_value=_paper_value(cell), ours="", outcome="", verdict="", tag="",
                   reason="", reason_kind="", also="", our_condition="", runs="", link="", link_text="",
                   claim=claims[index] if claims else "")
        if found:
            name, entry = found[0]
            row["ours"] = entry.ours
            row["outcome"], row["verdict"] = _verdict(entry)
            row["tag"] = entry.verdict.tag if entry.verdict else ""
            if entry.our_condition != cell["condition"]:  # ours is named otherwise: a stand-in scene, an unstated N
                row["our_condition"] = entry.our_condition
            row["runs"] = str(entry.runs)
            row["link"] = f"{page_link(name, summaries[name].scale)}#{entry.table_name}"
            row["link_text"] = f"{name}: {entry.table_name}"
            row["also"] = "; ".join(
                f"{e.table_name}{' ' + e.our_condition if e.our_condition else ''}: {e.ours}, {_verdict(e)[1]}"
                for _, e in found[1:]
            )
        else:
            unmatched, name = _why_not(cell, summaries, configs, scene_notes)
            row["reason"], row["reason_kind"] = str(unmatched), unmatched.kind
            row["link"] = f"{page_link(name, summaries[name].scale)}#unmatched" if name in summaries else ""
            row["link_text"] = name if name in summaries else ""
        rows.append(row)
    columns = [*KEYS, "note", "paper_value", "ours", "runs", "our_condition", "outcome", "verdict", "tag", "reason",
               "reason_kind",
               "also", "claim", "link", "link_text"]
    return pd.DataFrame(rows, columns=columns)


def counts(table: pd.DataFrame, summaries: dict[str, Summary] | None = None) -> dict:
    """How many cells were compared, with which outcomes, and why the others were not (first words); with
    ``summaries``, also the outcomes of the numbers judged within a tolerance, as configured and at each
    other tolerance (``sensitivity``: {'as configured' or '+-5%': {outcome: count}})."""
    compared = table[table["verdict"] != ""]
    verdicts = compared["outcome"].value_counts()
    reasons = table[table["reason_kind"] != ""]["reason_kind"].value_counts()
    moved, seen = {}, set()
    for summary in (summaries or {}).values():  # the first entry of each cell, as summary_table shows it
        for entry in summary.cells:
            if entry.published_index in seen:
                continue
            seen.add(entry.published_index)
            if entry.at_tolerance:
                moved.setdefault("as configured", Counter())[entry.verdict.outcome.value] += 1
            for tolerance, outcome in entry.at_tolerance.items():
                moved.setdefault(f"+-{float(tolerance):.0%}", Counter())[outcome.value] += 1
    return {"cells": len(table), "compared": len(compared), "verdicts": dict(verdicts.items()),
            "reasons": dict(reasons.items()),
            "sensitivity": {t: dict(c) for t, c in moved.items()}}


def _verdict(entry: CellResult) -> tuple[str, str]:
    """(outcome, the verdict as read) of a matched cell; a row of ours without a published number has none."""
    return (entry.verdict.outcome.value, str(entry.verdict)) if entry.verdict else ("", "no published number")


def _paper_value(cell: pd.Series) -> str:
    value = str(cell["value"])
    if not value:
        return ""
    return f"{value} {cell['unit']}".strip() if cell["unit"] else value


def _scene_notes(published: pd.DataFrame) -> dict[tuple, str]:
    """The first note of each (paper, experiment) in the csv: what the scene is ('real soccer video ...')."""
    notes = {}
    for paper, experiment, note in zip(published["paper"], published["experiment"], published["note"]):
        if note:
            notes.setdefault((paper, experiment), note)
    return notes


def _covering(cell: pd.Series, configs: dict[str, dict]) -> list[tuple[str, Compared]]:
    """(experiment, table spec) of each table of ours that compares with the cell's paper table and metric."""
    found = []
    for name, config in configs.items():
        if str(config.get("paper", "")) != cell["paper"]:
            continue
        for spec in table_specs(config):
            if isinstance(spec, Compared) and str(cell["table"]) in spec.paper_tables and \
                    spec.published_metric == cell["metric"]:
                found.append((name, spec))
    return found


@dataclass(frozen=True)
class Unmatched:
    """Why a published cell was not compared: its kind ('not run yet', 'scene not reproduced', ...: what
    the index counts) and the detail a reader needs."""

    kind: str
    detail: str

    def __str__(self) -> str:
        return f"{self.kind}: {self.detail}"


def _why_not(cell: pd.Series, summaries: dict, configs: dict, scene_notes: dict) -> tuple[Unmatched, str]:
    """Why no table of ours matched ``cell``, and the experiment the reason is about ('' if none)."""
    if not str(cell["value"]):
        return Unmatched("no value in the paper", cell["note"] or "cell empty"), ""
    covering = _covering(cell, configs)
    if not covering:
        return Unmatched("not yet replicated", f"no table of ours covers {cell['paper']} table {cell['table']}"), ""
    ran = [(name, spec) for name, spec in covering if name in summaries]
    name, spec = (ran or covering)[0]
    config = configs[name]
    if cell["method"] not in config.get("methods", {}):
        return Unmatched("method not reproduced", f"{cell['method']} is not among {name}'s methods"), name
    wanted = [paper for _, paper in matched(spec)]
    scenes = {str(m["experiment"]) for m in wanted if "experiment" in m}
    if scenes and cell["experiment"] not in scenes:
        note = scene_notes.get((cell["paper"], cell["experiment"]), "")
        private = any(word in note.lower() for word in ("not public", "private"))
        what = "private video, no stand-in" if private else "scene not reproduced"
        return Unmatched(what, f"{cell['experiment']}{f' ({note})' if note else ''}"), name
    conditions = {str(m["condition"]) for m in wanted if "condition" in m}
    stated = cell["condition"] or spec.paper_condition
    if conditions and stated not in conditions:
        return Unmatched("condition not reproduced", stated or "unstated"), name
    if name not in summaries:
        return Unmatched("not run yet", f"experiment={name}"), name
    summary = summaries[name]
    if not summary.n_records:
        return Unmatched("not run yet", f"no stored runs of {name}"), name
    if summary.scale != "paper":
        return Unmatched("not run at this scale", f"{name} at scale=paper (ran at {summary.scale})"), name
    return Unmatched("not matched", f"no row of {name} met this cell (see its page)"), name
