"""Figures drawn from run records with matplotlib (Agg backend, PNG files)."""

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from replication.report.aggregate import summarise  # noqa: E402


def parse_condition(condition: str) -> dict[str, str]:
    return dict(part.split("=", 1) for part in condition.split(";") if part)


def metric_vs_condition(records: pd.DataFrame, spec: dict, experiment: dict, path: Path) -> Path:
    """Mean and 95% interval of ``spec.metric`` against the swept variable ``spec.x``, one line per series.

    ``by`` (a swept variable) splits the figure into one panel per value;
    x is on a log scale unless ``log_x: false``;
    ``fit_slope`` adds each series' log-log slope to its label.  A
    method that does not sweep ``x`` (the point-mass reference, say) is drawn
    as a horizontal band.
    """
    methods = experiment["methods"]
    summary = summarise(records, spec["metric"])
    conditions = summary["condition"].map(parse_condition)
    summary["x"] = conditions.map(lambda c: float(c.get(spec["x"], "nan")))
    summary["panel"] = conditions.map(lambda c: c.get(spec.get("by"), ""))
    summary["series"] = [
        " ".join([methods[m].get("label", m)] + [f"{k}={v}" for k, v in c.items() if k not in (spec["x"], spec.get("by"))])
        for m, c in zip(summary["method"], conditions)
    ]
    reference = summary["x"].isna() & (summary["panel"] == "")  # e.g. the Bayes floor: drawn in every panel
    panels = list(dict.fromkeys(summary.loc[~reference, "panel"])) or [""]
    fig, axes = plt.subplots(1, len(panels), figsize=(6 * len(panels), 4), squeeze=False)
    for ax, panel in zip(axes[0], panels):
        rows = summary[(summary["panel"] == panel) | reference]
        for series, group in rows[rows["x"].notna()].groupby("series", sort=False):
            group = group.sort_values("x")
            if spec.get("fit_slope") and len(group) > 1:  # power law y ~ x^slope, fitted on the log-log means
                slope = np.polyfit(np.log(group["x"]), np.log(group["mean"]), 1)[0]
                series = f"{series} (slope {slope:.2f})"
            ax.plot(group["x"], group["mean"], marker="o", label=series)
            ax.fill_between(group["x"], group["ci_low"], group["ci_high"], alpha=0.2)
        for _, row in rows[rows["x"].isna()].iterrows():
            line = ax.axhline(row["mean"], linestyle="--", color="k", label=row["series"])
            ax.axhspan(row["ci_low"], row["ci_high"], color=line.get_color(), alpha=0.1)
        if spec.get("log_x", True):
            ax.set_xscale("log")
        if spec.get("log_y"):
            ax.set_yscale("log")
        ax.set_xlabel(spec["x"])
        ax.set_ylabel(f"{spec['metric']} (mean, 95% CI)")
        ax.set_title(f"{spec.get('by')}={panel}" if panel else spec.get("title", ""), fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def _figures():
    from replication.report.qmc_figures import point_sets
    from replication.report.tracking_figures import mode_strip, otb_curves, per_frame_curve, snapshots, track

    return {
        "metric_vs_condition": metric_vs_condition,
        "per_frame_curve": per_frame_curve,
        "track": track,
        "snapshots": snapshots,
        "mode_strip": mode_strip,
        "point_sets": point_sets,
        "otb_curves": otb_curves,
    }


def draw(records: pd.DataFrame, spec: dict, experiment: dict, path: Path) -> Path:
    """Draw the figure ``spec`` (its ``kind`` names the function) from run records into ``path``."""
    figures = _figures()
    if spec["kind"] not in figures:
        raise ValueError(f"unknown figure kind {spec['kind']!r}; choose one of {sorted(figures)}")
    return figures[spec["kind"]](records, spec, experiment, path)
