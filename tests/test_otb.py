"""The OTB loader on the shared sequences and on hand-made files with every separator."""

import numpy as np
import pytest

from replication.paths import resolve
from replication.scenes import OTBSequence, find_otb
from replication.scenes.otb import OTB_ROOT, read_groundtruth

HAVE_OTB = (resolve(OTB_ROOT) / "Girl" / "groundtruth_rect.txt").exists()


@pytest.mark.parametrize(
    "text", ["1,2,3,4\n5,6,7,8\n", "1\t2\t3\t4\r\n5\t6\t7\t8\r\n", "1 2 3 4\n5  6 7 8", "1, 2, 3, 4\n5,6,7,8\n\n"]
)
def test_groundtruth_separators_and_one_based_coordinates(tmp_path, text):
    path = tmp_path / "groundtruth_rect.txt"
    path.write_text(text)
    np.testing.assert_array_equal(read_groundtruth(path), [[0, 1, 3, 4], [4, 5, 7, 8]])


def test_absent_sequences_are_reported_not_raised(tmp_path):
    present, missing = find_otb(["Matrix", "Liquor"], root=str(tmp_path))
    assert present == [] and len(missing) == 2 and "'Matrix' is not in" in missing[0]


@pytest.mark.skipif(not HAVE_OTB, reason="../shared/data/otb is not beside the project")
def test_real_sequences_load_with_the_published_initial_boxes():
    girl = OTBSequence("Girl")
    assert girl.n_frames == 500 and girl.size == (128, 96)
    np.testing.assert_array_equal(girl.truth[0, 0], [56, 20, 31, 45])  # OTB init rect 57,21,31,45
    assert girl.frame(0).shape == (96, 128, 3)
    jogging = OTBSequence("Jogging-2")
    np.testing.assert_array_equal(jogging.truth[0, 0], [179, 78, 37, 114])
    suv = OTBSequence("Suv", last=3)
    assert suv.n_frames == 3 and suv.frame(0).ndim == 3 and suv.frame(0).shape[2] == 3  # grey JPEG as BGR
    first, _ = find_otb(["Girl", "CarScale", "Matrix"])
    assert first == ["Girl", "CarScale"]


@pytest.mark.skipif(not HAVE_OTB, reason="../shared/data/otb is not beside the project")
@pytest.mark.parametrize(
    ("name", "frames"),
    # OTB-100's frame counts for the hspf sequences that are here (Girl: the extension)
    [("Skating1", 400), ("Jogging-2", 307), ("David3", 252), ("CarScale", 252), ("Suv", 945), ("Girl", 500)],
)
def test_each_hspf_sequence_has_one_box_per_frame(name, frames):
    sequence = OTBSequence(name)
    assert sequence.n_frames == frames and sequence.truth.shape == (frames, 1, 4)
    assert (sequence.truth[..., 2:] > 0).all()  # every frame has a real box
    last = sequence.frame(frames - 1)
    assert last.shape[:2] == (sequence.size[1], sequence.size[0])
