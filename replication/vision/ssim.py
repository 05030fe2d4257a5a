"""Structural similarity of grey patches (Wang et al. 2004; fusion_pf eq 4), many boxes in one call.

Every box is resampled to the template's size with one ``cv2.remap`` call over
all boxes stacked vertically (bilinear; points outside the image read as 0,
and the share of each patch inside the image is returned beside it), then

    S = (2 mu_x mu_y + C1) / (mu_x^2 + mu_y^2 + C1)
        * (2 sd_x sd_y + C2) / (sd_x^2 + sd_y^2 + C2)
        * (cov_xy + C3) / (sd_x sd_y + C3)

with Wang et al.'s C1 = (0.01 L)^2, C2 = (0.03 L)^2, C3 = C2 / 2, L = 255, which
keep S defined on flat patches (fusion_pf eq (4) has no constants).
"""

import cv2
import numpy as np

C1, C2 = (0.01 * 255) ** 2, (0.03 * 255) ** 2
C3 = C2 / 2


def patches(grey: np.ndarray, boxes: np.ndarray, size: tuple[int, int]) -> tuple[np.ndarray, np.ndarray]:
    """Grey patches (N, h, w) float32 of ``boxes`` (N, 4: cx, cy, w, h) and the share of each inside the image."""
    boxes = np.atleast_2d(boxes).astype(np.float32)
    tw, th = size
    n = len(boxes)
    u = (np.arange(tw, dtype=np.float32) + 0.5) / tw - 0.5
    v = (np.arange(th, dtype=np.float32) + 0.5) / th - 0.5
    map_x = boxes[:, 0, None, None] + u[None, None, :] * boxes[:, 2, None, None] - 0.5
    map_y = boxes[:, 1, None, None] + v[None, :, None] * boxes[:, 3, None, None] - 0.5
    map_x = np.broadcast_to(map_x, (n, th, tw)).reshape(n * th, tw)
    map_y = np.broadcast_to(map_y, (n, th, tw)).reshape(n * th, tw)
    sampled = cv2.remap(grey.astype(np.float32), map_x, map_y, cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT)
    height, width = grey.shape
    inside = (map_x >= -0.5) & (map_x <= width - 0.5) & (map_y >= -0.5) & (map_y <= height - 0.5)
    return sampled.reshape(n, th, tw), inside.reshape(n, -1).mean(axis=1)


def structural_similarity(candidates: np.ndarray, template: np.ndarray) -> np.ndarray:
    """S (N,) of each candidate patch (N, h, w) against ``template`` (h, w), global statistics per patch."""
    x = candidates.reshape(len(candidates), -1).astype(np.float64)
    y = template.reshape(-1).astype(np.float64)
    mu_x, mu_y = x.mean(axis=1), y.mean()
    sd_x, sd_y = x.std(axis=1), y.std()
    cov = ((x - mu_x[:, None]) * (y - mu_y)).mean(axis=1)
    luminance = (2 * mu_x * mu_y + C1) / (mu_x**2 + mu_y**2 + C1)
    contrast = (2 * sd_x * sd_y + C2) / (sd_x**2 + sd_y**2 + C2)
    structure = (cov + C3) / (sd_x * sd_y + C3)
    return luminance * contrast * structure
