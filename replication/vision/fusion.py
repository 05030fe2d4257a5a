"""fusion_pf's observation model: colour and structure similarities fused with adaptive coefficients.

For a particle's box, rho is the Bhattacharyya coefficient of its kernel
colour histogram against the first frame's (eqs 1-3) and S the structural
similarity of the grey ``square`` x ``square`` px patch centred on the
particle against the first frame's patch (eq 4).  The weight is eq (5),

    w = exp(([alpha_k rho + beta_k S] - 1) / (2 sigma^2)) / (sqrt(2 pi) sigma),

with sigma = 1 in the paper ("the standard normal density").  After each
frame the coefficients move to the similarities at the estimated state
(eqs 6-7): alpha = rho' / (rho' + S'), beta = S' / (rho' + S').  SSIM can be
negative (inverted structure) and eq (7) would then give a negative beta: S'
is clipped at 0 in the update, so beta stays in [0, 1] (our choice; the
paper is silent).  With ``adaptive = False`` the coefficients stay at their
initial values: alpha = 1 is the colour-only filter, whose weight does not
depend on S, so S is not computed.
"""

from dataclasses import dataclass, field

import cv2
import numpy as np

from replication.vision.colour import ColourLikelihood
from replication.vision.derived import derived
from replication.vision.histogram import ColourHistogram
from replication.vision.likelihood import gaussian_similarity_log_likelihood
from replication.vision.ssim import patches, structural_similarity


def fusion_coefficients(rho: float, s: float) -> tuple[float, float]:
    """(alpha, beta) of eqs (6)-(7) at the estimated state; S' < 0 counts as 0, and (rho', S') = 0 gives (1, 0)."""
    rho, s = max(float(rho), 0.0), max(float(s), 0.0)
    if rho + s == 0.0:
        return 1.0, 0.0
    return rho / (rho + s), s / (rho + s)


def grey(frame: np.ndarray) -> np.ndarray:
    """The frame's grey levels (uint8), once per kept frame (:mod:`replication.vision.derived`)."""
    return derived(frame, "grey", lambda: cv2.cvtColor(frame, cv2.COLOR_BGR2GRAY))


@dataclass
class FusionLikelihood:
    """p(z | box) by eq (5); ``alpha`` is alpha_k (beta_k = 1 - alpha_k), updated by :meth:`adapt`."""

    colour: ColourLikelihood  # rho against q, the first frame's colour histogram (its sigma is not used)
    template: np.ndarray  # the first frame's grey square patch
    sigma: float = 1.0
    alpha: float = 0.5
    adaptive: bool = True
    history: list = field(default_factory=list)  # alpha_k after each frame

    def __post_init__(self):
        if not 0.0 <= self.alpha <= 1.0:
            raise ValueError(f"alpha must lie in [0, 1], got {self.alpha}")

    @classmethod
    def from_frame(cls, frame, box, histogram: ColourHistogram, sigma: float = 1.0, square: int = 20,
                   alpha: float = 0.5, adaptive: bool = True):
        """The colour reference of ``box`` (cx, cy, w, h) and the grey template of the square around its centre."""
        box = np.asarray(box, dtype=float)
        colour = ColourLikelihood.from_frame(frame, box, histogram, sigma)
        if square < 2:
            raise ValueError(f"the structure template needs at least 2 px, got {square}")
        template, _ = patches(grey(frame), np.array([[box[0], box[1], square, square]]), (square, square))
        return cls(colour, template[0], sigma, alpha, adaptive)

    def prepare(self, frame: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return self.colour.prepare(frame), grey(frame)

    def similarities(self, boxes: np.ndarray, prepared, structure: bool = True):
        """rho (eq 3), S (eq 4; zeros when not asked for) and whether each box has a pixel in the image."""
        bin_image, grey_image = prepared
        rho, valid = self.colour.similarity(boxes, bin_image)
        s = np.zeros(len(boxes))
        if structure:
            square = self.template.shape[::-1]
            centred = np.column_stack([boxes[:, :2], np.broadcast_to(square, (len(boxes), 2))])
            s = structural_similarity(patches(grey_image, centred, square)[0], self.template)
        return rho, s, valid

    def log_likelihood(self, boxes: np.ndarray, prepared) -> np.ndarray:
        """log w of eq (5) for every box."""
        rho, s, valid = self.similarities(boxes, prepared, structure=self.alpha < 1.0)
        fused = self.alpha * rho + (1.0 - self.alpha) * s
        return gaussian_similarity_log_likelihood(fused, self.sigma, valid)

    def adapt(self, box: np.ndarray, prepared) -> None:
        """Eqs (6)-(7) at the estimated box (cx, cy, w, h); a fixed-coefficient filter only records alpha."""
        if self.adaptive:
            rho, s, _ = self.similarities(np.asarray(box, dtype=float)[None, :4], prepared)
            self.alpha, _ = fusion_coefficients(rho[0], s[0])
        self.history.append(self.alpha)
