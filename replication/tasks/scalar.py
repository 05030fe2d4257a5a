"""One filter on one simulated trajectory of a scalar state-space model."""

from replication.filters.registry import build_filter
from replication.metrics import filter_diagnostics, rmse
from replication.models import MODELS
from replication.run import Run
from replication.smc.loop import expect_output
from replication.smc.work import Counted, Work
from replication.stopwatch import Stopwatch


def build_model(params: dict):
    if params.get("name") not in MODELS:
        raise ValueError(f"unknown model {params.get('name')!r}; known models: {', '.join(sorted(MODELS))}")
    return MODELS[params["name"]](**{k: v for k, v in params.items() if k != "name"})


def check(model: dict, method: dict) -> None:
    build_model(model)


def run(run: Run) -> dict:
    """Simulate x_1..x_T, z_1..z_T from the ``data`` stream, filter with the ``filter`` stream, score.

    Every method at the same model condition and repetition sees the same
    trajectory (common random numbers), so paired differences between
    methods are much tighter than the unpaired intervals suggest.  The work
    it did is counted on its model (:mod:`replication.smc.work`).
    """
    model = build_model(run.model)
    states, observations = model.simulate(run.rng("data"))
    method, work = build_filter(run.method, run.method_params), Work()
    with Stopwatch() as stopwatch:
        output = method.run(Counted(model, work), observations, run.rng("filter"))
    output = expect_output(output, states.shape, run.method)  # a user's method may return anything
    return {
        "rmse": rmse(output.means, states),
        "ms_per_step": 1000.0 * stopwatch.wall / model.steps,
        "cpu_ms_per_step": 1000.0 * stopwatch.cpu / model.steps,
        **work.record(model.steps),
        **filter_diagnostics(output),
    }
