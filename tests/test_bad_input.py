"""Bad and hostile input through the command line: one line naming the key or the file, exit status 2,
nothing written; config errors before the numerical stack is imported, data errors before any worker starts.

What makes a check fast is asserted, not its seconds (the machine may be loaded): each request runs through
the command line's ``main(argv)`` in a fresh interpreter, several requests in turn in one (interpreters and
the numerical stack's imports are what costs), which reports the top-level modules loaded once it has run
and whether joblib started its workers.  The seconds a user waits are ``benchmarks/bad_input_latency.py``'s.
"""

import json
import shutil
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np
import pytest
from conftest import PROJECT_ROOT

from replication.evidence import summary
from replication.scenes.otb import OTB_ROOT

# The command line, on each request read from stdin in turn, in one interpreter: for each, its exit status (a
# traceback as the exception's line), its stderr, the top-level modules loaded by then and whether joblib's
# workers were started (its reusable executor made).
PROBE = """
import contextlib, io, json, sys
from replication.cli import main

found = []
for argv in json.loads(sys.stdin.read()):
    err = io.StringIO()
    with contextlib.redirect_stderr(err):
        try:
            main(argv)
            status = 0
        except SystemExit as exit:
            status = exit.code
        except BaseException as error:
            status = f"Traceback: {type(error).__name__}: {error}"
    loky = sys.modules.get("joblib.externals.loky.reusable_executor")
    found.append({"status": status, "stderr": err.getvalue(), "workers": bool(loky and loky._executor),
                  "modules": sorted({name.partition(".")[0] for name in sys.modules})})
print(json.dumps(found))
"""
# the numerical and parallel stack: none of it is imported before a config error is said
HEAVY = {"numpy", "scipy", "cv2", "numba", "llvmlite", "pandas", "pyarrow", "matplotlib", "PIL", "joblib", "dask",
         "distributed", "ray"}


def command_lines(requests: list[list[str]]) -> list[dict]:
    """Each of ``requests`` through the command line in turn, in one fresh interpreter (:data:`PROBE`)."""
    done = subprocess.run([sys.executable, "-c", PROBE], input=json.dumps(requests), cwd=PROJECT_ROOT,
                          capture_output=True, text=True, timeout=900, check=False)
    assert done.returncode == 0, done.stderr[-3000:]
    return json.loads(done.stdout.splitlines()[-1])


@dataclass(frozen=True)
class Bad:
    """A bad request: its arguments (``{here}``: a folder of its own; after the store and reports in it, so that
    they may override them), a text its one line must hold, the files it needs in its folder (path: text) and
    the words before every setting (a command)."""

    args: tuple[str, ...]
    named: str
    files: tuple[tuple[str, str], ...] = ()
    command: tuple[str, ...] = ()

    def argv(self, here: Path) -> list[str]:
        for path, text in self.files:
            (here / path).parent.mkdir(parents=True, exist_ok=True)
            (here / path).write_text(text)
        args = [arg.format(here=here) for arg in self.args]
        own = any(arg.startswith(("store=", "reports=")) for arg in args)
        out = [] if own else [f"store={here / 'experiments'}", f"reports={here / 'reports'}", "outside_project=true"]
        return [*self.command, *out, *args, "progress=false"]


def own_file(text: str, named: str) -> Bad:
    """An experiment file of one's own, read through ``--config-dir``."""
    return Bad(("--config-dir", "{here}/conf", "experiment=mine"), named, (("conf/experiment/mine.yaml", text),))


CONFIG_ERRORS = [
    Bad(("experiment=hspf_ungm", "base_seed=abc"), "base_seed"),
    Bad(("experiment=hspf_ungm", "base_seed=null"), "base_seed"),
    Bad(("experiment=hspf_ungm", "base_seed=-1"), "base_seed"),
    Bad(("experiment=hspf_ungm", "base_seed=1.5"), "base_seed"),
    Bad(("experiment=hspf_ungm", "n_jobs=-5"), "n_jobs"),
    Bad(("experiment=hspf_ungm", "n_jobs=0"), "n_jobs"),
    Bad(("experiment=hspf_ungm", "scale=huge"), "scale"),
    Bad(("experiment=hspf_ungm", "experiment.model.Q=0"), "experiment.model.Q must be positive"),
    Bad(("experiment=hspf_ungm", "experiment.model.R=-0.1"), "experiment.model.R must be positive"),
    Bad(("experiment=hspf_ungm", "experiment.model.x0=nan"), "experiment.model.x0 must be a finite"),
    Bad(("experiment=hspf_ungm", "experiment.model.x0=inf"), "experiment.model.x0 must be a finite"),
    Bad(("experiment=demo_scene", "experiment.model.observation.sigma=0"), "observation.sigma must be positive"),
    Bad(("experiment=demo_scene", "experiment.model.motion.step_sd=[4,nan,0.5,0.5]"), "motion.step_sd"),
    Bad(("experiment=demo_scene", "experiment.model.motion.step_sd=[4,-4,0.5,0.5]"), "must not be negative"),
    Bad(("experiment=hspf_ungm", "experiment.runs.quick=2.5"), "experiment.runs.quick"),
    # measured against the file's 100, not against the overridden count itself
    Bad(("experiment=hspf_ungm", "scale=paper", "experiment.runs.paper=5000"),
        "= 5,000 runs per condition, against the paper's 100"),
    Bad(("experiment=hspf_ungm", "experiment.name=../../../x"), "experiment.name"),
    Bad(("experiment=hspf_ungm", "experiment.name=a/b"), "experiment.name"),
    Bad(("experiment=hspf_ungm", "experiment.methods=[1,2]"), "experiment.methods=[1,2]"),
    Bad(("experiment=hspf_ungm", "outside_project=maybe"), "outside_project"),
    Bad(("experiment=hspf_ungm", "skip_recorded=1"), "skip_recorded must be true or false"),
    Bad(("experiment=hspf_ungm", "dry_run=yes"), "dry_run must be true or false"),
    Bad(("experiment=hspf_ungm", "draw=no"), "draw must be true or false"),
    Bad(("experiment=hspf_ungm", "record=null"), "record must be a folder"),
    Bad(("experiment=hspf_ungm", "n_job=4"), "unknown key 'n_job'"),
    Bad(("experiment=hspf_ungm", "experiment.methods.PF.bogus=1"), "unknown key 'experiment.methods.PF.bogus'"),
    Bad(("experiment=hspf_ungm", "n_jobs=[1"), "no viable alternative"),
    Bad(("experiment=hspf_uncm",), "unknown experiment 'hspf_uncm'"),
    Bad(("experiment=hspf_ungm",), "unknown command 'frobnicate'; commands: run, report,", command=("frobnicate",)),
    # a sequence is named by its folder in data.otb: a path is refused, as docs/commands.md says
    Bad(("experiment=hspf", "sequences=[../otb/Girl]"), "sequences: '../otb/Girl' is a path, not a sequence's name"),
    Bad(("experiment=hspf", "sequences=[Girl,/data/otb/Girl]"), "sequences: '/data/otb/Girl' is a path"),
    Bad(("experiment=bis_pf_pets", "sequences=[My\\Seq]"), "sequences: 'My\\\\Seq' is a path"),  # a Windows path
    Bad(("experiment=hspf_ungm", "store=../../elsewhere"), "store=../../elsewhere is outside the project"),
    Bad(("experiment=hspf_ungm", "store=/tmp/elsewhere"), "store=/tmp/elsewhere is outside the project"),
    Bad(("experiment=hspf_ungm", "reports=../../elsewhere"), "reports=../../elsewhere is outside the project"),
    Bad(("experiment=hspf_ungm", "reports=/tmp/elsewhere"), "add outside_project=true to write there"),
    Bad(("experiment=hspf_ungm", "store={here}/a_file/x", "reports={here}/reports", "outside_project=true"),
        "store: {here}/a_file is a file", (("a_file", ""),)),
    own_file("name: mine\ntask: scalar\nmethods:\n  PF: {filter: bootstrap\n", "mine.yaml:5"),  # unclosed brace
    own_file("name: mine\n  task: [scalar\n", "mine.yaml:2"),
    own_file("", "mine.yaml is empty"),
    own_file("- a list\n- not a mapping\n", "mine.yaml holds a list"),
    own_file("name: mine\ntask: scalar\nruns: {paper: 5, quick: 5}\nmodel: {name: ungm}\nmethods:\n  ../x: {filter: bootstrap}\n",
             "experiment.methods: the name '../x' must be"),
    own_file("name: mine\ntask: scalar\nruns: {paper: 5, quick: 5}\nmodel: {name: ungm}\nmethods: [PF, HSPF]\n",
             "experiment.methods must be a mapping, got a list"),
]


def requests_in(folder: Path, cases: list[Bad]) -> list[list[str]]:
    """Each case's command line, each with a folder of its own under ``folder``."""
    found = []
    for number, case in enumerate(cases):
        (folder / str(number)).mkdir()
        found.append(case.argv(folder / str(number)))
    return found


@pytest.fixture(scope="module")
def config_errors(tmp_path_factory) -> tuple[Path, list[dict]]:
    folder = tmp_path_factory.mktemp("config_errors")
    return folder, command_lines(requests_in(folder, CONFIG_ERRORS))


def assert_one_line(found: dict, here: Path, named: str) -> None:
    assert found["status"] == 2, found
    assert len(found["stderr"].strip().splitlines()) == 1, found["stderr"]
    assert named.format(here=here) in found["stderr"], found["stderr"]
    assert not (here / "experiments").exists() and not (here / "reports").exists()  # nothing written


@pytest.mark.parametrize("number", range(len(CONFIG_ERRORS)), ids=lambda n: CONFIG_ERRORS[n].named[:40])
def test_config_errors_are_one_line_before_any_heavy_import(config_errors, number):
    folder, found = config_errors
    assert_one_line(found[number], folder / str(number), CONFIG_ERRORS[number].named)
    heavy = HEAVY & set(found[number]["modules"])
    assert not heavy, f"imported before the error was said (by this request or one before it): {sorted(heavy)}"


def test_a_broken_experiment_file_never_breaks_another_report(tmp_path, monkeypatch, capsys):
    conf = tmp_path / "conf"
    shutil.copytree(summary.CONF_DIR / "experiment", conf / "experiment")
    (conf / "experiment" / "broken.yaml").write_text("name: broken\nmethods: {PF: [\n")
    monkeypatch.setattr(summary, "CONF_DIR", conf)
    monkeypatch.setattr(summary, "experiment_names", lambda: sorted(p.stem for p in (conf / "experiment").glob("*.yaml")))
    configs = summary.experiment_configs()
    assert "broken" not in configs and "hspf" in configs
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "broken.yaml does not parse" in err


def girl_copy(tmp_path, last=20):
    """The first ``last`` frames of OTB's Girl in a folder of our own, to be broken by the test."""
    source = PROJECT_ROOT / OTB_ROOT / "Girl"
    if not source.is_dir():
        pytest.skip(f"OTB data not at {source}")
    girl = tmp_path / "otb" / "Girl"
    (girl / "img").mkdir(parents=True)
    for k in range(1, last + 1):
        shutil.copy(source / "img" / f"{k:04d}.jpg", girl / "img")
    rows = (source / "groundtruth_rect.txt").read_text().splitlines()[:last]
    (girl / "groundtruth_rect.txt").write_text("\n".join(rows) + "\n")
    return girl


def break_frame(girl):
    (girl / "img" / "0005.jpg").write_bytes(b"not a jpeg at all")


def resize_frame(girl):
    image = cv2.imread(str(girl / "img" / "0005.jpg"))
    cv2.imwrite(str(girl / "img" / "0005.jpg"), cv2.resize(image, (64, 48)))


def nan_row(girl):
    rows = (girl / "groundtruth_rect.txt").read_text().splitlines()
    rows[4] = "nan,nan,nan,nan"
    (girl / "groundtruth_rect.txt").write_text("\n".join(rows) + "\n")


def word_in_a_row(girl):
    rows = (girl / "groundtruth_rect.txt").read_text().splitlines()
    rows[2] = "abc,1,2,3"
    (girl / "groundtruth_rect.txt").write_text("\n".join(rows) + "\n")


def short_row(girl):
    rows = (girl / "groundtruth_rect.txt").read_text().splitlines()
    rows[6] = ",".join(rows[6].replace("\t", ",").split(",")[:3])
    (girl / "groundtruth_rect.txt").write_text("\n".join(rows) + "\n")


def empty_first_box(girl):
    rows = (girl / "groundtruth_rect.txt").read_text().splitlines()
    x, y, _, h = rows[0].replace("\t", ",").split(",")
    rows[0] = f"{x},{y},0,{h}"
    (girl / "groundtruth_rect.txt").write_text("\n".join(rows) + "\n")


def lose_frame(girl):
    (girl / "img" / "0012.jpg").unlink()


def lose_last_frames(girl):
    (girl / "img" / "0019.jpg").unlink()
    (girl / "img" / "0020.jpg").unlink()


def intact(girl):
    pass


DAMAGED = ("experiment=ism_pf_otb", "scale=quick", "+experiment.scenes.Girl.root={here}/otb",
           "experiment.scenes.Girl.last=20")
OWN = ("experiment=hspf", "scale=quick", "data.otb={here}/otb")
DATA_ERRORS = [  # each on its own copy of Girl's first 20 frames, in {here}/otb, damaged so
    (break_frame, Bad(DAMAGED, "0005.jpg: not a readable image")),
    (resize_frame, Bad(DAMAGED, "0005.jpg: 64x48 pixels where the frames before it are 128x96")),
    (nan_row, Bad(DAMAGED, "groundtruth_rect.txt:5: a ground-truth box that is not four finite numbers")),
    (word_in_a_row, Bad(DAMAGED, "groundtruth_rect.txt:3: a ground-truth box that is not four numbers: 'abc,1,2,3'")),
    (short_row, Bad(DAMAGED, "groundtruth_rect.txt:7: a ground-truth box of 3 numbers, not 4")),
    (empty_first_box, Bad(DAMAGED, "groundtruth_rect.txt:1: the first box has no area")),
    (lose_frame, Bad(DAMAGED, "otb/Girl: 19 frames but 20 ground-truth boxes: missing img/0012.jpg")),
    (lose_last_frames, Bad((*OWN, "sequences=[Girl]"),
                           "otb/Girl: 18 frames but 20 ground-truth boxes: missing img/0019.jpg, img/0020.jpg")),
    (intact, Bad((*OWN, "sequences=[Girl,Grl]"), "sequences: OTB sequence 'Grl' is not in")),
    (intact, Bad(("experiment=hspf", "scale=quick", "data.otb=/no/such/folder", "sequences=[Girl]"),
                 "data.otb: no folder /no/such/folder")),
]


@pytest.fixture(scope="module")
def data_errors(tmp_path_factory) -> tuple[Path, list[dict]]:
    folder = tmp_path_factory.mktemp("data_errors")
    for number, (damage, _) in enumerate(DATA_ERRORS):
        damage(girl_copy(folder / str(number)))
    requests = [case.argv(folder / str(number)) for number, (_, case) in enumerate(DATA_ERRORS)]
    return folder, command_lines(requests)


@pytest.mark.parametrize("number", range(len(DATA_ERRORS)), ids=lambda n: DATA_ERRORS[n][0].__name__)
def test_bad_sequences_fail_in_one_line_before_any_worker(data_errors, number):
    """A damaged frame or ground truth, a missing frame, a misspelt sequence or data folder: one line naming
    the file (the frames missing), before any worker or cluster is started."""
    folder, found = data_errors
    assert_one_line(found[number], folder / str(number), DATA_ERRORS[number][1].named)
    assert not found[number]["workers"] and not {"dask", "distributed", "ray"} & set(found[number]["modules"])


def test_frames_and_boxes_that_do_not_pair_up_name_the_frames():
    """The gaps in the numbering; past its end where it starts at 1; either end where it starts later (OTB's
    David starts at 0300.jpg); the frames beyond the last box; the first few of many, and how many."""
    from replication.runner.validate import unpaired

    def frames(numbers):
        return [Path(f"img/{n:04d}.jpg") for n in numbers]

    here = Path("/data/MyClip")
    said = unpaired(here, frames(range(1, 500)), 500)
    assert said == f"{here}: 499 frames but 500 ground-truth boxes: missing img/0500.jpg"
    assert unpaired(here, frames(n for n in range(1, 501) if n != 250), 500).endswith(": missing img/0250.jpg")
    assert unpaired(here, frames(n for n in range(1, 501) if n % 7), 500).endswith(
        ": missing img/0007.jpg, img/0014.jpg, img/0021.jpg ... (71 in all)")
    assert unpaired(here, frames(range(300, 770)), 471).endswith(
        ": missing 1 before img/0300.jpg or after img/0769.jpg")
    assert unpaired(here, frames(range(1, 503)), 500).endswith(": img/0501.jpg, img/0502.jpg beyond the last box")


def test_the_intact_copy_passes(tmp_path):
    """The damage above, not the copying, is what the checks catch."""
    from replication.scenes.otb import OTBSequence

    sequence = OTBSequence("Girl", str(girl_copy(tmp_path).parent))
    assert sequence.n_frames == 20 and sequence.size == (128, 96)
    assert np.isfinite(sequence.truth).all()


@pytest.mark.e2e  # a subprocess, a killed runner or a cluster: make test-e2e runs it, make test does not
def test_a_users_own_sequences_get_their_own_report_and_leave_the_scorecard_alone(cli, tmp_path):
    """``data.otb=<folder> sequences=[...]`` on a copy of a shipped sequence under another name: the
    experiment's methods on it alone, reported as hspf@mine with what differs, no companion run, and
    claims.csv byte-identical before and after."""
    from replication.evidence.scorecard import Scorecard
    from replication.report.pages.index import write_index

    clip = girl_copy(tmp_path).rename(tmp_path / "otb" / "MyClip")
    before = (write_index(tmp_path / "reports", Scorecard.read(tmp_path / "reports")).parent / "claims.csv").read_bytes()
    result = cli("experiment=hspf", "scale=quick", "experiment.runs.quick=1", f"data.otb={clip.parent}",
                 "sequences=[MyClip]", "label=mine", timeout=900)
    assert result.returncode == 0, result.stderr
    records = list((tmp_path / "experiments" / "hspf" / "runs").glob("*.json"))
    assert records and all("scene=MyClip" in r.read_text() for r in records)
    assert (tmp_path / "reports" / "claims.csv").read_bytes() == before
    assert not {"hspf", "hspf_ungm"} & {p.name for p in (tmp_path / "reports").rglob("*") if p.is_dir()}
    assert "skipped: hspf_ungm" in result.stderr
    page = (tmp_path / "reports" / "quick" / "hspf@mine" / "index.html").read_text()
    assert "Not the paper's experiment" in page and "scenes.MyClip: added" in page and "sequences=[MyClip]" in page
    assert 'href="quick/hspf@mine/index.html"' in (tmp_path / "reports" / "index.html").read_text()


def test_every_shipped_experiment_passes_the_preflight(tmp_path):
    """The checks refuse nothing the project ships at either scale (their rules are about values, not about our
    configs).  Each experiment is composed once: no value of the configs depends on the scale until it is
    applied, which the checks do."""
    from hydra import compose, initialize_config_dir

    from replication.paths import experiment_names
    from replication.runner.preflight import check_yaml, preflight

    out = [f"store={tmp_path / 'experiments'}", f"reports={tmp_path / 'reports'}", "outside_project=true"]
    with initialize_config_dir(config_dir=str(summary.CONF_DIR), version_base="1.3"):
        for name in experiment_names():
            written = check_yaml(summary.CONF_DIR / "experiment" / f"{name}.yaml")
            cfg = compose("config", overrides=[f"experiment={name}", *out])
            for scale in ("quick", "paper"):
                cfg.scale = scale
                preflight(cfg, written)


@pytest.mark.e2e  # a subprocess, a killed runner or a cluster: make test-e2e runs it, make test does not
def test_a_users_own_mot_sequence_gets_its_own_report_and_leaves_the_scorecard_alone(cli, tmp_path):
    """bis_pf_pets with another MOTChallenge sequence in the PETS scene's place: reported as bis_pf_pets@campus,
    the bis_pf.pets and bis_pf.cost rows (and every other) of claims.csv byte-identical."""
    from replication.evidence.scorecard import Scorecard
    from replication.report.pages.index import write_index

    if not (PROJECT_ROOT / "../shared/data/mot/TUD-Campus").is_dir():
        pytest.skip("MOT data not beside the project")
    before = (write_index(tmp_path / "reports", Scorecard.read(tmp_path / "reports")).parent / "claims.csv").read_bytes()
    result = cli("experiment=bis_pf_pets", "scale=quick", "experiment.runs.quick=1",
                 "experiment.scenes.exp6_pets09.name=TUD-Campus", "experiment.scenes.exp6_pets09.last=20",
                 "label=campus", timeout=900)
    assert result.returncode == 0, result.stderr
    assert "reported as bis_pf_pets@campus" in result.stdout
    assert (tmp_path / "reports" / "claims.csv").read_bytes() == before
    page = (tmp_path / "reports" / "quick" / "bis_pf_pets@campus" / "index.html").read_text()
    assert "Not the paper&#39;s experiment" in page or "Not the paper's experiment" in page
    assert 'scenes.exp6_pets09.name: &#34;PETS09-S2L1&#34; -&gt; &#34;TUD-Campus&#34;' in page
    assert not (tmp_path / "reports" / "quick" / "bis_pf_pets").exists()


@pytest.mark.e2e  # a subprocess, a killed runner or a cluster: make test-e2e runs it, make test does not
def test_sequences_of_ones_own_run_through_a_mot_experiment_and_its_figures_follow_them(cli, tmp_path):
    """``data.mot=<folder> sequences=[...]`` with bis_pf_pets: the runs are on the user's MOTChallenge sequence
    alone (a copy of TUD-Campus under another name), its snapshots and identity timeline drawn for it, and
    the report is its own."""
    source = PROJECT_ROOT / "../shared/data/mot/TUD-Campus"
    if not source.is_dir():
        pytest.skip("MOT data not beside the project")
    mine = tmp_path / "mot" / "MyCampus"
    mine.mkdir(parents=True)
    (mine / "img1").symlink_to(source.resolve() / "img1")
    for part in ("seqinfo.ini", "gt", "det"):
        (shutil.copytree if (source / part).is_dir() else shutil.copy)(source / part, mine / part)
    result = cli("experiment=bis_pf_pets", "scale=quick", "experiment.runs.quick=1", f"data.mot={mine.parent}",
                 "sequences=[MyCampus]", "label=mine", timeout=900)
    assert result.returncode == 0, result.stderr
    records = list((tmp_path / "experiments" / "bis_pf_pets" / "runs").glob("*.json"))
    assert records and all("scene=MyCampus" in r.read_text() for r in records)
    folder = tmp_path / "reports" / "quick" / "bis_pf_pets@mine"
    assert (folder / "snapshots.png").stat().st_size > 10_000 and (folder / "identities.png").exists()
    sequence_page = (folder / "sequences" / "MyCampus.html").read_text()  # a page of its own, its figures on it
    assert 'href="sequences/MyCampus.html"' in (folder / "index.html").read_text()
    for figure in ("snapshots", "identities", "video"):
        assert f'src="MyCampus/{figure}.png"' in sequence_page
        assert (folder / "sequences" / "MyCampus" / f"{figure}.png").stat().st_size > 5_000
    assert "table1_time needs {scene: exp6_pets09}" in result.stderr  # the paper's timing table: said up front
