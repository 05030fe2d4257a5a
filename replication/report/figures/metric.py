"""Figures drawn from run records with matplotlib (Agg backend, PNG files)."""

import re
import textwrap
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.ticker import FuncFormatter, NullFormatter  # noqa: E402

from replication.condition import label_of, values_of  # noqa: E402
from replication.display import method_label  # noqa: E402
from replication.evidence.aggregate import summarise  # noqa: E402
from replication.evidence.published import cells  # noqa: E402
from replication.evidence.curves import clip_diverged, clip_level  # noqa: E402
from replication.report.figures.style import (  # noqa: E402
    BLACK, PAPER, axis_label, clipped_note, method_look, save, shades,
)
from replication.evidence.figures import MetricVsCondition  # noqa: E402
from replication.report.figures.base import draws  # noqa: E402

PLAIN = FuncFormatter(lambda value, _: f"{value:g}")  # 0.1, 20, 500 rather than powers of ten


@draws(MetricVsCondition)
def metric_vs_condition(records: pd.DataFrame, spec: MetricVsCondition, experiment: dict, path: Path,
                        published: pd.DataFrame | None = None) -> Path:
    """Mean and 95% interval of ``spec.metric`` against the swept variable ``spec.x``, one line per series.

    ``by`` (a swept variable) splits the figure into one panel per value;
    x is on a log scale unless ``log_x: false``; ``xlabel`` overrides the
    axis' words; ``fit_slope`` adds each series' log-log slope to its label.  A
    method that does not sweep ``x`` (the point-mass reference, say) is drawn
    as a horizontal band.  A method's series (one per value of another
    parameter) are shades of its colour.  A run more than 10 times its cell's
    median (or beyond ``clip``), or not finite, diverged: it counts at that
    level and its series' label says how many did.  With ``paper_table`` (and
    ``published``), the paper's values are hollow diamonds in the method's
    colour (see :func:`paper_points`).
    """
    metric = spec.metric
    summary = _summary(records, metric, spec)
    summary = summary[summary["mean"].notna()]  # a metric the method does not have (the grid's ESS)
    summary["x"] = pd.to_numeric(values_of(summary, spec.x), errors="coerce").astype(float)
    summary["panel"] = ["" if v is None else str(v) for v in values_of(summary, spec.by)]
    summary["rest"] = label_of(summary, without=(spec.x, spec.by), sep=" ")
    colours = _series_colours(summary, experiment)
    paper = (paper_points(published, spec, experiment, set(summary["method"]))
             if published is not None and spec.paper else None)
    reference = summary["x"].isna() & (summary["panel"] == "")  # e.g. the Bayes floor: drawn in every panel
    panels = list(dict.fromkeys(summary.loc[~reference, "panel"])) or [""]
    fig, axes = plt.subplots(1, len(panels), figsize=(6 * len(panels), 4), squeeze=False)
    legend_rows = 0  # of the tallest legend
    for ax, panel in zip(axes[0], panels):
        rows = summary[(summary["panel"] == panel) | reference]
        _series(ax, rows[rows["x"].notna()], colours, spec, experiment)
        for _, row in rows[rows["x"].isna()].iterrows():
            colour = colours[row["method"], row["rest"]]
            label = f"{method_label(experiment, row['method'])} {row['rest']}".strip()
            ax.axhline(row["mean"], linestyle="--", color=colour,
                       label=label + clipped_note(row["diverged"], row["total"]))
            ax.axhspan(row["ci_low"], row["ci_high"], color=colour, alpha=0.1)
        if paper is not None:
            for method, points in paper.groupby("method", sort=False):
                ax.plot(points["x"], points["value"], **PAPER, label="paper", zorder=3,
                        markeredgecolor=method_look(experiment, method).colour)
        _axes(ax, spec, list(rows["x"].dropna()) + (list(paper["x"]) if paper is not None else []))
        ax.set_ylabel(f"{axis_label(metric)}\n(mean and 95% CI)")
        title = f"{axis_label(spec.by)}: {panel}" if panel else spec.title
        ax.set_title(textwrap.fill(title, 75), fontsize=9)
        legend_rows = max(legend_rows, _legend(ax))
    fig.set_figheight(4 + 0.17 * legend_rows)
    return save(fig, path, dpi=120)


def _series(ax, rows: pd.DataFrame, colours: dict, spec: MetricVsCondition, experiment: dict) -> None:
    """One line per (method, other parameters), its 95% intervals as error bars; the lines are nudged
    apart along x so that equal means do not hide each other."""
    series = list(rows.groupby(["method", "rest"], sort=False))
    for i, ((method, rest), group) in enumerate(series):
        group = group.sort_values("x")
        label = f"{method_label(experiment, method)} {rest}".strip()
        if spec.fit_slope and len(group) > 1:  # power law y ~ x^slope, fitted on the log-log means
            label += f" (slope {np.polyfit(np.log(group['x']), np.log(group['mean']), 1)[0]:.2f})"
        label += clipped_note(group["diverged"].sum(), group["total"].sum())
        x = _nudged(group["x"], i - (len(series) - 1) / 2, rows["x"], spec.log_x)
        below, above = group["mean"] - group["ci_low"], group["ci_high"] - group["mean"]
        ax.errorbar(x, group["mean"], yerr=[below, above], **{**method_look(experiment, method).line(),
                    "color": colours[method, rest]}, markersize=5, capsize=2, elinewidth=0.8, label=label)


def _nudged(x: pd.Series, step: float, every_x: pd.Series, log: bool) -> pd.Series:
    """``x`` moved by ``step`` times 1.2% of the x range (of its logarithm, on a log axis)."""
    if log:
        return x * (every_x.max() / every_x.min()) ** (0.012 * step)
    return x + 0.012 * step * (every_x.max() - every_x.min())


def _axes(ax, spec: MetricVsCondition, xs: list[float]) -> None:
    """Scales, x label and grid; ticks at the values drawn when they are few (a sweep's), in plain numbers."""
    ax.set_xscale("log" if spec.log_x else "linear")
    if spec.log_y:
        ax.set_yscale("log")
        ax.yaxis.set_major_formatter(PLAIN)
        ax.yaxis.set_minor_formatter(_minor_labels(*ax.get_ylim()))
    values = sorted(set(xs))
    if len(values) <= 12:
        ax.set_xticks(values, [f"{v:g}" for v in values])
        ax.xaxis.set_minor_formatter(NullFormatter())
    ax.set_xlabel(spec.xlabel or axis_label(spec.x))
    ax.grid(True, which="both", alpha=0.3)


def _summary(records: pd.DataFrame, metric: str, spec: MetricVsCondition) -> pd.DataFrame:
    """:func:`summarise` of the clipped runs, with each cell's count of diverged runs and of all runs."""
    values, diverged = _clipped(records, metric, spec)
    records = records.assign(**{metric: values, "diverged": diverged})
    runs = records.groupby(["method", "condition"], sort=False)["diverged"]
    counts = runs.agg(diverged="sum", total="size")
    return summarise(records, metric).merge(counts.reset_index(), on=["method", "condition"])


def _clipped(records: pd.DataFrame, metric: str, spec: MetricVsCondition) -> tuple[pd.Series, pd.Series]:
    """``metric`` per run, each (method, condition) cell's diverged runs clipped at 10 times the cell's
    median (or ``spec.clip``); and which runs diverged.  A cell with no finite value (a metric the
    method does not have) is left as it is."""
    values = records[metric].astype(float)
    clipped, diverged = values.copy(), pd.Series(False, index=records.index)
    for index in records.groupby(["method", "condition"], sort=False).groups.values():
        cell = values[index]
        if np.isfinite(cell).any():
            clipped[index], diverged[index] = clip_diverged(cell, clip_level(spec.clip, cell.median()))
    return clipped, diverged


def _series_colours(summary: pd.DataFrame, experiment: dict) -> dict[tuple[str, str], tuple]:
    """(method, other parameters) -> colour: the method's own, in shades (dark to light, in the
    parameters' natural order) where it has several series."""
    colours = {}
    for method, group in summary.groupby("method", sort=False):
        rests = sorted(set(group["rest"]), key=_natural)
        colours.update(zip([(method, r) for r in rests], shades(method_look(experiment, method).colour, len(rests))))
    return colours


def _natural(text: str) -> list[tuple]:
    """Sort key reading the numbers in ``text`` as numbers: hms=2 before hms=10."""
    return [(0, float(part), "") if re.fullmatch(r"\d+\.?\d*", part) else (1, 0.0, part)
            for part in re.split(r"(\d+\.?\d*)", text)]


def paper_points(published: pd.DataFrame, spec: MetricVsCondition, experiment: dict, methods: set[str]) -> pd.DataFrame:
    """The published values a figure rebuilds, as (method, x, value): the cells of ``spec.paper_table``
    and ``spec.paper_metric`` (default: ``metric``) for the figure's methods, at the x their condition
    gives (``N=500``) or, where it gives none, at ``spec.paper_x[<the cell's experiment>]``;
    ``paper_scale`` puts the paper's unit on ours (0.01: a percentage on a share)."""
    metric = spec.paper_metric or spec.metric
    chosen = cells(published, experiment["paper"], spec.paper_table, metric)
    chosen = chosen[chosen["method"].isin(methods) & chosen["number"].notna()]
    at = spec.paper_x
    x = [at.get(scene) if value is None else value for value, scene in zip(values_of(chosen, spec.x),
                                                                          chosen["experiment"])]
    points = pd.DataFrame({"method": chosen["method"], "x": pd.to_numeric(pd.Series(x, index=chosen.index)),
                           "value": chosen["number"] * spec.paper_scale})
    return points.dropna()


def _minor_labels(low: float, high: float) -> FuncFormatter:
    """Which minor ticks of a log axis get a label: all within a factor 3, 2, 3 and 5 within a decade,
    none beyond (the powers of ten suffice)."""
    digits = set(range(2, 10)) if high < 3 * low else {2, 3, 5} if high < 10 * low else set()

    def label(value, _):
        return f"{value:g}" if round(value / 10 ** np.floor(np.log10(value))) in digits else ""

    return FuncFormatter(label)


def _legend(ax) -> int:
    """The axes' legend below them, in two columns, the paper's values once (a hollow black diamond);
    return its number of rows."""
    entries = dict(zip(*ax.get_legend_handles_labels()[::-1]))
    if entries.pop("paper", None):  # once, last
        entries["paper"] = Line2D([], [], **PAPER, markeredgecolor=BLACK)
    if entries:
        ax.legend(entries.values(), entries.keys(), fontsize=7, ncol=2, frameon=False, loc="upper center",
                  bbox_to_anchor=(0.5, -0.16))
    return (len(entries) + 1) // 2
