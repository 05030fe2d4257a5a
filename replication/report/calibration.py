"""``reports/calibration.csv`` and its page (:mod:`replication.report.pages.calibration`): how often each verdict
rule errs.

The table is :func:`replication.evidence.calibration.calibrate`'s: every rule
simulated through the code that decides, under normal, heavy-tailed and skewed
noise, at the run and check counts the scales use.  It takes minutes, so it is
kept beside a note of the code and replications that made it
(``calibration.json``) and made again only when a module the calibration
runs (``replication/evidence/calibration.py`` and what it imports) changes or
more replications are asked for:
``make replicate`` reuses it.

    python -m replication.report.calibration [reports=DIR] [replications=N] [force=true]
"""

import json
import sys
from dataclasses import dataclass
from pathlib import Path

import pandas as pd
from omegaconf import OmegaConf
from tqdm.auto import tqdm

from replication import atomic
from replication.arguments import read as read_arguments
from replication.evidence import calibration
from replication.evidence.settings import INFERENCE
from replication.paths import CONF_DIR, resolve
from replication.report.pages.calibration import write_calibration_page
from replication.runner.provenance import run_code_digest

CSV = "calibration.csv"
NOTE = "calibration.json"


def evidence_digest() -> str:
    """SHA-256 (12 hex digits) of the deciding code the calibration simulates: its module and every module it
    imports (:func:`~replication.runner.provenance.run_code_digest`)."""
    return run_code_digest(("evidence/calibration.py",))


def load_or_calibrate(reports: Path, replications: int = calibration.REPLICATIONS, force: bool = False) -> pd.DataFrame:
    """The stored table when the deciding code, the inference setting and the replications are those that made
    it, else a new one."""
    csv, note = reports / CSV, reports / NOTE
    wanted = {"evidence": evidence_digest(), "replications": replications, "seed": calibration.SEED,
              "inference": INFERENCE.as_dict()}
    if not force and csv.exists() and note.exists() and json.loads(note.read_text()) == wanted:
        return read(csv)
    with tqdm(total=len(calibration.cases()), desc="calibration", unit="rule") as bar:
        table = calibration.calibrate(replications, progress=lambda done, total: bar.update(1))
    reports.mkdir(parents=True, exist_ok=True)
    atomic.save(csv, lambda tmp: table.to_csv(tmp, index=False))
    atomic.write_text(note, json.dumps(wanted, indent=1))
    return table


def read(path: Path) -> pd.DataFrame:
    """The table back from its CSV ('null' is a truth, not a missing value)."""
    return pd.read_csv(path, keep_default_na=False, na_values=[""])


def write_calibration(reports: Path, replications: int = calibration.REPLICATIONS, force: bool = False) -> Path:
    """The calibration page (and its table, made only when stale)."""
    return write_calibration_page(load_or_calibrate(reports, replications, force), reports)


@dataclass(frozen=True)
class Options:
    reports: str | None = None
    replications: int = calibration.REPLICATIONS
    force: bool = False


def main(argv: list[str]) -> None:
    options, _ = read_arguments(argv, Options, "python -m replication.report.calibration")
    reports = resolve(options.reports or OmegaConf.load(CONF_DIR / "config.yaml").reports)
    page = write_calibration(reports, options.replications, options.force)
    print(f"calibration: {page}")


if __name__ == "__main__":
    main(sys.argv[1:])
