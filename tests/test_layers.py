"""The deciding layer looks only down: replication/evidence/ imports numpy, scipy and pandas, never the
report, the runner, matplotlib or Jinja, and nothing that loads OpenCV or numba; the report's pages and figures
only draw, importing no runner, task, metric or scene (read from the source with ast, so nothing is imported,
except where a fresh interpreter checks what importing the evidence loads)."""

import ast
import subprocess
import sys

from replication.paths import PACKAGE_DIR

FORBIDDEN = ("replication.report", "replication.runner", "replication.cli", "matplotlib", "jinja2", "omegaconf",
             "hydra", "cv2", "numba", "replication.scenes", "replication.metrics", "replication.tasks",
             "replication.filters", "replication.compiled", "replication.vision", "replication.smc")
BENEATH_THE_PAGES = ("replication.runner", "replication.tasks", "replication.metrics", "replication.scenes")


def _imports(path) -> set[str]:
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            found |= {alias.name for alias in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module:
            found.add(node.module)
    return found


def test_evidence_imports_nothing_above_it():
    files = sorted((PACKAGE_DIR / "evidence").rglob("*.py"))
    assert len(files) >= 20
    for path in files:
        upward = {name for name in _imports(path) if name.startswith(FORBIDDEN)}
        assert not upward, (path.name, upward)


def test_evidence_loads_neither_opencv_nor_numba():
    """Importing the evidence (the judge with it) in a fresh interpreter loads no OpenCV and no numba, however
    deep the imports go: what needs video or compiled code reaches it as data from the caller."""
    code = ("import sys, replication.evidence, replication.evidence.judge, replication.evidence.tables; "
            "print(sorted(m for m in ('cv2', 'numba') if m in sys.modules))")
    loaded = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert loaded.strip() == "[]", loaded
    assert "numba" in subprocess.run([sys.executable, "-c", "import sys, replication.runner.footage; "
                                      "print(sorted(sys.modules))"], capture_output=True, text=True,
                                     check=True).stdout  # the check can fail: what the caller uses loads it


def test_pages_and_figures_import_no_runner_task_metric_or_scene():
    """A page or figure draws what the judge and the caller hand it; it computes nothing from the runs."""
    drawing = [*(PACKAGE_DIR / "report" / "pages").rglob("*.py"), *(PACKAGE_DIR / "report" / "figures").rglob("*.py")]
    assert len(drawing) >= 15
    for path in drawing:
        below = {name for name in _imports(path) if name.startswith(BENEATH_THE_PAGES)}
        assert not below, (path.relative_to(PACKAGE_DIR).as_posix(), below)


def test_the_record_imports_nothing_above_it():
    """The paper-scale record reads the runner's runs and the tables' needs; the report draws it, not the
    other way round."""
    files = sorted((PACKAGE_DIR / "record").rglob("*.py"))
    assert len(files) >= 5
    for path in files:
        upward = {name for name in _imports(path) if name.startswith(("replication.report", "replication.cli"))}
        assert not upward, (path.name, upward)


def test_a_run_is_keyed_by_the_code_it_runs(tmp_path):
    """A change of a verdict rule or a drawing computes no run anew; a change of one filter recomputes the
    runs of that filter (and of the filters built on it) and no other."""
    import shutil

    from replication.filters.registry import builders
    from replication.runner.provenance import run_code_digest, source_of
    from replication.tasks import TASKS

    digest = run_code_digest.__wrapped__  # uncached: the same folder is hashed after each edit
    package = tmp_path / "replication"
    shutil.copytree(PACKAGE_DIR, package, ignore=shutil.ignore_patterns("__pycache__", "conf"))
    pairs = {(task, name): (source_of(TASKS[task]), source_of(made)) for task in TASKS for name, made in builders().items()}

    def keys() -> dict:
        return {pair: digest(entries, package) for pair, entries in pairs.items()}

    before = keys()
    for edited in ("evidence/verdict.py", "evidence/tables/table.py", "report/pages/render.py", "cli.py",
                   "record/runs.py"):
        (package / edited).write_text((package / edited).read_text() + "\n# a new rule\n")
        assert keys() == before, edited
    (package / "filters/harmony.py").write_text((package / "filters/harmony.py").read_text() + "\n# x\n")
    after = keys()
    changed = {name for (task, name), key in after.items() if key != before[task, name]}
    assert changed == {"hspf", "hs", "ms", "mspf"}  # harmony's own, and mean shift's, which imports it
    assert all(after[task, name] != before[task, name] for task in TASKS for name in changed)
    (package / "smc/loop.py").write_text((package / "smc/loop.py").read_text() + "\n# x\n")
    assert all(key != after[pair] for pair, key in keys().items())  # the SMC core: every run


def test_one_report_judges_against_one_published_values_file(tmp_path):
    """The index and the figures take the file the report was given; nothing reloads the default."""
    import pandas as pd

    from replication.evidence.scorecard import Scorecard

    from replication.report.pages.index import write_index

    for figure in (PACKAGE_DIR / "report" / "figures").glob("*.py"):
        assert not {name for name in _imports(figure) if name.startswith("replication.report.pages")}, figure.name
    own = tmp_path / "mine.csv"
    own.write_text("paper,table,experiment,method,metric,condition,value,unit,note\n"
                   "gps_qmcpf,1,ungm,PF,rmse,N=500,9.99,,a number of my own\n")
    write_index(tmp_path / "reports", Scorecard.read(tmp_path / "reports", own))
    summary = pd.read_csv(tmp_path / "reports" / "summary.csv", keep_default_na=False, dtype=str)
    assert list(summary["paper_value"]) == ["9.99"] and list(summary["note"]) == ["a number of my own"]


def _module_graph() -> dict[str, set[str]]:
    """Each module of the package and the package modules it imports (at the top or inside a function)."""
    modules = {".".join(("replication", *p.relative_to(PACKAGE_DIR).with_suffix("").parts)).removesuffix(".__init__"): p
               for p in PACKAGE_DIR.rglob("*.py")}
    graph = {}
    for name, path in modules.items():
        found = set()
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                found |= {a.name for a in node.names if a.name in modules}
            elif isinstance(node, ast.ImportFrom) and node.module in modules:
                found.add(node.module)
                found |= {f"{node.module}.{a.name}" for a in node.names if f"{node.module}.{a.name}" in modules}
        graph[name] = found - {name}
    return graph


def test_no_import_circle_in_the_package():
    graph = _module_graph()
    state: dict[str, int] = {}

    def visit(module: str, path: list[str]) -> None:
        state[module] = 1  # on the path
        for imported in sorted(graph[module]):
            if state.get(imported) == 1:
                circle = path[path.index(imported):] + [imported]
                raise AssertionError("import circle: " + " -> ".join(circle))
            if imported not in state:
                visit(imported, path + [imported])
        state[module] = 2  # done

    for module in sorted(graph):
        if module not in state:
            visit(module, [module])


def test_the_report_is_a_pipeline_that_looks_down():
    """pages -> figures -> evidence: a figure never imports a page or the PDF, and nothing below the report
    (evidence, runner, the lower layers) imports it."""
    graph = _module_graph()
    for module, imported in graph.items():
        if module.startswith("replication.report.figures"):
            assert not {m for m in imported if m.startswith(("replication.report.pages", "replication.report.pdf"))}, module
        if not module.startswith(("replication.report", "replication.cli", "replication.__main__")):
            assert not {m for m in imported if m.startswith("replication.report")}, module
