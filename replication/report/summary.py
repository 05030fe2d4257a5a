"""Every published cell, one row each: ours beside it where a table of ours matched it, otherwise why not.

Each experiment's ``summary.json`` lists, under ``cells``, the published cells
its tables matched (:func:`matched_cells` builds those entries); this module
joins them with ``published_values.csv`` so that the summary at the top of
``reports/index.html`` (and the PDF's first pages) has one row per published
cell, in the file's order.  A cell that no experiment matched still has its
row, with the reason: not run yet or not at this scale, a scene or method we do
not reproduce (a private video, say), no value in the paper, or not yet
replicated at all.
"""

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import yaml

from replication.paths import CONF_DIR, experiment_names

KEYS = ["paper", "table", "experiment", "method", "metric", "condition"]


# -- what an experiment's report writes -------------------------------------------------------------


def matched_cells(
    table: pd.DataFrame, hits, published: pd.DataFrame, spec: dict, experiment: dict
) -> list[dict]:
    """The published cells one report table matched, one JSON-ready entry each, for ``summary.json``.

    ``table`` and ``hits`` are what ``build_table`` / ``build_rating_table`` /
    ``build_improvement_table`` returned for ``spec``.  Each entry names the cell
    (``published_index``, its row in ``published_values.csv`` counted from 0
    after the header, and the key columns :data:`KEYS`) and the row of ours it
    was compared with: ``table_name``, ``our_method``, ``our_condition``,
    ``runs``, ``ours``, ``ci_low``, ``ci_high`` (None where undefined, or for a
    rating), ``verdict``.  A cell two rows of ours matched (two stand-in scenes
    for one paper scene) has two entries.
    """
    hits = sorted(hits)
    if not hits or table.empty:
        return []
    theirs = published.loc[hits]
    kind = spec.get("kind")
    key_of = {m.get("label", name): name for name, m in experiment.get("methods", {}).items()}
    match = {ours: m if isinstance(m, dict) else {"condition": m}
             for ours, m in spec.get("match", {}).items()}
    entries, used = [], set()
    for _, row in table.iterrows():
        condition = "" if row["condition"] == "-" else row["condition"]
        if kind == "improvement":  # one row of ours for the paper's one relative claim
            chosen = theirs
        else:
            chosen = theirs[theirs["method"] == key_of.get(row["method"], row["method"])]
            if kind in ("rating", "modes"):  # text verdicts, matched by scene
                wanted = match.get(condition, {})
                chosen = chosen[chosen["experiment"] == wanted.get("experiment", condition)]
            else:
                wanted = match.get(condition, {"condition": condition})
                stated = chosen["condition"].replace("", spec.get("paper_condition", ""))
                if "condition" in wanted:
                    chosen = chosen[stated == wanted["condition"]]
                if "experiment" in wanted:
                    chosen = chosen[chosen["experiment"] == wanted["experiment"]]
        for index, cell in chosen.iterrows():
            used.add(index)
            entries.append(_entry(index, cell, row, spec["name"], rating=kind in ("rating", "modes")))
    for index in sorted(set(hits) - used):  # should not happen: matched, but to no row we can tell
        entries.append({"published_index": int(index), **{k: published.at[index, k] for k in KEYS},
                        "table_name": spec["name"], "our_method": None, "our_condition": None, "runs": None,
                        "ours": None, "ci_low": None, "ci_high": None, "verdict": "matched"})
    return entries


def _entry(index, cell: pd.Series, row: pd.Series, table_name: str, rating: bool) -> dict:
    return {
        "published_index": int(index),
        **{k: str(cell[k]) for k in KEYS},
        "table_name": table_name,
        "our_method": str(row["method"]),
        "our_condition": "" if row["condition"] == "-" else str(row["condition"]),
        "runs": int(row["runs"]),
        "ours": str(row["ours"]) if rating else _number(row["ours"]),
        "ci_low": None if rating else _number(row.get("ci_low")),
        "ci_high": None if rating else _number(row.get("ci_high")),
        "verdict": str(row["verdict"]),
    }


def _number(value) -> float | None:
    try:
        value = float(value)
    except (TypeError, ValueError):
        return None
    return value if math.isfinite(value) else None


# -- the summary of every published cell --------------------------------------------------------------


def load_summaries(reports: Path) -> dict[str, dict]:
    """Each experiment's ``summary.json`` under ``reports``, by experiment name (configs' order)."""
    summaries = {}
    for name in experiment_names():
        path = Path(reports) / name / "summary.json"
        if path.exists():
            summaries[name] = json.loads(path.read_text())
    return summaries


def experiment_configs() -> dict[str, dict]:
    """Every experiment config as written (``conf/experiment/*.yaml``), by name.

    As written means without what a file inherits through Hydra's ``defaults:``,
    on purpose: a derived experiment (an N sweep, an ablation, the OTB runs)
    re-draws its parent's tables on other settings, and a published cell is
    compared only with the experiment that declares its table.  Plain YAML
    (the configs use anchors, no interpolation): 20 times faster than OmegaConf here.
    """
    loader = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
    return {name: yaml.load((CONF_DIR / "experiment" / f"{name}.yaml").read_text(), Loader=loader)
            for name in experiment_names()}


def summary_table(
    published: pd.DataFrame, summaries: dict[str, dict], configs: dict[str, dict]
) -> pd.DataFrame:
    """One row per published cell (the csv's order): the paper's value, ours and the verdict, or why not.

    Columns: the key columns, ``note``, ``paper_value`` (value and unit),
    ``ours`` ('mean [low, high]', or a rating), ``verdict`` (empty where not
    compared), ``reason`` (why not compared; empty where compared), ``also``
    (further rows of ours compared with the same cell), ``link`` (the
    experiment page's section, relative to ``reports/``) and ``link_text``.
    """
    by_key = {}
    for name, summary in summaries.items():
        for entry in summary.get("cells", []):
            by_key.setdefault(tuple(str(entry.get(k, "")) for k in KEYS), []).append((name, summary, entry))
    scene_notes = _scene_notes(published)
    rows = []
    for index, cell in published.iterrows():
        key = tuple(str(cell[k]) for k in KEYS)
        found = by_key.get(key, [])
        row = {k: cell[k] for k in KEYS}
        row.update(note=cell["note"], paper_value=_paper_value(cell), ours="", verdict="", reason="", also="",
                   our_condition="", runs="", link="", link_text="")
        if found:
            name, summary, entry = found[0]
            row["ours"] = _ours(entry)
            row["verdict"] = entry["verdict"]
            ours_named = entry.get("our_condition") or ""
            if ours_named != cell["condition"]:  # ours is named otherwise: a stand-in scene, an unstated N
                row["our_condition"] = ours_named
            row["runs"] = "" if entry.get("runs") is None else str(entry["runs"])
            row["link"] = f"{name}/index.html#{entry['table_name']}"
            row["link_text"] = f"{name}: {entry['table_name']}"
            row["also"] = "; ".join(
                f"{e.get('table_name')}{' ' + e['our_condition'] if e.get('our_condition') else ''}: "
                f"{_ours(e)}, {e['verdict']}"
                for _, _, e in found[1:]
            )
        else:
            row["reason"], name = _why_not(cell, summaries, configs, scene_notes)
            row["link"] = f"{name}/index.html#unmatched" if name in summaries else ""
            row["link_text"] = name if name in summaries else ""
        rows.append(row)
    columns = [*KEYS, "note", "paper_value", "ours", "runs", "our_condition", "verdict", "reason", "also",
               "link", "link_text"]
    return pd.DataFrame(rows, columns=columns)


def counts(table: pd.DataFrame) -> dict:
    """How many cells were compared, with which verdicts, and why the others were not (first words)."""
    compared = table[table["verdict"] != ""]
    verdicts = compared["verdict"].map(lambda v: v.split(" (")[0]).value_counts()
    reasons = table[table["reason"] != ""]["reason"].map(lambda r: r.split(":")[0]).value_counts()
    return {"cells": len(table), "compared": len(compared), "verdicts": dict(verdicts.items()),
            "reasons": dict(reasons.items())}


def _paper_value(cell: pd.Series) -> str:
    value = str(cell["value"])
    if not value:
        return ""
    return f"{value} {cell['unit']}".strip() if cell["unit"] else value


def _ours(entry: dict) -> str:
    ours = entry.get("ours")
    if ours is None:
        return ""
    if isinstance(ours, str):
        return ours
    low, high = entry.get("ci_low"), entry.get("ci_high")
    if low is None or high is None or not (np.isfinite(low) and np.isfinite(high)):
        return f"{ours:.4g}"
    return f"{ours:.4g} [{low:.4g}, {high:.4g}]"


def _scene_notes(published: pd.DataFrame) -> dict[tuple, str]:
    """The first note of each (paper, experiment) in the csv: what the scene is ('real soccer video ...')."""
    notes = {}
    for paper, experiment, note in zip(published["paper"], published["experiment"], published["note"]):
        if note:
            notes.setdefault((paper, experiment), note)
    return notes


def _as_list(value) -> list[str]:
    return [] if value is None else [str(v) for v in value] if isinstance(value, list) else [str(value)]


def _covering(cell: pd.Series, configs: dict[str, dict]) -> list[tuple[str, dict]]:
    """(experiment, table spec) of each table of ours that compares with the cell's paper table and metric."""
    found = []
    for name, config in configs.items():
        if str(config.get("paper", "")) != cell["paper"]:
            continue
        for spec in config.get("report", {}).get("tables", []):
            if str(cell["table"]) in _as_list(spec.get("paper_table")) and \
                    spec.get("paper_metric", spec.get("metric")) == cell["metric"]:
                found.append((name, spec))
    return found


def _why_not(cell: pd.Series, summaries: dict, configs: dict, scene_notes: dict) -> tuple[str, str]:
    """Why no table of ours matched ``cell``, and the experiment the reason is about ('' if none)."""
    if not str(cell["value"]):
        return f"no value in the paper: {cell['note'] or 'cell empty'}", ""
    covering = _covering(cell, configs)
    if not covering:
        return f"not yet replicated: no table of ours covers {cell['paper']} table {cell['table']}", ""
    ran = [(name, spec) for name, spec in covering if name in summaries]
    name, spec = (ran or covering)[0]
    config = configs[name]
    if cell["method"] not in config.get("methods", {}):
        return f"method not reproduced: {cell['method']} is not among {name}'s methods", name
    wanted = [m if isinstance(m, dict) else {"condition": m} for m in spec.get("match", {}).values()]
    scenes = {str(m["experiment"]) for m in wanted if "experiment" in m}
    if scenes and cell["experiment"] not in scenes:
        note = scene_notes.get((cell["paper"], cell["experiment"]), "")
        private = any(word in note.lower() for word in ("not public", "private"))
        what = "private video, no stand-in" if private else "scene not reproduced"
        return f"{what}: {cell['experiment']}{f' ({note})' if note else ''}", name
    conditions = {str(m["condition"]) for m in wanted if "condition" in m}
    stated = cell["condition"] or spec.get("paper_condition", "")
    if conditions and stated not in conditions:
        return f"condition not reproduced: {stated or 'unstated'}", name
    if name not in summaries:
        return f"not run yet: experiment={name}", name
    summary = summaries[name]
    if "cells" not in summary:  # written before reports listed the cells they matched
        return f"see {name}'s page: its summary.json lists no cells (python -m replication.report)", name
    if not summary.get("n_records"):
        return f"not run yet: no stored runs of {name}", name
    if summary.get("scale") != "paper":
        return f"not run at this scale ({summary.get('scale')}): {name} at scale=paper", name
    return f"not matched: no row of {name} met this cell (see its page)", name
