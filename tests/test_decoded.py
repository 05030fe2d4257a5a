"""Frames decoded once per process (replication.scenes.decoded) and the bin images kept with them."""

import cv2
import numpy as np
import pytest

from replication.scenes import decoded as module
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
    assert list(module._kept) == frames[:2]  # the third is past the budget
    assert module.decoded(frames[0]) is a and module.decoded(frames[2]) is not c
    np.testing.assert_array_equal(module.decoded(frames[2]), c)
    module.decoded(frames[3])  # another folder: the first sequence's frames go
    assert list(module._kept) == [frames[3]]
    assert module.decoded(frames[0]) is not a and np.array_equal(module.decoded(frames[0]), a)
    with pytest.raises(OSError, match="cannot read"):
        module.decoded(frames[0].with_name("absent.png"))


def test_a_kept_frames_bin_image_is_computed_once_per_bins_and_equals_a_fresh_one(frames):
    frame = module.decoded(frames[0])
    fresh = hsv_bin_image(frame.copy(), (8, 8, 4))  # a writeable frame: computed every time
    kept = hsv_bin_image(frame, (8, 8, 4))
    assert hsv_bin_image(frame, (8, 8, 4)) is kept and not kept.flags.writeable
    np.testing.assert_array_equal(kept, fresh)
    np.testing.assert_array_equal(hsv_bin_image(frame, (4, 4, 4)), hsv_bin_image(frame.copy(), (4, 4, 4)))
    assert hsv_bin_image(frame.copy(), (8, 8, 4)) is not hsv_bin_image(frame.copy(), (8, 8, 4))
