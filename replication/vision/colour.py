"""The colour-histogram likelihood: reference histogram q from the first frame, Bhattacharyya, Gaussian."""

from dataclasses import dataclass

import numpy as np

from replication.vision.histogram import ColourHistogram, hsv_bin_image
from replication.vision.likelihood import gaussian_similarity_log_likelihood


@dataclass
class ColourLikelihood:
    """p(z | box) = N(d; 0, sigma) with d = sqrt(1 - rho[p(box), q]) (ism_pf eq 30; hspf; gps_qmcpf eq 17)."""

    histogram: ColourHistogram
    reference: np.ndarray
    sigma: float = 0.1

    @classmethod
    def from_frame(cls, frame: np.ndarray, box: np.ndarray, histogram: ColourHistogram, sigma: float):
        """Reference histogram q of ``box`` (cx, cy, w, h) in ``frame``."""
        reference = histogram.of_boxes(hsv_bin_image(frame, histogram.bins), np.asarray(box)[None])[0]
        if reference.sum() == 0:
            raise ValueError("the reference box has no pixel inside the first frame")
        return cls(histogram, reference, sigma)

    def prepare(self, frame: np.ndarray) -> np.ndarray:
        return hsv_bin_image(frame, self.histogram.bins)

    def similarity(self, boxes: np.ndarray, bin_image: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """rho of each box against the reference, and whether the box is a box with a pixel in the image."""
        rho, inside = self.histogram.bhattacharyya(bin_image, boxes, self.reference)
        return rho, inside & (boxes[:, 2] > 0) & (boxes[:, 3] > 0)

    def log_likelihood(self, boxes: np.ndarray, bin_image: np.ndarray) -> np.ndarray:
        rho, valid = self.similarity(boxes, bin_image)
        return gaussian_similarity_log_likelihood(rho, self.sigma, valid)
