"""OTB precision and success against the GOT-10k toolkit (``pip install got10k``), and its re-reading of our
exported results (:mod:`replication.export`).

The toolkit's ``ExperimentOTB`` scores as OTB's MATLAB toolkit does (the first frame counted, set to the
truth); ``ExperimentGOT10k`` leaves the first frame out.  Both are run as published, on a dataset of
the OTB sequences in ``../shared/data/otb`` read by the toolkit's own OTB reader: their ``__init__``
would download the benchmark, so the dataset class they build is replaced by that one.
"""

import json
from types import SimpleNamespace

import numpy as np
import pytest
from PIL import Image

from replication.export import LAYOUTS, export_results, main
from replication.metrics import tracking as tm
from replication.paths import resolve
from replication.runner.config import expand
from replication.runner.execute import execute
from replication.runner.store import Store
from replication.scenes import OTBSequence
from replication.scenes.otb import OTB_ROOT

HAVE_OTB = (resolve(OTB_ROOT) / "Girl" / "groundtruth_rect.txt").exists()
pytestmark = pytest.mark.skipif(not HAVE_OTB, reason="../shared/data/otb is not beside the project")
ONE_BASED = np.array([1.0, 1.0, 0.0, 0.0])  # OTB's pixel coordinates are ours plus one


class Sequences:
    """A dataset as the toolkit's experiments read one: by index or name, ``(img_files, anno[, meta])``."""

    def __init__(self, sequences: dict[str, tuple[list, np.ndarray]], return_meta: bool = False):
        self.sequences, self.seq_names, self.return_meta = sequences, list(sequences), return_meta

    def __len__(self):
        return len(self.seq_names)

    def __getitem__(self, index):
        name = index if isinstance(index, str) else self.seq_names[index]  # IndexError ends iteration
        img_files, anno = self.sequences[name]
        if not self.return_meta:
            return img_files, anno
        size = Image.open(img_files[0]).size
        return img_files, anno, {"cover": np.ones(len(anno)), "resolution": str(size)}  # the target always visible


@pytest.fixture(scope="module")
def toolkit_otb():
    """Every sequence of ``../shared/data/otb`` as the toolkit reads it: name -> (img_files, 1-based anno)."""
    datasets = pytest.importorskip("got10k.datasets", reason="the GOT-10k toolkit is not installed (pip install -e '.[test]')")
    otb = datasets.OTB(str(resolve(OTB_ROOT)), version=2015, download=False)
    return {name: otb[name] for name in otb.seq_names}


def toolkit(monkeypatch, kind: str, sequences: dict, result_dir, report_dir):
    """The toolkit's ``ExperimentOTB`` or ``ExperimentGOT10k`` (val subset) on ``sequences``."""
    module = pytest.importorskip(f"got10k.experiments.{kind}")
    if kind == "otb":
        monkeypatch.setattr(module, "OTB", lambda root_dir, version, download: Sequences(sequences))
        return module.ExperimentOTB("unused", result_dir=str(result_dir), report_dir=str(report_dir))
    monkeypatch.setattr(module, "GOT10k", lambda root_dir, subset: Sequences(sequences))
    return module.ExperimentGOT10k("unused", subset="val", result_dir=str(result_dir), report_dir=str(report_dir))


def perturbed(anno: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """A tracker's boxes: the truth jittered in place (8 px) and size (10%), and lost 30-150 px away in 15% of frames."""
    boxes = anno + rng.normal(0, 1, anno.shape) * np.hstack([np.full((len(anno), 2), 8.0), 0.1 * anno[:, 2:]])
    lost = rng.random(len(anno)) < 0.15
    boxes[lost, :2] += rng.uniform(30, 150, (lost.sum(), 2)) * rng.choice([-1, 1], (lost.sum(), 2))
    boxes[:, 2:] = np.maximum(boxes[:, 2:], 1.0)
    return boxes


def calc_rect_int(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """OTB's ``calcRectInt.m`` (tracker_benchmark v1.0): overlap of inclusive pixel ranges over w * h areas."""
    right_a, bottom_a = a[:, 0] + a[:, 2] - 1, a[:, 1] + a[:, 3] - 1
    right_b, bottom_b = b[:, 0] + b[:, 2] - 1, b[:, 1] + b[:, 3] - 1
    inter = (np.maximum(0, np.minimum(right_a, right_b) - np.maximum(a[:, 0], b[:, 0]) + 1)
             * np.maximum(0, np.minimum(bottom_a, bottom_b) - np.maximum(a[:, 1], b[:, 1]) + 1))
    return inter / (a[:, 2] * a[:, 3] + b[:, 2] * b[:, 3] - inter)


def test_otb_scores_equal_the_toolkits_on_every_sequence(toolkit_otb, monkeypatch, tmp_path):
    """Perturbed truth of the 7 OTB targets here: per-frame IoU and CLE, precision and success curves,
    precision at 20 px and AUC, with the first frame counted (OTB) and left out (GOT-10k)."""
    experiment = toolkit(monkeypatch, "otb", {}, tmp_path, tmp_path)
    got10k = toolkit(monkeypatch, "got10k", {}, tmp_path, tmp_path)
    rng = np.random.default_rng(21)
    assert len(toolkit_otb) == 7  # CarScale, David3, Girl, Jogging.1, Jogging.2, Skating1, Suv
    for name, (_, anno) in toolkit_otb.items():
        boxes = perturbed(anno, rng)
        boxes[0] = anno[0]  # the one-pass evaluation's given first box (the toolkit sets it too)
        ious, errors = experiment._calc_metrics(boxes, anno)
        success, precision = experiment._calc_curves(ious, errors)
        ours_iou, ours_cle = tm.iou(boxes - ONE_BASED, anno - ONE_BASED), tm.centre_error(boxes - ONE_BASED, anno - ONE_BASED)
        np.testing.assert_allclose(ours_iou, ious, rtol=0, atol=1e-12)
        np.testing.assert_allclose(ours_iou, calc_rect_int(boxes, anno), rtol=0, atol=1e-12)
        np.testing.assert_allclose(ours_cle, errors, rtol=0, atol=1e-12)
        counted_cle, counted_iou = tm.scored_frames(ours_cle), tm.scored_frames(ours_iou)
        assert len(counted_cle) == len(anno)  # the default follows OTB's toolkit
        np.testing.assert_allclose(tm.precision_curve(counted_cle), precision, rtol=0, atol=1e-12)
        np.testing.assert_allclose(tm.success_curve(counted_iou), success, rtol=0, atol=1e-12)
        assert tm.precision_at(counted_cle) == pytest.approx(precision[20], abs=1e-12)
        assert tm.success_auc(counted_iou) == pytest.approx(success.mean(), abs=1e-12)
        assert 0.5 < tm.precision_at(counted_cle) < 0.95 and 0.3 < tm.success_auc(counted_iou) < 0.8, name  # not trivial
        # GOT-10k leaves the first frame out: 101 thresholds, the average overlap (AO) and the success rate (SR)
        excluded = tm.scored_frames(ours_iou, count_first_frame=False)
        ao, sr, _, curve = got10k._evaluate(experiment._calc_metrics(boxes[1:], anno[1:])[0], np.array([]))
        np.testing.assert_allclose(tm.success_curve(excluded, np.linspace(0, 1, 101)), curve, rtol=0, atol=1e-12)
        assert excluded.mean() == pytest.approx(ao, abs=1e-12) and (excluded > 0.5).mean() == pytest.approx(sr, abs=1e-12)
        assert tm.precision_at(counted_cle) != pytest.approx(tm.precision_at(tm.scored_frames(ours_cle, False)), abs=1e-12)


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    """Two repetitions of PF (N = 10) on Girl's first 30 frames, run, stored and exported in both layouts."""
    from hydra import compose, initialize_config_dir

    from replication.paths import CONF_DIR

    root = tmp_path_factory.mktemp("export")
    overrides = (f"store={root / 'store'}", f"reports={root / 'reports'}", "experiment.runs.quick=2",
                 "experiment.model.sweep.scene=[Girl]", "experiment.scenes.Girl.last.quick=30", "progress=false")
    with initialize_config_dir(config_dir=str(CONF_DIR), version_base="1.3"):
        cfg = compose("config", overrides=["experiment=ism_pf_otb", "scale=quick", *overrides])
    runs = [r for r in expand(cfg) if r.method == "PF" and str(r.condition) == "scene=Girl;N=10"]
    store = Store(root / "store", "ism_pf_otb")
    execute(runs, store, n_jobs=1, progress=False)
    written = {layout: export_results("ism_pf_otb", "quick", root / "results", layout, overrides) for layout in LAYOUTS}
    records = store.load(runs).sort_values("repetition").to_dict("records")
    return SimpleNamespace(root=root, written=written, records=records, cfg=cfg, runs=runs, store=store, overrides=overrides)


def test_export_follows_the_toolkits_layouts(exported):
    otb, got = exported.root / "results" / "OTB2015", exported.root / "results" / "GOT-10k"
    written, records = exported.written, exported.records
    assert written["otb"] == [otb / "PF_N=10" / "Girl.txt"] and (otb / "PF_N=10" / "times" / "Girl_time.txt").exists()
    assert written["got10k"] == [got / "PF_N=10" / "Girl" / f"Girl_00{r}.txt" for r in (1, 2)]
    assert sorted(p.name for p in (got / "PF_N=10" / "Girl").iterdir()) == ["Girl_001.txt", "Girl_002.txt", "Girl_time.txt"]
    boxes = np.loadtxt(got / "PF_N=10" / "Girl" / "Girl_002.txt", delimiter=",")
    np.testing.assert_array_equal(boxes[0], [57, 21, 31, 45])  # Girl's first line of groundtruth_rect.txt
    np.testing.assert_allclose(boxes - ONE_BASED, np.asarray(records[1]["per_frame"]["box"])[:, 0], atol=1e-9)
    times = np.loadtxt(got / "PF_N=10" / "Girl" / "Girl_time.txt", delimiter=",")
    assert times.shape == (30, 2) and np.isnan(times[0]).all() and (times[1:] > 0).all()
    np.testing.assert_array_equal(np.loadtxt(otb / "PF_N=10" / "times" / "Girl_time.txt"), times[:, 0])


def test_exported_results_rescored_by_the_toolkit(exported, toolkit_otb, monkeypatch, tmp_path):
    """The toolkit's own evaluation reads the export: OTB scores of the first repetition, GOT-10k's of both."""
    root, records = exported.root, exported.records
    img_files, anno = toolkit_otb["Girl"]
    girl = {"Girl": (img_files[:30], anno[:30])}
    truth = OTBSequence("Girl", last=30).truth[:, 0]
    boxes = [np.asarray(r["per_frame"]["box"], dtype=float)[:, 0] for r in records]  # as stored, 0-based
    seconds = np.concatenate([np.asarray(r["per_frame"]["seconds"][1:]) for r in records])

    otb = toolkit(monkeypatch, "otb", girl, root / "results", tmp_path)
    scores = otb.report(["PF_N=10"])["PF_N=10"]["seq_wise"]["Girl"]
    errors, overlaps = tm.centre_error(boxes[0], truth), tm.iou(boxes[0], truth)
    np.testing.assert_allclose(tm.precision_curve(tm.scored_frames(errors)), scores["precision_curve"], rtol=0, atol=1e-12)
    np.testing.assert_allclose(tm.success_curve(tm.scored_frames(overlaps)), scores["success_curve"], rtol=0, atol=1e-12)
    assert tm.precision_at(tm.scored_frames(errors)) == pytest.approx(scores["precision_score"], abs=1e-12)
    assert tm.success_auc(tm.scored_frames(overlaps)) == pytest.approx(scores["success_score"], abs=1e-12)
    # The run's own scores (first frame counted) are the toolkit's but for frames that the boxes' rounding to
    # 0.01 px could move across a threshold (leaving the first frame out would move the AUC by (20/21 - AUC) / 30).
    near = (np.abs(overlaps[:, None] - tm.SUCCESS_THRESHOLDS[None, :]) < 1e-3).sum()
    assert abs(records[0]["success_auc"] - scores["success_score"]) <= near / overlaps.size / len(tm.SUCCESS_THRESHOLDS)
    assert records[0]["precision20"] == pytest.approx(tm.precision_at(tm.scored_frames(errors)), abs=(np.abs(errors - 20) < 0.01).mean())
    assert scores["speed_fps"] == pytest.approx(np.mean(1 / np.asarray(records[0]["per_frame"]["seconds"][1:])), rel=1e-12)

    got10k = toolkit(monkeypatch, "got10k", girl, root / "results", tmp_path)
    for b in [*boxes, truth]:  # inside Girl's 128 x 96 in 1-based pixels: GOT-10k clips boxes to the image
        assert (b[:, 0] + 1 + b[:, 2] <= 128).all() and (b[:, 1] + 1 + b[:, 3] <= 96).all()
    performance = got10k.report(["PF_N=10"])["PF_N=10"]
    overlaps = np.concatenate([tm.scored_frames(tm.iou(b, truth), count_first_frame=False) for b in boxes])
    np.testing.assert_allclose(tm.success_curve(overlaps, np.linspace(0, 1, 101)), performance["overall"]["succ_curve"],
                               rtol=0, atol=1e-12)
    assert overlaps.mean() == pytest.approx(performance["seq_wise"]["Girl"]["ao"], abs=1e-12)
    assert performance["seq_wise"]["Girl"]["speed_fps"] == pytest.approx(np.mean(1 / seconds), rel=1e-12)
    assert json.loads((tmp_path / "GOT-10k" / "PF_N=10" / "performance.json").read_text())["PF_N=10"]["overall"]["ao"] \
        == pytest.approx(overlaps.mean(), abs=1e-12)


def test_the_experiment_report_exports_runs_on_otb_sequences(exported):
    from replication.report.experiments import write_experiment
    from replication.runner.results import Results

    page = write_experiment(exported.cfg, Results.of(exported.cfg, exported.runs, exported.store))
    assert 'href="results/OTB2015/"' in page.read_text() and 'href="results/GOT-10k/"' in page.read_text()
    for layout in ("OTB2015/PF_N=10/Girl.txt", "GOT-10k/PF_N=10/Girl/Girl_002.txt"):
        assert (page.parent / "results" / layout).read_text() == (exported.root / "results" / layout).read_text()


def test_the_command_line_writes_a_layout(exported, tmp_path, capsys):
    main(["experiment=ism_pf_otb", "scale=quick", "layout=got10k", f"out={tmp_path}", *exported.overrides])
    assert capsys.readouterr().out == f"ism_pf_otb: 2 result files in the got10k layout under {tmp_path / 'GOT-10k'}\n"
    assert (tmp_path / "GOT-10k" / "PF_N=10" / "Girl" / "Girl_time.txt").exists() and not (tmp_path / "OTB2015").exists()


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["experiment=nope"], "name a tracking experiment: experiment=<name>; known: "),
        (["experiment=hspf_ungm", "scale=quick"], "experiment 'hspf_ungm' is not a tracking experiment (task: scalar)"),
        (["experiment=ism_pf_otb", "scale=quick", "layout=vot"], "unknown layout 'vot'; choose one of otb, got10k"),
        (["experiment=ism_pf_otb", "scale=quick", "experiment.runs.quick=0"], "experiment.runs.quick must be a positive"),
        (["experiment=ism_pf_otb", "scale=quick", "layout=otb"], "no stored run of ism_pf_otb at scale quick is on an OTB"),
        (["experiment=ism_pf_otb", "quick"], "arguments are key=value; got quick"),
        (["experiment=gps_qmcpf_readings"], "gps_qmcpf_readings is a multiverse: its runs are stored under its "
                                            "experiments', name one of them: gps_qmcpf, gps_qmcpf_cost"),
    ],
)
def test_the_command_line_says_what_is_wrong_in_one_line(args, message, tmp_path, capsys):
    with pytest.raises(SystemExit) as exit:
        main([*args, f"store={tmp_path}", f"out={tmp_path}"])
    error = capsys.readouterr().err
    assert exit.value.code == 2 and error.startswith(f"error: {message}") and error.count("\n") == 1, error
