"""Paper tables rebuilt from run records: ours (mean, 95% interval) | paper | verdict."""

import numpy as np
import pandas as pd

from replication.report.aggregate import comparison_interval, mean_interval, summarise
from replication.report.published import cells
from replication.report.verdict import verdict

FLOOR_FILTER = "point_mass"


def build_table(records: pd.DataFrame, spec: dict, experiment: dict, published: pd.DataFrame):
    """Return (table, index labels of the published cells it matched) for one ``report.tables`` entry."""
    metric, paper_metric = spec["metric"], spec.get("paper_metric", spec["metric"])
    if "scale" in spec:  # e.g. a share of frames as the paper's percentage
        records = records.assign(**{metric: records[metric] * spec["scale"]})
    ours = summarise(records, metric)
    ours = ours[ours["runs"] > 0].reset_index(drop=True)
    if spec.get("statistic") == "median":  # timings: the median and its order-statistic interval
        ours["mean"], ours["ci_low"], ours["ci_high"] = ours["median"], ours["median_low"], ours["median_high"]
    theirs = cells(published, experiment["paper"], spec["paper_table"], paper_metric).copy()
    theirs["condition"] = theirs["condition"].replace("", spec.get("paper_condition", ""))
    # our condition -> the published cell it is compared with: a condition, or {experiment, condition}
    match = {ours_: m if isinstance(m, dict) else {"condition": m} for ours_, m in spec.get("match", {}).items()}
    methods = experiment["methods"]
    paper_runs = spec.get("paper_runs")
    ours[["cmp_low", "cmp_high"]] = [
        comparison_interval(m, sd, n, paper_runs) for m, sd, n in zip(ours["mean"], ours["sd"], ours["runs"])
    ]
    floor_low, excess = None, {}
    if metric == "rmse":
        floors = ours[[methods[m]["filter"] == FLOOR_FILTER for m in ours["method"]]]
        floor_low = floors["cmp_low"].min() if len(floors) else None
        excess = excess_over_floor(records, [m for m in methods if methods[m]["filter"] == FLOOR_FILTER])
    if match:  # a table of the conditions the paper's table covers
        ours = ours[ours["condition"].isin(list(match))]
    rows, matched = [], set()
    for _, row in ours.iterrows():
        wanted = match.get(row["condition"], {"condition": row["condition"]})
        chosen = theirs["method"] == row["method"]
        if "condition" in wanted:
            chosen &= theirs["condition"] == wanted["condition"]
        if "experiment" in wanted:
            chosen &= theirs["experiment"] == wanted["experiment"]
        hit = theirs[chosen]
        paper = float(hit["number"].iloc[0]) if len(hit) else np.nan
        matched.update(hit.index)
        entry = {
            "method": methods[row["method"]].get("label", row["method"]),
            "condition": row["condition"] or "-",
            "runs": row["runs"],
            "ours": row["mean"],
            "ci_low": row["ci_low"],
            "ci_high": row["ci_high"],
        }
        if excess:
            entry["excess_over_floor"], entry["excess_ci_low"], entry["excess_ci_high"] = excess.get(
                (row["method"], row["condition"]), (np.nan, np.nan, np.nan)
            )
        if spec.get("show_variance"):
            entry["variance"] = row["variance"]
        entry["paper"] = paper
        entry["verdict"] = verdict(paper, row["mean"], row["cmp_low"], row["cmp_high"], paper_metric, floor_low)
        rows.append(entry)
    return pd.DataFrame(rows), matched


def stability(failures: int, runs: int) -> str:
    """bis_pf's rating over (nominally 10) runs: good = no failure, medium = 2 or more, poor = 5 or more."""
    scaled = failures * 10 / runs  # the rule is stated per 10 runs
    return "poor" if scaled >= 5 else "medium" if scaled >= 2 else "good"


def build_rating_table(records: pd.DataFrame, spec: dict, experiment: dict, published: pd.DataFrame):
    """Failed runs and the paper's stability rating per method and condition (bis_pf Table 3)."""
    theirs = cells(published, experiment["paper"], spec["paper_table"], spec["paper_metric"])
    match = spec.get("match", {})
    rows, matched = [], set()
    for (method, condition), group in records.groupby(["method", "condition"], sort=False):
        failures, runs = int(group[spec["metric"]].sum()), len(group)
        ours = stability(failures, runs)
        wanted = match.get(condition, {})
        hit = theirs[(theirs["method"] == method) & (theirs["experiment"] == wanted.get("experiment", condition))]
        matched.update(hit.index)
        paper = hit["value"].iloc[0] if len(hit) else ""
        rows.append(
            {
                "method": experiment["methods"][method].get("label", method),
                "condition": condition or "-",
                "runs": runs,
                "failed runs": failures,
                "ours": ours,
                "paper": paper,
                "verdict": "reference" if not paper else "agrees" if paper == ours else "differs",
            }
        )
    return pd.DataFrame(rows), matched


def build_summary_table(records: pd.DataFrame, spec: dict, experiment: dict) -> pd.DataFrame:
    """One row per method and condition, one column per metric: 'mean [95% CI]' over runs."""
    columns = {}
    for metric in spec["metrics"]:
        summary = summarise(records, metric)
        columns[metric] = {
            (m, c): f"{mean:.4g} [{lo:.4g}, {hi:.4g}]" if np.isfinite(lo) else f"{mean:.4g}"
            for m, c, mean, lo, hi in zip(summary["method"], summary["condition"], summary["mean"], summary["ci_low"], summary["ci_high"])
        }
    keys = list(columns[spec["metrics"][0]])
    table = pd.DataFrame(
        {
            "method": [experiment["methods"][m].get("label", m) for m, _ in keys],
            "condition": [c or "-" for _, c in keys],
            "runs": [int((records["method"] == m).where(records["condition"] == c, False).sum()) for m, c in keys],
        }
    )
    for metric, values in columns.items():
        table[metric] = [values.get(key, "") for key in keys]
    return table


def excess_over_floor(records: pd.DataFrame, floor_methods: list[str]) -> dict:
    """Paired RMSE minus the point-mass filter's RMSE on the same trajectory: mean and 95% interval.

    Every method filters the same data at a given repetition, so the paired
    difference isolates the filter's own error from the run-to-run spread.
    """
    floor = records[records["method"].isin(floor_methods)][["data_condition", "repetition", "rmse"]]
    if floor.empty:
        return {}
    paired = records.merge(floor, on=["data_condition", "repetition"], suffixes=("", "_floor"))
    paired = paired[~paired["method"].isin(floor_methods)]
    return {
        key: mean_interval(group["rmse"] - group["rmse_floor"])
        for key, group in paired.groupby(["method", "condition"], sort=False)
    }


def format_table(table: pd.DataFrame) -> pd.DataFrame:
    """Numbers as text for HTML: 'mean [low, high]' and the paper's value as printed."""
    shown = pd.DataFrame({"method": table["method"], "condition": table["condition"], "runs": table["runs"]})
    shown["ours (95% CI)"] = [
        f"{m:.4g} [{lo:.4g}, {hi:.4g}]" if np.isfinite(lo) else f"{m:.4g}"
        for m, lo, hi in zip(table["ours"], table["ci_low"], table["ci_high"])
    ]
    if "excess_over_floor" in table:
        shown["excess over the floor (paired, 95% CI)"] = [
            "" if not np.isfinite(m) else f"{m:+.3g} [{lo:+.3g}, {hi:+.3g}]"
            for m, lo, hi in zip(table["excess_over_floor"], table["excess_ci_low"], table["excess_ci_high"])
        ]
    if "variance" in table:
        shown["variance over runs"] = table["variance"].map(lambda v: f"{v:.4g}")
    shown["paper"] = table["paper"].map(lambda v: "" if np.isnan(v) else f"{v:g}")
    shown["verdict"] = table["verdict"]
    return shown


def build_improvement_table(records: pd.DataFrame, spec: dict, experiment: dict, published: pd.DataFrame):
    """A paper's relative claim: 100 (metric[baseline] - metric[method]) / mean metric[baseline], paired by run.

    Both methods filter the same data at a repetition, so the interval is the
    t-interval of the paired differences, scaled by the baseline's mean.
    """
    metric, baseline, method = spec["metric"], spec["baseline"], spec["method"]
    columns = ["data_condition", "repetition", metric]
    paired = records[records["method"] == baseline][columns].merge(
        records[records["method"] == method][columns], on=["data_condition", "repetition"], suffixes=("_base", "")
    )
    if paired.empty:
        return pd.DataFrame(), set()
    scale = 100.0 / paired[f"{metric}_base"].mean()
    mean, low, high = (scale * v for v in mean_interval(paired[f"{metric}_base"] - paired[metric]))
    theirs = cells(published, experiment["paper"], spec["paper_table"], spec["paper_metric"])
    paper = float(theirs["number"].iloc[0]) if len(theirs) else np.nan
    label = f"{experiment['methods'][method].get('label', method)} vs {experiment['methods'][baseline].get('label', baseline)}"
    row = {"method": label, "condition": "-", "runs": len(paired), "ours": mean, "ci_low": low, "ci_high": high,
           "paper": paper, "verdict": verdict(paper, mean, low, high, spec["paper_metric"])}
    return pd.DataFrame([row]), set(theirs.index)
