"""Each paper's findings are rendered from the record, never typed: ``docs/findings/`` is what the shipped
record renders (a changed record without regenerated findings fails here), a template naming what the
record lacks fails in one line, and the numbers are shown as the report shows them."""

import io
import json
import shutil
from pathlib import Path

import pandas as pd
import pytest

from replication.paths import PACKAGE_DIR
from replication.record.manifest import MANIFEST, PAGES
from replication.report.__main__ import findings, main as report
from replication.evidence.scorecard import Scorecard
from replication.evidence.tables import interval as estimate, number
from replication.report.findings import (README, README_MARKS, README_TEMPLATE, Drawn, drawn_inputs, duration, inputs,
                                         readme_part, record_digest, render, stale, write_html, write_pages)

ROOT = PACKAGE_DIR.parent
FINDINGS = ROOT / "docs" / "findings"
PUBLISHED = ROOT.parent / "shared" / "reference" / "published_values.csv"


@pytest.fixture(scope="module")
def shipped_pages(tmp_path_factory):
    """The shipped record's pages, drawn as ``report source=record`` draws them."""
    if not PUBLISHED.exists():
        pytest.skip("../shared/reference is not beside this clone")
    reports = tmp_path_factory.mktemp("reports")
    report(["source=record", f"record={ROOT / 'record'}", f"reports={reports}", "pdf=false", "outside_project=true"])
    return reports


def test_the_findings_on_disk_were_rendered_from_this_record_these_templates_and_this_code():
    if not PUBLISHED.exists():
        pytest.skip("../shared/reference is not beside this clone")
    why = stale(FINDINGS, inputs(ROOT / "record", FINDINGS / "templates", PUBLISHED), ROOT / "README.md")
    assert not why, f"docs/findings/ is stale ({'; '.join(why)}): run make findings"


def test_a_changed_input_or_a_page_edited_by_hand_makes_the_findings_stale(tmp_path):
    rendered_from = {"record": "a", "templates": "b", "code": "c"}
    readme = tmp_path / "project" / "README.md"
    readme.parent.mkdir()
    readme.write_text(f"# R\n\n{README_MARKS[0]} by hand -->\nold\n{README_MARKS[1]}\n\nbelow\n")
    write_pages({"p": "# P\n", "index": "# all\n", README: "12 MB\n"}, tmp_path, rendered_from, readme)
    assert readme.read_text() == f"# R\n\n{README_MARKS[0]} by hand -->\n12 MB\n{README_MARKS[1]}\n\nbelow\n"
    assert not (tmp_path / f"{README}.md").exists()
    assert stale(tmp_path, rendered_from, readme) == []
    assert stale(tmp_path, {**rendered_from, "record": "z"}, readme) == ["the record changed since they were rendered"]
    (tmp_path / "p.md").write_text("# P, better\n")
    (tmp_path / "q.md").write_text("# Q\n")
    readme.write_text(readme.read_text().replace("12 MB", "11 MB"))  # the README's rendered part typed over
    assert stale(tmp_path, rendered_from, readme) == [
        "README.md's part on the record was edited by hand", "p.md was edited by hand", "q.md is not rendered"]
    readme.write_text("# R, marks gone\n")
    assert "README.md's part on the record was edited by hand" in stale(tmp_path, rendered_from, readme)
    with pytest.raises(LookupError, match="README.md has no part for the record: put <!-- rendered from the record"):
        write_pages({README: "12 MB\n"}, tmp_path, rendered_from, readme)


@pytest.mark.slow  # draws every page of the record (about 2 minutes); the test above checks the same inputs
def test_the_findings_on_disk_are_what_the_shipped_record_renders(shipped_pages):
    pages = render(Drawn(shipped_pages / PAGES), FINDINGS / "templates")
    on_disk = {p.stem: p.read_text() for p in FINDINGS.glob("*.md")}  # drawn by the code and record of today
    on_disk[README] = readme_part(ROOT / "README.md")
    assert set(pages) == set(on_disk) == {"index", "ism_pf", "bis_pf", "gps_qmcpf", "fusion_pf", "hspf", README}
    stale = [name for name in pages if pages[name] != on_disk[name]]
    assert not stale, f"docs/findings/ differs from what the record renders for {stale}: run pf-replicate findings"
    assert (shipped_pages / PAGES / "findings" / "bis_pf.html").exists()  # and the record's pages show them
    status = json.loads((shipped_pages / PAGES / "status.json").read_text())
    assert status["drawn_from"]["record"] == record_digest(ROOT / "record")  # its manifest and profile
    assert f"{status['runs']:,} runs" in pages["index"]


def _drawn(tmp_path: Path) -> Drawn:
    folder = tmp_path / "pages"
    (folder / "exp").mkdir(parents=True)
    claims = io.StringIO("paper,claim_id,claim,quote_english,where,verdict,reason,number,ci_low,ci_high,"
                         "level,runs,deciding,robustness\np,p.a,A beats B,A is better than B,Table 1,"
                         "reproduced,2 of 2 checks hold,0.123456,0.1,0.15,0.9,20,A - B,one reading\n"
                         "p,p.b,C beats D,C is better than D,Table 2,not reproduced,a cell,0.5,0.25,0.75,"
                         "0.95,10,C N=1,one reading\n")
    cells = io.StringIO("paper,table,method,condition,metric,paper_value,ours,runs,verdict\n"
                        "p,1,A,N=1,rmse,4.2,4.25,20,reproduced\n")
    (folder / "exp" / "t.csv").write_text("method,condition,ours,ci_low,ci_high,failed runs\n"
                                          "A,N=1,12345.6,,,3\nB,N=1,0.5,0.25,0.75,0\n")
    (folder / "exp" / "summary.json").write_text(json.dumps({"paper": "p"}))
    methods = [{"experiment": "exp", "method": "A", "cpu_minutes": 1.5, "parts": {"frames": 0.2, "filter": 0.8}},
               {"experiment": "exp", "method": "B", "cpu_minutes": 0.5, "parts": {"frames": 0.6, "likelihood": 0.4}},
               {"experiment": "exp", "method": "C", "cpu_minutes": 0.5, "parts": {}}]  # C: made by older code
    (folder / "status.json").write_text(json.dumps({"runs": 40, "megabytes": 11.8, "experiments": {
        "exp": {"runs": 40, "minutes": 1.25, "cpu_minutes": 2.5, "stale": 0, "universes": 0, "designed": 0,
                "thread_cpu_minutes": 2.25, "load_1m": [1.5, 2.25], "reference_ms": 4.5,
                "before": {"minutes": 2.0, "cpu_minutes": 4.0, "commits": ["abc1234"], "written": "2026-11-01"}},
        "exp_readings": {"runs": 300, "minutes": None, "cpu_minutes": 9.5, "stale": 0, "universes": 6,
                         "designed": 17, "before": None}},
        "profile": {"made": {"git_commit": "abcdef123456", "machine": "x86_64 CPU"},
                    "stages": ["frames", "likelihood", "filter", "scoring", "rest"], "methods": methods}}))
    cells = pd.read_csv(cells, keep_default_na=False, na_values=[""], dtype={"ours": str}).assign(link_text="")
    decided = Scorecard({}, {}, cells, {}, pd.read_csv(claims, keep_default_na=False, na_values=[""]))
    return Drawn(folder, decided=decided)


def test_a_template_renders_claims_rows_and_tables_from_the_drawn_pages(tmp_path):
    (tmp_path / "t").mkdir()
    (tmp_path / "t" / "p.md.j2").write_text(
        '{{ claim("p.a").verdict }}: {{ claim("p.a").estimate }}; {% set t = table("exp", "t") -%}'
        '{{ t.at(method="A").ours }} {{ t.at(method="B").estimate }} {{ t.at(method="A")["failed runs"] }}; '
        '{{ experiment("exp").minutes }}\n{{ scorecard() }}\n{{ cells() }}\n{{ times() }}\n')
    page = render(_drawn(tmp_path), tmp_path / "t")["p"]
    first, *tables = page.splitlines()
    assert first == "reproduced: 0.1235 [0.1, 0.15]; 12,346 0.5 [0.25, 0.75] 3; 1.25"
    assert "| claim | the paper says | verdict | deciding | estimate [interval] | runs | under every reading |" in tables
    # each interval says its level: a one-sided test's 90 %, a published cell's 95 %
    assert ("| `p.a`: A beats B | \u201cA is better than B\u201d (Table 1) | **reproduced** | A - B | 0.1235 [0.1, 0.15] (90% CI) "
            "| 20 | one reading |") in tables
    assert ("| `p.b`: C beats D | \u201cC is better than D\u201d (Table 2) | **not reproduced** | C N=1 | 0.5 [0.25, 0.75] "
            "(95% CI) | 10 | one reading |") in tables
    assert "| 1 | A | N=1 | rmse | 4.2 | 4.25 | 20 | reproduced |" in tables
    # recorded again: what it took, with its threads' CPU, the load (median / max) and the machine's speed
    assert "| `exp` | 40 |  | 1.25 | 2.5 | 2.25 | 1.5 / 2.25 | 4.5 | 2 min, 4 CPU-min (abc1234) |" in tables
    assert "| `exp_readings` | 300 | 6 of 17 |  | 9.5 |  |  |  |  |" in tables  # a multiverse the record holds in part


def test_the_readme_part_gives_the_record_size_and_what_each_part_took(tmp_path):
    (tmp_path / "t").mkdir()
    (tmp_path / "t" / README_TEMPLATE).write_text("{{ record.megabytes }} MB\n{{ parts() }}\n{{ profiled.git_commit }} "
                                                  "{{ profiled_experiments }}\n{{ where_time_goes(false) }}\n"
                                                  "{{ where_time_goes(true) }}\n")
    drawn = _drawn(tmp_path)
    status = json.loads((drawn.folder / "status.json").read_text())
    status["experiments"]["exp_readings"]["before"] = {"minutes": None, "cpu_minutes": 15.0, "commits": ["abc1234"],
                                                       "written": "2026-11-01"}  # recorded again, in less time
    (drawn.folder / "status.json").write_text(json.dumps(status))
    pages = render(drawn, tmp_path / "t")
    assert set(pages) == {README}  # a part, not a page of its own
    size, *table = pages[README].splitlines()
    assert size == "11.8 MB"
    assert "| part | runs | universes | CPU-hours | CPU-hours before | on 2 workers | on 2 workers before |" in table
    # 2.5 CPU-minutes, 4 before
    assert "| the 1 experiments | 40 |  | 0.04 | 0.07 | 1 min, measured | 2 min, measured |" in table
    assert "| `exp_readings` | 300 | 6 of 17 | 0.16 | 0.25 | 5 min, CPU-hours / 2 | 8 min, CPU-hours / 2 |" in table
    assert "abcdef123456 1" in table
    # the methods' parts weighted by their CPU (1.5 and 0.5 minutes; C, not profiled, left out): frames
    # (1.5 x 0.2 + 0.5 x 0.6) / 2 = 30 %, the likelihood 0.5 x 0.4 / 2 = 10 %, the filter 1.5 x 0.8 / 2 = 60 %
    assert "| experiment | CPU-minutes profiled | frames % | likelihood % | filter % |" in table
    assert "| `exp` | 2 | 30 | 10 | 60 |" in table
    assert "| `exp` | A | 1.5 | 20 |  | 80 |" in table and "| `exp` | B | 0.5 | 60 | 40 |  |" in table
    assert [duration(m) for m in (41.1, 89, 90, 265)] == ["41 min", "89 min", "1.5 h", "4.4 h"]
    assert write_html(pages, tmp_path / "html") == []  # the index page says the same


@pytest.mark.parametrize("template, named", [
    ('{{ claim("p.zz").verdict }}', "no claim 'p.zz'"),
    ('{{ table("exp", "t").at(method="C").ours }}', "exp/t at method=C: 0 rows, not one"),
    ('{{ table("exp", "t").at(method="A").nope }}', "exp/t at method=A has no column 'nope'"),
    ('{{ table("exp", "gone").rows }}', "no table exp/gone"),
    ('{{ undefined_name }}', "'undefined_name' is undefined"),
])
def test_a_template_naming_what_the_record_lacks_fails_naming_it(tmp_path, template, named):
    (tmp_path / "t").mkdir()
    (tmp_path / "t" / "p.md.j2").write_text(template)
    with pytest.raises(LookupError, match="p.md.j2: .*" + named.replace("(", r"\(")):
        render(_drawn(tmp_path), tmp_path / "t")


def test_numbers_are_shown_to_four_digits_and_an_interval_only_where_it_is_defined():
    assert [number(v) for v in (0.123456, 4.5, 1234.5, 12345.6, float("nan"), None)] == \
        ["0.1235", "4.5", "1234", "12,346", "", ""]
    assert estimate(4.25, 4.0, 4.5) == "4.25 [4, 4.5]"
    assert estimate(4.25, None, 4.5) == estimate(4.25, float("nan"), 4.5) == "4.25"


def test_the_html_pages_link_to_each_other(tmp_path):
    written = write_html({"p": "# P\n\n[All papers](index.md), [x](https://example.org/a.md)\n\n| a |\n|---|\n| 1 |\n"},
                         tmp_path)
    html = written[0].read_text()
    assert '<a href="index.html">All papers</a>' in html and 'href="https://example.org/a.md"' in html
    assert "<table>" in html and "<title>P</title>" in html


def test_findings_without_a_record_is_one_line(tmp_path, capsys):
    with pytest.raises(SystemExit) as stopped:
        findings([f"record={tmp_path}", f"findings={tmp_path}"])
    assert stopped.value.code == 2
    assert "no record here" in capsys.readouterr().err


def test_findings_writes_the_pages_and_draws_the_record_only_when_needed(tmp_path, monkeypatch, capsys):
    pages = _drawn(tmp_path).folder
    record, reports, out = tmp_path / "record", tmp_path / "reports", tmp_path / "findings"
    record.mkdir()
    (record / MANIFEST).write_text("{}")
    shutil.copytree(pages, reports / PAGES)
    (out / "templates").mkdir(parents=True)
    drawn_from = drawn_inputs(inputs(record, out / "templates", tmp_path / "none.csv"))
    status = json.loads((reports / PAGES / "status.json").read_text())
    (reports / PAGES / "status.json").write_text(json.dumps({**status, "drawn_from": drawn_from}))
    (out / "templates" / "p.md.j2").write_text('{{ experiment("exp").runs }}\n')
    drew = []
    monkeypatch.setattr("replication.report.__main__.main", lambda argv: drew.append(argv))
    argv = [f"record={record}", f"reports={reports}", f"findings={out}", f"published_values={tmp_path / 'none.csv'}"]
    findings(argv)
    assert (out / "p.md").read_text() == "40\n" and not drew
    assert stale(out, inputs(record, out / "templates", tmp_path / "none.csv"), tmp_path / "README.md") == []
    (record / MANIFEST).write_text('{"changed": 1}')  # another record: its pages are drawn again first
    findings(argv)
    assert drew and "source=record" in drew[0]
