"""Frames made once per process (replication.scenes.kept): decoded or rendered, and the bin images kept with
them; a run reading kept frames gives the record it gives on frames made afresh."""

import cv2
import numpy as np
import pytest

from replication.scenes import kept as module
from replication.scenes.synthetic import SyntheticScene
from replication.vision.fusion import grey
from replication.vision.histogram import hsv_bin_image


@pytest.fixture
def frames(tmp_path, monkeypatch):
    monkeypatch.setattr(module, "_kept", {})
    rng = np.random.default_rng(0)
    paths = []
    for folder in ("one", "one", "one", "two"):
        (tmp_path / folder).mkdir(exist_ok=True)
        paths.append(tmp_path / folder / f"{len(paths)}.png")
        cv2.imwrite(str(paths[-1]), rng.integers(0, 256, (20, 30, 3), dtype=np.uint8))
    return paths


def test_a_frame_is_decoded_once_read_only_and_as_imread_gives_it(frames):
    first = module.decoded(frames[0])
    assert module.decoded(frames[0]) is first and not first.flags.writeable
    np.testing.assert_array_equal(first, cv2.imread(str(frames[0]), cv2.IMREAD_COLOR))
    with pytest.raises(ValueError):
        first[0, 0, 0] = 1  # no run can change what the next one reads


def test_one_sequence_is_kept_up_to_the_budget_and_another_drops_it(frames, monkeypatch):
    monkeypatch.setattr(module, "BUDGET_BYTES", 2 * 20 * 30 * 3)  # two frames
    a, b, c = (module.decoded(path) for path in frames[:3])
    assert list(module._kept) == [(path.parent, path) for path in frames[:2]]  # the third is past the budget
    assert module.decoded(frames[0]) is a and module.decoded(frames[2]) is not c
    np.testing.assert_array_equal(module.decoded(frames[2]), c)
    module.decoded(frames[3])  # another folder: the first sequence's frames go
    assert list(module._kept) == [(frames[3].parent, frames[3])]
    assert module.decoded(frames[0]) is not a and np.array_equal(module.decoded(frames[0]), a)
    with pytest.raises(OSError, match="cannot read"):
        module.decoded(frames[0].with_name("absent.png"))


def test_a_kept_frames_bin_and_grey_images_are_computed_once_and_equal_fresh_ones(frames):
    frame = module.decoded(frames[0])
    fresh = hsv_bin_image(frame.copy(), (8, 8, 4))  # a writeable frame: computed every time
    kept = hsv_bin_image(frame, (8, 8, 4))
    assert hsv_bin_image(frame, (8, 8, 4)) is kept and not kept.flags.writeable
    np.testing.assert_array_equal(kept, fresh)
    np.testing.assert_array_equal(hsv_bin_image(frame, (4, 4, 4)), hsv_bin_image(frame.copy(), (4, 4, 4)))
    assert hsv_bin_image(frame.copy(), (8, 8, 4)) is not hsv_bin_image(frame.copy(), (8, 8, 4))
    levels = grey(frame)  # fusion_pf's structure term reads it
    assert grey(frame) is levels and not levels.flags.writeable
    np.testing.assert_array_equal(levels, cv2.cvtColor(frame, cv2.COLOR_BGR2GRAY))


def test_a_scene_renders_each_frame_once_read_only_and_another_scene_drops_them(monkeypatch):
    monkeypatch.setattr(module, "_kept", {})
    spec = {"size": [40, 30], "frames": 3, "seed": 1, "camera_noise": 2.0,
            "targets": [{"shape": "ball", "size": [8, 8], "colour": [40, 200, 220],
                         "motion": {"kind": "random_walk", "noise_var": 0.4}}]}
    scene, again = SyntheticScene(spec), SyntheticScene(spec)
    first = scene.frame(1)
    assert scene.frame(1) is first and not first.flags.writeable
    assert first.tobytes() == scene.render(1).tobytes() == again.frame(1).tobytes()  # the same video, made anew
    assert list(module._kept) == [(again, 1)]  # another scene object: its own frames, the first's dropped
    with pytest.raises(IndexError):
        scene.frame(3)


@pytest.mark.parametrize("experiment, methods, overrides", [
    ("bis_pf", ("MIPF", "BIS-PF"), ["experiment.model.sweep.scene=[exp2_16_targets]", "experiment.scenes.exp2_16_targets.frames=6"]),
    ("fusion_pf", ("color-only PF", "color+structure fusion PF"), ["experiment.model.sweep.scene=[elk]", "experiment.scenes.elk.frames=8"]),
])
def test_runs_reading_kept_frames_give_the_records_of_frames_drawn_afresh(make_cfg, monkeypatch, experiment, methods,
                                                                          overrides):
    """Every method of two repetitions (bis_pf: a video drawn per repetition, fusion_pf: one video), computed
    in the runner's order reading kept frames and their kept bin images, and in another order (a repetition's
    runs apart, so the frames are dropped between them) on frames drawn afresh at every read (writeable,
    their bin images computed every time, as before frames were kept): the same records but the timings."""
    from replication.runner.config import expand
    from replication.runner.execute import TIMING_COLUMNS, _performed, schedule

    runs = schedule([run for run in expand(make_cfg(experiment, "scale=quick", "experiment.runs.quick=2", *overrides))
                     if run.method in methods])

    def numbers(record: dict) -> dict:
        return {k: v for k, v in record.items() if k not in TIMING_COLUMNS and k != "per_frame"} | {
            "per_frame": {k: v for k, v in record["per_frame"].items() if k != "seconds"}}

    monkeypatch.setattr(module, "_kept", {})
    shared = {run.run_id: numbers(_performed(run)) for run in runs}
    assert module._kept and all(not frame.flags.writeable for frame in module._kept.values())
    monkeypatch.setattr(SyntheticScene, "frame", SyntheticScene.render)
    fresh = {run.run_id: numbers(_performed(run)) for run in sorted(runs, key=lambda run: run.method)}
    assert fresh == shared
