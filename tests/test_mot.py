"""The MOT loader on the shared MOTChallenge sequences and on hand-made folders."""

import csv

import cv2
import numpy as np
import pytest
from mot_cases import needs_mot

from replication.paths import resolve
from replication.scenes import load_mot
from replication.scenes.base import SequenceMissing
from replication.scenes.mot import MOT_ROOT


def write_sequence(root, gt="1,1,1,1,10,20,1,-1,-1,-1\n", det="1,-1,1,1,10,20,0.5,-1,-1,-1\n", n_frames=2):
    folder = root / "Tiny"
    (folder / "img1").mkdir(parents=True)
    (folder / "gt").mkdir()
    (folder / "det").mkdir()
    (folder / "seqinfo.ini").write_text(
        f"[Sequence]\nname=Tiny\nimDir=img1\nframeRate=5\nseqLength={n_frames}\nimWidth=32\nimHeight=24\nimExt=.jpg\n"
    )
    for k in range(1, n_frames + 1):
        cv2.imwrite(str(folder / "img1" / f"{k:06d}.jpg"), np.zeros((24, 32, 3), np.uint8))
    (folder / "gt" / "gt.txt").write_text(gt)
    (folder / "det" / "det.txt").write_text(det)
    return str(root)


def test_one_based_top_left_becomes_zero_based_and_flag_zero_is_ignored(tmp_path):
    root = write_sequence(tmp_path, gt="1,1,1,1,10,20,1,-1,-1,-1\n2,7,5,6,3,4,0,-1,-1,-1\n")
    tiny = load_mot("Tiny", root)
    assert (tiny.name, tiny.frame_rate, tiny.size, tiny.n_frames) == ("Tiny", 5.0, (32, 24), 2)
    assert tiny.truth[["frame", "id", "x", "y", "w", "h"]].values.tolist() == [[1, 1, 0, 0, 10, 20]]
    assert tiny.ignored[["frame", "id", "x", "y", "w", "h"]].values.tolist() == [[2, 7, 4, 5, 3, 4]]
    assert tiny.detections.values.tolist() == [[1, 0, 0, 10, 20, 0.5]]
    assert tiny.image(2).shape == (24, 32, 3)
    with pytest.raises(IndexError):
        tiny.image(0)


@pytest.mark.parametrize(
    ("line", "problem"),
    [
        ("1,2,3,4,5,6", "at least 7"),
        ("1,2,x,4,5,6,1", "at least 7"),
        ("3,2,3,4,5,6,1", "frame 3 is not an integer in 1..2"),
        ("1,2,3,4,0,6,1", "width and height"),
        ("1,2,3,4,5,6,2", "flag of 0 or 1"),
    ],
)
def test_a_malformed_ground_truth_line_is_named(tmp_path, line, problem):
    root = write_sequence(tmp_path, gt=f"1,1,1,1,10,20,1,-1,-1,-1\n{line}\n")
    with pytest.raises(ValueError, match=rf"gt[/\\]gt\.txt:2: .*{problem}") as error:
        load_mot("Tiny", root)
    assert "\n" not in str(error.value)


def test_missing_frames_or_bad_seqinfo_are_errors_not_skips(tmp_path):
    root = write_sequence(tmp_path)
    (tmp_path / "Tiny" / "img1" / "000002.jpg").unlink()
    with pytest.raises(ValueError, match="000001.jpg..000002.jpg"):
        load_mot("Tiny", root)
    (tmp_path / "Tiny" / "seqinfo.ini").write_text("[Sequence]\nseqLength=two\n")
    with pytest.raises(ValueError, match="seqinfo.ini: not a MOT seqinfo.ini"):
        load_mot("Tiny", root)


def test_an_absent_sequence_or_file_raises_the_skip_exception(tmp_path):
    with pytest.raises(SequenceMissing, match="'MOT17-02' is not in"):
        load_mot("MOT17-02", str(tmp_path))
    root = write_sequence(tmp_path)
    (tmp_path / "Tiny" / "det" / "det.txt").unlink()
    with pytest.raises(SequenceMissing, match="no det/det.txt"):
        load_mot("Tiny", root)


def csv_counts(name):
    """Rows, distinct ids and flag-0 rows of gt.txt, and det rows per frame, read with plain csv."""
    folder = resolve(MOT_ROOT) / name
    with open(folder / "gt" / "gt.txt", newline="") as handle:
        gt = list(csv.reader(handle))
    with open(folder / "det" / "det.txt", newline="") as handle:
        det_frames = [int(row[0]) for row in csv.reader(handle)]
    return len(gt), len({row[1] for row in gt}), sum(row[6] == "0" for row in gt), det_frames


@needs_mot
@pytest.mark.parametrize(
    ("name", "frames", "size", "fps", "ids", "boxes", "ignored"),
    # SOURCES.md's table; the 174 ignore rows are PETS's people behind the signpost or at the border
    [
        ("PETS09-S2L1", 795, (768, 576), 7, 19, 4650, 174),
        ("TUD-Campus", 71, (640, 480), 25, 8, 359, 0),
        ("TUD-Stadtmitte", 179, (640, 480), 25, 10, 1156, 0),
    ],
)
def test_real_sequences_have_the_published_counts(name, frames, size, fps, ids, boxes, ignored):
    sequence = load_mot(name)
    assert (sequence.n_frames, sequence.size, sequence.frame_rate) == (frames, size, fps)
    both = len(sequence.truth) + len(sequence.ignored)
    all_ids = set(sequence.truth.id) | set(sequence.ignored.id)
    assert (len(all_ids), both, len(sequence.ignored)) == (ids, boxes, ignored)
    rows, csv_ids, flag_zero, det_frames = csv_counts(name)
    assert (rows, csv_ids, flag_zero) == (boxes, ids, ignored)
    assert len(sequence.detections) == len(det_frames)
    assert sequence.truth.frame.between(1, frames).all() and sequence.truth.frame.nunique() == frames
    first = sequence.image(1)
    assert first.shape == (size[1], size[0], 3) and first.dtype == np.uint8


@needs_mot
def test_pets_boxes_and_detections_per_frame():
    pets = load_mot("PETS09-S2L1")
    assert (
        set(pets.ignored.id) <= set(pets.truth.id) and pets.truth.id.nunique() == 19
    )  # every person is a target somewhere
    first = pets.truth[(pets.truth.frame == 1) & (pets.truth.id == 9)]
    np.testing.assert_allclose(first[["x", "y", "w", "h"]].values, [[498, 157, 31.03, 75.17]])  # gt: 499,158
    per_frame = pets.detections.frame.value_counts()
    _, _, _, det_frames = csv_counts("PETS09-S2L1")
    assert len(det_frames) == 5578
    for frame, count in [(1, 3), (2, 4), (795, 7)]:
        assert per_frame[frame] == count == det_frames.count(frame)
    campus = load_mot("TUD-Campus")
    assert (campus.detections.frame == 1).sum() == 7 and len(campus.detections) == 322
