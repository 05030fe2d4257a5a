"""Error against cost: a method below another's line at equal cost is better at that budget, whatever the
particle counts (the SMC literature's comparison at equal work: Gerber and Chopin, JRSS B 2015)."""

import math
import textwrap
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pandas as pd  # noqa: E402
from matplotlib.ticker import FuncFormatter  # noqa: E402

from replication.condition import label_of  # noqa: E402
from replication.evidence.aggregate import summarise  # noqa: E402
from replication.evidence.quantities import quantity  # noqa: E402
from replication.evidence.statistics import mean  # noqa: E402
from replication.evidence.figures import MetricVsCost  # noqa: E402
from replication.report.figures.base import draws  # noqa: E402
from replication.display import method_label  # noqa: E402
from replication.report.figures.style import axis_label, method_look, save, shades  # noqa: E402


@draws(MetricVsCost)
def metric_vs_cost(records: pd.DataFrame, spec: MetricVsCost, experiment: dict, path: Path) -> Path:
    """``spec.metric`` (mean and 95% interval over runs) against each cost of ``spec.costs`` (mean over
    runs; a time's median, which a slow first run does not move; log scale), one panel per cost; a
    method's conditions (its particle counts, say) are joined by a line in order of cost with its
    interval as a band (a single condition: a point with its interval), its other swept variable
    ``spec.by`` (a scene) split into lines of their own; ``spec.log_y`` puts the metric on a log scale;
    ``spec.paired_to`` (a method) draws the metric minus that method's on the same data, run by run."""
    metric, costs = spec.metric, spec.costs
    missing = [c for c in (metric, *costs) if c not in records]
    if missing:
        raise ValueError(f"figure {spec.name!r}: the runs have no {missing}")
    reference = spec.paired_to
    y = summarise(records, metric) if reference is None else _paired(records, metric, reference)
    y["line"] = label_of(y, without=[v for v in _swept(y) if v != spec.by], sep=" ") if spec.by else ""
    fig, axes = plt.subplots(1, len(costs), figsize=(6 * len(costs), 4.4), squeeze=False)
    for ax, cost in zip(axes[0], costs):
        statistic = "median" if quantity(cost).machine_dependent else "mean"  # a time: robust to a slow first run
        x = summarise(records, cost, statistic=statistic)[["method", "condition", "mean"]]
        x = x.rename(columns={"mean": "cost"})
        points = y.merge(x, on=["method", "condition"])
        points = points[points["cost"] > 0]  # no work counted: a reference without a likelihood
        lines = points.groupby("method", sort=False)["line"].unique()  # a method's lines: shades of its colour
        for (method, line), group in points.groupby(["method", "line"], sort=False):
            group = group.sort_values("cost")
            look, label = method_look(experiment, method), f"{method_label(experiment, method)} {line}".strip()
            colour = shades(look.colour, len(lines[method]))[list(lines[method]).index(line)]
            drawn = {**look.line(), "color": colour}
            if len(group) > 1:  # a line through its budgets, its interval a band
                ax.plot(group["cost"], group["mean"], **drawn, markersize=4, label=label)
                ax.fill_between(group["cost"], group["ci_low"], group["ci_high"], color=colour, alpha=0.15,
                                linewidth=0)
            else:  # one budget: a point and its interval
                interval = [group["mean"] - group["ci_low"], group["ci_high"] - group["mean"]]
                ax.errorbar(group["cost"], group["mean"], yerr=interval, **drawn, markersize=6, capsize=3,
                            elinewidth=0.9, label=label)
        ax.set_xscale("log")
        ax.xaxis.set_major_formatter(FuncFormatter(lambda value, _: f"{value:g}"))
        ax.xaxis.set_minor_formatter(FuncFormatter(_two_and_five))
        if spec.log_y:  # a method far off the others (a chain that loses the balls) on one axis
            ax.set_yscale("log")
            ax.yaxis.set_major_formatter(FuncFormatter(lambda value, _: f"{value:g}"))
        ax.set_xlabel(f"{axis_label(cost)} ({statistic} over runs, log scale)")
        ax.set_ylabel(f"{axis_label(metric)}\n(mean and 95% CI)" if reference is None else
                      f"{axis_label(metric)} minus {reference}'s\n(same runs; mean and 95% CI)")
        ax.grid(True, which="both", alpha=0.3)
    fig.suptitle(textwrap.fill(spec.title, 120), fontsize=9)
    axes[0][-1].legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.02, 1.0))
    return save(fig, path, dpi=120)


def _paired(records: pd.DataFrame, metric: str, reference: str) -> pd.DataFrame:
    """``summarise``'s columns for ``metric`` minus the ``reference`` method's on the same data and repetition,
    run by run (the data's run-to-run spread, which the unpaired intervals carry, cancels), each method and
    condition's mean with its t interval; the reference itself left out."""
    theirs = records.loc[records["method"] == reference, ["data_condition", "repetition", metric]]
    joined = records[records["method"] != reference].merge(theirs, on=["data_condition", "repetition"],
                                                            suffixes=("", " reference"))
    variables = [c for c in records.columns if c.startswith("condition.")]
    rows = []
    for (method, condition), group in joined.groupby(["method", "condition"], sort=False):
        found = mean((group[metric] - group[f"{metric} reference"]).to_numpy(dtype=float), -math.inf, math.inf)
        rows.append({"method": method, "condition": condition, "mean": found.value, "ci_low": found.low,
                     "ci_high": found.high, **group[variables].iloc[0].to_dict()})
    return pd.DataFrame(rows, columns=["method", "condition", "mean", "ci_low", "ci_high", *variables])


def _two_and_five(value: float, _) -> str:
    """A minor tick's label on a log axis, at 2 and 5 times a power of ten only (the others stay unlabelled)."""
    lead = value / 10 ** math.floor(math.log10(value))
    return f"{value:g}" if round(lead, 6) in (2.0, 5.0) else ""


def _swept(summary: pd.DataFrame) -> list[str]:
    return [c.removeprefix("condition.") for c in summary.columns if c.startswith("condition.")]
