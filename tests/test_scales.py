"""One default scale, said everywhere, and the two scales' reports apart: a quick run never replaces a
paper-scale page or its verdict on the scorecard, which names each verdict's scale."""

import shutil
import subprocess
import sys

import pandas as pd
import yaml

from conftest import PROJECT_ROOT
from replication.evidence.schema import Summary
from replication.paths import CONF_DIR
from replication.report.experiments import write_experiment
from replication.evidence.scorecard import Scorecard
from replication.report.pages.index import write_index
from replication.runner.config import expand
from replication.runner.execute import execute
from replication.runner.results import Results
from replication.runner.store import Store
from replication.scales import SCALES, default_scale, index_from, report_folder


def test_the_default_scale_is_quick_and_every_place_says_so():
    assert yaml.safe_load((CONF_DIR / "config.yaml").read_text())["scale"] == default_scale() == "quick"
    shown = subprocess.run([sys.executable, "-m", "replication", "--help"], cwd=PROJECT_ROOT, capture_output=True,
                           text=True, timeout=60, check=True).stdout
    assert "scale              quick (the default" in shown
    assert "the quick scale (the default)" in (PROJECT_ROOT / "README.md").read_text()
    assert "The quick scale is the default" in (PROJECT_ROOT / "docs" / "commands.md").read_text()


def test_both_scales_pages_stay_and_the_scorecard_names_each_verdicts_scale(make_cfg, tmp_path, capsys):
    """hspf_ungm run at the paper scale (5 runs of each method), then at the quick one (2): both pages stay; the
    scorecard takes the paper scale's verdict and says so, and the quick one's where no paper-scale page stands."""
    reports = tmp_path / "reports"
    for scale, runs in (("paper", 5), ("quick", 2)):
        cfg = make_cfg("hspf_ungm", f"scale={scale}", f"experiment.runs.{scale}={runs}")
        store = Store(tmp_path / "experiments", "hspf_ungm")
        execute(expand(cfg), store, n_jobs=1, progress=False)
        write_experiment(cfg, Results.of(cfg, expand(cfg), store))
    paper, quick = (Summary.read(report_folder(reports, "hspf_ungm", scale) / "summary.json") for scale in SCALES)
    assert (paper.scale, paper.n_runs, quick.scale, quick.n_runs) == ("paper", 15, "quick", 6)
    assert report_folder(reports, "hspf_ungm", "quick") == reports / "quick" / "hspf_ungm"
    for scale in SCALES:  # each page links back to the one index
        page, home = report_folder(reports, "hspf_ungm", scale) / "index.html", index_from("hspf_ungm", scale)
        assert f'href="{home}"' in page.read_text() and (page.parent / home).resolve() == reports / "index.html"

    def scorecard() -> tuple[str, str, str]:
        index = write_index(reports, Scorecard.read(reports)).read_text()
        row = index.split('<tr id="hspf.ungm">', 1)[1].split("</tr>", 1)[0]
        return index, row, pd.read_csv(reports / "claims.csv").set_index("claim_id").loc["hspf.ungm", "scale"]

    index, row, scale = scorecard()
    assert 'href="hspf_ungm/index.html"' in index and 'href="quick/hspf_ungm/index.html"' in index  # both pages
    assert scale == "paper" and "paper scale" in row and 'href="hspf_ungm/index.html#claims"' in row
    # a page in the other scale's folder (written before the scales lived apart) is skipped, and said
    shutil.copy(report_folder(reports, "hspf_ungm", "quick") / "summary.json", reports / "hspf_ungm" / "summary.json")
    capsys.readouterr()
    index, row, scale = scorecard()
    assert "hspf_ungm/summary.json is at the quick scale, in the paper scale's folder" in capsys.readouterr().err
    assert scale == "quick" and "quick scale" in row and 'href="quick/hspf_ungm/index.html#claims"' in row
