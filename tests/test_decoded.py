"""Frames decoded once per process (replication.scenes.decoded) and the bin images kept with them."""

import cv2
import numpy as np
import pytest

from replication.scenes import decoded as module
from replication.vision.histogram import hsv_bin_image


@pytest.fixture
def frames(tmp_path, monkeypatch):
    monkeypatch.setattr(module, "_kept", type(module._kept)())
    monkeypatch.setattr(module, "_size", [0])
    rng = np.random.default_rng(0)
    paths = []
    for k in range(3):
        paths.append(tmp_path / f"{k}.png")
        cv2.imwrite(str(paths[-1]), rng.integers(0, 256, (20, 30, 3), dtype=np.uint8))
    return paths


def test_a_frame_is_decoded_once_read_only_and_as_imread_gives_it(frames):
    first = module.decoded(frames[0])
    assert module.decoded(frames[0]) is first and not first.flags.writeable
    np.testing.assert_array_equal(first, cv2.imread(str(frames[0]), cv2.IMREAD_COLOR))
    with pytest.raises(ValueError):
        first[0, 0, 0] = 1  # no run can change what the next one reads


def test_the_least_recently_read_frame_goes_first_past_the_budget(frames, monkeypatch):
    monkeypatch.setattr(module, "BUDGET_BYTES", 2 * 20 * 30 * 3)  # two frames
    a, b = module.decoded(frames[0]), module.decoded(frames[1])
    module.decoded(frames[0])  # a read again: b is now the oldest
    module.decoded(frames[2])
    assert list(module._kept) == [frames[0], frames[2]] and module._size[0] == 2 * a.nbytes
    assert module.decoded(frames[1]) is not b and np.array_equal(module.decoded(frames[1]), b)
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
