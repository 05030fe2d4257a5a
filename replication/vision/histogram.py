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

The likelihood's hot path, :meth:`ColourHistogram.bhattacharyya`, is a compiled
kernel (:func:`_bhattacharyya_kernel`) that reads each box's sample points and
accumulates its weighted histogram and Bhattacharyya sum in one pass, without
the (N, K) maps and (N, B) tallies of the vectorised numpy path (still there as
:meth:`ColourHistogram.bhattacharyya_numpy`, the reference the kernel is tested
against).  It picks the same pixels (float32 coordinates rounded half to even,
as ``cv2.remap``'s nearest neighbour does) and adds the same weights in the same
order per bin, so the counts are bit-identical; only the final dot product's
order of summation differs from BLAS's (about 1e-16).  Boxes whose samples fall on
the same pixels (most of a fixed-size particle cloud's: :func:`_same_pattern`) are
read once, each getting the numbers it would get alone.
"""

import weakref
from dataclasses import dataclass
from functools import lru_cache

import cv2
import numpy as np
from numba import njit, uint64

from replication.compiled import pairwise_sum
from replication.vision.derived import derived

KERNELS = ("epanechnikov", "diagonal", "uniform")
GROUP = 8  # boxes the compiled kernel reads side by side (see _bhattacharyya_kernel; its fast path spells out 8)
BLOCK_SAMPLES = 100_000  # sample points per bincount: big enough to amortise the calls, small enough for cache


@lru_cache(maxsize=16)
def _contributions(bins: tuple[int, int, int]) -> np.ndarray:
    """(256, 3) uint16 table: channel value -> its term in the joint bin index (OpenCV HSV ranges)."""
    bh, bs, bv = bins
    rows = [np.minimum(np.arange(256) * n // top, n - 1) * stride
            for n, top, stride in ((bh, 180, bs * bv), (bs, 256, bv), (bv, 256, 1))]
    return np.stack(rows, axis=-1).astype(np.uint16)


def hsv_bin_image(frame: np.ndarray, bins: tuple[int, int, int]) -> np.ndarray:
    """(H, W) uint16 image of joint HSV bin indices ``(h * Bs + s) * Bv + v`` of a BGR frame.

    A read-only frame (one a sequence keeps for its next run: :mod:`replication.scenes.kept`) gets its bin
    image computed once per ``bins`` and kept while the frame lives (:mod:`replication.vision.derived`)."""
    if max(bins) > 256:
        raise ValueError(f"at most 256 bins per channel, got {bins}")
    bins = tuple(bins)
    return derived(frame, ("hsv bins", bins), lambda: _bin_image(frame, bins))


def _bin_image(frame: np.ndarray, bins: tuple[int, int, int]) -> np.ndarray:
    return _joint_bins(cv2.cvtColor(frame, cv2.COLOR_BGR2HSV), _contributions(bins))


@njit(cache=True)
def _joint_bins(hsv, terms):
    """Each pixel's ``terms[h, 0] + terms[s, 1] + terms[v, 2]``, in one pass over the HSV image (what
    ``cv2.LUT`` then ``cv2.transform`` with weights (1, 1, 1) give in two: the sum is below 65536, exact)."""
    height, width = hsv.shape[0], hsv.shape[1]
    out = np.empty((height, width), np.uint16)
    for y in range(height):
        for x in range(width):
            out[y, x] = terms[hsv[y, x, 0], 0] + terms[hsv[y, x, 1], 1] + terms[hsv[y, x, 2], 2]
    return out


_LARGEST_BIN: list = [None, 0]  # (weak reference to) the last bin image checked, and its largest bin


def _largest_bin(image: np.ndarray) -> int:
    """The largest bin index in ``image``, found once per image (every target's likelihood reads
    the same frame's bin image; the frame's bin image is not changed in place)."""
    seen = _LARGEST_BIN[0]
    if seen is None or seen() is not image:
        _LARGEST_BIN[:] = weakref.ref(image), int(image.max()) if image.size else 0
    return _LARGEST_BIN[1]


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
        self._runs = _pattern_runs(self.points, None if self.samples is not None else tuple(self.grid))

    def of_boxes(self, bin_image: np.ndarray, boxes: np.ndarray) -> np.ndarray:
        """Normalised histograms (N, B) of ``boxes`` (N, 4) as centre x, centre y, width, height."""
        return np.vstack([
            np.divide(counts, totals[:, None], out=np.zeros_like(counts), where=totals[:, None] > 0)
            for counts, totals in self.counts(bin_image, boxes)
        ])

    def bhattacharyya(self, bin_image: np.ndarray, boxes: np.ndarray, reference: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """rho[p(box), q] for every box, and whether the box has a sample in the image.

        With counts c_u and total T, rho = sum_u sqrt(c_u / T) sqrt(q_u) =
        (sqrt(c) . sqrt(q)) / sqrt(T), T being the kernel's weight of the samples
        inside the image.  One compiled pass over each box's samples
        (:func:`_bhattacharyya_kernel`); :meth:`bhattacharyya_numpy` is the same
        computation in numpy.
        """
        boxes = np.ascontiguousarray(np.atleast_2d(np.asarray(boxes, dtype=float))[:, :4])
        image = np.ascontiguousarray(bin_image, dtype=np.uint16)
        if _largest_bin(image) >= self.n_bins:  # the kernel indexes its histograms by bin, unchecked
            raise ValueError(f"the bin image has bins up to {_largest_bin(image)}, this histogram {self.n_bins}")
        us, vs, rows, first_column, last_column, first_sample = self._runs
        return _bhattacharyya_kernel(
            image, boxes, us, vs, rows, first_column, last_column, first_sample, self.weights,
            self._one_minus_v2[0], self._u2_minus_v2[0], self.kernel == "diagonal", self._total_weight,
            np.sqrt(np.asarray(reference, dtype=float)[: self.n_bins]),
        )

    def bhattacharyya_numpy(self, bin_image: np.ndarray, boxes: np.ndarray, reference: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`bhattacharyya` by ``cv2.remap`` and ``np.bincount`` over blocks of boxes (the path
        before the compiled kernel, kept as its reference).

        The square root is taken in place over the tally, whose spare column
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


def _pattern_runs(points: np.ndarray, grid: tuple[int, int] | None):
    """The sample pattern as runs for :func:`_bhattacharyya_kernel`: the distinct normalised
    column and row positions (float32, as ``gather`` uses them) and, per run of samples on one row
    at consecutive columns, its row, first and last + 1 column and first sample.

    A grid's kept points (row-major, the epanechnikov ellipse cutting the corners) form one run per
    row; sampled points each form their own run, column and row.
    """
    if grid is None:
        k = len(points)
        index = np.arange(k)
        us, vs, columns, rows = points[:, 0], points[:, 1], index, index
    else:
        gw, gh = grid
        us = (np.arange(gw) + 0.5) / gw * 2.0 - 1.0
        vs = (np.arange(gh) + 0.5) / gh * 2.0 - 1.0
        columns = np.rint((points[:, 0] + 1.0) / 2.0 * gw - 0.5).astype(np.int64)
        rows = np.rint((points[:, 1] + 1.0) / 2.0 * gh - 0.5).astype(np.int64)
        if not (np.array_equal(us[columns], points[:, 0]) and np.array_equal(vs[rows], points[:, 1])):
            raise AssertionError("a grid point is not on the grid")  # cannot happen: sample_pattern's meshgrid
    starts = np.flatnonzero(np.r_[True, (rows[1:] != rows[:-1]) | (columns[1:] != columns[:-1] + 1)])
    ends = np.r_[starts[1:], len(points)]
    return (us.astype(np.float32), vs.astype(np.float32), rows[starts].astype(np.int64),
            columns[starts].astype(np.int64), (columns[starts] + ends - starts).astype(np.int64), starts.astype(np.int64))


@njit(cache=True)
def _weight(weights, one_minus_v2, u2_minus_v2, share, k):
    """Sample k's kernel weight: the fixed kernel's (``share`` = -1), or the diagonal kernel's
    1 - v^2 - share (u^2 - v^2) with share = w^2 / (w^2 + h^2), as ``gather`` computes it."""
    return weights[k] if share < 0 else one_minus_v2[k] - share * u2_minus_v2[k]


@njit(cache=True)
def _pixel_offsets(boxes, b, us, vs, width, height, column, g, row):
    """Pixel column (or -1 outside the image) of each pattern column of box b, into
    ``column[i * GROUP + g]``, and row offset (row * width, or -1) of each pattern row, into
    ``row[j]``: ``gather``'s float32 arithmetic and ``cv2.remap``'s rounding to nearest, half to
    even.  Whether every one is inside the image."""
    half, two = np.float32(0.5), np.float32(2.0)
    ox, oy = np.float32(boxes[b, 0]) - half, np.float32(boxes[b, 1]) - half
    hw, hh = np.float32(boxes[b, 2]) / two, np.float32(boxes[b, 3]) / two
    inside = True
    for i in range(us.size):
        x = np.rint(ox + us[i] * hw)
        if x >= 0 and x <= width - 1:
            column[i * GROUP + g] = np.int64(x)
        else:
            column[i * GROUP + g], inside = -1, False
    for j in range(vs.size):
        y = np.rint(oy + vs[j] * hh)
        if y >= 0 and y <= height - 1:
            row[j] = np.int64(y) * width
        else:
            row[j], inside = -1, False
    return inside


@njit(cache=True)
def _same_pattern(boxes, us, vs, width, height):
    """source[b]: the first box whose samples fall on the same pixels as box b's (b itself if none, or if
    that cannot be told safely).  Such boxes have the same counts and total, so the kernel reads one of them.

    Only boxes of one size are compared (a fixed-size model's cloud, where a quarter of 400 particles' boxes,
    or fewer, fall on pixels another box has: pixels are coarser than the cloud); boxes of drifting sizes
    almost never do, and get source[b] = b at no cost.  With one size, sample i of a box with corner o (its
    centre less half a pixel, float32, as :func:`_pixel_offsets` has it) reads pixel rint(o + s_i), s_i the
    sample's offset; writing o = n + f (n an integer, 0 <= f < 1), that pixel is n + a constant + [f >= beta_i]
    with beta_i = 1 - frac(s_i + 1/2), unless o + s_i lies within rounding of a half pixel.  So the pattern
    of a box is fixed by (n, #{i : beta_i <= f}) on each axis (:func:`_cell`), and a box whose f lies within
    ``eps`` of a beta_i or of 0 or 1 (eps far above float32's rounding of o + s_i) is left alone."""
    n = boxes.shape[0]
    source = np.arange(n)
    for b in range(1, n):
        if boxes[b, 2] != boxes[0, 2] or boxes[b, 3] != boxes[0, 3]:
            return source
    half, two = np.float32(0.5), np.float32(2.0)
    beta_x, reach_x = _edges_of_cells(us, np.float32(boxes[0, 2]) / two)
    beta_y, reach_y = _edges_of_cells(vs, np.float32(boxes[0, 3]) / two)
    keys = np.empty((n, 4), np.int64)
    slots = 1
    while slots < 2 * n:
        slots *= 2
    table = np.full(slots, -1, np.int64)  # open addressing: a box of each cell seen
    for b in range(n):
        column, count_x, safe_x = _cell(np.float64(np.float32(boxes[b, 0]) - half), beta_x, reach_x)
        row, count_y, safe_y = _cell(np.float64(np.float32(boxes[b, 1]) - half), beta_y, reach_y)
        if not (safe_x and safe_y):
            continue
        keys[b, 0], keys[b, 1], keys[b, 2], keys[b, 3] = column, count_x, row, count_y
        h = uint64(column) * uint64(0x9E3779B97F4A7C15) ^ uint64(row) * uint64(0xC2B2AE3D27D4EB4F)
        h ^= uint64(count_x * 64 + count_y) * uint64(0x165667B19E3779F9)
        slot = np.int64(h >> uint64(32)) & (slots - 1)
        while table[slot] >= 0:
            other = table[slot]
            if (keys[other, 0] == column and keys[other, 1] == count_x and keys[other, 2] == row
                    and keys[other, 3] == count_y):
                source[b] = other
                break
            slot = (slot + 1) & (slots - 1)
        if source[b] == b:
            table[slot] = b
    return source


@njit(cache=True)
def _edges_of_cells(offsets, scale):
    """The sorted beta_i = 1 - frac(s_i + 1/2) of a box's samples s_i = offsets_i * scale (float32, as
    :func:`_pixel_offsets` forms them; exact in float64), and the largest |s_i|."""
    beta = np.empty(offsets.size)
    reach = 0.0
    for i in range(offsets.size):
        shift = np.float64(offsets[i] * scale) + 0.5
        beta[i] = 1.0 - (shift - np.floor(shift))
        reach = max(reach, abs(shift))
    return np.sort(beta), reach


@njit(cache=True, inline="always")
def _cell(corner, beta, reach):
    """(n, #{i : beta_i <= f}, safe) of a box corner o = n + f, f past every beta_i counted as n + 1 and none
    (the same pixels); safe when f lies farther than eps from 0, 1 and every beta_i, eps = 1e-6 (|o| +
    max |s_i| + 1): sixteen times float32's rounding of o + s_i."""
    whole = np.floor(corner)
    f = corner - whole
    nearest = min(f, 1.0 - f)
    count = 0
    for i in range(beta.size):
        nearest = min(nearest, abs(f - beta[i]))
        count += f >= beta[i]
    safe = nearest > 1e-6 * (abs(corner) + reach + 1.0) and abs(whole) < 2.0**52
    if count == beta.size:
        whole, count = whole + 1.0, 0
    return np.int64(whole) if safe else 0, count, safe


@njit(cache=True, error_model="numpy")  # IEEE division: a zero-size diagonal-kernel box gives NaN, as numpy does
def _bhattacharyya_kernel(image, boxes, us, vs, rows, first_column, last_column, first_sample, weights,
                          one_minus_v2, u2_minus_v2, diagonal, total_weight, root):
    """rho and validity of every box: :meth:`ColourHistogram.bhattacharyya` in one pass per box.

    Boxes are read ``GROUP`` (8) at a time, side by side, each into its own histogram,
    interleaved (``hist[bin * GROUP + box]``): an update of a bin waits on the previous update of
    that bin, and neighbouring pixels mostly share a bin, so eight independent histograms keep
    the processor busy where one would wait.  A group whose samples all lie inside the image
    takes that fast path; otherwise each of its boxes is read alone, its samples outside the
    image going to a spare bin.  Each bin gets its weights in the order of the samples, as
    ``np.bincount`` adds them, and the diagonal kernel's total is summed in numpy's order, so
    the counts and totals are bit-identical to the numpy path's.  Only the bins of the reference
    (q_u > 0) are square-rooted: another bin adds sqrt(c_u) 0, nothing, to rho; the group's
    histograms are then reset at once.
    """
    height, width = image.shape
    flat = image.ravel()
    n, n_bins = boxes.shape[0], root.size
    rho, valid = np.zeros(n), np.zeros(n, np.bool_)
    hist = np.zeros((n_bins + 1) * GROUP)
    column = np.empty(us.size * GROUP, np.int64)
    row = np.empty((GROUP, vs.size), np.int64)
    share = np.full(GROUP, -1.0)  # the diagonal kernel's w^2 / (w^2 + h^2) per box; -1: a fixed kernel
    whole = np.full(GROUP, total_weight)  # the kernel's weight over all the samples of each box
    diagonal_weights = np.empty(weights.size)
    support = np.flatnonzero(root != 0.0)  # the reference's bins, in order
    G = uint64(GROUP)
    source = _same_pattern(boxes, us, vs, width, height)
    todo = np.flatnonzero(source == np.arange(n))  # one box of each pattern
    for start in range(0, todo.size, GROUP):
        m = min(GROUP, todo.size - start)
        fast = m == GROUP
        for g in range(m):
            b = todo[start + g]
            if not _pixel_offsets(boxes, b, us, vs, width, height, column, g, row[g]):
                fast = False
            if diagonal:  # r^2 = (u^2 hx^2 + v^2 hy^2) / (hx^2 + hy^2): fusion_pf eq (2)
                share[g] = boxes[b, 2] ** 2 / (boxes[b, 2] ** 2 + boxes[b, 3] ** 2)
                for k in range(weights.size):
                    diagonal_weights[k] = _weight(weights, one_minus_v2, u2_minus_v2, share[g], k)
                whole[g] = pairwise_sum(diagonal_weights)
        if fast and not diagonal:
            for r in range(rows.size):
                j = rows[r]
                shift = uint64(first_sample[r] - first_column[r])
                y0, y1, y2, y3 = uint64(row[0, j]), uint64(row[1, j]), uint64(row[2, j]), uint64(row[3, j])
                y4, y5, y6, y7 = uint64(row[4, j]), uint64(row[5, j]), uint64(row[6, j]), uint64(row[7, j])
                for i in range(first_column[r], last_column[r]):
                    c = uint64(i) * G
                    w = weights[uint64(i) + shift]
                    hist[uint64(flat[y0 + uint64(column[c])]) * G] += w
                    hist[uint64(flat[y1 + uint64(column[c + uint64(1)])]) * G + uint64(1)] += w
                    hist[uint64(flat[y2 + uint64(column[c + uint64(2)])]) * G + uint64(2)] += w
                    hist[uint64(flat[y3 + uint64(column[c + uint64(3)])]) * G + uint64(3)] += w
                    hist[uint64(flat[y4 + uint64(column[c + uint64(4)])]) * G + uint64(4)] += w
                    hist[uint64(flat[y5 + uint64(column[c + uint64(5)])]) * G + uint64(5)] += w
                    hist[uint64(flat[y6 + uint64(column[c + uint64(6)])]) * G + uint64(6)] += w
                    hist[uint64(flat[y7 + uint64(column[c + uint64(7)])]) * G + uint64(7)] += w
        elif fast:  # the same with each box's own diagonal-kernel weights
            s0, s1, s2, s3, s4, s5, s6, s7 = share[0], share[1], share[2], share[3], share[4], share[5], share[6], share[7]
            for r in range(rows.size):
                j = rows[r]
                shift = uint64(first_sample[r] - first_column[r])
                y0, y1, y2, y3 = uint64(row[0, j]), uint64(row[1, j]), uint64(row[2, j]), uint64(row[3, j])
                y4, y5, y6, y7 = uint64(row[4, j]), uint64(row[5, j]), uint64(row[6, j]), uint64(row[7, j])
                for i in range(first_column[r], last_column[r]):
                    c = uint64(i) * G
                    a, d = one_minus_v2[uint64(i) + shift], u2_minus_v2[uint64(i) + shift]
                    hist[uint64(flat[y0 + uint64(column[c])]) * G] += a - s0 * d
                    hist[uint64(flat[y1 + uint64(column[c + uint64(1)])]) * G + uint64(1)] += a - s1 * d
                    hist[uint64(flat[y2 + uint64(column[c + uint64(2)])]) * G + uint64(2)] += a - s2 * d
                    hist[uint64(flat[y3 + uint64(column[c + uint64(3)])]) * G + uint64(3)] += a - s3 * d
                    hist[uint64(flat[y4 + uint64(column[c + uint64(4)])]) * G + uint64(4)] += a - s4 * d
                    hist[uint64(flat[y5 + uint64(column[c + uint64(5)])]) * G + uint64(5)] += a - s5 * d
                    hist[uint64(flat[y6 + uint64(column[c + uint64(6)])]) * G + uint64(6)] += a - s6 * d
                    hist[uint64(flat[y7 + uint64(column[c + uint64(7)])]) * G + uint64(7)] += a - s7 * d
        else:
            spare = n_bins * GROUP
            for g in range(m):
                for r in range(rows.size):
                    y = row[g, rows[r]]
                    shift = first_sample[r] - first_column[r]
                    for i in range(first_column[r], last_column[r]):
                        w = _weight(weights, one_minus_v2, u2_minus_v2, share[g], i + shift)
                        x = column[i * GROUP + g]
                        if y < 0 or x < 0:
                            hist[spare + g] += w
                        else:
                            hist[np.int64(flat[y + x]) * GROUP + g] += w
        acc = np.zeros(GROUP)  # each box's sum of sqrt(c_u) sqrt(q_u), bin after bin
        for k in range(support.size):  # a bin is one cache line of its 8 boxes' counts
            u = support[k]
            for g in range(m):
                count = hist[u * GROUP + g]
                if count != 0.0:
                    acc[g] += np.sqrt(count) * root[u]
        for g in range(m):
            outside = hist[n_bins * GROUP + g]
            total = whole[g] - outside  # all the kernel's weight but the points outside the image
            if total <= 1e-9 * whole[g]:  # nothing inside, up to rounding
                total = 0.0
            s = acc[g]
            if np.isnan(outside):  # a NaN weight outside (a zero-size diagonal-kernel box): NaN, as numpy's dot
                s = np.nan
            elif np.isnan(share[g]):  # every weight of such a box is that NaN, as are its counts
                s = share[g]
            rho[todo[start + g]] = s / np.sqrt(total if total > 0 else 1.0)
            valid[todo[start + g]] = total > 0
        hist[:] = 0.0
    for b in range(n):  # a box on another's pixels has its histogram
        rho[b], valid[b] = rho[source[b]], valid[source[b]]
    return rho, valid
