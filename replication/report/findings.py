"""Each paper's findings, rendered from the paper-scale record into ``docs/findings/<paper>.md`` (and
``index.md``) and the record's report pages, never typed (``pf-replicate findings``:
:func:`replication.report.__main__.findings`).

A paper's page is a hand-written Jinja template, ``docs/findings/templates/<paper>.md.j2``: the prose that
explains (what the paper leaves open, what we chose and why, why a number differs from the paper's), with
every number it quotes taken from the record's drawn pages (``<reports>/record``: the claims and cells their
``summary.json`` files decide, read through their schema as the scorecard reads them, each experiment's table
CSVs and ``status.json``) through these names:

- ``claim("bis_pf.time")``: a claim's row (``.verdict``, ``.estimate`` "value [low, high]", ``.runs``,
  ``.why``, ``.robustness``, ``.at_equal_cost``);
- ``table("bis_pf", "table2_error").at(method="BIS-PF", condition="scene=exp2_16_targets")``: one row of a
  table (:class:`~replication.evidence.tables.Table`, the one table class: ``.ours``, ``.estimate``, any column
  by name: ``row["failed runs"]``), its numbers shown to 4 significant digits; ``.rows`` every row;
- ``experiment("bis_pf")``: its runs, minutes and CPU-minutes as recorded (a multiverse's ``universes``
  recorded of those ``designed``);
- ``scorecard()``, ``cells()``, ``times()``: the paper's claims, its published cells beside ours, and its
  experiments' cost, as Markdown tables; ``criteria()``: per paper and over all, the claims meeting each
  replication criterion (:mod:`replication.evidence.criteria`), ``surviving``: the median share of the papers'
  effects that survives, in words.

- ``parts()``: the record's parts (the experiments together, each multiverse) and what each took.
- ``where_time_goes(by_method)``: the record's profile (``record/profile.json``, made by ``make record``)
  of its slowest experiments as a Markdown table, a row per experiment (its methods' parts weighted by
  their CPU) or per method; ``profiled``: what made it (commit, machine), ``profiled_experiments``: how many.

The README's part on the record (its size, what made it and what each part took: ``templates/_readme.md.j2``)
is rendered the same way between the README's :data:`README_MARKS`, the rest of the README staying as
written.  A row a template names that the record does not hold stops the rendering with one line naming it.
:data:`RENDERED` records what the pages were rendered from (the record, the templates, the configs, the
published values, the code) so that a check costs no drawing: :func:`stale` says why pages no longer match
(``tests/test_findings.py``).
"""

import hashlib
import json
import re
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

import jinja2
import pandas as pd

from replication import atomic
from replication.evidence.claims import Paper, load_papers
from replication.evidence.criteria import CRITERIA
from replication.evidence.scorecard import Scorecard
from replication.evidence.tables import Table, cell_value, interval, number
from replication.paths import CONF_DIR
from replication.record.manifest import MANIFEST, PROFILE, sha256
from replication.report.pages.effects import surviving_said
from replication.report.pages.recorded import STATUS
from replication.runner.provenance import run_code_digest

RENDERED = "rendered.json"  # beside the pages: what they were rendered from, and each page's SHA-256
README = "README"  # the name of the README's part on the record among the pages rendered
README_TEMPLATE = "_readme.md.j2"  # its template, beside the pages'
README_MARKS = ("<!-- rendered from the record", "<!-- end of the part rendered from the record -->")


def duration(minutes: float) -> str:
    """A wall time as the findings show it: whole minutes up to an hour and a half, else hours to 0.1."""
    return f"{minutes:.0f} min" if minutes < 90 else f"{minutes / 60:.1f} h"


@dataclass(frozen=True)
class Drawn:
    """The record's drawn pages (``<reports>/record``) as the templates read them: the claims and cells their
    summaries decide (judged against ``published``, the default values where none is given), their tables and
    status."""

    folder: Path
    published: Path | None = None
    decided: Scorecard | None = None  # what they decide; None: what the folder's summaries decide

    @property
    def status(self) -> dict:
        return json.loads((self.folder / STATUS).read_text())

    @cached_property
    def card(self) -> Scorecard:
        return self.decided or Scorecard.read(self.folder, self.published)

    @property
    def claims(self) -> pd.DataFrame:
        return self.card.claims

    @property
    def cells(self) -> pd.DataFrame:
        return self.card.cell_table

    def table(self, experiment: str, name: str) -> Table:
        """One of an experiment's tables as its page wrote it (numbers shown as :func:`number` shows them)."""
        path = self.folder / experiment / f"{name}.csv"
        if not path.exists():
            raise LookupError(f"the record's pages have no table {experiment}/{name}")
        return Table.read(pd.read_csv(path), f"{experiment}/{name}")

    def experiments_of(self, paper: str) -> list[str]:
        """The paper's experiments the record holds, by their summaries."""
        return [name for name, summary in self.card.summaries.items() if summary.paper == paper]


def context(drawn: Drawn, paper: str, papers: dict[str, Paper]) -> dict:
    """The names a template may use (see the module's docstring); ``paper`` its paper's key (or ``index``)."""
    claims = drawn.claims.set_index("claim_id", drop=False)
    status = drawn.status
    profile = status.get("profile") or {}  # where the slowest experiments' time goes (none: not profiled)

    def claim(claim_id: str) -> dict:
        if claim_id not in claims.index:
            raise LookupError(f"the record has no claim {claim_id!r}")
        c = {k: cell_value(v) for k, v in claims.loc[claim_id].to_dict().items()}
        return {**c, "verdict": c["verdict"], "why": c["reason"], "runs": number(c["runs"]),
                "estimate": interval(c["number"], c["ci_low"], c["ci_high"]) if c["number"] is not None else ""}

    def experiment(name: str) -> dict:
        if name not in status["experiments"]:
            raise LookupError(f"the record holds no experiment {name!r}")
        return {k: v if isinstance(v, (dict, list)) else number(v) for k, v in status["experiments"][name].items()}

    def scorecard() -> str:
        rows = claims[claims["paper"] == paper]
        header = ["claim", "the paper says", "verdict", "deciding", "estimate [interval]", "runs", "under every reading"]
        return markdown_table(header,
                              [[f"`{c}`: {t}", f"\u201c{q}\u201d ({w})", f"**{v}**", d or "",
                                interval(n, lo, hi, cell_value(lv)) if n == n else "", number(r) if r == r else "", rb or ""]
                               for c, t, q, w, v, d, n, lo, hi, lv, r, rb in rows[
                                   ["claim_id", "claim", "quote_english", "where", "verdict", "deciding", "number",
                                    "ci_low", "ci_high", "level", "runs", "robustness"]].itertuples(index=False)])

    def cells() -> str:
        rows = drawn.cells[drawn.cells["paper"] == paper].fillna("")
        return markdown_table(["table", "method", "condition", "metric", "paper", "ours", "runs", "verdict"],
                              [[t, m, c, mt, p, number(_float(o)), number(_float(r)), v] for t, m, c, mt, p, o, r, v
                               in rows[["table", "method", "condition", "metric", "paper_value", "ours", "runs",
                                        "verdict"]].itertuples(index=False)])

    def criteria() -> str:
        """Each replication criterion, its source, and per paper and over all the claims meeting it of those it
        applies to, then the effects."""
        shares = drawn.card.criteria
        return markdown_table(["criterion", "source", *(row["paper"] for row in shares)],
                              [[c.name, c.source, *(str(row[c.key]) for row in shares)] for c in CRITERIA])

    def verdicts(key: str) -> str:
        counted = claims[claims["paper"] == key]["verdict"].value_counts()
        return ", ".join(f"{n} {verdict}" for verdict, n in counted.items())

    def times() -> str:
        names = drawn.experiments_of(paper) if paper in papers else list(status["experiments"])
        rows = []
        for name in (n for n in names if n in status["experiments"]):
            shown, counts = experiment(name), status["experiments"][name]
            universes = f"{counts['universes']} of {counts['designed']}" if counts.get("designed") else ""
            load = counts.get("load_1m")
            rows.append([f"`{name}`", shown["runs"], universes, shown["minutes"], shown["cpu_minutes"],
                         shown.get("thread_cpu_minutes", ""), f"{number(load[0])} / {number(load[1])}" if load else "",
                         shown.get("reference_ms", ""), _previous(counts.get("before"))])
        return markdown_table(["experiment", "runs", "universes", "minutes (2 workers)", "CPU-minutes",
                               "thread CPU-minutes", "load (median / max)", "reference work (ms)",
                               "its previous recording"], rows)

    def parts() -> str:
        experiments = status["experiments"]
        single = [e for e in experiments.values() if not e.get("designed")]

        def took(recorded: list[dict]) -> tuple[str, str]:  # the experiments: CPU-hours, and their wall measured
            return (number(round(sum(e["cpu_minutes"] for e in recorded) / 60, 2)),
                    f"{duration(sum(e['minutes'] or 0 for e in recorded))}, measured")

        def spread(part: dict | None) -> tuple[str, str]:  # a multiverse: CPU-hours, and them on 2 workers
            return (number(round(part["cpu_minutes"] / 60, 2)), f"{duration(part['cpu_minutes'] / 2)}, CPU-hours / 2") \
                if part else ("", "")

        def row(part: str, runs: int, universes: str, now: tuple[str, str], before: tuple[str, str]) -> list[str]:
            return [part, number(runs), universes, now[0], before[0], now[1], before[1]]

        # an experiment recorded once took what it takes
        rows = [row(f"the {len(single)} experiments", sum(e["runs"] for e in single), "", took(single),
                    took([e.get("before") or e for e in single]))]
        rows += [row(f"`{name}`", e["runs"], f"{e['universes']} of {e['designed']}", spread(e), spread(e.get("before")))
                 for name, e in experiments.items() if e.get("designed")]
        return markdown_table(["part", "runs", "universes", "CPU-hours", "CPU-hours before", "on 2 workers",
                               "on 2 workers before"], rows)

    def where_time_goes(by_method: bool) -> str:
        if not profile:
            raise LookupError("the record has no profile (make record writes record/profile.json)")
        methods = pd.DataFrame([{"experiment": m["experiment"], "method": m["method"], "cpu": m["cpu_minutes"],
                                 **m["parts"]} for m in profile["methods"] if m["parts"]])
        stages = [s for s in profile["stages"] if s in methods]
        if by_method:
            rows = methods
        else:  # each method's split weighted by its CPU
            weighted = methods[stages].mul(methods["cpu"], axis=0).groupby(methods["experiment"], sort=False).sum()
            cpu = methods.groupby("experiment", sort=False)["cpu"].sum()
            rows = weighted.div(cpu, axis=0).assign(cpu=cpu).reset_index()
        return markdown_table(["experiment", *(["method"] if by_method else []), "CPU-minutes profiled",
                               *(f"{s} %" for s in stages)],
                              [[f"`{r['experiment']}`", *([r["method"]] if by_method else []), number(r["cpu"]),
                                *(number(round(100 * r[s], 1)) for s in stages)] for _, r in rows.iterrows()])

    return {"paper": papers.get(paper), "papers": papers, "page": paper,
            "record": {k: number(v) if isinstance(v, (int, float)) else v for k, v in status.items()},
            "claim": claim, "table": drawn.table, "experiment": experiment, "verdicts": verdicts,
            "scorecard": scorecard, "cells": cells, "times": times, "parts": parts, "criteria": criteria,
            "surviving": surviving_said(drawn.card),
            "where_time_goes": where_time_goes, "profiled": profile.get("made"),
            "profiled_experiments": len({m["experiment"] for m in profile.get("methods", [])})}


def _previous(before: dict | None) -> str:
    """What an experiment's previous recording took, as a cell: its minutes (an experiment's), CPU-minutes
    and commits; '' where it was recorded once."""
    if not before:
        return ""
    minutes = f"{number(before['minutes'])} min, " if before["minutes"] is not None else ""
    return f"{minutes}{number(before['cpu_minutes'])} CPU-min ({', '.join(before['commits'])})"


def _float(text):
    try:
        return float(text)
    except (TypeError, ValueError):
        return text or None


def markdown_table(header: list[str], rows: list[list]) -> str:
    def clean(value) -> str:
        return str(value).replace("|", "\\|").replace("\n", " ")

    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    return "\n".join(lines + ["| " + " | ".join(clean(v) for v in row) + " |" for row in rows])


def render(drawn: Drawn, templates: Path) -> dict[str, str]:
    """Each template of ``templates`` rendered: its page's name (``bis_pf``, ``index``) -> Markdown; and the
    README's part on the record (:data:`README_TEMPLATE`) as :data:`README`."""
    env = jinja2.Environment(loader=jinja2.FileSystemLoader(templates), undefined=jinja2.StrictUndefined,
                             keep_trailing_newline=True, autoescape=False)
    papers = {paper.key: paper for paper in load_papers()}
    names = {path.name: path.name.removesuffix(".md.j2") for path in sorted(Path(templates).glob("[!_]*.md.j2"))}
    if (Path(templates) / README_TEMPLATE).exists():
        names[README_TEMPLATE] = README
    pages = {}
    for template, name in names.items():  # _name.md.j2: a part the pages include (or the README's)
        try:
            pages[name] = env.get_template(template).render(**context(drawn, name, papers))
        except (LookupError, AttributeError, jinja2.UndefinedError) as error:
            raise LookupError(f"{template}: {error}") from None
    return pages


def inputs(record: Path, templates: Path, published: Path) -> dict[str, str]:
    """What the pages are rendered from, each as a digest: the record (its manifest's SHA-256, which holds
    every file's, and its profile's), the templates, the configs (the claims' words, the experiments' methods and tables), the
    papers' published values, and the code that draws the record's pages and renders them (every module the
    report's command imports)."""
    return {"record": record_digest(record), "templates": _files(Path(templates), "*.md.j2"),
            "configs": _files(CONF_DIR, "*.yaml"), "published": sha256(published) if Path(published).exists() else "",
            "code": run_code_digest(("report/__main__.py",))}


def record_digest(record: Path) -> str:
    """The record as its pages depend on it: its manifest's SHA-256 (which holds every file's), then its
    profile's where it has one."""
    return "".join(sha256(Path(record) / name) for name in (MANIFEST, PROFILE) if (Path(record) / name).exists())


def drawn_inputs(rendered_from: dict[str, str]) -> dict[str, str]:
    """Of the pages' inputs, those the record's drawn pages depend on (all but the templates)."""
    return {k: v for k, v in rendered_from.items() if k != "templates"}


def _files(folder: Path, pattern: str) -> str:
    digest = hashlib.sha256()
    for path in sorted(folder.rglob(pattern)):
        digest.update(path.relative_to(folder).as_posix().encode() + b"\0" + path.read_bytes() + b"\0")
    return digest.hexdigest()


def write_pages(pages: dict[str, str], out: Path, rendered_from: dict[str, str], readme: Path) -> list[Path]:
    """The pages as ``<out>/<name>.md``, the :data:`README` part into ``readme`` (:func:`embed`), and
    :data:`RENDERED`: their inputs and each page's SHA-256."""
    written = []
    for name, text in pages.items():
        if name == README:
            written.append(embed(readme, text))
        else:
            written.append(out / f"{name}.md")
            atomic.write_text(written[-1], text)
    digests = {name: _digest(text) for name, text in pages.items()}
    rendered = {"inputs": rendered_from, "pages": digests}
    atomic.write_text(out / RENDERED, json.dumps(rendered, indent=1) + "\n")
    return written


def stale(out: Path, rendered_from: dict[str, str], readme: Path) -> list[str]:
    """Why the pages in ``out`` (and ``readme``'s part) are not what the record renders today: an input
    changed since they were rendered (the record, the templates, the code), or a page was edited, added or
    removed by hand."""
    if not (out / RENDERED).exists():
        return [f"{out / RENDERED} is missing"]
    written = json.loads((out / RENDERED).read_text())
    reasons = [f"the {name} changed since they were rendered" for name, digest in rendered_from.items()
               if written["inputs"].get(name) != digest]
    on_disk = {p.stem: _digest(p.read_text()) for p in out.glob("*.md")}
    if README in written["pages"]:
        part = readme_part(readme)
        on_disk[README] = _digest(part) if part is not None else "no part"
    reasons += [f"{_shown(name, readme)} was edited by hand" for name in sorted(on_disk.keys() & written["pages"].keys())
                if on_disk[name] != written["pages"][name]]
    reasons += [f"{_shown(name, readme)} is not rendered" for name in sorted(on_disk.keys() ^ written["pages"].keys())]
    return reasons


def embed(readme: Path, text: str) -> Path:
    """``readme`` with ``text`` between its :data:`README_MARKS` (the rest stays as written by hand)."""
    parts = _parts(readme)
    if parts is None:
        raise LookupError(f"{readme} has no part for the record: put {' and '.join(README_MARKS)} in it")
    atomic.write_text(readme, parts[0] + text + parts[2])
    return readme


def readme_part(readme: Path) -> str | None:
    """The text between ``readme``'s :data:`README_MARKS` (None where it has no such part)."""
    parts = _parts(readme)
    return parts[1] if parts else None


def _parts(readme: Path) -> tuple[str, str, str] | None:
    """``readme`` as (up to its first mark and that mark's line, between the marks, from its second mark);
    None where it lacks either mark."""
    text = readme.read_text() if readme.exists() else ""
    head, first, rest = text.partition(README_MARKS[0])
    line, _, rest = rest.partition("\n")
    body, second, tail = rest.partition(README_MARKS[1])
    if not (first and second):
        return None
    return head + first + line + "\n", body, second + tail


def _shown(name: str, readme: Path) -> str:
    return f"{readme.name}'s part on the record" if name == README else f"{name}.md"


def _digest(text: str) -> str:
    return hashlib.sha256(text.encode()).hexdigest()


def write_html(pages: dict[str, str], out: Path) -> list[Path]:
    """The rendered pages as HTML in the report's style, under ``out`` (``<reports>/record/findings``); links
    to sibling pages point at their HTML."""
    from markdown_it import MarkdownIt
    from markupsafe import Markup

    from replication.report.pages.render import render as render_page

    markdown = MarkdownIt("commonmark").enable("table")
    out.mkdir(parents=True, exist_ok=True)
    written = []
    for name, text in pages.items():
        if name == README:  # the README's part: the index page says the same
            continue
        body = re.sub(r'href="([\w-]+)\.md"', r'href="\1.html"', markdown.render(text))
        title = next((line[2:] for line in text.splitlines() if line.startswith("# ")), name)
        path = out / f"{name}.html"
        atomic.write_text(path, render_page("findings.html.j2", title=title, body=Markup(body)))
        written.append(path)
    return written

