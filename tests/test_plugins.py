"""A user's own method and claims from outside the package: one registration mechanism for built-ins and
plugins, a plugin's code in its runs' keys, every bad plugin in one line, and the worked example
(examples/auxiliary_pf, the auxiliary particle filter) run and judged with no file under replication/
changed (docs/tutorial_your_method.md, run as written)."""

import hashlib
import os
import re
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest
from conftest import PROJECT_ROOT

from replication.errors import ConfigError
from replication.filters import registry
from replication.filters.registry import builder, builders
from replication.models import LinearGaussian, kalman_filter
from replication.paths import PACKAGE_DIR

EXAMPLE = PROJECT_ROOT / "examples" / "auxiliary_pf"
BASH = re.compile(r"```bash\n(.*?)```", re.DOTALL)


@pytest.fixture
def example(monkeypatch):
    """The example's package importable, as its folder on PYTHONPATH makes it; forgotten afterwards."""
    monkeypatch.syspath_prepend(str(EXAMPLE))
    yield
    for name in [name for name in sys.modules if name.split(".")[0] == "auxiliary_pf"]:
        del sys.modules[name]


@pytest.fixture
def installed(tmp_path, monkeypatch):
    """``installed(**entry_points)``: a distribution registering ``name = module:attribute`` under the
    filters' group, found as pip's would be (a dist-info folder on sys.path)."""

    def install(distribution="my-pf", **points):
        info = tmp_path / distribution / f"{distribution.replace('-', '_')}-1.0.dist-info"
        info.mkdir(parents=True)
        (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {distribution}\nVersion: 1.0\n")
        (info / "entry_points.txt").write_text(
            f"[{registry.GROUP}]\n" + "".join(f"{name} = {value}\n" for name, value in points.items()))
        monkeypatch.syspath_prepend(str(info.parent))
        registry.FILTERS.forget()

    yield install
    registry.FILTERS.forget()


def test_the_built_ins_come_in_by_the_entry_points_this_package_declares():
    declared = tomllib.loads((PROJECT_ROOT / "pyproject.toml").read_text())["project"]["entry-points"][registry.GROUP]
    found = builders()
    assert set(found) == set(declared) and len(found) >= 20
    for name, value in declared.items():
        module, _, attribute = value.partition(":")
        assert found[name].__module__ == module and found[name].__name__ == attribute


def test_an_import_path_and_an_installed_name_reach_the_same_builder(example, installed):
    from auxiliary_pf.apf import auxiliary_pf

    assert builder("auxiliary_pf.apf:auxiliary_pf") is auxiliary_pf
    installed(auxiliary_pf="auxiliary_pf.apf:auxiliary_pf")
    assert builder("auxiliary_pf") is auxiliary_pf
    assert builder("bootstrap") is builders()["bootstrap"]  # the built-ins beside it


def test_two_distributions_registering_one_name_is_one_line(example, installed):
    installed(bootstrap="auxiliary_pf.apf:auxiliary_pf")
    with pytest.raises(ConfigError, match=r"^two filters are registered as 'bootstrap': .*; uninstall one$") as said:
        builder("ism")
    assert "auxiliary_pf.apf:auxiliary_pf (by my-pf 1.0)" in str(said.value)
    assert "replication.filters.bootstrap:bootstrap (by pf-tracking-replication" in str(said.value)


@pytest.mark.parametrize("method, said", [
    ("{filter: nosuch.filters:MyPF, n_particles: 50}",
     "filter 'nosuch.filters:MyPF': module nosuch.filters does not import (ModuleNotFoundError: No module named "
     "'nosuch')"),
    ("{filter: broken:pf, n_particles: 50}",
     "filter 'broken:pf': module broken does not import (RuntimeError: needs a GPU)"),
    ("{filter: auxiliary_pf.apf:apf, n_particles: 50}", "filter 'auxiliary_pf.apf:apf': module auxiliary_pf.apf has no 'apf'"),
    ("{filter: auxiliary_pf.apf:LOOK_AHEADS, n_particles: 50}",
     "filter 'auxiliary_pf.apf:LOOK_AHEADS' is a dict, not a builder (a class or function)"),
    ("{filter: auxiliary_pf.apf:auxiliary_pf, n_particles: 50, lookahead: mean}",
     "method 'Mine': auxiliary_pf() got an unexpected keyword argument 'lookahead'"),
    ("{filter: auxiliary_pf.apf:auxiliary_pf, n_particles: 50, look_ahead: mode}",
     "method 'Mine': look_ahead must be one of ['draw', 'mean'], got 'mode'"),
    ("{filter: auxiliary_pf.apf:auxiliary_pf, n_particles: many}",
     "experiment.methods.Mine.n_particles must be an integer, got 'many'"),
    ("{filter: my_pf, n_particles: 50}", "unknown filter 'my_pf'; known filters: bis, bootstrap, "),
])
def test_a_bad_plugin_is_one_line_before_any_run(make_cfg, tmp_path, monkeypatch, example, method, said):
    """Each is the run command's check before any work (``prepare``: its message is the one line it prints)."""
    from replication.runner.validate import prepare

    (tmp_path / "plugins").mkdir()
    (tmp_path / "plugins" / "broken.py").write_text('raise RuntimeError("needs a GPU")\n')
    monkeypatch.syspath_prepend(str(tmp_path / "plugins"))
    with pytest.raises(ConfigError) as error:
        prepare(make_cfg("hspf_ungm", "scale=quick", f"+experiment.methods.Mine={method}"))
    assert str(error.value).startswith(said) and "\n" not in str(error.value)
    assert not (tmp_path / "experiments").exists()  # nothing ran


def test_a_plugin_that_does_not_import_is_one_line_on_the_command_line(cli, tmp_path):
    env = {**os.environ, "PYTHONPATH": str(EXAMPLE)}
    done = cli("experiment=hspf_ungm", "scale=quick", "+experiment.methods.Mine={filter: nosuch:MyPF}", env=env)
    assert done.returncode == 2, done.stderr
    assert done.stderr == ("error: filter 'nosuch:MyPF': module nosuch does not import (ModuleNotFoundError: No "
                           "module named 'nosuch')\n")
    assert not (tmp_path / "experiments").exists()


def test_a_method_returning_the_wrong_shape_fails_its_runs_and_keeps_the_others(cli, tmp_path):
    plugin = tmp_path / "plugins" / "short_pf.py"
    plugin.parent.mkdir()
    plugin.write_text(
        "from dataclasses import replace\n\nfrom replication.filters.bootstrap import bootstrap\n\n\n"
        "class Short:\n    def __init__(self, n_particles: int):\n        self.inner = bootstrap(n_particles)\n\n"
        "    def run(self, model, observations, rng):  # one estimate short\n"
        "        output = self.inner.run(model, observations, rng)\n"
        "        return replace(output, means=output.means[1:])\n")
    env = {**os.environ, "PYTHONPATH": str(plugin.parent)}
    done = cli("experiment=hspf_ungm", "scale=quick", "experiment.runs.quick=3",
               "+experiment.methods.Short={filter: short_pf:Short, n_particles: 50}", env=env)
    assert done.returncode == 3, done.stderr
    assert "method 'Short': run returned means of shape (59,), not (60,) (one estimate per step)" in done.stderr
    store = tmp_path / "experiments" / "hspf_ungm"
    assert len(list(store.rglob("*.failed"))) == 3  # the plugin's three runs, each with its reason
    assert "12 runs computed" in done.stdout
    assert len(list(store.rglob("*.json"))) == 9  # PF's, HSPF's and the grid's, stored


def test_a_plugins_runs_are_keyed_by_its_own_source(make_cfg, tmp_path, monkeypatch):
    """An edit of the plugin's module gives its runs new keys; the papers' methods keep theirs."""
    from replication.runner.config import expand

    copy = tmp_path / "plugin"
    shutil.copytree(EXAMPLE / "auxiliary_pf", copy / "auxiliary_pf", ignore=shutil.ignore_patterns("__pycache__"))
    monkeypatch.syspath_prepend(str(copy))
    cfg = make_cfg("hspf_ungm", "scale=quick",
                   "+experiment.methods.APF={filter: auxiliary_pf.apf:auxiliary_pf, n_particles: 100}")

    def keys() -> dict:
        return {run.method: run.key for run in expand(cfg)}

    before = keys()
    (copy / "auxiliary_pf" / "apf.py").write_text((copy / "auxiliary_pf" / "apf.py").read_text() + "\n# tuned\n")
    after = keys()
    assert {method for method in before if after[method] != before[method]} == {"APF"}
    (copy / "auxiliary_pf" / "__init__.py").write_text((copy / "auxiliary_pf" / "__init__.py").read_text() + "#\n")
    assert keys()["APF"] != after["APF"]  # its package runs on import too
    for name in [name for name in sys.modules if name.split(".")[0] == "auxiliary_pf"]:
        del sys.modules[name]


STEADY = '''"""A new filter: the bootstrap filter under a name of its own, drawn in a look of its own."""

from replication.filters.bootstrap import bootstrap
from replication.filters.registry import drawn


@drawn("yellow", "-.", "X")
def steady(n_particles: int):
    return bootstrap(n_particles)
'''


def test_a_new_filter_is_its_file_its_registration_and_its_yaml_entry(make_cfg, installed, keep_figures, tmp_path,
                                                                     monkeypatch):
    """A filter's module (declaring its look), its entry point and one method in an experiment's YAML: it runs
    beside the papers' methods, is labelled in the tables and drawn in its look, with no other file changed."""
    from matplotlib.colors import to_hex

    from replication.report.experiments import write_experiment
    from replication.report.figures import draw, metric
    from replication.runner.execute import execute
    from replication.runner.footage import SceneFootage
    from replication.runner.results import Results
    from replication.runner.store import Store
    from replication.runner.validate import prepare

    package = _tree_digest(PACKAGE_DIR)
    (tmp_path / "filters" / "my_filters").mkdir(parents=True)
    (tmp_path / "filters" / "my_filters" / "__init__.py").write_text("")
    (tmp_path / "filters" / "my_filters" / "steady.py").write_text(STEADY)
    monkeypatch.syspath_prepend(str(tmp_path / "filters"))
    installed(steady="my_filters.steady:steady")
    cfg = make_cfg("hspf_ungm", "scale=quick", "experiment.runs.quick=2",
                   "+experiment.methods.Steady={filter: steady, sweep: {n_particles: [50, 100]}}")
    runs, _, _ = prepare(cfg)
    store = Store(tmp_path / "experiments", "hspf_ungm")
    execute([run for run in runs if run.method in ("PF", "Steady")], store, n_jobs=1, progress=False)
    results = Results.of(cfg, runs, store)
    records = results.records
    assert len(records[records["method"] == "Steady"]) == 4 and records["rmse"].notna().all()
    drawn = keep_figures(metric)
    page = write_experiment(cfg, results)
    table = (page.parent / "table1_rmse.csv").read_text()
    assert "\nSteady,N=50," in table and "\nPF (bootstrap),-," in table  # its key (no label:)
    draw(records, {"name": "f", "kind": "metric_vs_condition", "metric": "rmse", "x": "N"}, results.experiment,
         tmp_path / "rmse.png", footage=SceneFootage())
    line = next(line for ax in drawn[-1].axes for c in ax.containers if c.get_label().startswith("Steady")
                for line in c.lines[:1])
    assert (to_hex(line.get_color()), line.get_linestyle(), line.get_marker()) == ("#f0e442", "-.", "X")
    assert _tree_digest(PACKAGE_DIR) == package  # nothing under replication/ changed
    for name in [name for name in sys.modules if name.split(".")[0] == "my_filters"]:
        del sys.modules[name]


@pytest.mark.parametrize("look_ahead", ["mean", "draw"])
def test_the_example_apf_agrees_with_the_kalman_filter(example, look_ahead):
    """Pitt and Shephard's filter is consistent: its filtering means approach the exact ones as N grows
    (here at R = 4 > Q, where both look-aheads give second-stage weights of finite variance)."""
    from auxiliary_pf.apf import auxiliary_pf

    model = LinearGaussian(a=0.9, Q=1.0, R=4.0, x0=0.0, P0=1.0, steps=50)
    observations = model.simulate(np.random.default_rng(3))[1]
    means, variances, log_evidence = kalman_filter(model, observations)
    gaps, evidence = {}, []
    for n in (250, 4000):
        outputs = [auxiliary_pf(n, look_ahead).run(model, observations, np.random.default_rng(seed))
                   for seed in range(8)]
        gaps[n] = np.sqrt(np.mean([(o.means - means) ** 2 / variances for o in outputs]))  # in posterior sds
        evidence = [o.log_evidence - log_evidence for o in outputs]
    assert gaps[4000] < 0.1 and 2.0 < gaps[250] / gaps[4000] < 8.0  # sqrt(16) = 4: the N^(-1/2) rate
    assert abs(np.mean(evidence)) < 3 * np.std(evidence) / np.sqrt(len(evidence)) + 0.02


def _tree_digest(folder: Path) -> str:
    digest = hashlib.sha256()
    for path in sorted(p for p in folder.rglob("*") if p.is_file() and "__pycache__" not in p.parts):
        digest.update(path.relative_to(folder).as_posix().encode() + path.read_bytes())
    return digest.hexdigest()


def readme_command(section: str) -> str:
    """The shell block of the README's section ``section``."""
    text = (PROJECT_ROOT / "README.md").read_text().split(f"\n## {section}\n", 1)[1].split("\n## ", 1)[0]
    return re.search(r"```sh\n(.*?)```", text, re.DOTALL)[1]


@pytest.mark.e2e
def test_the_tutorial_runs_the_sixth_paper_and_judges_it_with_the_package_untouched(tmp_path):
    """docs/tutorial_your_method.md's commands, in order, then the README's, in a fresh project folder holding
    a copy of the example (as a clone's folder does): the APF beside two shipped experiments (the UNGM, and
    real video), then its own experiment and claim judged; then an edit of its source reruns exactly its runs."""
    package = _tree_digest(PACKAGE_DIR)
    project = tmp_path / "project"
    shutil.copytree(EXAMPLE, project / "examples" / "auxiliary_pf", ignore=shutil.ignore_patterns("__pycache__"))
    (tmp_path / "shared").symlink_to(PROJECT_ROOT.parent / "shared")  # ../shared beside the project, as here
    script = "\n".join([*BASH.findall((PROJECT_ROOT / "docs" / "tutorial_your_method.md").read_text()),
                        readme_command("Your own method")])  # the README's, as written, from the same folder
    env = {**os.environ, "PATH": os.pathsep.join((str(Path(sys.executable).parent), os.environ["PATH"]))}
    env.pop("PYTHONPATH", None)
    done = subprocess.run(["bash", "-euo", "pipefail", "-c", script], cwd=project, env=env, capture_output=True,
                          text=True, timeout=900)
    assert done.returncode == 0, done.stderr[-3000:]
    reports = project / "reports"
    for name in ("hspf_ungm@apf", "hspf@apf"):
        page = (reports / "quick" / name / "index.html").read_text()
        assert "APF" in page, name
    readmes = [p for p in (reports / "quick").glob("hspf_ungm@*") if p.name != "hspf_ungm@apf"]  # a digest
    assert len(readmes) == 1 and "APF" in (readmes[0] / "index.html").read_text()
    own = [p for p in (reports / "quick").glob("apf_ungm@*") if p.is_dir()]
    assert len(own) == 1
    import json

    claims = json.loads((own[0] / "summary.json").read_text())["claims"]
    assert set(claims) == {"apf.ungm"} and len(claims["apf.ungm"]) == 3
    assert all(reading["verdict"]["outcome"] != "not testable" for reading in claims["apf.ungm"].values())
    assert "apf.ungm" not in (reports / "claims.csv").read_text()  # never on the papers' scorecard
    apf = project / "examples" / "auxiliary_pf" / "auxiliary_pf" / "apf.py"
    apf.write_text(apf.read_text() + "\n# an edit\n")
    again = subprocess.run(["bash", "-c", "PYTHONPATH=examples/auxiliary_pf pf-replicate --config-dir "
                            "examples/auxiliary_pf/conf experiment=apf_ungm scale=quick"], cwd=project, env=env,
                           capture_output=True, text=True, timeout=300)
    assert again.returncode == 0, again.stderr[-2000:]
    assert "apf_ungm: 40 runs computed, 40 already stored" in again.stdout  # APF's and APF-draw's; PF's, grid's kept
    assert _tree_digest(PACKAGE_DIR) == package  # no file under replication/ changed
