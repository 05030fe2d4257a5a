"""Reports written atomically: every file of the reports, the record and the store goes through
replication.atomic (a temporary file in the same folder, then renamed), so a full disk under ``reports=`` is
one line naming the folder and the previous reports stay whole."""

import ast
import errno
from pathlib import Path

import pandas as pd
import pytest

from replication import atomic
from replication.atomic import DiskFull
from replication.paths import PACKAGE_DIR

# what writes a file given its path (a PdfPages' savefig takes a figure: it writes the book it was opened on)
WRITERS = {"write_text", "write_bytes", "to_csv", "to_parquet", "savefig", "write_table", "savetxt", "copyfile"}
WRITING = ("report", "record", "export.py", "runner/results.py", "runner/store.py", "evidence/schema.py")


def filling(write, name: str):
    """``write`` (a writer given a path), except that writing a file called ``name`` fills the disk part-way."""
    def full(self, path, *args, **kwargs):
        if Path(path).name.startswith(f".{name}."):  # its temporary
            Path(path).write_text("experiment,pap")  # part of it, then no space is left
            raise OSError(errno.ENOSPC, "No space left on device", str(path))
        return write(self, path, *args, **kwargs)
    return full


def test_a_full_disk_under_reports_is_one_line_naming_the_folder_and_the_previous_file_stays(tmp_path, monkeypatch):
    from replication.evidence.scorecard import Scorecard
    from replication.report.pages.index import write_index

    reports = tmp_path / "reports"
    write_index(reports, Scorecard.read(reports))
    before = {name: (reports / name).read_bytes() for name in ("summary.csv", "claims.csv", "index.html")}
    monkeypatch.setattr(pd.DataFrame, "to_csv", filling(pd.DataFrame.to_csv, "summary.csv"))
    with pytest.raises(DiskFull) as full:
        write_index(reports, Scorecard.read(reports))
    message = str(full.value)
    assert "\n" not in message and message.startswith(f"{reports}: no space left on its disk (writing summary.csv)")
    assert {name: (reports / name).read_bytes() for name in before} == before  # whole, as before
    assert sorted(p.name for p in reports.iterdir()) == ["claims.csv", "glance.png", "index.html", "summary.csv"]


def test_the_report_command_says_a_full_disk_in_one_line(tmp_path, monkeypatch, capsys):
    """``pf-replicate report`` with the disk full while writing the index's table: exit status 2 and one line
    naming the reports folder, no traceback."""
    from replication.cli import main

    reports = tmp_path / "reports"
    monkeypatch.setattr(pd.DataFrame, "to_csv", filling(pd.DataFrame.to_csv, "summary.csv"))
    with pytest.raises(SystemExit) as stopped:
        main(["report", "experiment=hspf_ungm", "scale=quick", f"store={tmp_path / 'store'}", f"reports={reports}",
              "outside_project=true", "pdf=false", "n_jobs=1"])
    assert stopped.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1].startswith(f"error: {reports}: no space left on its disk (writing summary.csv)")
    assert not (reports / "summary.csv").exists()  # never a truncated one
    assert not list(reports.rglob(atomic.TEMPORARIES))


def test_a_writer_that_fails_leaves_the_previous_file_and_no_temporary(tmp_path):
    path = atomic.write_text(tmp_path / "page.html", "the previous page")

    def breaks(tmp):
        tmp.write_text("half a pa")
        raise RuntimeError("a bug in the writer")

    with pytest.raises(RuntimeError):
        atomic.save(path, breaks)
    assert path.read_text() == "the previous page" and [p.name for p in tmp_path.iterdir()] == ["page.html"]


def test_a_full_disk_wrapped_by_a_library_is_still_a_full_disk(tmp_path):
    def wrapped(tmp):
        try:
            raise OSError(errno.EDQUOT, "Disk quota exceeded")
        except OSError as error:
            raise RuntimeError("the library's own error") from error

    with pytest.raises(DiskFull, match=f"^{tmp_path}: no space left on its disk"):
        atomic.save(tmp_path / "runs.parquet", wrapped)


def test_a_figure_is_written_in_the_format_its_name_says(tmp_path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig = plt.figure()
    assert atomic.save_figure(fig, tmp_path / "f.png").read_bytes().startswith(b"\x89PNG")
    assert b"<svg" in atomic.save_figure(fig, tmp_path / "f.svg").read_bytes()[:400]
    plt.close(fig)


def _writes(path: Path) -> list[str]:
    """The calls in ``path`` that write a file by its path other than to a temporary of replication.atomic's
    (an argument named ``tmp``) or through it (``atomic.write_text``)."""
    found = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr in WRITERS:
            receiver = ast.unparse(node.func.value)
            through = receiver == "atomic" or any(isinstance(a, ast.Name) and a.id == "tmp" for a in node.args)
            book = node.func.attr == "savefig" and receiver in ("pdf", "super()")  # PdfPages: a page of the book
            if not (through or book):
                found.append(f"{path.relative_to(PACKAGE_DIR)}:{node.lineno}: {ast.unparse(node)[:80]}")
        elif isinstance(node, ast.Call) and ast.unparse(node.func) == "open" and len(node.args) > 1:
            found.append(f"{path.relative_to(PACKAGE_DIR)}:{node.lineno}: {ast.unparse(node)[:80]}")
    return found


def test_every_report_record_and_store_file_is_written_through_one_helper():
    files = [p for part in WRITING for p in ([PACKAGE_DIR / part] if part.endswith(".py")
                                             else sorted((PACKAGE_DIR / part).rglob("*.py")))]
    assert len(files) > 30
    assert [line for path in files for line in _writes(path)] == []
    assert _writes(PACKAGE_DIR / "atomic.py") != []  # the helper itself is the one place that opens a file
