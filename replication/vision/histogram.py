"""Kernel-weighted HSV colour histograms of many boxes in one pass.

The frame is converted once into an image of bin indices (OpenCV HSV: H in
[0, 180), S and V in [0, 256); at most 65535 bins).  Each box is read at a fixed pattern of K
sample points, given in coordinates normalised to the box ([-1, 1]^2): a dense
grid (one point per pixel of the reference box: "all pixels", resampled by
nearest neighbour when a particle's box has another size) or ``samples``
points drawn uniformly in the box (the hspf paper uses 100).  The kernel
weight of a point depends only on its normalised position, so the N x K bin
indices are gathered with one ``cv2.remap`` call and the N histograms come
out of one ``np.bincount``.

Kernels: ``epanechnikov`` is k(r) = 1 - r^2 with r^2 = (dx/hx)^2 + (dy/hy)^2
(Comaniciu et al. 2003; 0 outside the inscribed ellipse); ``diagonal`` is the
fusion_pf paper's eq (2), k(r) = 1 - r^2 with r = distance / h and
h = sqrt(hx^2 + hy^2), the half-diagonal; ``uniform`` weights every point
alike.  Sample points outside the image are dropped (the box is clipped); a
box with no sample inside gets an all-zero histogram, which the likelihood
turns into -inf.
"""

from dataclasses import dataclass
from functools import lru_cache

import cv2
import numpy as np

KERNELS = ("epanechnikov", "diagonal", "uniform")
BLOCK_SAMPLES = 100_000  # sample points per bincount: big enough to amortise the calls, small enough for cache


_SUM_CHANNELS = np.ones((1, 3), np.float32)


@lru_cache(maxsize=16)
def _contributions(bins: tuple[int, int, int]) -> np.ndarray:
    """(256, 1, 3) uint16 table: channel value -> its term in the joint bin index (OpenCV HSV ranges)."""
    bh, bs, bv = bins
    rows = [np.minimum(np.arange(256) * n // top, n - 1) * stride
            for n, top, stride in ((bh, 180, bs * bv), (bs, 256, bv), (bv, 256, 1))]
    return np.stack(rows, axis=-1)[:, None, :].astype(np.uint16)


def hsv_bin_image(frame: np.ndarray, bins: tuple[int, int, int]) -> np.ndarray:
    """(H, W) uint16 image of joint HSV bin indices ``(h * Bs + s) * Bv + v`` of a BGR frame."""
    if max(bins) > 256:
        raise ValueError(f"at most 256 bins per channel, got {bins}")
    terms = cv2.LUT(cv2.cvtColor(frame, cv2.COLOR_BGR2HSV), _contributions(tuple(bins)))
    return cv2.transform(terms, _SUM_CHANNELS)


def sample_pattern(kernel: str, grid: tuple[int, int] | None, samples: int | None, rng: np.random.Generator | None):
    """Normalised sample points (K, 2) in [-1, 1]^2 and their kernel weights (K,)."""
    if kernel not in KERNELS:
        raise ValueError(f"unknown kernel {kernel!r}; choose one of {KERNELS}")
    if samples is not None:
        if samples <= 0 or rng is None:
            raise ValueError("sampled histograms need samples > 0 and a generator")
        points = rng.uniform(-1.0, 1.0, (int(samples), 2))
    else:
        gw, gh = grid
        xs = (np.arange(gw) + 0.5) / gw * 2.0 - 1.0
        ys = (np.arange(gh) + 0.5) / gh * 2.0 - 1.0
        points = np.stack(np.meshgrid(xs, ys), axis=-1).reshape(-1, 2)
    r2 = (points**2).sum(axis=1)
    if kernel == "epanechnikov":
        weights = np.clip(1.0 - r2, 0.0, None)
    else:  # uniform; "diagonal" depends on each box's aspect ratio and is weighted in of_boxes
        weights = np.ones(len(points))
    keep = weights > 0
    return points[keep], weights[keep]


@dataclass
class ColourHistogram:
    """Histograms of boxes (cx, cy, w, h) in a frame, ``bins`` = (H, S, V) bin counts."""

    bins: tuple[int, int, int] = (8, 8, 4)
    kernel: str = "epanechnikov"
    grid: tuple[int, int] = (32, 32)
    samples: int | None = None
    rng: np.random.Generator | None = None

    def __post_init__(self):
        self.bins = tuple(int(b) for b in self.bins)
        if len(self.bins) != 3 or min(self.bins) < 1:
            raise ValueError(f"bins must be three positive counts, got {self.bins}")
        self.n_bins = int(np.prod(self.bins))
        if self.n_bins > 65535:
            raise ValueError(f"at most 65535 bins in all, got {self.n_bins}")
        self.points, self.weights = sample_pattern(self.kernel, tuple(self.grid), self.samples, self.rng)
        self._u, self._v = (self.points[:, i].astype(np.float32) for i in (0, 1))
        self._total_weight = float(self.weights.sum())  # of every sample of a box (fixed kernels)
        self._tile = np.empty((0, len(self.weights)))  # the weights of the most boxes asked for at once
        u2, v2 = self.points[:, 0] ** 2, self.points[:, 1] ** 2  # the diagonal kernel is 1 - v^2 - share (u^2 - v^2)
        self._one_minus_v2, self._u2_minus_v2 = (1.0 - v2)[None, :], (u2 - v2)[None, :]

    def of_boxes(self, bin_image: np.ndarray, boxes: np.ndarray) -> np.ndarray:
        """Normalised histograms (N, B) of ``boxes`` (N, 4) as centre x, centre y, width, height."""
        return np.vstack([
            np.divide(counts, totals[:, None], out=np.zeros_like(counts), where=totals[:, None] > 0)
            for counts, totals in self.counts(bin_image, boxes)
        ])

    def bhattacharyya(self, bin_image: np.ndarray, boxes: np.ndarray, reference: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """rho[p(box), q] for every box, and whether the box has a sample in the image.

        With counts c_u and total T, rho = sum_u sqrt(c_u / T) sqrt(q_u) =
        (sqrt(c) . sqrt(q)) / sqrt(T): no normalised (N, B) array is formed, and
        the square root is taken in place over the tally, whose spare column
        (points outside the image) meets a zero in sqrt(q).  T is the kernel's
        whole weight less that spare column.
        """
        root, rho, valid = np.append(np.sqrt(reference), 0.0), [], []
        for table, totals in self._tables(bin_image, boxes):
            inside = totals > 0
            rho.append(cv2.sqrt(table, table) @ root / np.sqrt(np.where(inside, totals, 1.0)))  # cv2: twice numpy's speed
            valid.append(inside)
        return np.concatenate(rho), np.concatenate(valid)

    def counts(self, bin_image: np.ndarray, boxes: np.ndarray):
        """Kernel-weighted bin counts (n, B) and their totals (n,) over samples inside the image, by blocks of boxes."""
        for table, totals in self._tables(bin_image, boxes):
            yield table[:, : self.n_bins], totals

    def _tables(self, bin_image: np.ndarray, boxes: np.ndarray):
        """Tallies (n, B + 1) and totals inside the image (n,), by blocks of boxes.

        One ``cv2.remap`` (nearest neighbour) gathers the bin indices of a block
        of boxes; points outside the image read a spare bin B; one
        ``np.bincount`` over box-offset indices gives the block's tallies.
        Blocks of about ``BLOCK_SAMPLES`` sample points keep the work in cache.
        """
        boxes = np.atleast_2d(np.asarray(boxes, dtype=float))
        block = max(1, BLOCK_SAMPLES // len(self.weights))
        for i in range(0, len(boxes), block):
            bins, weights = self.gather(bin_image, boxes[i : i + block])
            table = self.tally(bins, weights)
            row = weights.sum(axis=1) if self.kernel == "diagonal" else self._total_weight
            totals = row - table[:, -1]  # all the kernel's weight but the points outside the image
            totals[totals <= 1e-9 * row] = 0.0  # nothing inside, up to rounding
            yield table, totals

    def _tiled(self, n: int) -> np.ndarray:
        """The kernel weights repeated for n boxes (n, K): the first rows of one array, grown to the
        largest n asked for (at most a block), not one array per n (MCMC asks for a different n each call)."""
        if len(self._tile) < n:
            self._tile = np.tile(self.weights, (n, 1))
        return self._tile[:n]

    def gather(self, bin_image: np.ndarray, boxes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Bin index (n, K) of every sample point of ``boxes`` (n, >= 4: cx, cy, w, h), the spare bin B
        for points outside the image, and each point's kernel weight (n, K): one ``cv2.remap``."""
        n, spare = len(boxes), self.n_bins
        single = boxes.astype(np.float32)
        # sample k of box n sits at (cx + u_k w / 2, cy + v_k h / 2); pixel p covers [p, p + 1)
        map_x = single[:, 0:1] - 0.5 + self._u[None, :] * (single[:, 2:3] / 2)
        map_y = single[:, 1:2] - 0.5 + self._v[None, :] * (single[:, 3:4] / 2)
        gathered = cv2.remap(
            bin_image, map_x, map_y, cv2.INTER_NEAREST, borderMode=cv2.BORDER_CONSTANT, borderValue=spare
        )
        if self.kernel == "diagonal":  # r^2 = (u^2 hx^2 + v^2 hy^2) / (hx^2 + hy^2): fusion_pf eq (2)
            share = boxes[:, 2:3] ** 2 / (boxes[:, 2:3] ** 2 + boxes[:, 3:4] ** 2)
            weights = self._one_minus_v2 - share * self._u2_minus_v2
        else:
            weights = self._tiled(n)
        return gathered.astype(np.intp), weights

    def tally(self, bins: np.ndarray, weights: np.ndarray) -> np.ndarray:
        """Kernel-weighted counts (n, B + 1) of gathered ``bins`` (the last column: points outside the
        image), one ``np.bincount`` over box-offset indices."""
        n, width = len(bins), self.n_bins + 1
        index = bins + width * np.arange(n, dtype=np.intp)[:, None]
        return np.bincount(index.ravel(), weights=weights.ravel(), minlength=n * width).reshape(n, width)
