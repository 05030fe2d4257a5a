"""Chopin's ``particles`` on the UNGM: the bootstrap PF (systematic resampling at every step,
ESSrmin = 1) and SQMC (``qmc=True``: ``ssm.Bootstrap`` with scrambled Sobol points and the
Hilbert sort), no history kept, the weighted mean and variance collected at every step (as ours
records them).

The UNGM of gps_qmcpf eqs (11)-(12), in ours' time t = 1..T: x_0 ~ N(x0, P0),
x_t = 0.5 x + 25 x / (1 + x^2) + 8 cos(1.2 (t - 1)) + N(0, Q), z_t = x_t^2 / 20 + N(0, R).
``particles`` observes y_0 at X_0, ours observes nothing at x_0: so y_0 here is a dummy 0 with a
Dirac law at 0 (every particle's weight 1) and y_t = z_t for t >= 1; its filtering means at
t = 1..T are ours'.  The seconds per step are of the whole run over T (its extra t = 0 included).
"""

import numpy as np
import particles
from harness import main
from particles import collectors
from particles import distributions as dists
from particles import state_space_models as ssm


class UNGM(ssm.StateSpaceModel):
    """Q, R, x0, P0 given as keywords (``--model``)."""

    def PX0(self):
        return dists.Normal(loc=self.x0, scale=np.sqrt(self.P0))

    def PX(self, t, xp):
        mean = 0.5 * xp + 25.0 * xp / (1.0 + xp**2) + 8.0 * np.cos(1.2 * (t - 1))
        return dists.Normal(loc=mean, scale=np.sqrt(self.Q))

    def PY(self, t, xp, x):
        if t == 0:
            return dists.Dirac(loc=np.zeros_like(x))
        return dists.Normal(loc=x**2 / 20.0, scale=np.sqrt(self.R))


def filtering_means(qmc: bool):
    def run(observations, n, model):
        fk = ssm.Bootstrap(ssm=UNGM(**model), data=[0.0, *observations])
        smc = particles.SMC(fk=fk, N=n, qmc=qmc, resampling="systematic", ESSrmin=1.0, store_history=False,
                            collect=[collectors.Moments()])
        smc.run()
        return [moments["mean"] for moments in smc.summaries.moments[1:]]

    return run


if __name__ == "__main__":
    main({"bootstrap PF step": filtering_means(qmc=False), "SQMC step": filtering_means(qmc=True)},
         ("particles", "numpy", "scipy"), per_step=True)
