"""Figures of tracking runs: per-frame curves, tracks against the truth, snapshot grids."""

from pathlib import Path

import cv2
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from replication.scenes.factory import cached_sequence


def _by_condition(records: pd.DataFrame):
    return list(records.groupby("condition", sort=False))


def _label(experiment: dict, method: str) -> str:
    return experiment["methods"][method].get("label", method)


def per_frame_curve(records: pd.DataFrame, spec: dict, experiment: dict, path: Path) -> Path:
    """Mean and 10-90% band over runs of a per-frame series (``spec.series``), one panel per condition."""
    groups = _by_condition(records)
    fig, axes = plt.subplots(len(groups), 1, figsize=(7, 2.6 * len(groups)), squeeze=False)
    for ax, (condition, group) in zip(axes[:, 0], groups):
        for method, runs in group.groupby("method", sort=False):
            series = np.array([r[spec["series"]] for r in runs["per_frame"]], dtype=float)
            frames = np.arange(1, series.shape[1] + 1)
            ax.plot(frames, np.nanmean(series, axis=0), label=_label(experiment, method))
            low, high = np.nanpercentile(series, [10, 90], axis=0)
            ax.fill_between(frames, low, high, alpha=0.2)
        ax.set_title(condition, fontsize=9)
        ax.set_ylabel(spec.get("ylabel", spec["series"]))
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7)
    axes[-1, 0].set_xlabel("frame")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def _first_runs(group: pd.DataFrame) -> pd.DataFrame:
    return group.sort_values("repetition").groupby("method", sort=False).head(1)


def _sequence(experiment: dict, condition_records: pd.DataFrame):
    scenes = experiment["scenes"]
    scene = [p.split("=", 1)[1] for p in condition_records["condition"].iloc[0].split(";") if p.startswith("scene=")]
    name = scene[0] if scene else experiment["model"]["scene"]
    return cached_sequence(scenes[name]), experiment["model"].get("target", 0)


def track(records: pd.DataFrame, spec: dict, experiment: dict, path: Path) -> Path:
    """Centre x and y against the frame for the first run of each method, beside the truth."""
    groups = _by_condition(records)
    fig, axes = plt.subplots(len(groups), 2, figsize=(9, 2.6 * len(groups)), squeeze=False)
    for row, (condition, group) in zip(axes, groups):
        sequence, target = _sequence(experiment, group)
        truth = sequence.truth[:, target]
        centre = truth[:, :2] + truth[:, 2:] / 2
        for axis, ax in enumerate(row):
            ax.plot(centre[:, axis], "k-", lw=2, label="truth")
            for _, run in _first_runs(group).iterrows():
                boxes = np.array(run["per_frame"]["box"])
                ax.plot(boxes[:, axis] + boxes[:, axis + 2] / 2, label=_label(experiment, run["method"]))
            ax.set_title(f"{condition}: centre {'xy'[axis]}", fontsize=9)
            ax.grid(True, alpha=0.3)
        row[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


COLOURS = [(0, 0, 255), (255, 0, 0), (0, 200, 255), (255, 0, 255), (255, 255, 0)]


def snapshots(records: pd.DataFrame, spec: dict, experiment: dict, path: Path) -> Path:
    """A grid: one row per condition and method, one column per frame; truth green, estimate coloured."""
    tiles = []
    for condition, group in _by_condition(records):
        sequence, target = _sequence(experiment, group)
        frames = [k for k in spec["frames"] if k < sequence.n_frames]
        for index, (_, run) in enumerate(_first_runs(group).iterrows()):
            boxes = np.array(run["per_frame"]["box"])
            row = []
            for k in frames:
                image = sequence.frame(k).copy()
                for box, colour in ((sequence.truth[k, target], (0, 200, 0)), (boxes[k], COLOURS[index % 5])):
                    x, y, w, h = box
                    cv2.rectangle(image, (int(x), int(y)), (int(x + w), int(y + h)), colour, 1)
                row.append(image)
            tiles.append((f"{condition} / {_label(experiment, run['method'])}", frames, row))
    fig, axes = plt.subplots(len(tiles), max(len(t[2]) for t in tiles), figsize=(2.2 * 5, 1.9 * len(tiles)), squeeze=False)
    for ax_row, (title, frames, images) in zip(axes, tiles):
        for ax in ax_row:
            ax.axis("off")
        for ax, k, image in zip(ax_row, frames, images):
            ax.imshow(cv2.cvtColor(image, cv2.COLOR_BGR2RGB))
            ax.set_title(f"#{k + 1}", fontsize=8)
        ax_row[0].text(0, -0.25, title, transform=ax_row[0].transAxes, fontsize=7, va="top")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
