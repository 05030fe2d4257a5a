"""Observation models on images, vectorised over particles: one call gives N log-likelihoods."""

from replication.vision.histogram import ColourHistogram, hsv_bin_image
from replication.vision.likelihood import bhattacharyya, bhattacharyya_distance, gaussian_similarity_log_likelihood
from replication.vision.ssim import structural_similarity

__all__ = [
    "ColourHistogram",
    "bhattacharyya",
    "bhattacharyya_distance",
    "gaussian_similarity_log_likelihood",
    "hsv_bin_image",
    "structural_similarity",
]
