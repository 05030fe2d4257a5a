"""``reports/index.html``: every published cell against ours, then every experiment with a report, linked.

The summary of every published cell (:mod:`replication.report.summary`) is
also written as ``reports/summary.csv``.
"""

import datetime
from pathlib import Path

from omegaconf import OmegaConf

import replication
from replication.paths import CONF_DIR, experiment_names, resolve
from replication.report.published import load_published
from replication.report.render import render
from replication.report.summary import counts, experiment_configs, load_summaries, summary_table

TITLE = "Particle-filter tracking papers: replication report"


def default_published_values() -> Path:
    """The ``published_values`` of ``conf/config.yaml``, resolved from the project root."""
    return resolve(OmegaConf.load(CONF_DIR / "config.yaml").published_values)


def write_index(reports: Path, published_values: str | Path | None = None) -> Path:
    reports = Path(reports)
    summaries = load_summaries(reports)
    experiments, missing = [], []
    for name in experiment_names():
        if name not in summaries:
            missing.append(name)
            continue
        entry = dict(summaries[name])
        entry["verdicts"] = ", ".join(f"{k}: {v}" for k, v in sorted(entry["verdicts"].items())) or "-"
        entry["ablation"] = "ablation" in name  # the studies on top of the papers get their own section
        experiments.append(entry)
    published = load_published(str(resolve(published_values or default_published_values())))
    cells = summary_table(published, summaries, experiment_configs())
    reports.mkdir(parents=True, exist_ok=True)
    cells.drop(columns=["link_text"]).to_csv(reports / "summary.csv", index=False)
    page = reports / "index.html"
    page.write_text(
        render(
            "index.html.j2",
            title=TITLE,
            experiments=experiments,
            missing=missing,
            cells=cells.to_dict("records"),
            counts=counts(cells),
            benchmark=(reports / "benchmark" / "index.html").exists(),
            pdf=(reports / "replication.pdf").exists(),
            generated=datetime.date.today().isoformat(),
            version=replication.__version__,
        )
    )
    return page
