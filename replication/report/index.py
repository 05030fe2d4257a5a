"""``reports/index.html``: every experiment with a report, linked, with its verdict counts."""

import datetime
import json
from pathlib import Path

import replication
from replication.paths import experiment_names
from replication.report.render import render


def write_index(reports: Path) -> Path:
    experiments, missing = [], []
    for name in experiment_names():
        summary = reports / name / "summary.json"
        if not summary.exists():
            missing.append(name)
            continue
        entry = json.loads(summary.read_text())
        entry["verdicts"] = ", ".join(f"{k}: {v}" for k, v in sorted(entry["verdicts"].items())) or "-"
        experiments.append(entry)
    reports.mkdir(parents=True, exist_ok=True)
    page = reports / "index.html"
    page.write_text(
        render(
            "index.html.j2",
            title="Particle-filter tracking papers: replication report",
            experiments=experiments,
            missing=missing,
            benchmark=(reports / "benchmark" / "index.html").exists(),
            generated=datetime.date.today().isoformat(),
            version=replication.__version__,
        )
    )
    return page
