"""Figures of multi-target runs on MOTChallenge sequences: snapshot grids, identity timelines, an animation.

A run's record holds ``tracks``, the tracker's output as [frame, id, x, y, w, h] rows
(MOT frame numbers from 1, 0-based top-left boxes, ids from 1), and ``first_frame``
and ``last_frame``, the MOT frames it covered (inclusive); its condition names the
scene, ``scene=<key>``, and the experiment's ``scenes[<key>]`` is ``{kind: mot, name:
PETS09-S2L1, root: ...}`` (``root`` defaults to :data:`replication.scenes.mot.MOT_ROOT`).  The sequence, a
run's tracks as rows and their CLEAR MOT matches come from the
:class:`~replication.evidence.footage.Footage` the page is given (computed below the report).

Every figure draws a track in the colour :func:`track_colour` gives its id, the same
on every panel and figure; ground truth is a thin white outline, ignore regions a
dashed grey one.
"""

import textwrap
from typing import Any
from pathlib import Path

import cv2
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from matplotlib import patheffects
from matplotlib.colors import to_rgb
from matplotlib.patches import Rectangle
from PIL import Image

from replication import atomic
from replication.condition import PREFIX, values_of
from replication.display import method_label
from replication.evidence.footage import Footage
from replication.report.figures.style import save
from replication.evidence.figures import IdentityTimeline, TrackSnapshots, TrackVideo
from replication.report.figures.base import draws

# tab10 then Dark2, both without their grey (kept for the ignore regions) and without light tints (which
# would read as the white truth): 16 saturated colours, consecutive ids (mostly alive at the same time)
# in different hues
ID_COLOURS = tuple(c for name in ("tab10", "Dark2") for c in plt.get_cmap(name).colors
                   if not np.allclose(c, c[0], atol=0.02))
TRUTH, IGNORED = "white", "#b0b0b0"
BOX = ["x", "y", "w", "h"]  # a box's columns in the truth, ignore and track tables (0-based top-left, size)
OUTLINE = [patheffects.withStroke(linewidth=1.6, foreground="black")]  # an id's number, readable on any image


def track_colour(track_id: int) -> tuple[float, float, float]:
    """The colour of track ``track_id`` (RGB in 0..1) on every figure: it depends on the id alone."""
    return ID_COLOURS[(int(track_id) - 1) % len(ID_COLOURS)]


def scene_key(runs: pd.DataFrame) -> str:
    """The scene (its key in the experiment's ``scenes``) of one condition's runs."""
    return values_of(runs, "scene").iloc[0]


def _first_runs(group: pd.DataFrame) -> pd.DataFrame:
    return group.sort_values("repetition").groupby("method", sort=False).head(1)


def _between(table: pd.DataFrame, first: int, last: int) -> pd.DataFrame:
    return table[table["frame"].between(first, last)]


def _at(table: pd.DataFrame, frame: int) -> pd.DataFrame:
    return table[table["frame"] == frame]


def _boxes(ax, truth: pd.DataFrame, ignored: pd.DataFrame, tracks: pd.DataFrame, fontsize: float) -> None:
    """One frame's ignore regions (dashed grey), truth (thin white) and output boxes (coloured by id,
    numbered)."""
    for boxes, colour, style, width in ((ignored, IGNORED, "--", 0.8), (truth, TRUTH, "-", 0.6)):
        for x, y, w, h in boxes[BOX].to_numpy():
            ax.add_patch(Rectangle((x - 0.5, y - 0.5), w, h, fill=False, edgecolor=colour, linestyle=style,
                                   linewidth=width))
    for track_id, x, y, w, h in tracks[["id", *BOX]].to_numpy():
        colour = track_colour(track_id)
        ax.add_patch(Rectangle((x - 0.5, y - 0.5), w, h, fill=False, edgecolor=colour, linewidth=1.4))
        ax.text(x, y - 3, f"{int(track_id)}", color=colour, fontsize=fontsize, va="bottom", clip_on=True,
                path_effects=OUTLINE)


def _panel(ax, sequence: Any, frame: int, tracks: pd.DataFrame, fontsize: float = 5.5,
           window: tuple[float, float, float, float] | None = None) -> None:
    """Frame ``frame`` of ``sequence`` with its boxes, the frame number as title; ``window`` (x0, y0, x1,
    y1 px) shows part of it."""
    ax.imshow(cv2.cvtColor(sequence.image(frame), cv2.COLOR_BGR2RGB))
    _boxes(ax, _at(sequence.truth, frame), _at(sequence.ignored, frame), _at(tracks, frame), fontsize)
    x0, y0, x1, y1 = window or (0, 0, *sequence.size)
    ax.set_xlim(x0 - 0.5, x1 - 0.5)
    ax.set_ylim(y1 - 0.5, y0 - 0.5)
    ax.set_xticks([])
    ax.set_yticks([])
    ax.set_title(f"frame {frame}", fontsize=7, pad=2)


def _window(spec: TrackSnapshots, sequence: Any, frames: list[int], tables: list[pd.DataFrame],
            margin: float = 40) -> tuple[float, float, float, float]:
    """The part of a scene's frames the snapshots show: the boxes of ``tables`` in ``frames`` with a
    ``margin`` (px) around them, or the whole frame with ``crop: false``."""
    width, height = sequence.size
    boxes = pd.concat([table[table["frame"].isin(frames)] for table in tables])[BOX].to_numpy(float)
    if spec.crop is False or not len(boxes):
        return 0, 0, width, height
    x0, y0 = np.maximum(boxes[:, :2].min(axis=0) - margin, 0)
    x1, y1 = np.minimum((boxes[:, :2] + boxes[:, 2:]).max(axis=0) + margin, (width, height))
    return float(x0), float(y0), float(x1), float(y1)


def _snapshot_frames(spec: TrackSnapshots, scene: str, run: pd.Series, n_frames: int) -> list[int]:
    """The frames of a scene's snapshots: ``spec.frames`` (a list, or a list per scene key), else
    ``spec.columns`` (4) frames evenly spaced over the run's."""
    frames = spec.frames
    if isinstance(frames, dict):
        frames = frames.get(scene)
    if frames is None:
        first, last = int(run["first_frame"]), int(run["last_frame"])
        frames = np.unique(np.linspace(first, last, spec.columns).round().astype(int))
    return [int(k) for k in frames if 1 <= k <= n_frames]


CAPTION = ("Coloured boxes: the tracker's output, one colour per track id (its number above the box); "
           "white: ground truth; dashed grey: regions MOTChallenge ignores.")


@draws(TrackSnapshots)
def track_snapshots(records: pd.DataFrame, spec: TrackSnapshots, experiment: dict, path: Path,
                    footage: Footage) -> Path:
    """Frames of the real video with each method's output (its first run), one row per method and condition,
    one column per frame of ``spec.frames`` (``{<scene key>: [MOT frame numbers]}`` or one list for every
    scene; by default ``spec.columns``, 4, frames evenly spaced over the run).  The panels show the part of
    the frames where the boxes are (the whole frame with ``crop: false``)."""
    rows = []
    several = records["condition"].nunique() > 1
    for _, group in records.groupby("condition", sort=False):
        scene = scene_key(group)
        sequence = footage.mot_sequence(experiment, scene)
        runs = [run for _, run in _first_runs(group).iterrows()]
        frames = _snapshot_frames(spec, scene, runs[0], sequence.n_frames)
        tracks = [footage.tracks(run) for run in runs]
        window = _window(spec, sequence, frames, [sequence.truth, sequence.ignored, *tracks])
        for run, table in zip(runs, tracks):
            label = textwrap.fill(method_label(experiment, run["method"]), 24)
            label += f"\n{scene}" if several else ""
            rows.append((sequence, frames, table, label, window))
    n_cols = max(len(row[1]) for row in rows)
    heights = [2.5 * (y1 - y0) / (x1 - x0) + 0.3 for *_, (x0, y0, x1, y1) in rows]
    fig, axes = plt.subplots(len(rows), n_cols, squeeze=False, height_ratios=heights,
                             figsize=(2.5 * n_cols, sum(heights)))
    for ax in axes.ravel():
        ax.axis("off")
    for axes_row, (sequence, frames, tracks, label, window) in zip(axes, rows):
        for ax, frame in zip(axes_row, frames):
            ax.axis("on")
            _panel(ax, sequence, frame, tracks, window=window)
        axes_row[0].set_ylabel(label, fontsize=7)
    fig.text(0.01, 0, CAPTION, fontsize=7, va="top", wrap=True)
    return save(fig, path, dpi=120)


def _segments(frames: np.ndarray, values: np.ndarray) -> list[tuple[int, int, int]]:
    """Runs of consecutive frames with the same value: (first frame, number of frames, value)."""
    if not len(frames):
        return []
    breaks = np.flatnonzero((np.diff(frames) != 1) | (np.diff(values) != 0)) + 1
    starts, ends = np.r_[0, breaks], np.r_[breaks, len(frames)]
    return [(int(frames[s]), int(e - s), int(values[s])) for s, e in zip(starts, ends)]


def _on(colour) -> str:
    """Black or white, whichever reads better on ``colour``."""
    r, g, b = to_rgb(colour)
    return "black" if 0.299 * r + 0.587 * g + 0.114 * b > 0.5 else "white"


def timeline_matches(sequence: Any, run, footage: Footage) -> tuple[pd.DataFrame, pd.DataFrame]:
    """The truth of a run's frames and the CLEAR MOT matches of its tracks (as the metrics count them:
    :meth:`~replication.evidence.footage.Footage.matches`)."""
    first, last = int(run["first_frame"]), int(run["last_frame"])
    truth = _between(sequence.truth, first, last)
    tracks, ignored = _between(footage.tracks(run), first, last), _between(sequence.ignored, first, last)
    return truth, footage.matches(truth, tracks, ignored)


@draws(IdentityTimeline)
def identity_timeline(records: pd.DataFrame, spec: IdentityTimeline, experiment: dict, path: Path,
                      footage: Footage) -> Path:
    """Which output track held which person, frame by frame: one panel per method (its first run) and
    condition, one lane per ground-truth id, a bar in the matched track's colour (its id written in it)
    where CLEAR MOT matches them (IoU >= 0.5, a match kept while it holds), a grey line where the person
    is in the ground truth but unmatched, a black tick at each identity switch."""
    panels = []
    for _, group in records.groupby("condition", sort=False):
        scene = scene_key(group)
        sequence = footage.mot_sequence(experiment, scene)
        for _, run in _first_runs(group).iterrows():
            panels.append((scene, run, *timeline_matches(sequence, run, footage)))
    lanes = [max(truth["id"].nunique(), 1) for _, _, truth, _ in panels]
    fig, axes = plt.subplots(len(panels), 1, squeeze=False, height_ratios=lanes,
                             figsize=(10, 0.8 * len(panels) + 0.2 * sum(lanes)))
    for ax, (scene, run, truth, matches) in zip(axes[:, 0], panels):
        first, last = int(run["first_frame"]), int(run["last_frame"])
        ids = np.sort(truth["id"].unique())
        lane = {truth_id: k for k, truth_id in enumerate(ids)}
        for truth_id, rows in truth.groupby("id"):
            for start, length, _ in _segments(rows["frame"].to_numpy(), np.zeros(len(rows))):
                ax.broken_barh([(start - 0.5, length)], (lane[truth_id] - 0.06, 0.12), color="#c8c8c8", lw=0)
        for truth_id, rows in matches.groupby("truth_id"):
            y = lane[truth_id]
            for start, length, hyp in _segments(rows["frame"].to_numpy(), rows["hypothesis_id"].to_numpy()):
                colour = track_colour(hyp)
                ax.broken_barh([(start - 0.5, length)], (y - 0.38, 0.76), color=colour, lw=0)
                if length >= (last - first + 1) / 45:
                    ax.text(start - 0.5 + length / 2, y, str(hyp), ha="center", va="center", fontsize=5.5,
                            color=_on(colour))
        switches = matches[matches["switch"]]
        ax.vlines(switches["frame"] - 0.5, switches["truth_id"].map(lane) - 0.48,
                  switches["truth_id"].map(lane) + 0.48, color="black", lw=1.2)
        ax.set_yticks(range(len(ids)), [str(i) for i in ids], fontsize=6)
        ax.set_ylim(len(ids) - 0.5, -0.5)
        ax.set_xlim(first - 0.5, last + 0.5)
        ax.set_ylabel("ground-truth id", fontsize=8)
        ax.tick_params(axis="x", labelsize=7)
        ax.grid(True, axis="x", alpha=0.3)
        covered = len(matches) / len(truth) if len(truth) else float("nan")
        ax.set_title(f"{method_label(experiment, run['method'])}, {scene} (run "
                     f"{run['repetition']}): {covered:.0%} of truth boxes matched, {len(switches)} identity "
                     f"switches", fontsize=8)
    axes[-1, 0].set_xlabel("frame")
    fig.text(0.01, 0, "Bar: the person (lane) is matched to the output track of that colour, its id written "
             "in the bar when there is room; grey line: in the ground truth but unmatched; "
             "black tick: identity switch.", fontsize=7, va="top", wrap=True)
    return save(fig, path, dpi=130)


def _video_run(records: pd.DataFrame, spec: TrackVideo) -> pd.Series:
    """The first run of ``spec.method`` (default: the first method) in ``spec.scene``'s condition (default:
    the first condition the method has)."""
    method = spec.method or records["method"].iloc[0]
    runs = records[records["method"] == method]
    if spec.scene is not None:
        runs = runs[values_of(runs, "scene") == spec.scene]
    if runs.empty:
        raise ValueError(f"track_video: no run of method {method!r}" + (f" on scene {spec.scene!r}"
                                                                        if spec.scene is not None else ""))
    runs = runs[runs["condition"] == runs["condition"].iloc[0]]
    return runs.sort_values("repetition").iloc[0]


def _bgr(colour) -> tuple[int, int, int]:
    return tuple(round(255 * c) for c in to_rgb(colour)[::-1])


def video_frame(sequence: Any, frame: int, tracks: pd.DataFrame, width: int) -> np.ndarray:
    """Frame ``frame`` scaled to ``width`` px with its ignore regions (grey), truth (white) and output boxes
    (coloured by id, numbered), as RGB."""
    scale = width / sequence.size[0]
    image = cv2.resize(sequence.image(frame), None, fx=scale, fy=scale, interpolation=cv2.INTER_AREA)

    def corners(x, y, w, h):
        return (round(x * scale), round(y * scale)), (round((x + w) * scale), round((y + h) * scale))

    for boxes, colour in ((sequence.ignored, IGNORED), (sequence.truth, TRUTH)):
        for box in _at(boxes, frame)[BOX].to_numpy():
            cv2.rectangle(image, *corners(*box), _bgr(colour), 1)
    font = cv2.FONT_HERSHEY_SIMPLEX
    for track_id, *box in _at(tracks, frame)[["id", *BOX]].to_numpy():
        colour = track_colour(track_id)
        (left, top), bottom_right = corners(*box)
        cv2.rectangle(image, (left, top), bottom_right, _bgr(colour), 2)
        text = str(int(track_id))
        (w, h), _ = cv2.getTextSize(text, font, 0.35, 1)
        cv2.rectangle(image, (left - 1, top - h - 4), (left + w + 1, top), _bgr(colour), -1)
        cv2.putText(image, text, (left, top - 2), font, 0.35, _bgr(_on(colour)), 1, cv2.LINE_AA)
    label = f"frame {frame}"
    (w, h), _ = cv2.getTextSize(label, font, 0.4, 1)
    cv2.rectangle(image, (0, 0), (w + 6, h + 8), (0, 0, 0), -1)
    cv2.putText(image, label, (3, h + 4), font, 0.4, (255, 255, 255), 1, cv2.LINE_AA)
    return cv2.cvtColor(image, cv2.COLOR_BGR2RGB)


def write_gif(frames: list[np.ndarray], path: Path, fps: float, still: int = 14) -> Path:
    """An endlessly looping GIF of RGB ``frames``, small enough for a web page.

    All frames share one palette, undithered: the colours of the first, middle and last frames and
    every track colour.  A pixel that changed by less than ``still`` grey levels since the frame shown
    before keeps its colour (a static camera's sensor noise is not redrawn), so that Pillow writes it as
    transparent ("as before"), which costs almost nothing; the palette's last index is left unused for
    that.
    """
    fixed = [round(255 * c) for colour in (*ID_COLOURS, TRUTH, IGNORED, "black") for c in to_rgb(colour)]
    n_free = 255 - len(fixed) // 3
    sample = np.vstack([frames[0], frames[len(frames) // 2], frames[-1]])
    background = Image.fromarray(sample).quantize(colors=n_free, method=Image.Quantize.MEDIANCUT)
    palette = (background.getpalette() + [0] * 768)[: 3 * n_free] + fixed
    black = len(palette) // 3 - 1
    reference = Image.new("P", (1, 1))
    reference.putpalette(palette)
    images, shown = [], None
    for frame in frames:
        if shown is not None:
            same = (np.abs(frame.astype(np.int16) - shown).max(axis=2) < still)[..., None]
            frame = np.where(same, shown, frame).astype(np.uint8)
        index = np.asarray(Image.fromarray(frame).quantize(palette=reference, dither=Image.Dither.NONE))
        index = np.where(index == 255, black, index).astype(np.uint8)  # the padding is black too: take ours
        images.append(Image.fromarray(index, "P"))
        images[-1].putpalette(palette)
        shown = np.asarray(images[-1].convert("RGB")).astype(np.int16)
    atomic.save(path, lambda tmp: images[0].save(tmp, "GIF", save_all=True, append_images=images[1:], loop=0,
                                                 duration=round(1000 / fps), optimize=True, disposal=1))
    return path


@draws(TrackVideo)
def track_video(records: pd.DataFrame, spec: TrackVideo, experiment: dict, path: Path, footage: Footage) -> Path:
    """An animated GIF of one run, and a PNG poster as the figure: its first frame with an output box.

    The run is the first of ``spec.method`` (default: the first method) on ``spec.scene`` (a scene key;
    default: the method's first condition), over the MOT frames ``spec.frames: [first, last]`` (default:
    the run's first 100); frames ``spec.width`` (384) px wide at ``spec.fps`` (the sequence's frame rate).
    The GIF is written beside the PNG as ``spec.link`` (default: the PNG's name with ``.gif``): declare
    ``link: <name>.gif`` in the figure's spec for the report page to link it.
    """
    run = _video_run(records, spec)
    sequence = footage.mot_sequence(experiment, run[f"{PREFIX}scene"])
    first, last = spec.frames or (int(run["first_frame"]), int(run["first_frame"]) + 99)
    first = max(int(first), int(run["first_frame"]), 1)
    last = min(int(last), int(run["last_frame"]), sequence.n_frames)
    tracks = footage.tracks(run)
    animation = path.parent / (spec.link or path.with_suffix(".gif").name)
    frames = [video_frame(sequence, k, tracks, spec.width) for k in range(first, last + 1)]
    write_gif(frames, animation, sequence.frame_rate if spec.fps is None else spec.fps)
    width, height = sequence.size
    shown = _between(tracks, first, last)["frame"]
    poster = int(shown.min()) if len(shown) else first
    fig, ax = plt.subplots(figsize=(6.4, 6.4 * height / width + 0.4))
    _panel(ax, sequence, poster, tracks, fontsize=7)
    ax.set_title(f"{method_label(experiment, run['method'])} on {sequence.name} (run {run['repetition']}), "
                 f"frame {poster}; the animation shows frames {first}-{last}", fontsize=8)
    fig.text(0.01, 0, CAPTION, fontsize=7, va="top", wrap=True)
    return save(fig, path, dpi=130)
