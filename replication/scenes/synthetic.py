"""Synthetic scenes rendered with OpenCV, with exact ground truth.

A scene is declared as a dict (from Hydra config), for example::

    size: [320, 240]                 # width, height
    frames: 150
    seed: 0                          # textures, random-walk paths, camera noise
    background: {kind: clutter, colour: [60, 90, 60], like_target: 0, patches: 12}
                                     # optional: region [left, top, right, bottom] for the patches;
                                     # patch_structure: true and patch_rotate: degrees give them the
                                     # target's colours in another structure
    camera_noise: 2.0                # sd of Gaussian pixel noise (grey levels)
    illumination: [{start: 40, end: 60, gain: 0.5}]
    targets:
      - shape: head                  # ellipse | box | ball | head
        size: [30, 40]               # width, height at scale 1
        colour: [70, 110, 210]       # BGR
        back_colour: [30, 40, 60]    # what a head shows when it turns away
        appearance: [{start: 90, end: 110, to: back}, {start: 130, end: 140, to: front}]
        motion: {kind: scripted, keyframes: [[0, 60, 50], [149, 260, 180]]}
        scale: [[0, 1.0], [149, 1.4]]
        rotation: [[0, 0], [149, 30]]  # degrees anticlockwise; the truth box bounds the turned sprite
        depth: 1                     # smaller is nearer
    occluders:
      - {shape: box, size: [40, 120], colour: [20, 20, 20], depth: 0,
         motion: {kind: scripted, keyframes: [[0, 160, 120]]}}

A target with ``copies: n`` stands for n targets with depths depth, depth + 1,
... (the bis_pf balls); a random-walk copy draws its own start and velocity.

Motion kinds: ``scripted`` (linear between keyframes [frame, cx, cy]),
``velocity`` (piecewise constant velocity: start [cx, cy], segments
[[frame, vx, vy], ...]; a sudden speed change is a new segment) and
``random_walk`` (constant velocity disturbed by Gaussian noise of variance
``noise_var`` per frame, speed capped at ``max_speed``, bouncing off the
borders: the bis_pf tennis balls; ``noise_on: velocity``, the default, adds
the noise to the velocity, ``position`` to the centre, the velocity kept).

A scripted target hidden behind another may say so: ``hidden: {behind: 0,
frames: [51, 70]}``.  The scene's ``hidden_motion`` then reads its script:
``with_occluder`` (the default) follows the keyframes, which move it exactly
with the occluder while hidden (bis_pf's 3123 stand-in); ``own_velocity``
keeps its own velocity instead (:func:`own_velocity_path`).

Camera noise is i.i.d. Gaussian per pixel within a frame; to keep rendering
cheap, frame k reads it from one stored noise bank at an offset drawn from
(seed, k), so frames are reproducible in any order.

Objects are drawn back to front at whole-pixel positions; the truth box is the
box actually drawn, and the visibility of a target is the fraction of its
sprite's pixels that are inside the frame and not covered by a nearer object.
"""

from dataclasses import dataclass
from functools import cached_property

import cv2
import numpy as np
from numba import njit

from replication.scenes.kept import kept

SHAPES = ("ellipse", "box", "ball", "head")
BACKGROUNDS = ("flat", "gradient", "noise", "clutter")
MOTIONS = ("scripted", "velocity", "random_walk")
HIDDEN_MOTIONS = ("with_occluder", "own_velocity")
HALF_COVERED = 0.404  # centre distance / diameter at which a disc behind an equal disc is half covered
NOISE_OFFSETS = 1 << 16


class SceneError(ValueError):
    """A scene description that cannot be rendered."""


def _require(condition: bool, message: str) -> None:
    if not condition:
        raise SceneError(message)


def _ramp(frames: np.ndarray, start: int, end: int) -> np.ndarray:
    """0 before ``start``, 1 after ``end``, linear in between."""
    return np.clip((frames - start) / max(end - start, 1), 0.0, 1.0)


def trajectory(motion: dict, n_frames: int, size: tuple[int, int], rng: np.random.Generator) -> np.ndarray:
    """Centres (n_frames, 2) of an object under ``motion``."""
    kind = motion.get("kind")
    _require(kind in MOTIONS, f"unknown motion {kind!r}; choose one of {MOTIONS}")
    frames = np.arange(n_frames)
    if kind == "scripted":
        keys = np.asarray(motion["keyframes"], dtype=float)
        _require(keys.ndim == 2 and keys.shape[1] == 3, "scripted keyframes are [frame, cx, cy] rows")
        return np.column_stack([np.interp(frames, keys[:, 0], keys[:, 1]), np.interp(frames, keys[:, 0], keys[:, 2])])
    if kind == "velocity":
        segments = sorted(motion["segments"])
        velocity = np.zeros((n_frames, 2))
        for start, vx, vy in segments:
            velocity[int(start) :] = (vx, vy)
        steps = np.vstack([[0.0, 0.0], velocity[1:]])
        return np.asarray(motion["start"], dtype=float) + np.cumsum(steps, axis=0)
    # random walk with a speed cap, reflected at the borders
    centre = np.asarray(motion["start"], dtype=float) if "start" in motion else rng.uniform((0, 0), size)
    velocity = np.asarray(motion.get("velocity", rng.normal(0.0, 1.0, 2)), dtype=float)
    sd, cap, margin = np.sqrt(motion.get("noise_var", 0.4)), motion.get("max_speed", 2.0), motion.get("margin", 10)
    low, high = np.array([margin, margin]), np.array(size, dtype=float) - margin
    noise_on = motion.get("noise_on", "velocity")
    _require(noise_on in ("velocity", "position"), f"unknown noise_on {noise_on!r}; choose one of ('velocity', 'position')")
    path = np.empty((n_frames, 2))
    for k in range(n_frames):
        path[k] = centre
        noise = sd * rng.standard_normal(2)
        if noise_on == "velocity":
            velocity = velocity + noise
        speed = np.hypot(*velocity)
        if speed > cap:
            velocity *= cap / speed
        centre = centre + velocity + (noise if noise_on == "position" else 0.0)
        for axis in range(2):
            if not low[axis] <= centre[axis] <= high[axis]:
                velocity[axis] = -velocity[axis]
                centre[axis] = np.clip(centre[axis], low[axis], high[axis])
    return path


def own_velocity_path(path: np.ndarray, occluder: np.ndarray, frames, diameter: float) -> np.ndarray:
    """A hidden target that keeps its own velocity: a straight line relative to the ``occluder``'s path,
    in the direction the target's ``path`` comes in at ``frames[0]``, through the occluder's centre midway,
    at the speed that keeps it at least half covered over ``frames`` (bis_pf 3123: 2 hidden 51-70, 3 51-93).
    Behind an occluder in uniform motion it is a uniform motion of its own."""
    first, last = frames
    _require(0 < first < last < len(path), f"hidden frames {list(frames)} must lie inside the scene, first < last")
    relative = path - occluder
    direction = relative[first] - relative[first - 1]
    _require(np.hypot(*direction) > 0, "a hidden target must be moving against its occluder when it goes in")
    speed = 2 * HALF_COVERED * diameter / (last - first)
    return occluder + np.outer(np.arange(len(path)) - (first + last) / 2, speed * direction / np.hypot(*direction))


def _textured(colour, spread: float, shape: tuple[int, int], rng: np.random.Generator) -> np.ndarray:
    """A float32 (h, w, 3) patch of ``colour`` with per-pixel noise of sd ``spread`` (smoothed a little)."""
    noise = rng.normal(0.0, spread, (*shape, 3)).astype(np.float32)
    if spread > 0:
        noise = cv2.GaussianBlur(noise, (3, 3), 0)
    return np.clip(np.asarray(colour, np.float32) + noise, 0, 255)


def sprite(spec: dict, face: str, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Colour (h, w, 3) float32 and alpha (h, w) float32 of an object at scale 1."""
    shape = spec.get("shape", "ellipse")
    _require(shape in SHAPES, f"unknown shape {shape!r}; choose one of {SHAPES}")
    w, h = (int(v) for v in spec["size"])
    _require(w >= 2 and h >= 2, f"object size must be at least 2x2 px, got {w}x{h}")
    colour = spec["colour"] if face == "front" else spec.get("back_colour", spec["colour"])
    image = _textured(colour, spec.get("colour_spread", 12.0), (h, w), rng)
    alpha = np.zeros((h, w), np.float32)
    centre, axes = (w // 2, h // 2), (max(w // 2 - 1, 1), max(h // 2 - 1, 1))
    if shape == "box":
        alpha[:] = 1.0
    else:
        cv2.ellipse(alpha, centre, axes, 0, 0, 360, 1.0, -1, cv2.LINE_AA)
    if shape == "ball":  # shading: lighter towards the upper left
        yy, xx = np.mgrid[0:h, 0:w]
        light = 1.25 - 0.5 * np.hypot((xx - 0.35 * w) / w, (yy - 0.35 * h) / h)
        image = np.clip(image * light[..., None], 0, 255)
    structure = spec.get("structure", shape in ("head", "box"))
    dark = tuple(float(c) * 0.25 for c in spec.get("structure_colour", (40, 40, 40)))
    if shape == "head":
        hair = np.asarray(spec.get("back_colour", (30, 40, 60)), np.float32)
        top = np.zeros((h, w), np.float32)
        cv2.ellipse(top, centre, axes, 0, 180, 360, 1.0, -1)
        cut = int(h * 0.3) if face == "front" else h
        top[cut:] = 0.0
        image[top > 0] = hair
        if face == "front" and structure:
            for ex in (0.33, 0.67):
                cv2.circle(image, (int(w * ex), int(h * 0.45)), max(w // 12, 1), dark, -1)
            cv2.line(image, (int(w * 0.35), int(h * 0.72)), (int(w * 0.65), int(h * 0.72)), dark, max(h // 20, 1))
    elif structure:
        cv2.line(image, (w // 2, 1), (w // 2, h - 2), dark, max(w // 10, 1))
        cv2.line(image, (1, h // 2), (w - 2, h // 2), dark, max(h // 10, 1))
    return image, alpha


@dataclass
class _Object:
    spec: dict
    centres: np.ndarray
    scales: np.ndarray
    angles: np.ndarray
    turned: np.ndarray
    sprites: dict
    depth: float
    target: int | None

    @cached_property
    def sizes(self) -> np.ndarray:
        """(T, 2) width and height of the sprite in every frame before any rotation: scaled, rounded half
        to even (as ``round``), at least 2 px."""
        h, w = self.sprites["front"][1].shape
        return np.maximum(np.rint(np.multiply.outer(self.scales, (w, h))), 2.0).astype(np.int64)

    @cached_property
    def box(self) -> np.ndarray:
        """(T, 4) top-left corner and size of the sprite as :meth:`drawn` places it in every frame (the scene's
        truth): a rotated sprite's canvas where it is turned, the corner the centre less half the size rounded
        half to even, as ``round`` rounds."""
        sizes = self.sizes.copy()
        for k in np.flatnonzero(self.angles != 0):
            sizes[k] = _rotated_size(*sizes[k].tolist(), self.angles[k])
        return np.concatenate([np.rint(self.centres - sizes / 2).astype(np.int64), sizes], axis=1)

    def drawn(self, k: int) -> tuple[np.ndarray, np.ndarray, int, int]:
        """Colour, alpha and top-left corner of the object in frame k."""
        image, alpha = self.sprites["front"]
        if self.turned[k] > 0:
            image = (1 - self.turned[k]) * image + self.turned[k] * self.sprites["back"][0]
        sw, sh = self.sizes[k].tolist()
        if (sw, sh) != (alpha.shape[1], alpha.shape[0]):
            image = cv2.resize(image, (sw, sh), interpolation=cv2.INTER_LINEAR)
            alpha = cv2.resize(alpha, (sw, sh), interpolation=cv2.INTER_LINEAR)
        if self.angles[k] != 0:
            image, alpha = _rotated(image, alpha, self.angles[k])
        h, w = alpha.shape
        return image, alpha, int(round(self.centres[k, 0] - w / 2)), int(round(self.centres[k, 1] - h / 2))


def _rotated(image: np.ndarray, alpha: np.ndarray, degrees: float) -> tuple[np.ndarray, np.ndarray]:
    """A sprite turned by ``degrees`` (anticlockwise) about its centre, on the smallest canvas that holds it."""
    h, w = alpha.shape
    nw, nh = _rotated_size(w, h, degrees)
    turn = cv2.getRotationMatrix2D(((w - 1) / 2, (h - 1) / 2), float(degrees), 1.0)
    turn[:, 2] += ((nw - w) / 2, (nh - h) / 2)
    return (cv2.warpAffine(image, turn, (nw, nh), flags=cv2.INTER_LINEAR),
            cv2.warpAffine(alpha, turn, (nw, nh), flags=cv2.INTER_LINEAR))


def _rotated_size(w: int, h: int, degrees: float) -> tuple[int, int]:
    """Width and height of the smallest canvas that holds a w x h sprite turned by ``degrees``."""
    cos, sin = abs(np.cos(np.radians(degrees))), abs(np.sin(np.radians(degrees)))
    return tuple(int(np.ceil(v - 1e-6)) for v in (w * cos + h * sin, w * sin + h * cos))


@njit(cache=True)
def _composite(image, colour, alpha, x0, y0):
    """``image <- image (1 - a) + colour a`` over the pixels of a sprite at (x0, y0) that lie in the frame,
    in numpy's types and order: (1 - a) in alpha's type, each product in its operands' type, the sum
    rounded to the image's float32."""
    height, width = image.shape[0], image.shape[1]
    one = np.float32(1.0)
    for y in range(max(y0, 0), min(y0 + alpha.shape[0], height)):
        for x in range(max(x0, 0), min(x0 + alpha.shape[1], width)):
            a = alpha[y - y0, x - x0]
            keep = one - a
            for c in range(3):
                image[y, x, c] = image[y, x, c] * keep + colour[y - y0, x - x0, c] * a
    return image


@njit(cache=True)
def _exposed(image, noise):
    """``np.clip(image + noise, 0, 255).astype(np.uint8)`` in one pass over float32 arrays: the float32 sum,
    clipped, truncated to uint8, as numpy computes each step."""
    out = np.empty(image.shape, np.uint8)
    flat_in, flat_noise, flat_out = image.reshape(-1), noise.reshape(-1), out.reshape(-1)
    for i in range(flat_in.size):
        x = flat_in[i] + flat_noise[i]
        flat_out[i] = np.uint8(0.0 if x < 0 else (255.0 if x > 255 else x))
    return out


@njit(cache=True)
def _label(labels, alpha, x0, y0, value):
    """``value`` into ``labels`` where the sprite at (x0, y0) is solid (alpha > 0.5) inside the frame; the
    sprite's solid pixels, inside the frame or not."""
    height, width = labels.shape
    solid = 0
    for y in range(alpha.shape[0]):
        for x in range(alpha.shape[1]):
            if alpha[y, x] > 0.5:
                solid += 1
                if 0 <= y + y0 < height and 0 <= x + x0 < width:
                    labels[y + y0, x + x0] = value
    return solid


@njit(cache=True)
def _count(labels, alpha, x0, y0, value):
    """The pixels labelled ``value`` under the sprite's box at (x0, y0) (where ``value`` can be)."""
    height, width = labels.shape
    found = 0
    for y in range(max(y0, 0), min(y0 + alpha.shape[0], height)):
        for x in range(max(x0, 0), min(x0 + alpha.shape[1], width)):
            found += labels[y, x] == value
    return found


class SyntheticScene:
    """A rendered scene: ``frame(k)``, ``truth`` (T, M, 4), ``visibility`` (T, M)."""

    def __init__(self, spec: dict, name: str = "synthetic", stand_in: str | None = None):
        targets = [dict(t, depth=t.get("depth", 0) + i) for t in spec.get("targets", []) for i in range(t.get("copies", 1))]
        spec = {**spec, "targets": targets}
        self.spec, self.name, self.stand_in = spec, name, stand_in
        _require("size" in spec and "frames" in spec, "a scene needs size: [width, height] and frames:")
        self.size = tuple(int(v) for v in spec["size"])
        self.n_frames = int(spec["frames"])
        _require(self.size[0] >= 8 and self.size[1] >= 8 and self.n_frames >= 1, "scene too small")
        _require(len(spec.get("targets", [])) >= 1, "a scene needs at least one target")
        self.seed = int(spec.get("seed", 0))
        rng = np.random.default_rng(self.seed)
        self.background = self._background(spec.get("background", {"kind": "flat"}), rng)
        self.objects = [self._object(t, i, rng) for i, t in enumerate(spec["targets"])]
        hidden_motion = spec.get("hidden_motion", "with_occluder")
        _require(hidden_motion in HIDDEN_MOTIONS, f"unknown hidden_motion {hidden_motion!r}; choose one of {HIDDEN_MOTIONS}")
        for obj in self.objects:
            hidden = obj.spec.get("motion", {}).get("hidden")
            if hidden and hidden_motion == "own_velocity":
                drawn = 2 * (min(obj.spec["size"]) // 2 - 1)  # the disc sprite() draws
                obj.centres = own_velocity_path(obj.centres, self.objects[hidden["behind"]].centres, hidden["frames"], drawn)
        self.objects += [self._object(o, None, rng) for o in spec.get("occluders", [])]
        self.order = sorted(range(len(self.objects)), key=lambda i: -self.objects[i].depth)  # far to near
        frames = np.arange(self.n_frames)
        self.gain = np.ones(self.n_frames)
        for change in spec.get("illumination", []):
            self.gain *= 1.0 + (change["gain"] - 1.0) * _ramp(frames, change["start"], change["end"])
        self.camera_noise = float(spec.get("camera_noise", 0.0))
        if self.camera_noise > 0:  # one bank of noise; frame k reads it from its own random offset
            pixels = self.size[0] * self.size[1] * 3
            self._noise = self.camera_noise * rng.standard_normal(pixels + NOISE_OFFSETS, dtype=np.float32)
        self.truth = np.stack([obj.box.astype(float) for obj in self.objects if obj.target is not None], axis=1)

    def _object(self, spec: dict, target: int | None, rng: np.random.Generator) -> _Object:
        frames = np.arange(self.n_frames)
        centres = trajectory(spec.get("motion", {"kind": "scripted", "keyframes": [[0, *np.divide(self.size, 2)]]}),
                             self.n_frames, self.size, rng)
        keys = np.asarray(spec.get("scale", [[0, 1.0]]), dtype=float)
        scales = np.interp(frames, keys[:, 0], keys[:, 1])
        turns = np.asarray(spec.get("rotation", [[0, 0.0]]), dtype=float)
        _require(turns.ndim == 2 and turns.shape[1] == 2, "rotation keyframes are [frame, degrees] rows")
        angles = np.interp(frames, turns[:, 0], turns[:, 1])
        turned = np.zeros(self.n_frames)
        for change in spec.get("appearance", []):
            _require(change.get("to") in ("back", "front"), "appearance changes go 'to: back' or 'to: front'")
            ramp = _ramp(frames, change["start"], change["end"])
            turned = np.maximum(turned, ramp) if change["to"] == "back" else np.minimum(turned, 1.0 - ramp)
        sprites = {"front": sprite(spec, "front", rng), "back": sprite(spec, "back", rng)}
        return _Object(spec, centres, scales, angles, turned, sprites, float(spec.get("depth", 1.0)), target)

    def _background(self, spec: dict, rng: np.random.Generator) -> np.ndarray:
        kind = spec.get("kind", "flat")
        _require(kind in BACKGROUNDS, f"unknown background {kind!r}; choose one of {BACKGROUNDS}")
        width, height = self.size
        colour = np.asarray(spec.get("colour", (90, 90, 90)), np.float32)
        if kind == "gradient":
            end = np.asarray(spec.get("to_colour", colour * 0.5), np.float32)
            ramp = np.linspace(0.0, 1.0, height, dtype=np.float32)[:, None, None]
            return np.broadcast_to(colour + (end - colour) * ramp, (height, width, 3)).copy()
        if kind == "flat":
            return np.broadcast_to(colour, (height, width, 3)).copy()
        scale, amplitude = int(spec.get("scale", 8)), spec.get("amplitude", 25.0)
        grid = (height // scale + 1, width // scale + 1)
        small = rng.normal(0.0, amplitude, (*grid, 1)) + rng.normal(0.0, spec.get("chroma", amplitude / 4), (*grid, 3))
        image = colour + cv2.resize(small.astype(np.float32), (width, height), interpolation=cv2.INTER_CUBIC)
        if kind == "clutter":  # patches coloured like a target: the hard case for colour-only tracking
            like = self.spec["targets"][int(spec.get("like_target", 0))]
            pw, ph = spec.get("patch_size", like["size"])
            left, top, right, bottom = spec.get("region", (0, 0, width, height))  # where the patches lie
            _require(0 <= left < right - pw <= width and 0 <= top < bottom - ph <= height,
                     f"clutter region {[left, top, right, bottom]} must fit {pw}x{ph} patches inside the frame")
            for _ in range(int(spec.get("patches", 10))):
                patch_spec = {**like, "size": [pw, ph], "structure": spec.get("patch_structure", False),
                              "shape": spec.get("patch_shape", "ellipse")}
                patch, alpha = sprite(patch_spec, "front", rng)
                if spec.get("patch_rotate"):  # the target's colours in another structure (its cross turned to an X)
                    turn = cv2.getRotationMatrix2D(((pw - 1) / 2, (ph - 1) / 2), float(spec["patch_rotate"]), 1.0)
                    patch = cv2.warpAffine(patch, turn, (pw, ph), borderMode=cv2.BORDER_REFLECT)
                x0, y0 = int(rng.integers(left, right - pw)), int(rng.integers(top, bottom - ph))
                region = image[y0 : y0 + ph, x0 : x0 + pw]
                region[:] = region * (1 - alpha[..., None]) + patch * alpha[..., None]
        return np.clip(image, 0, 255).astype(np.float32)

    def frame(self, k: int) -> np.ndarray:
        """Frame k as read-only uint8 BGR, rendered once per process (:mod:`replication.scenes.kept`): every
        run on this scene, every method of a repetition whose video is drawn per run, reads the same array."""
        return kept(self, k, lambda: self.render(k))

    def render(self, k: int) -> np.ndarray:
        """Frame k drawn anew as uint8 BGR: background, objects far to near, illumination, camera noise."""
        if not 0 <= k < self.n_frames:
            raise IndexError(f"frame {k} outside 0..{self.n_frames - 1}")
        image = self._canvas
        np.copyto(image, self.background)
        for index in self.order:
            colour, alpha, x0, y0 = self.objects[index].drawn(k)
            _composite(image, colour, alpha, x0, y0)
        if self.gain[k] != 1.0:
            image *= self.gain[k]
        if self.camera_noise > 0:
            offset = int(np.random.default_rng([self.seed, 1, k]).integers(NOISE_OFFSETS))
            return _exposed(image, self._noise[offset : offset + image.size].reshape(image.shape))
        return np.clip(image, 0, 255, out=image).astype(np.uint8)

    @cached_property
    def _canvas(self) -> np.ndarray:
        """The float frame :meth:`render` composes in, one per scene (a process runs one run at a time: every
        backend starts one thread per worker): a new 2 MB array per frame costs more in page faults than the
        drawing (the allocator can hand such arrays back to the system each time)."""
        return np.empty_like(self.background)

    @cached_property
    def visibility(self) -> np.ndarray:
        """(T, M) share of each target's sprite pixels visible in the frame (label buffer, near wins)."""
        width, height = self.size
        n_targets = self.truth.shape[1]
        visibility = np.zeros((self.n_frames, n_targets))
        labels = np.full((height, width), n_targets, np.intp)  # n_targets: background or an occluder
        for k in range(self.n_frames):
            areas, counts = np.zeros(n_targets), np.zeros(n_targets)
            placed = [(self.objects[index], *self.objects[index].drawn(k)[1:]) for index in self.order]
            for obj, alpha, x0, y0 in placed:  # far to near: the nearest label stays
                solid = _label(labels, alpha, x0, y0, n_targets if obj.target is None else obj.target)
                if obj.target is not None:
                    areas[obj.target] = solid
            for obj, alpha, x0, y0 in placed:
                if obj.target is not None:
                    counts[obj.target] = _count(labels, alpha, x0, y0, obj.target)
            for _, alpha, x0, y0 in placed:
                _label(labels, np.ones_like(alpha), x0, y0, n_targets)  # the background again, where sprites lay
            visibility[k] = np.divide(counts, areas, out=np.zeros(n_targets), where=areas > 0)
        return visibility
