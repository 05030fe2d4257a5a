"""MOT figures (snapshots, identity timeline, animation) on stand-in records of SORT and detections-only
tracks on PETS09-S2L1, and the CLEAR MOT matches they draw, checked against py-motmetrics' event table."""

from itertools import pairwise

import numpy as np
import pandas as pd
import pytest
from matplotlib.patches import Rectangle
from mot_cases import COLUMNS, HAVE_MOT, motmetrics_accumulator, needs_mot, two_walkers
from PIL import Image, ImageSequence

from conftest import typed

from replication.filters.mot_baselines import detections_only, sort
from replication.metrics.mot import clear_mot_matches, drop_ignored, mot_metrics
from replication.report.figures import mot as mot_figures
from replication.report.figures import draw
from replication.report.pages.render import render
from replication.scenes import load_mot
from replication.tasks.mot import frame_table
from replication.runner.footage import SceneFootage

FOOTAGE = SceneFootage()  # the video the runs saw, as the pages are given it
EXPERIMENT = {"methods": {"SORT": {"label": "SORT"}, "detections_only": {}},
              "scenes": {"pets": {"kind": "mot", "name": "PETS09-S2L1"}}}
FIRST, LAST = 101, 250  # the stand-in runs' frames


def stand_in_records(sequence, first=FIRST, last=LAST) -> pd.DataFrame:
    """Records as the MOT task writes them: two methods, two runs each, tracks as [frame, id, x, y, w, h]
    rows."""
    rows = []
    for method, tracker in (("SORT", sort), ("detections_only", detections_only)):
        tracks = tracker(sequence.detections)
        tracks = tracks[tracks["frame"].between(first, last)][COLUMNS].values.tolist()
        rows += [{"method": method, "condition": "scene=pets", "repetition": r, "tracks": tracks,
                  "first_frame": first, "last_frame": last} for r in range(2)]
    return typed(pd.DataFrame(rows))


@pytest.fixture(scope="module")
def pets():
    if not HAVE_MOT:
        pytest.skip("../shared/data/mot is not beside the project")
    sequence = load_mot("PETS09-S2L1")
    return sequence, stand_in_records(sequence)


@pytest.fixture
def drawn(keep_figures):
    """The figures drawn, as matplotlib Figures (instead of PNG files)."""
    return keep_figures(mot_figures)


def test_a_track_id_has_one_colour_everywhere_and_neighbours_differ():
    colours = [mot_figures.track_colour(k) for k in range(1, 200)]
    assert colours == [mot_figures.track_colour(k) for k in range(1, 200)]
    assert mot_figures.track_colour(np.int64(7)) == mot_figures.track_colour(7.0) == colours[6]
    assert all(a != b for a, b in pairwise(colours))
    assert len(set(colours[:16])) == 16
    assert all(max(c) - min(c) > 0.2 for c in colours)  # no grey nor tint that would read as truth or ignore


def test_clear_mot_matches_marks_each_switch():
    truth = two_walkers()
    hyp = truth.assign(id=np.where((truth["frame"] > 5) == (truth["id"] == 1), 12, 11))
    matches = clear_mot_matches(truth, hyp.drop(index=[0]))  # truth 1 unmatched in frame 1
    assert len(matches) == 19 and matches.columns.tolist() == ["frame", "truth_id", "hypothesis_id", "switch"]
    assert matches.loc[matches["switch"], ["frame", "truth_id"]].values.tolist() == [[6, 1], [6, 2]]
    assert matches["switch"].sum() == mot_metrics(truth, hyp.drop(index=[0]))["switches"]


def motmetrics_matches(truth, hyp):
    """py-motmetrics' MATCH and SWITCH events, as (frame, truth id, hypothesis id, switch)."""
    acc = motmetrics_accumulator(truth, hyp)
    events = acc.mot_events.reset_index()
    events = events[events["Type"].isin(["MATCH", "SWITCH"])]
    return sorted(zip(events["FrameId"].astype(int), events["OId"].astype(int), events["HId"].astype(int),
                      events["Type"] == "SWITCH"))


@needs_mot
def test_the_timeline_matches_are_motmetrics_matches_on_pets():
    sequence = load_mot("PETS09-S2L1")
    run = {"tracks": sort(sequence.detections)[COLUMNS].values.tolist(), "first_frame": 1,
           "last_frame": sequence.n_frames}
    truth, ours = mot_figures.timeline_matches(sequence, run, FOOTAGE)
    kept = drop_ignored(frame_table(run), sequence.truth, sequence.ignored)
    theirs = motmetrics_matches(truth, kept)
    assert sorted(ours.itertuples(index=False, name=None)) == theirs
    assert 3000 < len(ours) and ours["switch"].sum() > 0  # SORT on PETS: thousands of matches, some switches


@needs_mot
def test_track_snapshots_draw_each_box_in_its_ids_colour(pets, drawn, tmp_path):
    _, records = pets
    spec = {"name": "f", "kind": "track_snapshots", "frames": {"pets": [120, 180, 240, 900]}}  # 900: beyond the sequence
    draw(records, spec, EXPERIMENT, tmp_path / "snapshots.png", footage=FOOTAGE)
    axes = [ax for ax in drawn[0].axes if ax.images]
    assert len(axes) == 2 * 3  # methods x frames
    assert [ax.get_title() for ax in axes[:3]] == ["frame 120", "frame 180", "frame 240"]
    assert [ax.get_ylabel() for ax in axes[::3]] == ["SORT", "detections_only"]
    colours = {}
    for ax in axes:
        outputs = [p for p in ax.patches if isinstance(p, Rectangle) and p.get_linewidth() == 1.4]
        assert len(outputs) == len(ax.texts) > 0
        for patch, text in zip(outputs, ax.texts):
            colour = tuple(patch.get_edgecolor()[:3])
            assert colour == pytest.approx(mot_figures.track_colour(int(text.get_text())))
            assert colours.setdefault(text.get_text(), colour) == colour  # one colour per id across panels
    (x0, x1), (y1, y0) = axes[0].get_xlim(), axes[0].get_ylim()
    assert (x1 - x0) * (y1 - y0) < 0.8 * 768 * 576  # cropped to the boxes
    drawn.clear()
    draw(records, {**spec, "crop": False}, EXPERIMENT, tmp_path / "whole.png", footage=FOOTAGE)
    assert next(ax.get_xlim() for ax in drawn[0].axes if ax.images) == (-0.5, 767.5)


@needs_mot
@pytest.mark.parametrize("spec", [
    {"name": "f", "kind": "track_snapshots"},  # frames evenly spaced over the run
    {"name": "f", "kind": "identity_timeline"},
    {"name": "f", "kind": "track_video", "method": "SORT", "frames": [101, 200], "link": "sort.gif"},
])
def test_each_kind_writes_a_file(pets, tmp_path, spec):
    _, records = pets
    path = draw(records, spec, EXPERIMENT, tmp_path / "figure.png", footage=FOOTAGE)
    assert path == tmp_path / "figure.png" and path.stat().st_size > 10_000
    with Image.open(path) as image:
        assert image.format == "PNG" and min(image.size) > 300
    if spec["kind"] == "track_video":
        gif = tmp_path / "sort.gif"
        assert 0 < gif.stat().st_size < 3_000_000
        with Image.open(gif) as animation:
            assert animation.format == "GIF" and animation.n_frames == 100 and animation.size == (384, 288)


@needs_mot
def test_the_timeline_draws_a_lane_per_person_and_the_runs_switches(pets, drawn, tmp_path):
    sequence, records = pets
    draw(records, {"name": "f", "kind": "identity_timeline"}, EXPERIMENT, tmp_path / "timeline.png", footage=FOOTAGE)
    axes = drawn[0].axes
    assert len(axes) == 2
    truth = sequence.truth[sequence.truth["frame"].between(FIRST, LAST)]
    for ax, method in zip(axes, ["SORT", "detections_only"]):
        run = records[records["method"] == method].iloc[0]
        _, matches = mot_figures.timeline_matches(sequence, run, FOOTAGE)
        assert [t.get_text() for t in ax.get_yticklabels()] == [str(i) for i in sorted(truth["id"].unique())]
        assert ax.get_title().endswith(f"{matches['switch'].sum()} identity switches")
        assert ax.get_xlim() == (FIRST - 0.5, LAST + 0.5)


def test_a_figure_link_is_on_the_page():
    figures = [{"name": "video", "title": "SORT on PETS", "file": "video.png", "link": "video.gif"},
               {"name": "plain", "title": "A plot", "file": "plain.png"}]
    page = render("experiment.html.j2", title="t", paper="p", scale="smoke", n_records=1, n_runs=1, n_failed=0, failures=[],
                  figures=figures, tables=[], scenes=[], claims=[], sweeps=[])
    assert '<a href="video.gif"><img src="video.png"' in page
    assert '<img src="plain.png"' in page and page.count("<a href=\"video.gif\">") == 2


def test_write_gif_redraws_what_moves_not_the_noise(tmp_path):
    rng = np.random.default_rng(0)
    y, x = np.mgrid[0:120, 0:160]
    background = np.stack([1.5 * x, 2 * y, x + y], axis=2)
    frames = []
    for k in range(30):  # sensor noise of a few grey levels, one white box moving right, a black label
        frame = np.clip(background + rng.integers(-4, 5, background.shape), 0, 255).astype(np.uint8)
        frame[40:60, 4 * k:4 * k + 10] = 255
        frame[:8, :20] = 0
        frames.append(frame)
    path = mot_figures.write_gif(frames, tmp_path / "a.gif", fps=7)
    with Image.open(path) as animation:
        assert animation.n_frames == 30 and animation.info["duration"] == 140  # 1/7 s, in GIF's hundredths
        shown = [np.asarray(frame.convert("RGB"), dtype=int) for frame in ImageSequence.Iterator(animation)]
    for frame, image in zip(frames, shown):
        error = np.abs(image - frame).max(axis=2)
        assert np.percentile(error, 99) < 30 and (error[:8, :20] == 0).all()  # the box and label exact
        assert (image[40:60][frame[40:60].min(axis=2) == 255] == 255).all()
    assert path.stat().st_size < 30 * 160 * 120 / 4  # a quarter of one byte per pixel and frame
