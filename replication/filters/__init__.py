"""Filter variants.  Each is a small builder that returns an object with
``run(model, observations, rng) -> FilterOutput``; particle filters are the one
loop of :mod:`replication.smc.loop` with their own proposal or move.

A method in an experiment config names its builder with ``filter:`` and passes
the rest of its keys to it.  A task tracking targets in video drives every
method through :func:`replication.filters.tracker.tracker`: one interface for
one or many targets, the multi-target filters of :mod:`replication.filters.bis`
stepping all targets together, any other filter one per target.
"""

from typing import Any

from replication.errors import ConfigError
from replication.filters.bis import BISPF, MIPF, MRFJPF
from replication.filters.bootstrap import bootstrap
from replication.filters.dmot import DMOT
from replication.filters.harmony import hs, hspf
from replication.filters.ism import ism
from replication.filters.mcmc import MCMCPF
from replication.filters.mean_field import MFMC
from replication.filters.mean_shift import ms, mspf
from replication.filters.open_tracker import detections_only_tracker, sort_tracker
from replication.filters.opencv_trackers import dft, mil
from replication.filters.point_mass import PointMassFilter
from replication.filters.pso import pso
from replication.filters.qmc import gps_qmcpf, nqmcpf, tr_sqmc

FILTERS = {
    "bootstrap": bootstrap,
    "point_mass": PointMassFilter,
    "pso": pso,
    "ism": ism,
    "mipf": MIPF,
    "bis": BISPF,
    "mrf_jpf": MRFJPF,
    "mfmc": MFMC,
    "dmot": DMOT,
    "mcmc": MCMCPF,
    "nqmcpf": nqmcpf,
    "gps_qmcpf": gps_qmcpf,
    "tr_sqmc": tr_sqmc,
    "hspf": hspf,
    "hs": hs,
    "ms": ms,
    "mspf": mspf,
    "mil": mil,
    "sort": sort_tracker,
    "detections_only": detections_only_tracker,
    "dft": dft,
}


def build_filter(method: str, params: dict[str, Any], condition: str = ""):
    """Method ``method``'s filter from its config ``params`` (``filter:`` names the builder); a bad
    parameter is a one-line :class:`~replication.errors.ConfigError` naming the method."""
    kwargs = {k: v for k, v in params.items() if k not in ("filter", "label")}
    try:
        return FILTERS[params["filter"]](**kwargs)
    except (TypeError, ValueError) as error:
        where = f" at {condition}" if condition else ""
        raise ConfigError(f"method {method!r}{where}: {error}") from None


__all__ = [
    "BISPF",
    "DMOT",
    "FILTERS",
    "MCMCPF",
    "MFMC",
    "MIPF",
    "MRFJPF",
    "PointMassFilter",
    "bootstrap",
    "build_filter",
    "dft",
    "gps_qmcpf",
    "hs",
    "hspf",
    "ism",
    "mil",
    "ms",
    "mspf",
    "nqmcpf",
    "pso",
    "tr_sqmc",
]
