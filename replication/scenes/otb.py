"""Real sequences in the OTB layout: ``img/0001.jpg ...`` and ``groundtruth_rect*.txt``.

OTB boxes are 1-based (x, y, w, h); they are turned into our 0-based boxes by
subtracting 1 from x and y.  Separators vary (comma, TAB, spaces) and some files
use CRLF, so rows are split on ``[,\\s]+``.  OTB-100's attributes of the sequences
(occlusion, scale variation...) are data, ``otb_attributes.yaml``.
"""

import functools
import os
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import yaml
from PIL import Image, UnidentifiedImageError

from replication.paths import resolve
from replication.scenes.kept import decoded

SHIPPED_OTB_ROOT = "../shared/data/otb"  # where the project's own OTB sequences are, beside it
OTB_ROOT = os.environ.get("REPLICATION_OTB") or SHIPPED_OTB_ROOT  # data.otb in conf/config.yaml
# Sequences whose usual ground-truth file is not groundtruth_rect.txt (see SOURCES.md).
GROUNDTRUTH_FILES = {"Jogging-1": ("Jogging", "groundtruth_rect.1.txt"), "Jogging-2": ("Jogging", "groundtruth_rect.2.txt")}
ATTRIBUTES_FILE = Path(__file__).with_name("otb_attributes.yaml")


def read_groundtruth(path: Path) -> np.ndarray:
    """Boxes (T, 4) from an OTB ground-truth file, converted to 0-based coordinates; a row that is not four
    numbers fails naming the file and line."""
    rows = []
    for number, line in enumerate(path.read_text().splitlines(), start=1):
        if not line.strip():
            continue
        tokens = re.split(r"[,\s]+", line.strip())
        try:
            row = [float(v) for v in tokens]
        except ValueError:
            raise ValueError(f"{path}:{number}: a ground-truth box that is not four numbers: {line.strip()!r}") from None
        if len(row) != 4:
            raise ValueError(f"{path}:{number}: a ground-truth box of {len(row)} numbers, not 4: {line.strip()!r}")
        rows.append(row)
    boxes = np.array(rows, dtype=float).reshape(-1, 4)
    boxes[:, :2] -= 1.0
    return boxes


@dataclass
class OTBSequence:
    """One OTB sequence, frames read lazily; grey JPEGs are returned as 3-channel BGR."""

    name: str
    root: str = OTB_ROOT
    first: int = 0
    last: int | None = None
    stand_in: str | None = None
    _frames: list[Path] = field(init=False, repr=False)

    def __post_init__(self):
        folder, gt_name = GROUNDTRUTH_FILES.get(self.name, (self.name, "groundtruth_rect.txt"))
        directory = resolve(self.root) / folder
        truth = read_groundtruth(directory / gt_name)
        frames = sorted((directory / "img").glob("*.jpg"))
        if len(frames) != len(truth):
            raise ValueError(f"{directory}: {len(frames)} frames but {len(truth)} ground-truth boxes")
        stop = len(frames) if self.last is None else self.last
        self._frames = frames[self.first : stop]
        self.truth = truth[self.first : stop, None, :]
        check_truth(self.truth[:, 0], directory / gt_name, self.first)
        self.visibility = np.ones(self.truth.shape[:2])
        self.n_frames = len(self._frames)
        self.size = frame_size(self._frames)

    def frame(self, k: int) -> np.ndarray:
        """Frame k as read-only uint8 BGR, decoded once per process (:mod:`replication.scenes.kept`)."""
        return decoded(self._frames[k])


def check_truth(boxes: np.ndarray, path: Path, first: int) -> None:
    """Every ground-truth row finite, and the first box (the tracker's initial state) non-empty."""
    bad = np.flatnonzero(~np.isfinite(boxes).all(axis=1))
    if bad.size:
        raise ValueError(f"{path}:{first + bad[0] + 1}: a ground-truth box that is not four finite numbers")
    if boxes.size and (boxes[0, 2] <= 0 or boxes[0, 3] <= 0):
        raise ValueError(f"{path}:{first + 1}: the first box has no area (w, h = {boxes[0, 2]:g}, {boxes[0, 3]:g})")


def frame_size(frames: list[Path]) -> tuple[int, int]:
    """The (width, height) every frame shares, read from the files' headers (no decoding)."""
    if not frames:
        raise ValueError("no frames")
    size = None
    for path in frames:
        try:
            with Image.open(path) as image:
                size, seen = size or image.size, image.size
        except (OSError, UnidentifiedImageError):
            raise ValueError(f"{path}: not a readable image") from None
        if seen != size:
            raise ValueError(f"{path}: {seen[0]}x{seen[1]} pixels where the frames before it are {size[0]}x{size[1]}")
    return size


def otb_names(root: str = OTB_ROOT) -> list[str]:
    """Every sequence under ``root``: its folders holding ``img/`` and a ground truth, by name."""
    folders = {p.parent.name for p in resolve(root).glob("*/img")}
    special = {name for name, (folder, _) in GROUNDTRUTH_FILES.items() if folder in folders}
    plain = {f for f in folders if (resolve(root) / f / "groundtruth_rect.txt").exists()}
    return sorted(plain | special)


def find_otb(names: list[str], root: str = OTB_ROOT) -> tuple[list[str], list[str]]:
    """Split ``names`` into the sequences present under ``root`` and messages for the absent ones."""
    present, missing = [], []
    for name in names:
        folder, gt_name = GROUNDTRUTH_FILES.get(name, (name, "groundtruth_rect.txt"))
        directory = resolve(root) / folder
        if (directory / gt_name).exists() and (directory / "img").is_dir():
            present.append(name)
        else:
            missing.append(f"OTB sequence {name!r} is not in {directory.parent}: skipped")
    return present, missing


@functools.cache
def otb_attributes() -> tuple[dict[str, str], dict[str, list[str]]]:
    """OTB's attributes (code -> meaning, in the benchmark's order) and the codes of each sequence listed
    in ``otb_attributes.yaml``; a sequence with a code that is not an attribute is an error."""
    table = yaml.safe_load(ATTRIBUTES_FILE.read_text())
    meanings, sequences = table["attributes"], table["sequences"]
    for name, codes in sequences.items():
        unknown = sorted(set(codes) - set(meanings))
        if unknown:
            raise ValueError(f"{ATTRIBUTES_FILE.name}: {name} has unknown attributes {unknown}; known: {list(meanings)}")
    return meanings, sequences
