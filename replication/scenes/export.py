"""Write a sequence to disk so a person can watch it: MP4 or an image folder, with its ground truth."""

from pathlib import Path

import cv2
import numpy as np

from replication.scenes.base import Sequence


def write_sequence(sequence: Sequence, out: Path, video: bool = True, fps: float = 25.0, boxes: bool = False) -> Path:
    """Write ``out/<name>.mp4`` (or ``out/<name>/img/0001.jpg ...``) and OTB-style ground truth.

    Ground truth goes to ``groundtruth_rect.<m>.txt`` per target (1-based x,y,w,h as OTB)
    and ``visibility.txt`` (one row per frame, one column per target).
    ``boxes=True`` draws the truth boxes into the frames.
    """
    out.mkdir(parents=True, exist_ok=True)
    folder = out / sequence.name
    folder.mkdir(exist_ok=True)
    writer = None
    if video:
        path = out / f"{sequence.name}.mp4"
        writer = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*"mp4v"), fps, sequence.size)
        if not writer.isOpened():
            raise OSError(f"OpenCV cannot write MP4 to {path}")
    else:
        path = folder / "img"
        path.mkdir(exist_ok=True)
    for k in range(sequence.n_frames):
        image = sequence.frame(k)
        if boxes:
            image = image.copy()  # a sequence's frames are read-only: the next reader sees them unmarked
            for x, y, w, h in sequence.truth[k]:
                cv2.rectangle(image, (int(x), int(y)), (int(x + w - 1), int(y + h - 1)), (0, 255, 0), 1)
        if writer is not None:
            writer.write(image)
        else:
            cv2.imwrite(str(path / f"{k + 1:04d}.jpg"), image)
    if writer is not None:
        writer.release()
    for m in range(sequence.truth.shape[1]):
        one_based = sequence.truth[:, m].copy()
        one_based[:, :2] += 1
        np.savetxt(folder / f"groundtruth_rect.{m + 1}.txt", one_based, fmt="%g", delimiter=",")
    np.savetxt(folder / "visibility.txt", sequence.visibility, fmt="%.3f", delimiter=",")
    return path
