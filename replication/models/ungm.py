"""The univariate nonstationary growth model (Kitagawa, 1987; Gordon et al., 1993)."""

from dataclasses import dataclass

from replication.compiled import elementwise
from replication.libm import cos
from replication.models.additive import AdditiveGaussianModel


@elementwise("float64(float64, float64)")
def _growth(x, drift):
    """0.5 x + 25 x / (1 + x^2) + drift, in numpy's operations and order: one compiled pass."""
    return 0.5 * x + 25.0 * x / (1.0 + x * x) + drift


@elementwise("float64(float64)")
def _square_over_20(x):
    return x * x / 20.0


@dataclass(frozen=True)
class UNGM(AdditiveGaussianModel):
    """gps_qmcpf eqs (11)-(12):

    x_t = 0.5 x_{t-1} + 25 x_{t-1} / (1 + x_{t-1}^2) + 8 cos(1.2 (t - 1)) + w_t,
    z_t = x_t^2 / 20 + v_t.

    The hspf paper prints 25x/(1 + x); we read it as 1 + x^2, as every other source does.
    """

    def f(self, x, t):
        return _growth(x, 8.0 * cos(1.2 * (t - 1)))

    def h(self, x):
        return _square_over_20(x)
