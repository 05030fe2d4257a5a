"""Real multi-target sequences in the MOTChallenge layout (motchallenge.net; Milan et al. 2016, arXiv:1603.00831).

A sequence folder holds ``seqinfo.ini`` (frameRate, seqLength, imWidth, imHeight, imDir,
imExt), frames ``img1/000001.jpg ...`` numbered from 1, ground truth ``gt/gt.txt`` with
rows ``frame, id, x, y, w, h, flag, ...`` and public detections ``det/det.txt`` with rows
``frame, -1, x, y, w, h, score, ...``.  A ground-truth row whose flag is 0 marks a region
to ignore (neither a target nor a false positive); flag 1 is a target.

Frame numbers and ids are MOT's own (frames count from 1 to n_frames).  Boxes are
converted from MOT's 1-based pixel coordinates to the project's 0-based (x, y, w, h) of
:mod:`replication.scenes.base` by subtracting 1 from x and y, as the OTB loader does.
"""

import configparser
import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from replication.paths import resolve
from replication.scenes.base import SequenceMissing
from replication.scenes.kept import decoded

SHIPPED_MOT_ROOT = "../shared/data/mot"  # where the project's own MOTChallenge sequences are, beside it
MOT_ROOT = os.environ.get("REPLICATION_MOT") or SHIPPED_MOT_ROOT  # data.mot in conf/config.yaml
BOX = ["x", "y", "w", "h"]


@dataclass(frozen=True, eq=False)
class MotSequence:
    """One MOT sequence; frames are decoded on demand by :meth:`image`.

    ``truth`` and ``ignored`` have columns frame, id, x, y, w, h; ``detections`` has
    frame, x, y, w, h, score.  Rows are sorted by frame (then id), boxes 0-based.
    ``size`` is (width, height) as in :class:`replication.scenes.base.Sequence`.
    """

    name: str
    frame_rate: float
    size: tuple[int, int]
    n_frames: int
    truth: pd.DataFrame
    ignored: pd.DataFrame
    detections: pd.DataFrame
    image_dir: Path
    image_ext: str

    def image(self, frame: int) -> np.ndarray:
        """Frame number ``frame`` (1..n_frames, MOT's numbering) as read-only uint8 BGR, decoded once per
        process (:mod:`replication.scenes.kept`)."""
        if not 1 <= frame <= self.n_frames:
            raise IndexError(f"{self.name}: frame {frame} outside 1..{self.n_frames}")
        return decoded(self.image_dir / f"{frame:06d}{self.image_ext}")


def read_rows(path: Path, n_frames: int, ground_truth: bool) -> np.ndarray:
    """The first 7 numbers of every row of a MOT ``gt.txt`` or ``det.txt``, checked line by line.

    Raises a one-line ValueError naming the file and line for a short or non-numeric row,
    a frame outside 1..n_frames, a box without positive width and height or, in ground
    truth, an id that is not an integer or a flag other than 0 or 1.
    """
    n_columns = 7
    rows = []
    for number, line in enumerate(path.read_text().splitlines(), start=1):
        if not line.strip():
            continue
        fields = line.split(",")
        try:
            values = [float(v) for v in fields[:n_columns]]
        except ValueError:
            values = []
        if len(values) < n_columns or not all(math.isfinite(v) for v in values):
            problem = f"expected at least {n_columns} comma-separated numbers"
        elif not values[0].is_integer() or not 1 <= values[0] <= n_frames:
            problem = f"frame {values[0]:g} is not an integer in 1..{n_frames}"
        elif values[4] <= 0 or values[5] <= 0:
            problem = "box width and height must be positive"
        elif ground_truth and not (values[1].is_integer() and values[6] in (0, 1)):
            problem = "ground truth needs an integer id and a flag of 0 or 1"
        else:
            rows.append(values)
            continue
        raise ValueError(f"{path}:{number}: {problem}: {line.strip()!r}")
    return np.array(rows, dtype=float).reshape(-1, n_columns)


def _sorted(table: pd.DataFrame, by: list[str]) -> pd.DataFrame:
    return table.sort_values(by, kind="stable").reset_index(drop=True)


def read_seqinfo(path: Path) -> tuple[float, tuple[int, int], int, str, str]:
    """frameRate, (imWidth, imHeight), seqLength, imDir and imExt of a ``seqinfo.ini``."""
    parser = configparser.ConfigParser()
    try:
        parser.read_string(path.read_text(), source=str(path))
        info = parser["Sequence"]
        size = (int(info["imWidth"]), int(info["imHeight"]))
        return (
            float(info["frameRate"]),
            size,
            int(info["seqLength"]),
            info.get("imDir", "img1"),
            info.get("imExt", ".jpg"),
        )
    except (configparser.Error, KeyError, ValueError) as error:
        message = f"{path}: not a MOT seqinfo.ini ({type(error).__name__}: {error})"
        raise ValueError(" ".join(message.split())) from None


def mot_names(root: str = MOT_ROOT) -> list[str]:
    """Every sequence under ``root``: its folders holding a ``seqinfo.ini``, by name."""
    return sorted(p.parent.name for p in resolve(root).glob("*/seqinfo.ini"))


def find_mot(names: list[str], root: str = MOT_ROOT) -> tuple[list[str], list[str]]:
    """Split ``names`` into the sequences present under ``root`` and messages for the absent ones."""
    present = set(mot_names(root))
    return ([n for n in names if n in present],
            [f"MOT sequence {n!r} is not in {resolve(root)}: skipped" for n in names if n not in present])


def load_mot(name: str, root: str = MOT_ROOT) -> MotSequence:
    """Sequence ``name`` under ``root``; :class:`SequenceMissing` if it or one of its files is absent."""
    directory = resolve(root) / name
    if not directory.is_dir():
        raise SequenceMissing(f"MOT sequence {name!r} is not in {directory.parent}: skipped")
    for part in ("seqinfo.ini", "gt/gt.txt", "det/det.txt"):
        if not (directory / part).is_file():
            raise SequenceMissing(f"MOT sequence {name!r} has no {part} in {directory}: skipped")
    frame_rate, size, n_frames, image_folder, image_ext = read_seqinfo(directory / "seqinfo.ini")
    image_dir = directory / image_folder
    expected = [f"{k:06d}{image_ext}" for k in range(1, n_frames + 1)]
    if sorted(p.name for p in image_dir.glob(f"*{image_ext}")) != expected:
        raise ValueError(
            f"{image_dir}: frames are not exactly {expected[0]}..{expected[-1]} (seqLength {n_frames})"
        )

    gt = read_rows(directory / "gt" / "gt.txt", n_frames, ground_truth=True)
    gt[:, 2:4] -= 1.0
    truth = pd.DataFrame(gt[:, :6], columns=["frame", "id", *BOX]).astype({"frame": int, "id": int})
    det = read_rows(directory / "det" / "det.txt", n_frames, ground_truth=False)
    det[:, 2:4] -= 1.0
    detections = pd.DataFrame(det[:, [0, 2, 3, 4, 5, 6]], columns=["frame", *BOX, "score"]).astype(
        {"frame": int}
    )
    return MotSequence(
        name=name,
        frame_rate=frame_rate,
        size=size,
        n_frames=n_frames,
        truth=_sorted(truth[gt[:, 6] == 1], ["frame", "id"]),
        ignored=_sorted(truth[gt[:, 6] == 0], ["frame", "id"]),
        detections=_sorted(detections, ["frame"]),
        image_dir=image_dir,
        image_ext=image_ext,
    )
