"""The report of a Hydra multirun sweep: a metric against the swept config value, from the store only.

    python -m replication experiment=ism_pf scale=quick -m experiment.methods.PF.n_particles=5,10,20,50
    python -m replication.report experiment=ism_pf scale=quick sweep=experiment.methods.PF.n_particles=5,10,20,50

Each value's runs are expanded from the config with that override, exactly as
the multirun job expanded them, and read back from the store (a value whose
runs are missing is named, not drawn).  One page per sweep,
``<reports>/<experiment>/sweeps/<key>.html``: the metric's mean and 95%
interval against the value, one line per method and condition, and its table.
"""

from pathlib import Path

import pandas as pd

from replication import atomic
from replication.condition import PREFIX, label_of
from replication.errors import ConfigError
from replication.evidence.aggregate import summarise
from replication.evidence.figures import figure_spec
from replication.report.figures.metric import metric_vs_condition
from replication.report.pages.render import html_table, render


def parse_sweep(text: str) -> tuple[str, list[str]]:
    """``key=v1,v2,...`` -> (key, values), as Hydra's multirun takes it."""
    key, _, values = text.partition("=")
    if not key or not values:
        raise ConfigError(f"sweep must read key=value1,value2,...; got {text!r}")
    return key, values.split(",")


def sweep_records(key: str, values: list[str], compose, expand, load) -> tuple[pd.DataFrame, list[str]]:
    """The stored records of every value's runs, with ``key``'s value in column ``swept``; and the
    values with runs missing.  ``compose(overrides)`` gives a config, ``expand(cfg)`` its runs and
    ``load(cfg, runs)`` their stored records."""
    frames, missing = [], []
    for value in values:
        cfg = compose([f"{key}={value}"])
        runs = expand(cfg)
        records = load(cfg, runs)
        if len(records) < len(runs):
            missing.append(f"{key}={value}: {len(runs) - len(records)} of {len(runs)} runs not stored")
        if len(records):
            frames.append(records.assign(swept=value))
    return (pd.concat(frames, ignore_index=True) if frames else pd.DataFrame()), missing


def unaffected(records: pd.DataFrame) -> pd.Series:
    """Rows of the methods whose runs are the same whatever the value (the sweep names another
    method's parameter): they are drawn once, as a reference line, not once per value."""
    keys = records.groupby(["method", "swept"])["run_key"].agg(frozenset)
    same = {m for m, per_value in keys.groupby(level="method") if per_value.nunique() == 1 and len(per_value) > 1}
    return records["method"].isin(same)


def default_metric(experiment: dict) -> str:
    """The metric of the experiment's first table: what the paper reports first."""
    for table in experiment.get("report", {}).get("tables", []):
        if "metric" in table:
            return table["metric"]
        if table.get("metrics"):
            return table["metrics"][0]
    raise ConfigError(f"{experiment['name']}: no table names a metric; give metric=<column>")


def write_sweep_report(records: pd.DataFrame, key: str, metric: str, experiment: dict, out: Path,
                       missing: list[str], command: str) -> Path:
    """Draw ``metric`` against the swept value and write the sweep's page; return its path."""
    if metric not in records:
        known = sorted(c for c in records.columns if pd.api.types.is_numeric_dtype(records[c]))
        raise ConfigError(f"metric {metric!r} is not in the records; numeric columns: {', '.join(known)}")
    name = key.rsplit(".", 1)[-1]
    out.mkdir(parents=True, exist_ok=True)
    stem = key.replace("/", "_")
    same = unaffected(records)
    tagged = records[~same]
    tagged = tagged.assign(**{f"{PREFIX}{name}": tagged["swept"].astype(object)})
    tagged = tagged.assign(condition=label_of(tagged))
    tagged = pd.concat([tagged, records[same & (records["swept"] == records["swept"].iloc[0])]])
    table = summarise(tagged, metric)
    atomic.save(out / f"{stem}.csv", lambda tmp: table.to_csv(tmp, index=False))
    sections = []
    numeric = pd.to_numeric(records["swept"], errors="coerce").notna().all()
    if numeric:  # a line against the value; a categorical sweep (a scheme's name) is the table alone
        figure = f"{stem}.png"
        x = pd.to_numeric(records["swept"]).unique()
        log_x = bool(x.min() > 0 and x.max() >= 10 * x.min())  # counts over decades; a c1 of 0..2 stays linear
        spec = figure_spec({"name": stem, "kind": "metric_vs_condition", "metric": metric, "x": name, "title": key,
                            "log_x": log_x})
        metric_vs_condition(tagged, spec, experiment, out / figure)
        sections.append({"title": f"{metric} against {key} (mean, 95% interval over runs)", "figure": figure,
                         "table": None})
    sections.append({"title": f"{metric} by value", "figure": None, "table": html_table(table.round(4))})
    page = out / f"{stem}.html"
    meta = f"Drawn from the store by: {command}. " + (
        "Missing: " + "; ".join(missing) + ". Run the multirun to store them." if missing else "Every run is stored."
    )
    atomic.write_text(page, render("sections.html.j2", title=f"{experiment['name']}: sweep of {key}",
                                   up="../index.html", up_label=experiment["name"], meta=meta, sections=sections))
    return page
