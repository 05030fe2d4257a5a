"""VideoSequence: a video file the test writes from OTB frames reads back as the OTB sequence does."""

import cv2
import numpy as np
import pytest

from replication.errors import ConfigError
from replication.paths import resolve
from replication.scenes import OTBSequence, VideoSequence
from replication.scenes.otb import OTB_ROOT

HAVE_OTB = (resolve(OTB_ROOT) / "Girl" / "groundtruth_rect.txt").exists()
FRAMES = 30


@pytest.fixture(scope="module")
def girl():
    return OTBSequence("Girl", last=FRAMES)


def write_video(sequence, path, codec="MJPG"):
    """``sequence``'s frames as a video at ``path`` and its ground truth beside it (OTB format, 1-based)."""
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*codec), 25.0, sequence.size)
    assert writer.isOpened()
    for k in range(sequence.n_frames):
        writer.write(sequence.frame(k))
    writer.release()
    truth = path.with_suffix(".txt")
    np.savetxt(truth, sequence.truth[:, 0] + [1, 1, 0, 0], fmt="%g", delimiter=",")
    return path, truth


def nearest_frame(image, sequence) -> int:
    """The sequence's frame closest to ``image`` (mean absolute difference): MJPG is lossy."""
    differences = [np.abs(image.astype(float) - sequence.frame(j)).mean() for j in range(sequence.n_frames)]
    return int(np.argmin(differences))


@pytest.mark.skipif(not HAVE_OTB, reason="../shared/data/otb is not beside the project")
def test_a_video_reads_back_as_its_otb_sequence_in_any_order(girl, tmp_path):
    path, truth = write_video(girl, tmp_path / "girl.avi")
    video = VideoSequence(path, groundtruth=truth)
    assert (video.name, video.n_frames, video.size) == ("girl", FRAMES, girl.size)
    np.testing.assert_array_equal(video.truth, girl.truth)  # 1-based file, 0-based boxes, as OTB
    np.testing.assert_array_equal(video.visibility, np.ones((FRAMES, 1)))
    for k in (0, 1, 2, 17, 29, 3, 3, 0):  # forward (one decode each), skipping ahead, and back (reopens)
        image = video.frame(k)
        assert image.shape == (96, 128, 3) and image.dtype == np.uint8
        assert nearest_frame(image, girl) == k
    with pytest.raises(IndexError):
        video.frame(FRAMES)

    middle = VideoSequence(path, groundtruth=truth, first=10, last=20)
    assert middle.n_frames == 10 and nearest_frame(middle.frame(0), girl) == 10
    np.testing.assert_array_equal(middle.truth, girl.truth[10:20])


@pytest.mark.skipif(not HAVE_OTB, reason="../shared/data/otb is not beside the project")
def test_a_stream_without_a_frame_count_is_counted(girl, tmp_path):
    path, _ = write_video(girl, tmp_path / "girl.mjpg")  # raw MJPEG: no container, no stated count
    assert cv2.VideoCapture(str(path)).get(cv2.CAP_PROP_FRAME_COUNT) <= 0
    video = VideoSequence(path)
    assert video.n_frames == FRAMES and video.truth.shape == (FRAMES, 0, 4)
    assert nearest_frame(video.frame(FRAMES - 1), girl) == FRAMES - 1


@pytest.mark.skipif(not HAVE_OTB, reason="../shared/data/otb is not beside the project")
def test_ground_truth_of_another_length_is_refused(girl, tmp_path):
    path, truth = write_video(girl, tmp_path / "girl.avi")
    truth.write_text("\n".join(truth.read_text().splitlines()[:-1]))
    with pytest.raises(ValueError, match=f"{FRAMES} frames but {FRAMES - 1} boxes"):
        VideoSequence(path, groundtruth=truth)


def test_an_unreadable_file_is_one_config_error(tmp_path):
    with pytest.raises(ConfigError, match="no such video file"):
        VideoSequence(tmp_path / "absent.mp4")
    text = tmp_path / "notes.avi"
    text.write_text("not a video\n")
    with pytest.raises(ConfigError) as error:
        VideoSequence(text)
    assert str(error.value) == f"{text}: OpenCV cannot read this video (not a video, or no codec for it)"
