"""Synthetic scenes: exact ground truth, visibility, events, determinism; export round trip."""

import numpy as np
import pytest
from hydra import compose, initialize_config_dir
from omegaconf import OmegaConf
from conftest import PROJECT_ROOT

from replication.scenes import OTBSequence, SyntheticScene
from replication.scenes.export import write_sequence
from replication.scenes.synthetic import SceneError, trajectory

GREY = [100, 100, 100]


def box_scene(**extra):
    spec = {
        "size": [120, 80],
        "frames": 10,
        "background": {"kind": "flat", "colour": GREY},
        "targets": [
            {
                "shape": "box",
                "size": [20, 10],
                "colour": [0, 0, 250],
                "colour_spread": 0,
                "structure": False,
                "motion": {"kind": "scripted", "keyframes": [[0, 30, 40], [9, 75, 40]]},
            }
        ],
    }
    spec.update(extra)
    return SyntheticScene(spec)


def painted_box(image):
    """Bounding box (x, y, w, h) of the pixels that differ from the grey background."""
    ys, xs = np.nonzero(np.any(image != GREY, axis=2))
    return np.array([xs.min(), ys.min(), xs.max() - xs.min() + 1, ys.max() - ys.min() + 1])


def test_truth_is_the_box_actually_drawn():
    scene = box_scene()
    for k in range(scene.n_frames):
        np.testing.assert_array_equal(painted_box(scene.frame(k)), scene.truth[k, 0])
    assert scene.truth[0, 0].tolist() == [20, 35, 20, 10]  # centre (30, 40), 20 x 10
    np.testing.assert_array_equal(scene.visibility[:, 0], 1.0)


def test_a_turning_sprite_keeps_its_centre_and_area_and_its_truth_bounds_it():
    plane = {"shape": "box", "size": [40, 24], "colour": [0, 0, 250], "colour_spread": 0, "structure": True,
             "motion": {"kind": "scripted", "keyframes": [[0, 60, 40]]}}
    still = box_scene(frames=3, targets=[plane])
    scene = box_scene(frames=3, targets=[{**plane, "rotation": [[0, 0], [1, 90], [2, 30]]}])
    np.testing.assert_array_equal(scene.frame(0), still.frame(0))  # 0 degrees: the rigid sprite
    # 90 degrees: 24 x 40; 30 degrees: ceil(40 cos 30 + 24 sin 30) x ceil(40 sin 30 + 24 cos 30) = 47 x 41
    assert scene.truth[1, 0].tolist() == [48, 20, 24, 40] and scene.truth[2, 0].tolist() == [36, 20, 47, 41]
    for k in range(3):
        frame = scene.frame(k)
        np.testing.assert_array_equal(painted_box(frame), scene.truth[k, 0])
        painted = frame[..., 0] < 53  # more than half covered (blue: 100 outside, 0 body, 10 cross)
        assert abs(painted.sum() - 40 * 24) <= 0.03 * 40 * 24  # a turn moves pixels, it does not add any
        ys, xs = np.nonzero(painted)
        assert abs(xs.mean() - 59.5) < 0.6 and abs(ys.mean() - 39.5) < 0.6  # about the same centre
    # the dark cross turns with the body: at 90 degrees the long arm is vertical
    dark = np.all(scene.frame(1) < 40, axis=2)
    assert np.ptp(np.nonzero(dark)[0]) > np.ptp(np.nonzero(dark)[1])
    assert np.ptp(np.nonzero(np.all(scene.frame(0) < 40, axis=2))[1]) > 30


def test_same_seed_same_frames_in_any_order():
    spec = {
        "size": [64, 48], "frames": 6, "seed": 5, "camera_noise": 3.0,
        "background": {"kind": "noise", "colour": GREY},
        "targets": [{"shape": "ball", "size": [10, 10], "colour": [20, 200, 20],
                     "motion": {"kind": "random_walk", "noise_var": 0.4, "max_speed": 2}}],
    }
    a, b = SyntheticScene(spec), SyntheticScene(spec)
    forwards = [a.frame(k) for k in range(6)]
    backwards = [b.frame(k) for k in reversed(range(6))][::-1]
    for x, y in zip(forwards, backwards):
        np.testing.assert_array_equal(x, y)
    other = SyntheticScene({**spec, "seed": 6})
    assert not np.array_equal(other.frame(0), forwards[0])
    assert not np.array_equal(forwards[0], forwards[1])  # camera noise differs from frame to frame


def test_occluder_visibility_half_and_complete():
    # the occluder covers the right half of the target in frame 0 and all of it from frame 5
    occluder = {"shape": "box", "size": [10, 30], "colour": [0, 0, 0], "colour_spread": 0, "depth": 0,
                "motion": {"kind": "scripted", "keyframes": [[0, 35, 40], [4, 35, 40], [5, 60, 40], [9, 60, 40]]}}
    scene = box_scene(occluders=[occluder])
    scene.objects[0].centres[:] = (30, 40)  # keep the target still: box x 20..39
    assert scene.visibility[0, 0] == pytest.approx(0.5)
    occluder_wide = {**occluder, "size": [30, 30], "motion": {"kind": "scripted", "keyframes": [[0, 30, 40]]}}
    covered = box_scene(occluders=[occluder_wide])
    covered.objects[0].centres[:] = (30, 40)
    np.testing.assert_array_equal(covered.visibility[:, 0], 0.0)


def test_visibility_counts_pixels_outside_the_frame_as_hidden():
    scene = box_scene()
    scene.objects[0].centres[:] = (0, 40)  # box x from -10 to 9: half outside
    assert scene.visibility[0, 0] == pytest.approx(0.5)


def test_mutual_occlusion_follows_depth():
    near = {"shape": "box", "size": [20, 10], "colour": [0, 250, 0], "colour_spread": 0, "structure": False,
            "depth": 0, "motion": {"kind": "scripted", "keyframes": [[0, 30, 40]]}}
    scene = box_scene(targets=[box_scene().spec["targets"][0] | {"depth": 1}, near])
    assert scene.visibility[0, 1] == 1.0 and scene.visibility[0, 0] == 0.0


def test_illumination_scales_the_frame():
    scene = box_scene(illumination=[{"start": 2, "end": 6, "gain": 0.5}])
    assert scene.frame(0)[0, 0].tolist() == GREY
    assert scene.frame(4)[0, 0].tolist() == [75, 75, 75]  # half-way through the ramp: gain 0.75
    assert scene.frame(9)[0, 0].tolist() == [50, 50, 50]


def test_head_turning_away_changes_colour():
    head = {"shape": "head", "size": [30, 40], "colour": [90, 130, 210], "back_colour": [30, 40, 60],
            "colour_spread": 0, "appearance": [{"start": 2, "end": 4, "to": "back"}],
            "motion": {"kind": "scripted", "keyframes": [[0, 60, 40]]}}
    scene = box_scene(targets=[head])
    centre = (40, 60)
    assert scene.frame(0)[centre].tolist() == [90, 130, 210]
    assert scene.frame(9)[centre].tolist() == [30, 40, 60]


def test_random_walk_respects_the_speed_cap_and_the_frame():
    rng = np.random.default_rng(0)
    path = trajectory({"kind": "random_walk", "noise_var": 0.4, "max_speed": 2.0, "margin": 10}, 1000, (480, 410), rng)
    speeds = np.linalg.norm(np.diff(path, axis=0), axis=1)
    assert speeds.max() <= 2.0 + 1e-9 and speeds.mean() > 0.5
    assert path.min() >= 10 - 1e-9 and path[:, 0].max() <= 470 and path[:, 1].max() <= 400


def test_velocity_segments_change_speed_suddenly():
    path = trajectory({"kind": "velocity", "start": [0, 0], "segments": [[0, 1, 0], [5, 4, 0]]}, 8, (100, 100), None)
    np.testing.assert_allclose(np.diff(path[:, 0]), [1, 1, 1, 1, 4, 4, 4])


@pytest.mark.parametrize(
    "change, message",
    [
        ({"targets": []}, "at least one target"),
        ({"background": {"kind": "plaid"}}, "unknown background"),
        ({"targets": [{"shape": "star", "size": [5, 5], "colour": GREY}]}, "unknown shape"),
        ({"targets": [{"shape": "box", "size": [5, 5], "colour": GREY, "rotation": [30]}]}, "rotation keyframes"),
    ],
)
def test_bad_scene_specs_are_explained(change, message):
    with pytest.raises(SceneError, match=message):
        box_scene(**change)


def test_export_round_trips_through_the_otb_loader(tmp_path):
    scene = box_scene()
    scene.name = "boxes"
    write_sequence(scene, tmp_path, video=False)
    (tmp_path / "boxes" / "groundtruth_rect.txt").write_text((tmp_path / "boxes" / "groundtruth_rect.1.txt").read_text())
    loaded = OTBSequence("boxes", root=str(tmp_path))
    np.testing.assert_array_equal(loaded.truth, scene.truth)
    assert loaded.n_frames == scene.n_frames and loaded.size == scene.size
    assert np.abs(loaded.frame(3).astype(int) - scene.frame(3).astype(int)).mean() < 3  # JPEG


def test_export_writes_a_playable_mp4(tmp_path):
    import cv2

    path = write_sequence(box_scene(), tmp_path, video=True)
    capture = cv2.VideoCapture(str(path))
    frames = 0
    while capture.read()[0]:
        frames += 1
    assert frames == 10


def test_scene_writer_command(tmp_path):
    import subprocess
    import sys

    command = [sys.executable, "-m", "replication.scenes", "experiment=demo_scene", f"out={tmp_path}", "format=images"]
    result = subprocess.run(command, cwd=PROJECT_ROOT, capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    assert len(list((tmp_path / "synthetic_head" / "img").glob("*.jpg"))) == 150
    assert len((tmp_path / "synthetic_head" / "groundtruth_rect.1.txt").read_text().splitlines()) == 150
    refused = subprocess.run(
        [sys.executable, "-m", "replication.scenes", "experiment=hspf_ungm"], cwd=PROJECT_ROOT, capture_output=True, text=True
    )
    assert refused.returncode == 2 and "no synthetic scene" in refused.stderr


def _3123(hidden_motion):
    from omegaconf import OmegaConf

    from replication.paths import CONF_DIR
    from replication.scales import at_scale
    from replication.scenes.factory import build_sequence

    experiment = OmegaConf.to_container(OmegaConf.load(CONF_DIR / "experiment" / "bis_pf.yaml"))
    return build_sequence({**at_scale(experiment["scenes"]["exp1_3123"], "paper"), "hidden_motion": hidden_motion})


def test_3123_hidden_targets_move_with_1_or_keep_their_own_velocity():
    """bis_pf's 3123 script, two readings: 2 (hidden 51-70) and 3 (hidden 51-93) move exactly with 1 while
    hidden, or keep one velocity of their own; either way 2 goes in from above and out below, 3 the reverse."""
    with_1, own = _3123("with_occluder"), _3123("own_velocity")
    one = with_1.objects[0].centres
    for target, (first, last) in ((1, (51, 70)), (2, (51, 93))):
        np.testing.assert_allclose(with_1.objects[target].centres[first : last + 1], one[first : last + 1], atol=1e-3)
        path = own.objects[target].centres
        np.testing.assert_allclose(np.diff(path, 2, axis=0), 0, atol=1e-9)  # one velocity throughout
        relative = path - one
        mid = (first + last) // 2  # through 1's centre midway, half covered (0.404 x 18 px) at the ends
        assert np.hypot(*relative[mid]) < np.hypot(*(relative[mid + 1] - relative[mid]))
        np.testing.assert_allclose(np.hypot(*relative[first]), 0.404 * 18, rtol=0.03)
        hidden = np.flatnonzero(own.visibility[:, target] < 0.5)
        assert abs(hidden[0] - first) <= 1 and abs(hidden[-1] - last) <= 1 and len(hidden) == hidden[-1] - hidden[0] + 1
        for scene in (with_1, own):
            side = np.sign(scene.objects[target].centres[[0, -1], 1] - one[[0, -1], 1])
            assert list(side) == ([-1, 1] if target == 1 else [1, -1])  # y grows downwards
    with pytest.raises(SceneError, match="hidden_motion"):
        _3123("bounce")


def test_random_walk_noise_on_velocity_or_position():
    """bis_pf's balls: 'constant velocity disturbed by Gaussian noise (variance 0.4 px)' (3.2), the noise on the
    velocity (it accumulates) or on the centre (the velocity stays); no noise, no difference."""
    walk = {"kind": "random_walk", "start": [100, 100], "velocity": [1.0, 0.5], "max_speed": 2.0}
    for noise_on in ("velocity", "position"):
        still = trajectory({**walk, "noise_var": 0.0, "noise_on": noise_on}, 6, (400, 400), np.random.default_rng(0))
        np.testing.assert_allclose(still, [[100 + k, 100 + k / 2] for k in range(6)])
    draws = np.random.default_rng(1)
    draws.normal(0.0, 1.0, 2)  # the unused default velocity is drawn first
    e = 0.5 * draws.standard_normal((5, 2))  # sd 0.5, one draw per frame
    walk["max_speed"] = 10.0  # no cap
    on_velocity = trajectory({**walk, "noise_var": 0.25}, 6, (400, 400), np.random.default_rng(1))
    np.testing.assert_allclose(np.diff(on_velocity, axis=0), [1.0, 0.5] + np.cumsum(e, axis=0))
    on_position = trajectory({**walk, "noise_var": 0.25, "noise_on": "position"}, 6, (400, 400), np.random.default_rng(1))
    np.testing.assert_allclose(np.diff(on_position, axis=0), [1.0, 0.5] + e)
    with pytest.raises(SceneError, match="noise_on"):
        trajectory({**walk, "noise_on": "size"}, 6, (400, 400), np.random.default_rng(1))


def _with_synthetic_scenes() -> list[str]:
    """The shipped experiments with a synthetic scene, read from their configs."""
    from replication.paths import CONF_DIR, experiment_names

    found = []
    for name in experiment_names():
        with initialize_config_dir(config_dir=str(CONF_DIR), version_base="1.3"):
            cfg = compose("config", overrides=[f"experiment={name}"])
        scenes = OmegaConf.to_container(cfg.experiment.scenes, resolve=True) if "scenes" in cfg.experiment else {}
        if any(spec.get("kind", "synthetic") == "synthetic" for spec in scenes.values()):
            found.append(name)
    return found


@pytest.mark.parametrize("name", _with_synthetic_scenes())
def test_the_scenes_command_writes_every_synthetic_scene_at_the_scale_asked(name, tmp_path):
    from replication.scenes.__main__ import main

    main([f"experiment={name}", "scale=quick", f"out={tmp_path}", "format=images"])
    written = [p for p in tmp_path.iterdir() if p.is_dir()]
    assert written and all(len(list((p / "img").glob("*.jpg"))) > 0 for p in written)
    assert all((p / "groundtruth_rect.1.txt").exists() for p in written)


@pytest.mark.parametrize("argv, said", [(["experiment=bis_pf", "scale=huge"], "scale must be one of paper, quick"),
                                        (["experiment=bis_pf", "frames=3"], "unknown option 'frames'")])
def test_the_scenes_command_refuses_a_bad_request_in_one_line(argv, said, capsys):
    from replication.scenes.__main__ import main

    with pytest.raises(SystemExit) as stopped:
        main(argv)
    assert stopped.value.code == 2 and said in capsys.readouterr().err


def test_frames_and_visibility_are_numpys_compositing_to_the_bit():
    """Every synthetic scene of the experiments (and one turning, scaling, changing sprite): each frame is the
    numpy compositing it replaced (background, each sprite blended far to near as image (1 - a) + colour a,
    gain, the camera noise, clipped and cast), and the visibility is the share of each target's solid pixels
    a full-frame label buffer gives it."""
    import glob

    import yaml

    from replication.scenes.synthetic import NOISE_OFFSETS

    def composed(scene, k):
        image = scene.background.copy()
        height, width = image.shape[:2]
        for index in scene.order:
            colour, alpha, x0, y0 = scene.objects[index].drawn(k)
            fy0, fx0 = max(y0, 0), max(x0, 0)
            fy1, fx1 = min(y0 + alpha.shape[0], height), min(x0 + alpha.shape[1], width)
            if fy0 < fy1 and fx0 < fx1:
                a = alpha[fy0 - y0 : fy1 - y0, fx0 - x0 : fx1 - x0][..., None]
                part = colour[fy0 - y0 : fy1 - y0, fx0 - x0 : fx1 - x0]
                image[fy0:fy1, fx0:fx1] = image[fy0:fy1, fx0:fx1] * (1.0 - a) + part * a
        image *= scene.gain[k]
        if scene.camera_noise > 0:
            offset = int(np.random.default_rng([scene.seed, 1, k]).integers(NOISE_OFFSETS))
            image += scene._noise[offset : offset + image.size].reshape(image.shape)
        return np.clip(image, 0, 255).astype(np.uint8)

    def labelled(scene, k):
        height, width = scene.background.shape[:2]
        labels, areas = np.full((height, width), -1), np.zeros(scene.truth.shape[1])
        for index in scene.order:
            obj = scene.objects[index]
            _, alpha, x0, y0 = obj.drawn(k)
            ys, xs = np.nonzero(alpha > 0.5)
            if obj.target is not None:
                areas[obj.target] = len(ys)
            inside = (ys + y0 >= 0) & (ys + y0 < height) & (xs + x0 >= 0) & (xs + x0 < width)
            labels[ys[inside] + y0, xs[inside] + x0] = -1 if obj.target is None else obj.target
        counts = np.bincount(labels.ravel() + 1, minlength=len(areas) + 1)[1:]
        return np.divide(counts, areas, out=np.zeros(len(areas)), where=areas > 0)

    specs = []
    for path in sorted(glob.glob(str(PROJECT_ROOT / "replication/conf/experiment/*.yaml"))):
        for spec in ((yaml.safe_load(open(path)) or {}).get("scenes") or {}).values():
            if isinstance(spec, dict) and spec.get("kind") == "synthetic":
                specs.append({k: v["quick"] if isinstance(v, dict) and "quick" in v else v for k, v in spec.items()})
    turning = dict(specs[0], frames=40)
    turning["targets"] = [dict(t, rotation=[[0, 0.0], [20, 37.0], [39, -95.5]], scale=[[0, 1.0], [39, 1.6]],
                               appearance=[{"to": "back", "start": 5, "end": 30}]) for t in turning["targets"]]
    assert len(specs) >= 10
    for spec in [*specs, turning]:
        scene = SyntheticScene(dict(spec, frames=min(int(spec["frames"]), 40)))
        for k in range(scene.n_frames):
            assert scene.frame(k).tobytes() == composed(scene, k).tobytes()
            np.testing.assert_array_equal(scene.visibility[k], labelled(scene, k))
