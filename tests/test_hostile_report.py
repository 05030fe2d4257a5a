"""Markup in every config string that reaches a page is shown as text: headless Chromium runs none of it."""

import re
import subprocess
import sys

import pytest
from conftest import PROJECT_ROOT

from replication.report.pages.render import browser, open_in_browser

# Each sets an attribute on the page if it ever runs; the dumped DOM would carry it.
# (no quotes inside: they go through Hydra's quoted override strings as they are)
SCRIPT = "<script>document.documentElement.setAttribute(`data-pwned`,`script`)</script>"
IMAGE = "<img src=x onerror=document.documentElement.setAttribute(`data-pwned`,`img`)>"
STRINGS = {
    "experiment.title": f"Title {SCRIPT}",
    "experiment.methods.PF.label": f"PF {IMAGE}",
    "experiment.methods.HSPF.label": f"HSPF {SCRIPT}",
    "experiment.report.tables.0.title": f"Table {IMAGE}",
    "+experiment.note": f"a note {SCRIPT}",  # reaches the page's config dump only
}


@pytest.mark.e2e  # a subprocess, a killed runner or a cluster: make test-e2e runs it, make test does not
@pytest.mark.skipif(browser() is None, reason="no Chromium on the PATH (make test installs it as root with apt)")
def test_markup_from_a_config_never_runs_in_the_report(tmp_path):
    overrides = [f"{key}='{value}'" for key, value in STRINGS.items()]
    command = [sys.executable, "-m", "replication", "experiment=hspf_ungm", "scale=quick", "experiment.runs.quick=5",
               "experiment.methods.grid.n_points=201", f"store={tmp_path / 'experiments'}",
               f"reports={tmp_path / 'reports'}", "outside_project=true", "progress=false", "label=hostile", *overrides]
    result = subprocess.run(command, check=False, cwd=PROJECT_ROOT, capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr
    own = tmp_path / "reports" / "quick" / "hspf_ungm@hostile" / "index.html"
    for page in (own, tmp_path / "reports" / "index.html"):
        seen = open_in_browser(page)
        html_tag = re.search(r"<html[^>]*>", seen["dom"])[0]  # where a script that ran left its mark
        assert "data-pwned" not in html_tag, page
    page = own.read_text()
    for value in STRINGS.values():  # each shown, escaped, as the text it is
        escaped = value.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")
        assert escaped.split(" ", 1)[1] in page, value
