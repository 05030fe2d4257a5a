"""State-space models with exact references where one exists."""

from replication.models.additive import AdditiveGaussianModel
from replication.models.linear_gaussian import LinearGaussian, kalman_filter
from replication.models.point_mass import point_mass_filter
from replication.models.ungm import UNGM

MODELS = {"ungm": UNGM, "linear_gaussian": LinearGaussian}

__all__ = ["MODELS", "UNGM", "AdditiveGaussianModel", "LinearGaussian", "kalman_filter", "point_mass_filter"]
