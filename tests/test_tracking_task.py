"""Tracking end to end: a colour PF follows an easy target; missing real data is skipped, not fatal."""

import numpy as np
from conftest import SMALL

from replication import bootstrap
from replication.boxes import corner_boxes
from replication.metrics.tracking import centre_error
from replication.models.box import BoxModel
from replication.runner.config import expand
from replication.runner.execute import execute
from replication.runner.store import Store
from replication.scenes import SyntheticScene
from replication.vision.colour import ColourLikelihood
from replication.vision.histogram import ColourHistogram

EASY = {
    "size": [160, 120], "frames": 60, "seed": 0, "camera_noise": 4.0,
    "background": {"kind": "gradient", "colour": [120, 140, 110], "to_colour": [80, 90, 70]},
    "targets": [{"shape": "ball", "size": [18, 18], "colour": [30, 40, 220],
                 "motion": {"kind": "velocity", "start": [30, 30], "segments": [[0, 1.5, 1.0]]}}],
}


def test_colour_pf_follows_a_distinct_ball():
    scene = SyntheticScene(EASY)
    x, y, w, h = scene.truth[0, 0]
    start = np.array([x + w / 2, y + h / 2, w, h])
    likelihood = ColourLikelihood.from_frame(scene.frame(0), start, ColourHistogram(grid=(18, 18)), sigma=0.1)
    model = BoxModel(start, likelihood, step_sd=(3.0, 3.0, 0.3, 0.3))
    output = bootstrap(200).run(model, (scene.frame(k) for k in range(1, 60)), np.random.default_rng(0))
    errors = centre_error(corner_boxes(output.means), scene.truth[1:, 0])
    assert errors.mean() < 2.0 and errors.max() < 5.0, errors
    assert output.degenerate.sum() == 0


def test_a_lost_filter_is_measured_as_lost():
    """Sanity check of the measurement: initialise far from the ball and the error stays large."""
    scene = SyntheticScene(EASY)
    x, y, w, h = scene.truth[0, 0]
    start = np.array([x + w / 2, y + h / 2, w, h])
    likelihood = ColourLikelihood.from_frame(scene.frame(0), start, ColourHistogram(grid=(18, 18)), sigma=0.1)
    model = BoxModel(start + [100, 60, 0, 0], likelihood, step_sd=(0.5, 0.5, 0.1, 0.1), initial_sd=(0.5, 0.5, 0.1, 0.1))
    output = bootstrap(50).run(model, (scene.frame(k) for k in range(1, 30)), np.random.default_rng(0))
    assert centre_error(corner_boxes(output.means), scene.truth[1:30, 0]).min() > 40


def test_demo_experiment_runs_and_skips_a_missing_sequence(make_cfg, tmp_path):
    cfg = make_cfg("demo_scene", *SMALL, "experiment.runs.quick=1", f"+experiment.scenes.Girl.root={tmp_path}/none")
    skipped = []
    runs = expand(cfg, skipped)
    assert {str(r.condition) for r in runs} == {"scene=synthetic_head"}
    assert len(skipped) == 1 and "'Girl' is not in" in skipped[0]
    store = Store(tmp_path / "store", "demo_scene")
    execute(runs, store, n_jobs=1, progress=False)
    record = store.load(runs).iloc[0]
    assert record["frames"] == 150 and len(record["per_frame"]["cle"]) == 150
    assert record["per_frame"]["cle"][0] == 0.0  # frame 1 is given, as in OTB's one-pass evaluation
    assert 0 < record["precision20"] <= 1 and record["mean_cle"] > 0


def test_tracking_runs_are_identical_with_one_or_two_jobs(make_cfg, tmp_path):
    from replication.runner.execute import TIMING_COLUMNS

    cfg = make_cfg("ism_pf", *SMALL, "experiment.runs.quick=2", "experiment.model.sweep.scene=[office_standin]")
    runs = [r for r in expand(cfg) if r.method in ("PF", "ISM-PF")]
    frames = []
    for label, n_jobs in (("one", 1), ("two", 2)):
        store = Store(tmp_path / label, "ism_pf")
        execute(runs, store, n_jobs=n_jobs, progress=False)
        records = store.load(runs).drop(columns=list(TIMING_COLUMNS), errors="ignore")
        frames.append(records.sort_values("run_id").reset_index(drop=True))
    assert len(frames[0]) == 4
    assert frames[0].drop(columns=["per_frame"]).equals(frames[1].drop(columns=["per_frame"]))
    assert [p["box"] for p in frames[0]["per_frame"]] == [p["box"] for p in frames[1]["per_frame"]]
