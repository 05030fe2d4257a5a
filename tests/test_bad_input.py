"""Bad and hostile input through the command line: one line naming the key or the file, exit status 2,
nothing written; config errors before the numerical stack is imported, in under a second."""

import shutil
import subprocess
import sys
import time

import cv2
import numpy as np
import pytest
from conftest import PROJECT_ROOT

from replication.evidence import summary
from replication.scenes.otb import OTB_ROOT

# Runs the command line in-process and prints, on exit, whether numpy had been imported by then.
PROBE = (
    "import atexit, sys; atexit.register(lambda: print('numpy imported:', 'numpy' in sys.modules));"
    "from replication.cli import main; main(sys.argv[1:])"
)


def request(tmp_path, *args, probe=False):
    """The command line with its store and reports in ``tmp_path``; (result, seconds)."""
    out = [f"store={tmp_path / 'experiments'}", f"reports={tmp_path / 'reports'}", "outside_project=true"]
    command = [sys.executable, "-c", PROBE] if probe else [sys.executable, "-m", "replication"]
    started = time.perf_counter()
    result = subprocess.run([*command, *out, *args, "progress=false"], check=False, cwd=PROJECT_ROOT,
                            capture_output=True, text=True, timeout=120)
    return result, time.perf_counter() - started


def assert_one_line(result, tmp_path, named):
    assert result.returncode == 2, result.stderr
    assert "Traceback" not in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1, result.stderr
    assert named in result.stderr, result.stderr
    assert not (tmp_path / "experiments").exists() and not (tmp_path / "reports").exists()  # nothing written


@pytest.mark.parametrize(
    "args, named",
    [
        (("experiment=hspf_ungm", "base_seed=abc"), "base_seed"),
        (("experiment=hspf_ungm", "base_seed=null"), "base_seed"),
        (("experiment=hspf_ungm", "base_seed=-1"), "base_seed"),
        (("experiment=hspf_ungm", "base_seed=1.5"), "base_seed"),
        (("experiment=hspf_ungm", "n_jobs=-5"), "n_jobs"),
        (("experiment=hspf_ungm", "n_jobs=0"), "n_jobs"),
        (("experiment=hspf_ungm", "scale=huge"), "scale"),
        (("experiment=hspf_ungm", "experiment.model.Q=0"), "experiment.model.Q must be positive"),
        (("experiment=hspf_ungm", "experiment.model.R=-0.1"), "experiment.model.R must be positive"),
        (("experiment=hspf_ungm", "experiment.model.x0=nan"), "experiment.model.x0 must be a finite"),
        (("experiment=hspf_ungm", "experiment.model.x0=inf"), "experiment.model.x0 must be a finite"),
        (("experiment=demo_scene", "experiment.model.observation.sigma=0"), "observation.sigma must be positive"),
        (("experiment=demo_scene", "experiment.model.motion.step_sd=[4,nan,0.5,0.5]"), "motion.step_sd"),
        (("experiment=demo_scene", "experiment.model.motion.step_sd=[4,-4,0.5,0.5]"), "must not be negative"),
        (("experiment=hspf_ungm", "experiment.runs.quick=2.5"), "experiment.runs.quick"),
        # measured against the file's 100, not against the overridden count itself
        (("experiment=hspf_ungm", "scale=paper", "experiment.runs.paper=5000"),
         "= 5,000 runs per condition, against the paper's 100"),
        (("experiment=hspf_ungm", "experiment.name=../../../x"), "experiment.name"),
        (("experiment=hspf_ungm", "experiment.name=a/b"), "experiment.name"),
        (("experiment=hspf_ungm", "experiment.methods=[1,2]"), "experiment.methods=[1,2]"),
        (("experiment=hspf_ungm", "outside_project=maybe"), "outside_project"),
        (("experiment=hspf_ungm", "skip_recorded=1"), "skip_recorded must be true or false"),
        (("experiment=hspf_ungm", "dry_run=yes"), "dry_run must be true or false"),
        (("experiment=hspf_ungm", "record=null"), "record must be a folder"),
    ],
)
def test_config_errors_are_one_line_before_any_heavy_import(tmp_path, args, named):
    result, seconds = request(tmp_path, *args, probe=True)
    assert_one_line(result, tmp_path, named)
    assert "numpy imported: False" in result.stdout
    assert seconds < 1.0 or request(tmp_path, *args, probe=True)[1] < 1.0  # once more if the machine was busy


@pytest.mark.parametrize("key", ["store", "reports"])
@pytest.mark.parametrize("where", ["../../elsewhere", "/tmp/elsewhere"])
def test_output_outside_the_project_is_refused_unless_asked(tmp_path, key, where):
    command = [sys.executable, "-m", "replication", "experiment=hspf_ungm", f"{key}={where}"]
    result = subprocess.run(command, check=False, cwd=PROJECT_ROOT, capture_output=True, text=True, timeout=60)
    assert result.returncode == 2 and f"{key}={where} is outside the project" in result.stderr
    assert "outside_project=true" in result.stderr and len(result.stderr.strip().splitlines()) == 1


def test_an_output_folder_that_cannot_be_written_is_named(tmp_path):
    (tmp_path / "a_file").write_text("")
    command = [sys.executable, "-m", "replication", "experiment=hspf_ungm", f"store={tmp_path / 'a_file' / 'x'}",
               f"reports={tmp_path / 'reports'}", "outside_project=true"]
    result = subprocess.run(command, check=False, cwd=PROJECT_ROOT, capture_output=True, text=True, timeout=60)
    assert result.returncode == 2 and "store:" in result.stderr and "a_file is a file" in result.stderr


@pytest.mark.parametrize(
    "text, named",
    [
        ("name: mine\ntask: scalar\nmethods:\n  PF: {filter: bootstrap\n", "mine.yaml:5"),  # unclosed brace
        ("name: mine\n  task: [scalar\n", "mine.yaml:2"),
        ("", "mine.yaml is empty"),
        ("- a list\n- not a mapping\n", "mine.yaml holds a list"),
        ("name: mine\ntask: scalar\nruns: {paper: 5, quick: 5}\nmodel: {name: ungm}\nmethods:\n  ../x: {filter: bootstrap}\n",
         "experiment.methods: the name '../x' must be"),
        ("name: mine\ntask: scalar\nruns: {paper: 5, quick: 5}\nmodel: {name: ungm}\nmethods: [PF, HSPF]\n",
         "experiment.methods must be a mapping, got a list"),
    ],
)
def test_a_broken_experiment_file_names_its_file_and_line(tmp_path, text, named):
    own = tmp_path / "conf" / "experiment"
    own.mkdir(parents=True)
    (own / "mine.yaml").write_text(text)
    result, seconds = request(tmp_path, "--config-dir", str(own.parent), "experiment=mine")
    assert_one_line(result, tmp_path, named)
    assert seconds < 1.0 or request(tmp_path, "--config-dir", str(own.parent), "experiment=mine")[1] < 1.0


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


@pytest.mark.parametrize(
    "damage, named",
    [
        (break_frame, "0005.jpg: not a readable image"),
        (resize_frame, "0005.jpg: 64x48 pixels where the frames before it are 128x96"),
        (nan_row, "groundtruth_rect.txt:5: a ground-truth box that is not four finite numbers"),
        (word_in_a_row, "groundtruth_rect.txt:3: a ground-truth box that is not four numbers: 'abc,1,2,3'"),
        (short_row, "groundtruth_rect.txt:7: a ground-truth box of 3 numbers, not 4"),
        (empty_first_box, "groundtruth_rect.txt:1: the first box has no area"),
    ],
)
def test_damaged_sequences_fail_before_any_work(tmp_path, damage, named):
    girl = girl_copy(tmp_path)
    damage(girl)
    result, _ = request(tmp_path, "experiment=ism_pf_otb", "scale=quick", f"+experiment.scenes.Girl.root={girl.parent}",
                        "experiment.scenes.Girl.last=20")
    assert_one_line(result, tmp_path, named)


def test_the_intact_copy_passes(tmp_path):
    """The damage above, not the copying, is what the checks catch."""
    from replication.scenes.otb import OTBSequence

    sequence = OTBSequence("Girl", str(girl_copy(tmp_path).parent))
    assert sequence.n_frames == 20 and sequence.size == (128, 96)
    assert np.isfinite(sequence.truth).all()


@pytest.mark.e2e  # a subprocess, a killed runner or a cluster: make test-fast leaves it out
def test_a_users_own_sequences_get_their_own_report_and_leave_the_scorecard_alone(tmp_path):
    """``data.otb=<folder> sequences=[...]`` on a copy of a shipped sequence under another name: the
    experiment's methods on it alone, reported as hspf@mine with what differs, no companion run, and
    claims.csv byte-identical before and after."""
    from replication.report.pages.index import write_index

    clip = girl_copy(tmp_path).rename(tmp_path / "otb" / "MyClip")
    before = (write_index(tmp_path / "reports").parent / "claims.csv").read_bytes()
    result, _ = request(tmp_path, "experiment=hspf", "scale=quick", "experiment.runs.quick=1",
                        f"data.otb={clip.parent}", "sequences=[MyClip]", "label=mine")
    assert result.returncode == 0, result.stderr
    records = list((tmp_path / "experiments" / "hspf" / "runs").glob("*.json"))
    assert records and all("scene=MyClip" in r.read_text() for r in records)
    assert (tmp_path / "reports" / "claims.csv").read_bytes() == before
    assert not {"hspf", "hspf_ungm"} & {p.name for p in (tmp_path / "reports").rglob("*") if p.is_dir()}
    assert "skipped: hspf_ungm" in result.stderr
    page = (tmp_path / "reports" / "quick" / "hspf@mine" / "index.html").read_text()
    assert "Not the paper's experiment" in page and "scenes.MyClip: added" in page and "sequences=[MyClip]" in page
    assert 'href="quick/hspf@mine/index.html"' in (tmp_path / "reports" / "index.html").read_text()


@pytest.mark.parametrize(
    "args, named",
    [
        (("sequences=[Girl,Grl]",), "sequences: OTB sequence 'Grl' is not in"),
        (("data.otb=/no/such/folder", "sequences=[Girl]"), "data.otb: no folder /no/such/folder"),
    ],
)
def test_a_misspelt_sequence_of_ones_own_fails_in_one_line(tmp_path, args, named):
    girl = girl_copy(tmp_path)
    result, _ = request(tmp_path, "experiment=hspf", "scale=quick", *(
        [f"data.otb={girl.parent}"] if not any(a.startswith("data.otb") for a in args) else []), *args)
    assert_one_line(result, tmp_path, named)


@pytest.mark.parametrize("scale", ["quick", "paper"])
def test_every_shipped_experiment_passes_the_preflight(make_cfg, scale):
    """The checks refuse nothing the project ships (their rules are about values, not about our configs)."""
    from replication.paths import experiment_names
    from replication.runner.preflight import check_yaml, preflight

    for name in experiment_names():
        written = check_yaml(summary.CONF_DIR / "experiment" / f"{name}.yaml")
        preflight(make_cfg(name, f"scale={scale}", "outside_project=true"), written)


@pytest.mark.e2e  # a subprocess, a killed runner or a cluster: make test-fast leaves it out
def test_a_users_own_mot_sequence_gets_its_own_report_and_leaves_the_scorecard_alone(tmp_path):
    """bis_pf_pets with another MOTChallenge sequence in the PETS scene's place: reported as bis_pf_pets@campus,
    the bis_pf.pets and bis_pf.cost rows (and every other) of claims.csv byte-identical."""
    from replication.report.pages.index import write_index

    if not (PROJECT_ROOT / "../shared/data/mot/TUD-Campus").is_dir():
        pytest.skip("MOT data not beside the project")
    before = (write_index(tmp_path / "reports").parent / "claims.csv").read_bytes()
    result, _ = request(tmp_path, "experiment=bis_pf_pets", "scale=quick", "experiment.runs.quick=1",
                        "experiment.scenes.exp6_pets09.name=TUD-Campus", "experiment.scenes.exp6_pets09.last=20",
                        "label=campus")
    assert result.returncode == 0, result.stderr
    assert "reported as bis_pf_pets@campus" in result.stdout
    assert (tmp_path / "reports" / "claims.csv").read_bytes() == before
    page = (tmp_path / "reports" / "quick" / "bis_pf_pets@campus" / "index.html").read_text()
    assert "Not the paper&#39;s experiment" in page or "Not the paper's experiment" in page
    assert 'scenes.exp6_pets09.name: &#34;PETS09-S2L1&#34; -&gt; &#34;TUD-Campus&#34;' in page
    assert not (tmp_path / "reports" / "quick" / "bis_pf_pets").exists()


@pytest.mark.e2e  # a subprocess, a killed runner or a cluster: make test-fast leaves it out
def test_sequences_of_ones_own_run_through_a_mot_experiment_and_its_figures_follow_them(tmp_path):
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
    result, _ = request(tmp_path, "experiment=bis_pf_pets", "scale=quick", "experiment.runs.quick=1",
                        f"data.mot={mine.parent}", "sequences=[MyCampus]", "label=mine")
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
