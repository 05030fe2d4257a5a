"""Figures of tracking runs: per-frame curves, tracks against the truth, snapshot grids."""

from pathlib import Path

import cv2
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from matplotlib.colors import to_rgb

from replication.boxes import centres
from replication.display import method_label
from replication.evidence.aggregate import scene_of
from replication.evidence.attributes import absent, attribute_scores
from replication.evidence.footage import Footage
from replication.report.figures.style import (
    NothingToDraw, axis_label, clipped_note, method_look, save,
)
from replication.evidence.figures import (
    AttributeMap, EncounterStrip, ModeStrip, OtbCurves, OutsideCurve, PerFrameCurve, Snapshots, Track,
)
from replication.report.figures.base import draws


def _by_condition(records: pd.DataFrame):
    return list(records.groupby("condition", sort=False))


@draws(PerFrameCurve)
def per_frame_curve(bands: pd.DataFrame, spec: PerFrameCurve, experiment: dict, path: Path) -> Path:
    """Mean and 10-90% band over runs of a per-frame series (``spec.series``), one panel per condition
    (:func:`~replication.runner.curves.per_frame_band`); methods that do not record the series are left out.

    A run diverged where it is not finite or beyond ``spec.clip`` (by default 10
    times the largest median over runs of any method at any frame, in size: a
    method that loses the target stays as it is, one run blown far beyond
    what any method typically does is not): it is clipped there, so that it
    does not flatten every other curve, and the method's label says how many
    runs did.
    """
    groups = list(bands.groupby("condition", sort=False))
    fig, axes = plt.subplots(len(groups), 1, figsize=(7, 2.6 * len(groups)), squeeze=False)
    for ax, (condition, group) in zip(axes[:, 0], groups):
        for method, band in group.groupby("method", sort=False):
            frames, look = band["frame"].to_numpy(), method_look(experiment, method)
            ax.plot(frames, band["mean"], **look.line(), markevery=max(1, len(frames) // 12),
                    markersize=4, lw=1.2,
                    label=method_label(experiment, method)
                    + clipped_note(band["diverged"].iloc[0], band["runs"].iloc[0]))
            ax.fill_between(frames, band["low"], band["high"], color=look.colour, alpha=0.15)
        ax.set_title(condition, fontsize=9)
        ax.set_ylabel(spec.ylabel or axis_label(spec.series))
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7)
    axes[-1, 0].set_xlabel("frame")
    return save(fig, path)


def _first_runs(group: pd.DataFrame) -> pd.DataFrame:
    return group.sort_values("repetition").groupby("method", sort=False).head(1)


def _sequence(experiment: dict, condition_records: pd.DataFrame, footage: Footage):
    """The video a condition's first runs saw (one per method, the same repetition) and the targets they track."""
    return footage.seen(experiment, condition_records), condition_records["per_frame"].iloc[0]["targets"]


@draws(Track)
def track(records: pd.DataFrame, spec: Track, experiment: dict, path: Path,
          footage: Footage) -> Path:
    """Centre x and y against the frame for the first run of each method, beside the truth."""
    groups = _by_condition(records)
    fig, axes = plt.subplots(len(groups), 2, figsize=(9, 2.6 * len(groups)), squeeze=False)
    for row, (condition, group) in zip(axes, groups):
        sequence, chosen = _sequence(experiment, group, footage)
        truth = sequence.truth[:, chosen]
        centre = truth[..., :2] + truth[..., 2:] / 2
        frames = np.arange(1, len(centre) + 1)
        for axis, ax in enumerate(row):
            ax.plot(frames, centre[..., axis], color="k", lw=2, alpha=0.35)[0].set_label("truth")
            for _, run in _first_runs(group).iterrows():
                boxes = np.array(run["per_frame"]["box"])
                look = method_look(experiment, run["method"])
                lines = ax.plot(frames, boxes[..., axis] + boxes[..., axis + 2] / 2, color=look.colour,
                                linestyle=look.linestyle, lw=1)
                lines[0].set_label(method_label(experiment, run["method"]))
            ax.set_title(f"{condition}: centre {'xy'[axis]}", fontsize=9)
            ax.set_ylabel(f"{'xy'[axis]} (px)")
            ax.grid(True, alpha=0.3)
        row[0].legend(fontsize=7)
    for ax in axes[-1]:
        ax.set_xlabel("frame")
    return save(fig, path)


def _frames(spec: Snapshots, scene: str, n_frames: int) -> list[int]:
    """Snapshot frames (0-based): one list for every scene, or a list per scene name."""
    frames = spec.frames[scene] if isinstance(spec.frames, dict) else spec.frames
    return [k for k in frames if k < n_frames]


@draws(Snapshots)
def snapshots(records: pd.DataFrame, spec: Snapshots, experiment: dict, path: Path,
              footage: Footage) -> Path:
    """Snapshot grids, one block per condition; truth white edged in black, each method's first run in
    its colour.

    ``rows: frames`` puts frames down and methods across (the papers' layout);
    otherwise methods down and frames across.
    """
    blocks = []
    for condition, group in _by_condition(records):
        sequence, chosen = _sequence(experiment, group, footage)
        frames = _frames(spec, scene_of(experiment, group), sequence.n_frames)
        runs = list(_first_runs(group).iterrows())
        grid = [[_snapshot(sequence, chosen, np.array(run["per_frame"]["box"]), k,
                           method_look(experiment, run["method"]).colour) for _, run in runs] for k in frames]
        labels = [method_label(experiment, run["method"]) for _, run in runs]
        if spec.rows != "frames":
            grid = [list(column) for column in zip(*grid)]
        blocks.append((condition, frames, labels, grid))
    n_rows = sum(len(grid) for *_, grid in blocks)
    n_cols = max(len(grid[0]) for *_, grid in blocks if grid)
    fig, axes = plt.subplots(n_rows, n_cols, figsize=(2.3 * n_cols, 1.9 * n_rows), squeeze=False)
    for ax in axes.ravel():
        ax.axis("off")
    row = 0
    for condition, frames, labels, grid in blocks:
        down, across = (frames, labels) if spec.rows == "frames" else (labels, frames)
        for r, images in enumerate(grid):
            for c, image in enumerate(images):
                ax = axes[row + r, c]
                ax.imshow(cv2.cvtColor(image, cv2.COLOR_BGR2RGB))
                title = across[c] if isinstance(across[c], str) else f"#{across[c] + 1}"
                side = down[r] if isinstance(down[r], str) else f"#{down[r] + 1}"
                ax.set_title(f"{condition}: {title}" if r == 0 else "", fontsize=6)
                ax.text(-0.02, 0.5, side, transform=ax.transAxes, fontsize=6, rotation=90, ha="right", va="center")
        row += len(grid)
    return save(fig, path)


def _snapshot(sequence, chosen: list[int], boxes: np.ndarray, k: int, colour: str) -> np.ndarray:
    """Frame ``k`` with each target's true box (white, edged in black outside) and estimated box
    (``colour``)."""
    image = sequence.frame(k).copy()
    estimate = tuple(int(255 * c) for c in to_rgb(colour)[::-1])  # BGR, as OpenCV draws
    for m, target in enumerate(chosen):
        x, y, w, h = sequence.truth[k, target]
        cv2.rectangle(image, (int(x) - 1, int(y) - 1), (int(x + w) + 1, int(y + h) + 1), (0, 0, 0), 1)
        for (x, y, w, h), bgr in ((sequence.truth[k, target], (255, 255, 255)), (boxes[k, m], estimate)):
            cv2.rectangle(image, (int(x), int(y)), (int(x + w), int(y + h)), bgr, 1)
    return image


@draws(ModeStrip)
def mode_strip(records: pd.DataFrame, spec: ModeStrip, experiment: dict, path: Path,
               footage: Footage) -> Path:
    """The marginal posterior of one target over x or y, frame by frame (first run of each method),
    with every target's true coordinate drawn over it: does a hidden target keep both modes?"""
    runs = list(_first_runs(records[records["strip"].notna()]).iterrows())
    if not runs:
        raise NothingToDraw(f"figure {spec.name!r}: no run recorded a strip (a scene's "
                            "strip: {target: ...} block, bis_pf's exp1_3123)")
    fig, axes = plt.subplots(len(runs), 1, figsize=(7, 2.6 * len(runs)), squeeze=False)
    for ax, (_, run) in zip(axes[:, 0], runs):
        sequence, _ = _sequence(experiment, run.to_frame().T, footage)
        density = np.array(run["strip"]["density"])  # (T - 1, bins)
        axis = "xy".index(run["strip"]["axis"])
        ax.imshow(density.T, origin="lower", aspect="auto", cmap="magma",
                  extent=(1, density.shape[0], 0, sequence.size[axis]))
        truth = centres(sequence.truth[1:])[..., axis]
        for m in range(truth.shape[1]):
            ax.plot(np.arange(1, len(truth) + 1), truth[:, m], lw=0.8, ls="--", label=f"truth {m + 1}")
        first, last = spec.window or (None, None)
        if first is not None:
            ax.axvspan(first, last, color="w", alpha=0.08)
        target = run["strip"]["target"] + 1
        ax.set_title(f"{method_label(experiment, run['method'])}: target {target}", fontsize=9)
        ax.set_ylabel(f"{run['strip']['axis']} (px)")
        ax.legend(fontsize=6, loc="upper left")
    axes[-1, 0].set_xlabel("frame")
    return save(fig, path)


@draws(OtbCurves)
def otb_curves(curves: pd.DataFrame, spec: OtbCurves, experiment: dict, path: Path) -> Path:
    """OTB one-pass precision and success plots over every sequence and run, one line per method.

    Each curve is the mean over runs of the per-run curve (:func:`~replication.runner.curves.otb_curves`),
    so every sequence weighs the same, as in OTB's toolkit; the legend gives precision at 20 px and the
    success AUC.
    """
    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    for ax, name, every in ((axes[0], "precision", 5), (axes[1], "success", 3)):
        for method, line in curves[curves["curve"] == name].groupby("method", sort=False):
            ax.plot(line["threshold"], line["value"], **method_look(experiment, method).line(), markevery=every,
                    markersize=4, label=f"{method_label(experiment, method)} [{line['score'].iloc[0]:.3f}]")
    axes[0].set(xlabel="location error threshold (px)", ylabel="precision", title="Precision plot (OPE)")
    axes[1].set(xlabel="overlap threshold", ylabel="success rate", title="Success plot (OPE)")
    for ax in axes:
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7)
    return save(fig, path)


@draws(AttributeMap)
def attribute_map(records: pd.DataFrame, spec: AttributeMap, experiment: dict, path: Path,
                  footage: Footage) -> Path:
    """OTB's per-attribute view as heat maps, methods down and attributes across: precision at 20 px,
    then success AUC, each the mean over the sequences carrying the attribute (under its code: how many,
    or the one sequence by name); the best method of each attribute is framed.
    """
    scores = attribute_scores(records, experiment, footage)
    rows = list(dict.fromkeys(zip(scores["method"], scores["series"])))
    codes = list(dict.fromkeys(scores["attribute"]))
    panels = [(metric, axis_label(metric)) for metric in ("precision20", "success_auc")]
    fig, axes = plt.subplots(len(panels), 1, figsize=(2.5 + 0.75 * max(len(codes), 4), 2 * (1.2 + 0.35 * len(rows))),
                             squeeze=False)
    if scores.empty:
        for ax in axes[:, 0]:
            ax.axis("off")
        axes[0, 0].text(0.5, 0.5, "no sequence here has OTB attributes listed", ha="center", va="center")
        return save(fig, path)
    carriers = {code: sorted(set().union(*group)) for code, group in scores.groupby("attribute")["sequences"]}
    columns = [f"{code}\n{carriers[code][0] if len(carriers[code]) == 1 else f'{len(carriers[code])} seq.'}"
               for code in codes]
    labels = [f"{method_label(experiment, method)} {series}".strip() for method, series in rows]
    for ax, (metric, name) in zip(axes[:, 0], panels):
        values = np.full((len(rows), len(codes)), np.nan)
        for method, series, code, estimate in zip(scores["method"], scores["series"], scores["attribute"],
                                                  scores[metric]):
            values[rows.index((method, series)), codes.index(code)] = estimate.value
        image = ax.imshow(values, cmap="viridis", vmin=0.0, vmax=1.0, aspect="auto")
        best = np.nanmax(values, axis=0)
        for (r, c), value in np.ndenumerate(values):
            if np.isfinite(value):
                ax.text(c, r, f"{value:.2f}", ha="center", va="center", fontsize=7,
                        color="black" if value > 0.6 else "white")
                if value == best[c]:
                    ax.add_patch(plt.Rectangle((c - 0.5, r - 0.5), 1, 1, fill=False, edgecolor="red", lw=1.5))
        ax.set_xticks(range(len(codes)), columns, fontsize=7)
        ax.set_yticks(range(len(rows)), labels, fontsize=7)
        ax.set_title(f"{name} per attribute (mean over the sequences carrying it; best framed)", fontsize=9)
        fig.colorbar(image, ax=ax, fraction=0.03, pad=0.02)
    missing = absent(scores, footage.meanings)
    if missing:
        axes[-1, 0].set_xlabel(f"no sequence here carries {', '.join(missing)}", fontsize=7)
    return save(fig, path)


@draws(EncounterStrip)
def encounter_strip(records: pd.DataFrame, spec: EncounterStrip, experiment: dict, path: Path,
                    footage: Footage) -> Path:
    """Why the per-identity error grows, for the first run of each method: above, its per-identity and
    identity-free error per frame; below, one row per pair of targets that comes within ``spec.distance`` px
    (a box width) of each other, grey while they are that close, a red tick where an estimate starts to sit
    on the other target of the pair (the frame's optimal assignment): an identity swap."""
    distance = spec.distance
    runs = _first_runs(records)
    sequence, chosen = _sequence(experiment, records, footage)
    truth = centres(sequence.truth[:, chosen])
    apart = np.linalg.norm(truth[:, :, None] - truth[:, None, :], axis=-1)
    pairs = [(i, j) for i, j in zip(*np.triu_indices(len(chosen), 1)) if (apart[:, i, j] < distance).any()]
    if not pairs:
        raise NothingToDraw(f"figure {spec.name!r}: no two targets come within {distance:g} px")
    row_of = {pair: k for k, pair in enumerate(sorted(pairs, key=lambda p: np.argmax(apart[:, p[0], p[1]] < distance)))}
    frames = np.arange(len(truth))
    fig, axes = plt.subplots(2 * len(runs), 1, figsize=(10, len(runs) * (1.6 + 0.05 * len(pairs))), squeeze=False,
                             gridspec_kw={"height_ratios": [1, max(1.5, 0.05 * len(pairs))] * len(runs)}, sharex=True)
    for (_, run), top, strip in zip(runs.iterrows(), axes[0::2, 0], axes[1::2, 0]):
        estimates = centres(np.array(run["per_frame"]["box"], dtype=float))
        assigned, near = footage.assignments(estimates, truth)
        top.plot(frames, np.linalg.norm(estimates - truth, axis=-1).mean(axis=1), color="C3", lw=1,
                 label="per identity")
        top.plot(frames, near.mean(axis=1), color="C0", lw=1, label="identity-free")
        top.set_ylabel("error (px)", fontsize=7)
        top.set_title(method_label(experiment, run["method"]), fontsize=9, loc="left")
        top.legend(fontsize=6, loc="upper left")
        for (i, j), row in row_of.items():
            close = apart[:, i, j] < distance
            strip.fill_between(frames, row - 0.4, row + 0.4, where=close, color="0.75", step="mid", lw=0)
        on_other = (assigned != np.arange(len(chosen))) & (near <= distance)
        starts = on_other & ~np.vstack([np.zeros((1, len(chosen)), bool), on_other[:-1]])
        for k, m in zip(*np.nonzero(starts)):
            row = row_of.get(tuple(sorted((int(m), int(assigned[k, m])))))
            if row is not None:
                strip.plot([k, k], [row - 0.45, row + 0.45], color="C3", lw=1.2)
        strip.set_ylim(-0.5, len(pairs) - 0.5)
        strip.set_yticks([])
        strip.set_ylabel(f"{len(pairs)} pairs", fontsize=7)
    axes[-1, 0].set_xlabel("frame")
    return save(fig, path)


@draws(OutsideCurve)
def outside_curve(shares: pd.DataFrame, spec: OutsideCurve, experiment: dict, path: Path) -> Path:
    """Per frame, the share of targets whose estimated centre lies outside the image (the filter's own state,
    never clipped), mean over runs, per method (:func:`~replication.runner.curves.outside_share`): a
    tracker that runs off the frame shows it here."""
    fig, ax = plt.subplots(figsize=(7, 2.8))
    for method, share in shares.groupby("method", sort=False):
        ax.plot(share["frame"], share["share"], **method_look(experiment, method).line(),
                markevery=max(1, len(share) // 12), markersize=4, lw=1.2, label=method_label(experiment, method))
    ax.set_xlabel("frame")
    ax.set_ylabel("share of estimates\noutside the image")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7)
    return save(fig, path)