"""``reports/replication.pdf``: the HTML report as one file, from the same tables and figures.

A title page with the experiments, the summary of every published cell
(paginated), then per experiment a page per table (from its CSV, formatted as
on its page) and a page per figure (its PNG).  Only matplotlib is needed.

``python -m replication.report.pdf [reports=DIR] [published_values=CSV]``
rebuilds ``reports/index.html`` and ``reports/replication.pdf`` from the
reports already written, redrawing nothing.
"""

import datetime
import re
import sys
import textwrap
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.image as mpimg  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import pandas as pd  # noqa: E402
from matplotlib.backends.backend_pdf import PdfPages  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402
from matplotlib.patches import Rectangle  # noqa: E402

import replication  # noqa: E402
from replication import atomic  # noqa: E402
from replication.arguments import read  # noqa: E402
from omegaconf import OmegaConf  # noqa: E402

from replication.paths import CONF_DIR, experiment_names, resolve  # noqa: E402
from replication.evidence.criteria import CRITERIA  # noqa: E402
from replication.report.pages import effects, glance  # noqa: E402
from replication.report.pages.index import TITLE  # noqa: E402
from replication.evidence.claims import Paper  # noqa: E402
from replication.report.pages.scale import PAPER_COMMAND, scale_note  # noqa: E402
from replication.evidence.scorecard import Scorecard, tally  # noqa: E402
from replication.evidence.schema import Summary  # noqa: E402
from replication.evidence.summary import counts  # noqa: E402
from replication.evidence.tables import Table  # noqa: E402
from replication.evidence.settings import rules  # noqa: E402
from replication.scales import report_folder  # noqa: E402

PAGE = (11.69, 8.27)  # A4 landscape, inches
FONT = 7.0  # table text, points: the smallest that reads in print (a long cell wraps rather than shrinks)
TABLE_FONT = 7.5  # an experiment's tables
SPACING = 1.35  # line pitch over the font's height
PAD = 0.4  # a cell's margin left and right, in em
BOX = (0.035, 0.05, 0.93, 0.80)  # the table's area on the page: left, bottom, width, height (page fractions)
SUMMARY_COLUMNS = {  # the summary's columns as printed: heading -> how wide it may get (characters)
    "paper": 10, "table": 5, "experiment / condition": 22, "method": 20, "metric": 21, "paper value": 18,
    "ours (95% CI)": 34, "verdict or reason": 60, "claim": 26,
}
SCORECARD_COLUMNS = {"claim": 60, "verdict": 15, "deciding number (its interval)": 30, "why": 60, "readings": 40}


def write_pdf(reports: Path, card: Scorecard) -> Path:
    """Write ``reports/replication.pdf`` from what ``reports/`` holds and ``card``, the scorecard its caller read
    from the reports' summaries (:meth:`~replication.evidence.scorecard.Scorecard.read`); return its path."""
    reports = Path(reports)
    summaries, papers = card.summaries, list(card.papers)
    path = reports / "replication.pdf"
    reports.mkdir(parents=True, exist_ok=True)
    quick = [name for name, s in summaries.items() if s.scale != "paper"]
    banner = (f"Quick scale ({len(quick)} of {len(summaries)} experiments): fewer runs and shorter scenes than "
              f"the papers'. Paper scale: {PAPER_COMMAND}." if quick else None)
    with atomic.replacing(path) as tmp:  # the book and its outline whole, then in place of the last one
        _write_book(tmp, reports, card, papers, banner)
    return path


def _write_book(path: Path, reports: Path, card: Scorecard, papers: list[Paper], banner: str | None) -> None:
    """Every page of the book as ``path``, then its outline."""
    summaries, cells, rows, tallies = card.summaries, card.cells, card.rows, card.tallies
    with plt.rc_context({"pdf.fonttype": 3, "font.family": "DejaVu Sans"}), _Book(path, banner) as pdf:
        _title_page(pdf, summaries, cells, rows, glance.write(reports, papers, rows))
        picture = effects.draw(card, reports / effects.FIGURE)  # second, after the glance, as on the index
        if picture is not None:
            _figure_page(pdf, "How much of each paper's effect survives", effects.surviving_said(card), picture)
            _table_pages(pdf, "The replication criteria", _criteria_frame(card), subtitle=CRITERIA_SAID,
                         font=TABLE_FONT)
        for paper in papers:
            counted = ", ".join(f"{n} {outcome}" for outcome, n in tally(rows[paper.key]).items())
            _table_pages(pdf, f"Scorecard: {paper.title}", _scorecard_frame(rows[paper.key], tallies),
                         widths=SCORECARD_COLUMNS,
                         subtitle=f"{paper.authors}; {paper.venue} ({paper.key}). Claims: {counted}.")
        _experiments_page(pdf, summaries)
        _table_pages(pdf, "How verdicts are made", pd.DataFrame({"rules": list(rules())}), widths={"rules": 200})
        _table_pages(pdf, "Every published cell", _summary_frame(cells), widths=SUMMARY_COLUMNS,
                     subtitle="One row per published value: ours and the verdict where a table of ours "
                     "matched it, otherwise why not")
        for name, summary in summaries.items():
            heading = summary.title
            folder = report_folder(reports, name, summary.scale)
            for table in [t for t in summary.tables if (folder / t["csv"]).exists()]:
                frame = _shown(pd.read_csv(folder / table["csv"]))
                subtitle = " ".join(filter(None, [table["title"], table.get("note")]))
                _table_pages(pdf, heading, frame, subtitle=subtitle, font=TABLE_FONT)
            for figure in [f for f in summary.figures if (folder / f["file"]).exists()]:
                _figure_page(pdf, heading, figure["title"], folder / figure["file"])
        info = pdf.infodict()
        info["Title"] = TITLE
        info["Subject"] = "The papers' published values against ours, with 95% intervals"
        info["Creator"] = f"replication {replication.__version__}"
    _outline(path, pdf.marks)


def _shown(frame: pd.DataFrame) -> pd.DataFrame:
    """A table's CSV as its HTML page shows it: 'mean [low, high]', the paper's value as printed."""
    frame = Table.read(frame).shown()
    return frame.map(lambda v: "" if pd.isna(v) else f"{v:.4g}" if isinstance(v, float) else str(v))


def _summary_frame(cells: pd.DataFrame) -> pd.DataFrame:
    def where(c):
        return f"{c['experiment']} / {c['condition']}" if c["condition"] else c["experiment"]

    def judged(c):
        if not c["verdict"]:
            return c["reason"]
        return f"{c['verdict']}; also {c['also']}" if c["also"] else c["verdict"]

    def ours(c):
        text = f"{c['ours']} ({c['runs']} runs)" if c["runs"] else c["ours"]
        return f"{text}, {c['our_condition']}" if c["our_condition"] else text

    return pd.DataFrame({
        "paper": cells["paper"],
        "table": cells["table"],
        "experiment / condition": [where(c) for _, c in cells.iterrows()],
        "method": cells["method"],
        "metric": cells["metric"],
        "paper value": cells["paper_value"],
        "ours (95% CI)": [ours(c) for _, c in cells.iterrows()],
        "verdict or reason": [judged(c) for _, c in cells.iterrows()],
        "claim": cells["claim"],
    })


def _scorecard_frame(rows, tallies: dict[str, str]) -> pd.DataFrame:
    """One paper's claims as the scorecard prints them."""
    return pd.DataFrame({
        "claim": [f"{r.claim.text} ({r.claim.where})" for r in rows],
        "verdict": [r.verdict.outcome.value for r in rows],
        "deciding number (its interval)": [r.primary.deciding.number if r.primary.deciding else "" for r in rows],
        "why": ["; ".join(filter(None, [r.verdict.why, tallies.get(r.claim.id, ""), r.claim.note])) for r in rows],
        "readings": [r.primary.reading.name + ("" if len(r.results) == 1 and r.multiverse is None
                                               else f"; {r.robustness}") for r in rows],
    })


CRITERIA_SAID = ("Per paper and over all, the claims meeting each criterion of the replication projects of "
                 "those it applies to (replication/evidence/criteria.py); shown, never combined into the verdicts")


def _criteria_frame(card: Scorecard) -> pd.DataFrame:
    """Each replication criterion, and per paper and over all the claims meeting it, as the index shows them."""
    shares = card.criteria
    return pd.DataFrame([{"criterion": c.name, "source": c.source, **{row["paper"]: str(row[c.key]) for row in shares}}
                         for c in CRITERIA])


def _title_page(pdf: PdfPages, summaries: dict[str, Summary], cells: pd.DataFrame, rows: dict, picture: Path) -> None:
    """The title, the counts, and every claim at a glance (:mod:`~replication.report.pages.glance`)."""
    fig = plt.figure(figsize=PAGE)
    fig.text(0.05, 0.95, TITLE, fontsize=18, weight="bold", va="top")
    cell_tally = counts(cells)
    verdicts = ", ".join(f"{k}: {v}" for k, v in cell_tally["verdicts"].items())
    claims = [row for paper_rows in rows.values() for row in paper_rows]
    claim_tally = ", ".join(f"{n} {outcome}" for outcome, n in tally(claims).items())
    quick = [s for s in summaries.values() if s.scale != "paper"]
    lines = [
        f"Generated {datetime.date.today().isoformat()} by replication {replication.__version__}. "
        f"{len(claims)} claims of five papers tested ({claim_tally}), each at a glance below; the scorecard "
        "follows, one page per paper, then the experiments.",
        f"{cell_tally['cells']} published cells; {cell_tally['compared']} compared with a table of ours"
        + (f" ({verdicts})" if verdicts else "") + "; the summary after the scorecard says why the others were not.",
    ] + ([f"{len(quick)} of {len(summaries)} experiments at the quick scale. " + scale_note("quick")] if quick else [])
    fig.text(0.05, 0.89, "\n".join(textwrap.fill(line, 170) for line in lines), fontsize=8.5, va="top",
             linespacing=1.4, parse_math=False)
    ax = fig.add_axes((0.03, 0.04, 0.94, 0.72))
    ax.imshow(mpimg.imread(picture), interpolation="antialiased")
    ax.set_axis_off()
    pdf.savefig(fig)
    plt.close(fig)


def _experiments_page(pdf: PdfPages, summaries: dict[str, Summary]) -> None:
    """Every experiment with a report: its scale, runs and cell verdicts, and those with none yet."""
    fig = plt.figure(figsize=PAGE)
    _header(fig, "Experiments", "Each experiment's scale, stored runs and cell verdicts; its tables and figures "
            "follow the summary of published cells")
    missing = [name for name in experiment_names() if name not in summaries]
    rows = [
        [s.title, s.scale, f"{s.n_records} / {s.n_runs}", ", ".join(f"{k}: {v}" for k, v in sorted(s.verdicts.items()))
         or "-"]
        for name, s in summaries.items()
    ]
    frame = pd.DataFrame(rows, columns=["experiment", "scale", "runs stored", "verdicts"])
    if len(frame):
        _draw_table(fig, frame, {"experiment": 95, "scale": 6, "runs stored": 11, "verdicts": 70},
                    box=(0.05, 0.08, 0.90, 0.76))
    else:
        fig.text(0.05, 0.65, "No experiment has a report yet: run make replicate.", fontsize=11)
    if missing:
        fig.text(0.05, 0.04, textwrap.fill("No stored results yet for: " + ", ".join(missing), 170),
                 fontsize=8, color="#8a5a00", va="bottom")
    pdf.savefig(fig)
    plt.close(fig)


def _figure_page(pdf: PdfPages, heading: str, title: str, png: Path) -> None:
    """The PNG as large as the page allows; a tall one (a grid of snapshots) on a portrait page."""
    image = mpimg.imread(png)
    tall = image.shape[0] > 0.9 * image.shape[1]
    fig = plt.figure(figsize=PAGE[::-1] if tall else PAGE)
    _header(fig, heading, title, width=80 if tall else 120)
    ax = fig.add_axes((0.03, 0.03, 0.94, 0.84 if tall else 0.80))
    ax.imshow(image, interpolation="antialiased")
    ax.set_axis_off()
    pdf.savefig(fig)
    plt.close(fig)


def _header(fig, heading: str, subtitle: str | None, width: int = 120) -> None:
    """The experiment's title and the table's or figure's, wrapped to the page; both name the page in
    the PDF outline."""
    fig.outline = (heading, subtitle)
    top = 1 - 0.035 * PAGE[1] / fig.get_size_inches()[1]
    fig.text(0.035, top, textwrap.fill(heading, width, break_on_hyphens=False), fontsize=12, weight="bold",
             va="top", parse_math=False)
    if subtitle:
        lines = textwrap.fill(heading, width, break_on_hyphens=False).count("\n") + 1
        fig.text(0.035, top - (0.03 + 0.025 * lines) * PAGE[1] / fig.get_size_inches()[1],
                 textwrap.fill(subtitle, int(width * 1.25), break_on_hyphens=False), fontsize=10, va="top",
                 parse_math=False)


def _table_pages(pdf: PdfPages, heading: str, frame: pd.DataFrame, subtitle: str | None = None,
                 widths: dict | None = None, font: float = FONT) -> None:
    """As many pages as ``frame`` needs, its header row repeated on each; a narrow table stays narrow."""
    frame = frame.astype(str)
    chars, points = _columns(frame, widths or {}, BOX[2] * PAGE[0] * 72, font)
    wrapped = [[_wrap(v, w) for v, w in zip(row, chars)] for row in frame.itertuples(index=False)]
    header = [_wrap(c, w) for c, w in zip(frame.columns, chars)]
    room = int(BOX[3] * PAGE[1] * 72 / _line(font)) - _lines(header)  # lines of body per page
    pages, page, used = [], [], 0
    for row in wrapped:
        need = _lines(row)
        if page and used + need > room:
            pages.append(page)
            page, used = [], 0
        page.append(row)
        used += need
    pages.append(page)
    box = (BOX[0], BOX[1], sum(points) / (PAGE[0] * 72), BOX[3])
    for number, rows in enumerate(pages):
        fig = plt.figure(figsize=PAGE)
        title = subtitle or ""
        if len(pages) > 1:
            title = f"{title} (page {number + 1} of {len(pages)})".strip()
        _header(fig, heading, title)
        _place(fig, header, rows, points, box, font)
        pdf.savefig(fig)
        plt.close(fig)


def _draw_table(fig, frame: pd.DataFrame, widths: dict, box) -> None:
    frame = frame.astype(str)
    chars, points = _columns(frame, widths, box[2] * PAGE[0] * 72, FONT)
    _place(fig, [_wrap(c, w) for c, w in zip(frame.columns, chars)],
           [[_wrap(v, w) for v, w in zip(row, chars)] for row in frame.itertuples(index=False)], points,
           (box[0], box[1], sum(points) / (PAGE[0] * 72), box[3]))


def _place(fig, header: list[str], rows: list[list[str]], points: list[float], box, font: float = FONT):
    """Draw one page of a table in ``box`` (figure fractions), columns in proportion to ``points``.

    One text block per column (a page of cells drawn one by one takes seconds):
    each cell is padded to its row's line count, so with a fixed line spacing
    every row starts on the line its rules are drawn at.
    """
    left, bottom, width, height = box
    pitch = _line(font) / (fig.get_size_inches()[1] * 72)  # one line, in figure fractions
    pad = PAD * font / (fig.get_size_inches()[0] * 72)
    xs = [left]
    for w in points:
        xs.append(xs[-1] + width * w / sum(points))
    table = [header, *rows]
    counts = [_lines(row) for row in table]
    top = bottom + height
    ys = [top]
    for n in counts:
        ys.append(ys[-1] - n * pitch)
    for i, (y_top, y_bottom) in enumerate(zip(ys, ys[1:])):
        if i == 0 or i % 2 == 0:
            shade = "#e9edf1" if i == 0 else "#f6f6f6"
            fig.patches.append(Rectangle((left, y_bottom), width, y_top - y_bottom, transform=fig.transFigure,
                                         facecolor=shade, edgecolor="none", zorder=0))
    rules = [[(left, y), (left + width, y)] for y in ys] + [[(x, ys[0]), (x, ys[-1])] for x in xs]
    fig.add_artist(LineCollection(rules, colors="#c4c4c4", linewidths=0.4, transform=fig.transFigure,
                                  zorder=1))
    for c in range(len(points)):
        body = "\n".join(row[c] + "\n" * (n - 1 - row[c].count("\n"))
                         for row, n in zip(table[1:], counts[1:]))
        head = table[0][c] + "\n" * (counts[0] - 1 - table[0][c].count("\n"))
        fig.text(xs[c] + pad, top, head, fontsize=font, weight="bold", va="top", linespacing=SPACING,
                 parse_math=False, zorder=2)
        if rows:
            fig.text(xs[c] + pad, ys[1], body, fontsize=font, va="top", linespacing=SPACING, parse_math=False,
                     zorder=2)


def _columns(frame: pd.DataFrame, caps: dict, room: float, font: float) -> tuple[list[int], list[float]]:
    """Each column's wrap width (characters) and drawn width (points), within ``room`` points.

    A column is as wide as its longest cell, up to its cap in characters; while
    the table is too wide the widest column wraps sooner; while there is room
    the most wrapped one widens.  Widths are measured in the font (digits are
    wider than letters), with a margin.
    """
    texts = [[str(c), *frame[c]] for c in frame.columns]
    longest = [max(len(t) for t in column) for column in texts]
    em = [1.1 * _width(max(column, key=len), font) / max(1, n) for column, n in zip(texts, longest)]
    em = [max(e, 0.45 * font) for e in em]  # per-character width of the column's own text, in points
    chars = [max(4, min(n, caps.get(c, 60))) for c, n in zip(frame.columns, longest)]

    def total():
        return sum(n * e + 2 * PAD * font for n, e in zip(chars, em))

    while total() > room and max(chars) > 8:  # wrap the widest sooner
        widest = max(range(len(chars)), key=lambda i: chars[i] * em[i])
        chars[widest] -= 1
    while any(n < m for n, m in zip(chars, longest)):  # room left: unwrap the most wrapped
        short = max(range(len(chars)), key=lambda i: longest[i] / chars[i])
        chars[short] += 1
        if total() > room:
            chars[short] -= 1
            break
    return chars, [n * e + 2 * PAD * font for n, e in zip(chars, em)]


@lru_cache(maxsize=4096)
def _width(text: str, font: float, bold: bool = False) -> float:
    """``text``'s width in points, set in the report's font."""
    from matplotlib.font_manager import FontProperties
    from matplotlib.textpath import text_to_path

    prop = FontProperties(family="DejaVu Sans", size=font, weight="bold" if bold else "normal")
    return text_to_path.get_text_width_height_descent(text, prop, ismath=False)[0]


@lru_cache(maxsize=4)
def _line(font: float = FONT) -> float:
    """A table line's pitch in points, as matplotlib lays it out (fixed spacing: every line the same)."""
    fig = plt.figure(figsize=(2, 2), dpi=72)
    text = fig.text(0, 0, "x\nx\nx", fontsize=font, linespacing=SPACING, parse_math=False)
    renderer = fig.canvas.get_renderer()
    three = text.get_window_extent(renderer).height
    text.set_text("x")
    one = text.get_window_extent(renderer).height
    plt.close(fig)
    return (three - one) / 2


def _wrap(text: str, width: int) -> str:
    return "\n".join(textwrap.wrap(str(text), width, break_on_hyphens=False)) if text else ""


def _lines(row: list[str]) -> int:
    return max([1] + [t.count("\n") + 1 for t in row])


class _Book(PdfPages):
    """PdfPages that numbers its pages and remembers each page's place in the outline (its heading and
    subtitle, as :func:`_header` gave them)."""

    def __init__(self, path: Path, banner: str | None = None):
        super().__init__(path)
        self.marks = []  # (heading, subtitle, page index)
        self.banner = banner  # printed at the foot of every page (the quick scale's warning)

    def savefig(self, figure, **kwargs):
        page = self.get_pagecount()
        if hasattr(figure, "outline"):
            self.marks.append((*figure.outline, page))
        figure.text(0.985, 0.012, f"page {page + 1}", ha="right", va="bottom", fontsize=8, color="#555555")
        if self.banner:
            figure.text(0.035, 0.012, self.banner, ha="left", va="bottom", fontsize=7, color="#8a5a00",
                        parse_math=False)
        super().savefig(figure, **kwargs)


def _outline(path: Path, marks: list[tuple[str, str | None, int]]) -> None:
    """Give the PDF its outline (bookmarks): a section per heading at its first page, under it an entry
    per table or figure (its subtitle, without a table's page count); the reader opens it beside page 1."""
    from pypdf import PdfWriter

    writer = PdfWriter(clone_from=str(path))
    section, last = None, (None, None)
    for heading, subtitle, page in marks:
        subtitle = re.sub(r" \(page \d+ of \d+\)$", "", subtitle or "")
        if heading != last[0]:
            section = writer.add_outline_item(title=textwrap.shorten(heading, 100, placeholder=" ..."),
                                              page_number=page)
        if subtitle and (heading, subtitle) != last:
            writer.add_outline_item(title=textwrap.shorten(subtitle, 100, placeholder=" ..."), page_number=page,
                                    parent=section)
        last = (heading, subtitle)
    writer.page_mode = "/UseOutlines"
    writer.write(str(path))


@dataclass(frozen=True)
class Options:
    reports: str | None = None
    published_values: str | None = None


def main(argv: list[str]) -> None:
    options, _ = read(argv, Options, "python -m replication.report.pdf")
    from replication.report.pages.index import write_index

    reports = resolve(options.reports or OmegaConf.load(CONF_DIR / "config.yaml").reports)
    path = write_pdf(reports, Scorecard.read(reports, options.published_values))
    print(f"pdf: {path}")
    print(f"index: {write_index(reports, Scorecard.read(reports, options.published_values))}")


if __name__ == "__main__":
    main(sys.argv[1:])
