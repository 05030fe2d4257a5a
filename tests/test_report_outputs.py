"""The report as a reader gets it: the summary of every published cell, offline pages, PDF, a browser."""

import json
import re
import shutil
import subprocess
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from hydra import compose, initialize_config_dir

from replication.evidence.quantities import quantity
from replication.paths import CONF_DIR, resolve
from replication.evidence.scorecard import Scorecard
from replication.report.pages.index import write_index
from replication.evidence.published import load_published
from replication.report.pages.render import ENVIRONMENT, browser, open_in_browser
from replication.evidence.summary import counts, experiment_configs, summary_table
from replication.evidence.schema import Summary, dump, load
from replication.evidence.statistics import Estimate
from replication.evidence.tables import KEYS, CellResult, TableKind
from replication.evidence.verdict import Outcome, Verdict

PUBLISHED = resolve("../shared/reference/published_values.csv")
CSV = (
    "paper,table,experiment,method,metric,condition,value,unit,note\n"
    "qmc,1,ungm,PF,rmse,N=100,4.2,,Q=10\n"  # 0: compared twice (two tables of ours)
    "qmc,1,ungm,QPF,rmse,N=100,2.0,,\n"  # 1: a method we do not have
    "qmc,1,ungm,PF,rmse,N=900,3.0,,\n"  # 2: a condition ours never maps to
    "qmc,2,heli,PF,ess,N=100,50,particles,private video of the authors\n"  # 3: the experiment is not run
    "trk,1,office,PF,time,N=10,4.5,ms,office sequence\n"  # 4: matched at a stand-in scene
    "trk,1,soccer,PF,time,,18.5,ms,real soccer video (not public)\n"  # 5: a scene we do not reproduce
    "trk,1,exp2,MCMC,error,,,px,failed (reported as error)\n"  # 6: no value in the paper
    "trk,9,exp2,PF,modes,,success,,\n"  # 7: no table of ours covers it
    "trk,1,office,PF,rate,N=10,40,%,\n"  # 8: the experiment ran, at quick scale
)
CONFIGS = {
    "qmc_ungm": {"paper": "qmc", "methods": {"PF": {}}, "report": {"tables": [
        {"name": "t1", "paper_table": "1", "metric": "rmse",
         "match": [{"ours": {"N": 100}, "paper": {"condition": "N=100"}}]}]}},
    "qmc_heli": {"paper": "qmc", "methods": {"PF": {}}, "report": {"tables": [
        {"name": "t2", "paper_table": ["2"], "metric": "ess"}]}},
    "trk": {"paper": "trk", "methods": {"PF": {}, "MCMC": {}}, "report": {"tables": [
        {"name": "time", "paper_table": "1", "metric": "ms", "paper_metric": "time",
         "match": [{"ours": {"scene": "office"}, "paper": {"experiment": "office"}}]},
        {"name": "rate", "paper_table": "1", "metric": "r", "paper_metric": "rate",
         "match": [{"ours": {"scene": "office"}, "paper": {"experiment": "office"}}]}]}},
    "ablation": {"methods": {"PF": {}}, "report": {"tables": [{"name": "s", "metrics": ["rmse"]}]}},
}


REPRODUCED = Verdict(Outcome.REPRODUCED)


def _cell(published, index, table_name, ours, verdict, ci_low=np.nan, ci_high=np.nan, our_condition=""
          ) -> CellResult:
    return CellResult(index, *(str(published.at[index, k]) for k in KEYS), table_name=table_name,
                      our_method=published.at[index, "method"], our_condition=our_condition, runs=20,
                      estimate=Estimate(ours, ci_low, ci_high, 20, "t"), verdict=verdict)


@pytest.fixture
def published(tmp_path):
    path = tmp_path / "published.csv"
    path.write_text(CSV)
    return load_published(str(path))


def test_summary_has_one_row_per_published_cell_with_ours_or_a_reason(published):
    summaries = {
        "qmc_ungm": Summary("qmc_ungm", "", "qmc", "paper", 40, 40, cells=(
            _cell(published, 0, table_name="t1", ours=4.0, ci_low=3.5, ci_high=4.5, verdict=REPRODUCED),
            _cell(published, 0, table_name="t1_other", ours=5.0,
                  verdict=Verdict(Outcome.NOT_REPRODUCED, "+19%")),
        )),
        "trk": Summary("trk", "", "trk", "quick", 6, 6, cells=(
            _cell(published, 4, table_name="time", our_condition="scene=office", ours=1.5,
                  verdict=Verdict(Outcome.NOT_TESTABLE, "machine-dependent; ours/theirs = 0.33")),
        )),
    }
    table = summary_table(published, summaries, CONFIGS)
    assert len(table) == len(published)
    assert list(table["method"]) == list(published["method"])  # the csv's order
    first = table.iloc[0]
    assert first["ours"] == "4 [3.5, 4.5]" and first["verdict"] == "reproduced" and first["reason"] == ""
    assert first["outcome"] == "reproduced"
    assert first["link"] == "qmc_ungm/index.html#t1" and "t1_other" in first["also"]
    assert "not reproduced (+19%)" in first["also"]
    assert table.iloc[4]["our_condition"] == "scene=office" and table.iloc[4]["paper_value"] == "4.5 ms"
    reasons = list(table["reason"])
    assert reasons[1].startswith("method not reproduced: QPF")
    assert reasons[2] == "condition not reproduced: N=900"
    assert reasons[3] == "not run yet: experiment=qmc_heli"
    assert reasons[5].startswith("private video, no stand-in: soccer (real soccer video (not public))")
    assert reasons[6] == "no value in the paper: failed (reported as error)"
    assert reasons[7].startswith("not yet replicated")
    assert reasons[8] == "not run at this scale: trk at scale=paper (ran at quick)"
    assert list(table["reason_kind"])[1:4] == ["method not reproduced", "condition not reproduced", "not run yet"]
    assert counts(table)["reasons"]["not run yet"] == 1  # counted by kind, not by cutting the text at a colon
    assert table.iloc[8]["link"] == "quick/trk/index.html#unmatched"  # its page at the scale it ran
    assert all(bool(v) != bool(r) for v, r in zip(table["verdict"], table["reason"]))  # one or the other


def test_index_shows_the_summary_from_the_experiments_summary_json(tmp_path, published):
    reports = tmp_path / "reports"
    (reports / "quick" / "gps_qmcpf").mkdir(parents=True)
    Summary("gps_qmcpf", "QMC filters", "qmc", "quick", 4, 4, cells=(
        _cell(published, 0, table_name="table1_rmse", ours=4.0, ci_low=3.5, ci_high=4.5, verdict=REPRODUCED),
    )).write(reports / "quick" / "gps_qmcpf")
    page = write_index(reports, Scorecard.read(reports, tmp_path / "published.csv"))
    html = page.read_text()
    body = html.split('<table id="cells"', 1)[1].split("</table>", 1)[0]
    assert body.count("<tr") == 1 + len(published)  # header + one row per cell
    assert 'href="quick/gps_qmcpf/index.html#table1_rmse"' in body and "4 [3.5, 4.5]" in body
    assert "no value in the paper: failed (reported as error)" in body
    assert len(pd.read_csv(reports / "summary.csv", keep_default_na=False)) == len(published)


def _fabricated_records(runs, metrics, rng) -> pd.DataFrame:
    frame = pd.DataFrame([r.identity() for r in runs])
    for metric in metrics:
        n = len(frame)
        frame[metric] = rng.integers(0, 2, n) if quantity(metric).proportion else rng.uniform(0, 1, n)
    return frame


@pytest.mark.parametrize("name", sorted(
    n for n, c in experiment_configs().items()
    if any("paper_table" in s and "metrics" not in s for s in c.get("report", {}).get("tables", []))
))
def test_matched_cells_name_every_published_cell_a_table_matched(name):
    """For every experiment that compares with a paper table: each cell its tables matched gets an entry."""
    if not PUBLISHED.exists():
        pytest.skip("../shared is not beside the project")
    from omegaconf import OmegaConf

    from replication.runner.config import expand
    from replication.scales import at_scale

    with initialize_config_dir(config_dir=str(CONF_DIR), version_base="1.3"):
        cfg = compose("config", overrides=[f"experiment={name}", "scale=quick", "experiment.runs.quick=3"])
    runs = expand(cfg)
    experiment = at_scale(OmegaConf.to_container(cfg.experiment, resolve=True), "quick")
    specs = [s for s in experiment["report"]["tables"]  # a modes table reads stored strips, not fabricable
             if "paper_table" in s and "metrics" not in s and s.get("kind") != "modes"]
    records = _fabricated_records(runs, {s["metric"] for s in specs}, np.random.default_rng(0))
    published = load_published(str(PUBLISHED))
    compared = 0
    for spec in specs:
        table = TableKind.of(spec, experiment, published).build(records)
        entries = table.cells
        assert all(e.our_method in set(table.frame["method"]) for e in entries), spec["name"]
        pairs = {(e.published_index, e.our_method, e.our_condition) for e in entries}
        assert len(pairs) == len(entries)  # one entry per cell and row of ours (two stand-ins: two entries)
        for e in entries:
            assert e.key == tuple(published.loc[e.published_index, list(KEYS)])
        written = json.loads(json.dumps(dump(entries), allow_nan=False))  # plain JSON: no NaN, no numpy types
        assert dump(load(tuple[CellResult, ...], written)) == written  # and back through the one schema
        compared += len(entries)
    if name == "gps_qmcpf":
        assert compared == 28  # Table 1 (12 RMSE, 12 times) and Table 2 (4 ESS at N = 100)


# -- a real (small) report: HTML pages, PDF, a browser's view -------------------------------------------


pytestmark = pytest.mark.xdist_group("report_outputs")  # make test -n 2: one worker builds the fixture

@pytest.fixture(scope="module")
def reports(tmp_path_factory):
    """gps_qmcpf and hspf_ungm at 2 runs each, rebuilt by ``python -m replication.report`` (PDF, screenshot)."""
    if not PUBLISHED.exists():
        pytest.skip("../shared is not beside the project")
    from replication.report.__main__ import main
    from replication.runner.config import expand
    from replication.runner.execute import execute
    from replication.runner.store import Store

    root = tmp_path_factory.mktemp("report")
    overrides = ["scale=quick", "experiment.runs.quick=2", f"store={root / 'experiments'}",
                 f"reports={root / 'reports'}", "progress=false"]
    with initialize_config_dir(config_dir=str(CONF_DIR), version_base="1.3"):
        for name in ("gps_qmcpf", "hspf_ungm"):
            cfg = compose("config", overrides=[f"experiment={name}", *overrides])
            execute(expand(cfg), Store(resolve(cfg.store), name), n_jobs=1, progress=False)
    main(["experiment=gps_qmcpf,hspf_ungm", *overrides, f"screenshot={str(browser() is not None).lower()}"])
    return root / "reports"


class _Links(HTMLParser):
    def __init__(self):
        super().__init__()
        self.links, self.images, self.styles = [], [], []

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        for key in ("src", "href", "data", "poster", "srcset", "action"):
            if attrs.get(key):
                self.links.append((tag, key, attrs[key]))
        if tag == "img":
            self.images.append(attrs.get("src", ""))
        if attrs.get("style"):
            self.styles.append(attrs["style"])

    def handle_data(self, data):
        self.styles.append(data)  # <style> and <script> text: no url(http...), no @import


REMOTE = re.compile(r"^\s*(https?:|//|ftp:)", re.IGNORECASE)


def test_every_page_is_self_contained(reports):
    pages = sorted(reports.rglob("*.html"))
    assert {p.relative_to(reports).as_posix() for p in pages} >= {"index.html", "quick/gps_qmcpf/index.html",
                                                                   "quick/hspf_ungm/index.html"}
    for page in pages:
        parser = _Links()
        parser.feed(page.read_text())
        remote = [link for link in parser.links if REMOTE.match(link[2])]
        assert not remote, f"{page}: {remote}"
        assert not [s for s in parser.styles if re.search(r"url\(\s*['\"]?\s*(https?:)?//|@import", s)], page
        for tag, key, target in parser.links:  # every local link resolves (anchors aside)
            path = target.split("#", 1)[0]
            if path and not path.startswith(("mailto:", "data:")):
                assert (page.parent / path).exists(), f"{page}: {tag} {key}={target} is missing"
        for src in parser.images:
            assert (page.parent / src).read_bytes().startswith(b"\x89PNG\r\n\x1a\n"), f"{page}: {src}"
    import replication.report

    templates = sorted((Path(replication.report.__file__).parent / "pages" / "templates").glob("*.j2"))
    assert len(templates) >= 5
    for template in templates:
        assert not re.search(r"(src|href)\s*=\s*['\"]?(https?:)?//", template.read_text()), template


def test_summary_in_the_index_covers_every_published_cell(reports):
    published = load_published(str(PUBLISHED))
    summary = pd.read_csv(reports / "summary.csv", dtype=str, keep_default_na=False)
    assert list(summary["method"]) == list(published["method"]) and len(summary) == len(published)
    assert (summary["verdict"] != "").ne(summary["reason"] != "").all()
    rmse = summary[(summary["paper"] == "gps_qmcpf") & (summary["table"] == "1")
                   & (summary["metric"] == "rmse")]
    assert (rmse["verdict"] != "").all() and rmse["link"].str.startswith("quick/gps_qmcpf/index.html#").all()
    html = (reports / "index.html").read_text()
    assert 'href="replication.pdf"' in html and 'id="cells"' in html
    assert html.index('id="scorecard"') < html.index('id="cells"')  # the claims come first
    assert 'id="scale-banner"' in html and "make replicate SCALE=paper" in html  # quick scale, said up front
    assert 'id="scale-banner"' in (reports / "quick" / "gps_qmcpf" / "index.html").read_text()


def test_claims_csv_has_one_row_per_claim_with_a_verdict_and_its_interval(reports):
    from replication.evidence.claims import load_papers

    claims = pd.read_csv(reports / "claims.csv", keep_default_na=False)
    expected = [c.id for p in load_papers() for c in p.claims]
    assert list(claims["claim_id"]) == expected
    assert set(claims["verdict"]) <= {"reproduced", "not reproduced", "inconclusive", "not testable"}
    assert claims["cells"].astype(int).sum() == len(load_published(str(PUBLISHED)))
    rmse = claims.set_index("claim_id").loc["gps_qmcpf.rmse"]
    assert rmse["verdict"] == "not testable" and rmse["reason"] == "too few runs (2)"  # 2 runs: no verdict
    judged = claims[claims["ci_low"] != ""]
    assert (judged["ci_low"].astype(float) <= judged["number"].astype(float)).all()
    assert (judged["number"].astype(float) <= judged["ci_high"].astype(float)).all()
    uniform = claims.set_index("claim_id").loc["gps_qmcpf.uniform"]  # no runs needed: deterministic point sets
    assert uniform["verdict"] == "not reproduced" and uniform["robustness"].startswith("hinges on the reading")


def test_no_interval_in_the_reports_leaves_its_metrics_range(reports):
    from replication.evidence.quantities import quantity

    for folder in (reports / "quick" / "gps_qmcpf", reports / "quick" / "hspf_ungm"):
        for spec in experiment_configs()[folder.name]["report"].get("tables", []):
            path = folder / f"{spec['name']}.csv"
            if "metric" not in spec or not path.exists():
                continue
            table = pd.read_csv(path)
            if "ci_low" not in table or spec.get("kind") == "improvement":
                continue
            kind = quantity(spec["metric"]).scaled(spec.get("scale", 1.0))
            shown = table.dropna(subset=["ci_low", "ci_high"])
            assert (shown["ci_low"] >= kind.low).all() and (shown["ci_high"] <= kind.high).all(), path
            assert (shown["ci_low"] <= shown["ours"]).all() and (shown["ours"] <= shown["ci_high"]).all(), path


def _pdf_pages_and_text(path: Path) -> tuple[int, str | None]:
    try:
        import pypdf
    except ImportError:
        pypdf = None
    if pypdf is not None:
        reader = pypdf.PdfReader(str(path))
        return len(reader.pages), " ".join(page.extract_text() for page in reader.pages)
    pages = len(re.findall(rb"/Type\s*/Page\b", path.read_bytes()))  # matplotlib writes page objects plainly
    if shutil.which("pdftotext"):
        done = subprocess.run(["pdftotext", str(path), "-"], capture_output=True, text=True, check=True)
        return pages, done.stdout
    return pages, None


def test_pdf_has_the_summary_then_every_table_and_figure(reports):
    path = reports / "replication.pdf"
    assert path.read_bytes().startswith(b"%PDF")
    from replication.evidence.summary import load_summaries

    summaries = load_summaries(reports)
    assert set(summaries) == {"gps_qmcpf", "hspf_ungm"}
    configs = experiment_configs()
    tables = sum(len(c["report"].get("tables", [])) for n, c in configs.items() if n in summaries)
    figures = sum(len(c["report"].get("figures", [])) for n, c in configs.items() if n in summaries)
    pages, text = _pdf_pages_and_text(path)
    assert pages >= 1 + 1 + tables + figures  # title, summary, a page per table and per figure
    if text is None:
        pytest.skip("no PDF text extractor: pypdf is not installed and pdftotext is not on the PATH")
    flat = " ".join(text.split())
    for name, summary in summaries.items():
        assert summary.title in flat, name
    assert "Every published cell" in flat and "Table 1: RMSE of the state estimate" in flat
    assert flat.index("Scorecard") < flat.index("Every published cell")
    assert "Quick scale" in flat
    # the first page opens on every claim at a glance (the experiments' table comes after the scorecard)
    assert flat.index("each at a glance below") < flat.index("Scorecard") < flat.index("Experiments")
    assert _valid_png(reports / "glance.png")[1] > 500
    assert '<img class="glance" src="glance.png"' in (reports / "index.html").read_text()


def _valid_png(path: Path) -> tuple[int, int]:
    from PIL import Image

    with Image.open(path) as image:
        image.verify()
    with Image.open(path) as image:
        return image.size


@pytest.mark.skipif(browser() is None, reason="no Chromium on the PATH (Debian: apt-get install chromium)")
def test_pages_in_headless_chromium(reports, tmp_path):
    pages = ((reports / "index.html", "index.png"), (reports / "quick" / "gps_qmcpf" / "index.html", "gps.png"))
    for page, shot in pages:
        seen = open_in_browser(page, tmp_path / shot)
        assert seen["console"] == [], f"{page}: {seen['console']}"
        assert _valid_png(tmp_path / shot) == (1280, 2000)
        parser = _Links()
        parser.feed(seen["dom"])
        for src in parser.images:
            assert _valid_png(page.parent / src)[0] > 100, src
        if page.name == "index.html" and page.parent == reports:
            rows = seen["dom"].split('id="cells"', 1)[1].split("</table>", 1)[0].count("<tr")
            assert rows == 1 + len(load_published(str(PUBLISHED)))
        else:
            assert len(parser.images) == 4  # rmse_vs_n, ess_vs_n, rmse_vs_cost, point_sets
    assert _valid_png(reports / "screenshot.png") == (1280, 2000)  # python -m replication.report screenshot=true


@pytest.mark.skipif(browser() is None, reason="no Chromium on the PATH (Debian: apt-get install chromium)")
def test_tables_sort_on_a_header_click_and_broken_images_are_reported(tmp_path):
    page = tmp_path / "sort.html"
    page.write_text(ENVIRONMENT.from_string(
        '{% extends "base.html.j2" %}{% block body %}'
        "<table><tr><th>N</th><th>name</th></tr><tr><td>N=500</td><td>b</td></tr>"
        "<tr><td>N=20</td><td>a</td></tr><tr><td>N=100</td><td>c</td></tr></table>"
        "<img src='missing.png' alt='gone'><script>window.addEventListener('load', function () "
        "{ document.querySelector('th').click(); });</script>"
        "{% endblock %}"
    ).render(title="sort"))
    seen = open_in_browser(page)
    assert re.findall(r"<td>(N=\d+)</td>", seen["dom"]) == ["N=20", "N=100", "N=500"]
    assert seen["console"] and "image not loaded: missing.png" in seen["console"][0]
