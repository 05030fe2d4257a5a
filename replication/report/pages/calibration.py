"""``reports/calibration/index.html``: how often each verdict rule errs, drawn from the calibration table
(:func:`replication.evidence.calibration.calibrate`'s, kept by :mod:`replication.report.calibration`)."""

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402

from replication import atomic  # noqa: E402
from replication.evidence.criteria import CRITERIA  # noqa: E402
from replication.evidence.inference import detectable  # noqa: E402
from replication.report.pages.render import html_table, render  # noqa: E402
from replication.evidence.settings import INFERENCE  # noqa: E402


def failures(table: pd.DataFrame, standard_errors: float = 2.0, control: bool = False) -> pd.DataFrame:
    """The null rows whose rate exceeds 5 % by more than ``standard_errors`` Monte Carlo standard errors: of
    the project's rules, or (``control``) of the old rules kept as controls, which decide no verdict."""
    null = table[(table["truth"] == "null") & (table["control"].astype(bool) == control) & ~_criteria(table)]
    return null[null["rate"] > INFERENCE.alpha + standard_errors * null["mc_se"]]


def _criteria(table: pd.DataFrame) -> pd.Series:
    """The rows of replication criteria (shown beside the verdicts, deciding none): not held to 5 %."""
    return table["criterion"].astype(bool)


def criteria_rates(table: pd.DataFrame) -> pd.DataFrame:
    """The replication criteria's rows side by side: per criterion, run counts and noise, the rate of success
    with no effect and with the paper's effect true, each with its Monte Carlo standard error."""
    rows = table[_criteria(table)]
    wide = rows.pivot_table(index=["test", "runs", "paper_runs", "distribution"], columns="truth",
                            values=["rate", "mc_se"], sort=False)
    wide.columns = [f"{value} ({truth})" for value, truth in wide.columns]
    return wide.reset_index().round(4)


def draw_null_rates(table: pd.DataFrame, path: Path) -> None:
    """Each null row's rate of wrong decisive verdicts with 2 Monte Carlo standard errors, by test kind and
    run count; the old rules (controls) in red; 5 % dashed."""
    null = table[(table["truth"] == "null") & ~_criteria(table)].copy()
    null["row"] = null["test"] + " | " + null["guards"]
    rows = list(dict.fromkeys(null.sort_values(["control", "test"])["row"]))
    fig, ax = plt.subplots(figsize=(9, 0.35 * len(rows) + 1.2))
    markers = {"normal": "o", "t3": "^", "lognormal": "s", "yes/no": "D"}
    for y, row in enumerate(rows):
        for _, r in null[null["row"] == row].iterrows():
            colour = "tab:red" if r["control"] else plt.cm.viridis(np.log(r["runs"]) / np.log(120))
            ax.errorbar(r["rate"], y + (np.log(r["runs"]) / np.log(120) - 0.5) * 0.6, xerr=2 * r["mc_se"],
                        fmt=markers.get(r["distribution"], "o"), color=colour, ms=3, lw=0.6)
    ax.axvline(INFERENCE.alpha, color="0.3", ls="--", lw=1)
    ax.set_yticks(range(len(rows)), rows, fontsize=7)
    ax.invert_yaxis()
    ax.set_xlabel("share of wrong decisive verdicts under the null (2 Monte Carlo SE)")
    handles = [plt.Line2D([], [], marker=m, color="0.4", ls="", label=d) for d, m in markers.items()]
    handles += [plt.Line2D([], [], marker="o", color="tab:red", ls="", label="old rule (control)")]
    ax.legend(handles=handles, fontsize=7, loc="lower right")
    ax.set_title("Error rates under the null (colour: run count, 5 to 100)", fontsize=9, loc="left")
    fig.tight_layout()
    atomic.save_figure(fig, path, dpi=110, bbox_inches="tight")  # the rules' names are long
    plt.close(fig)


def draw_power(table: pd.DataFrame, path: Path) -> None:
    """The operating characteristic of a single paired check and of the median's sign test: the share
    reproduced against the run count, at no effect and at effects of 0.5 and 1 standard deviation."""
    fig, axes = plt.subplots(1, 2, figsize=(9, 3.4), sharey=True)
    for ax, test in zip(axes, ["order", "threshold (median)"]):
        chosen = table[(table["test"] == test) & (table["guards"] == "reproduced")]
        for (distribution, effect), rows in chosen.groupby(["distribution", "effect"]):
            rows = rows.sort_values("runs")
            ax.plot(rows["runs"], rows["rate"], marker="o", ms=3,
                    ls={"normal": "-", "t3": "--", "lognormal": ":"}[distribution],
                    color={0.0: "tab:red", 0.5: "tab:orange", 1.0: "tab:green"}[effect],
                    label=f"{effect:g} sd, {distribution}")
        ax.axhline(INFERENCE.alpha, color="0.3", ls="--", lw=0.8)
        ax.axhline(0.8, color="0.6", ls=":", lw=0.8)
        ax.set_xscale("log")
        ax.set_xlabel("runs")
        ax.set_title(test, fontsize=9, loc="left")
    axes[0].set_ylabel("share reproduced")
    axes[1].legend(fontsize=6, ncol=1, loc="center right")
    fig.tight_layout()
    atomic.save_figure(fig, path, dpi=110, bbox_inches="tight")  # the rules' names are long
    plt.close(fig)


def write_calibration_page(table: pd.DataFrame, reports: Path) -> Path:
    """The calibration page of ``table`` (:func:`replication.evidence.calibration.calibrate`'s) under
    ``<reports>/calibration/``."""
    out = reports / "calibration"
    out.mkdir(parents=True, exist_ok=True)
    draw_null_rates(table, out / "null_rates.png")
    draw_power(table, out / "power.png")
    shown = table.drop(columns=["holds", "replications"]).round({"rate": 4, "mc_se": 4, "wrong_rate": 4,
                                                                   "power": 4})
    page = out / "index.html"
    atomic.write_text(page, render(
        "calibration.html.j2", title="How often the verdict rules err: calibration",
        failed=failures(table), controls=failures(table, control=True), table=html_table(shown), replications=int(table["replications"].max()),
        criteria=CRITERIA, criteria_rates=html_table(criteria_rates(table)),
        rows=len(table), floor=2.0 ** -5, equivalence_alpha=INFERENCE.equivalence_alpha,
        detect5=detectable(1.0, 5), detect100=detectable(1.0, 100)))
    return page
