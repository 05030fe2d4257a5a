"""The command line and JSON output shared by the peer scripts (numpy and the standard library only:
each peer runs in its own venv, without the project).

A peer script maps what it times (``"bootstrap PF step"``, ``"resample (systematic)"``, ...) to
a function ``run(data, n, model)`` and calls :func:`main`.  ``data`` is the array in
``--data`` (the UNGM's observations z_1..z_T, or the normalised weights to resample), ``model``
the UNGM's parameters in ``--model``.  Each function runs once untimed at the same N (imports,
first calls, the allocator's first pages: on ``data[:2]``, two steps of a filter, or on all the
weights of a resampler), then ``--repeats`` times timed.  The JSON written to ``--out`` holds, per
what, the seconds of each repeat (per step of the T steps with ``per_step``, else per call) and
its estimates, ``estimates(result, data)`` computed after the clock stops (the filtering means a
filter returns, or what a resampler's indices estimate).
"""

import argparse
import json
import time
from collections.abc import Callable
from importlib.metadata import version

import numpy as np


def arguments() -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", required=True, help=".npy: observations z_1..z_T, or weights")
    parser.add_argument("--n", type=int, required=True, help="particles")
    parser.add_argument("--repeats", type=int, default=1)
    parser.add_argument("--seed", type=int, default=0, help="seeds numpy's global generator")
    parser.add_argument("--model", type=json.loads, default="{}", help='the UNGM: {"Q", "R", "x0", "P0"}')
    parser.add_argument("--out", required=True, help="where the JSON goes")
    return parser.parse_args()


def main(runs: dict[str, Callable], packages: tuple[str, ...], per_step: bool,
         estimates: Callable = lambda result, data: result) -> None:
    args = arguments()
    data = np.load(args.data)
    np.random.seed(args.seed)
    results = []
    for what, run in runs.items():
        run(data[:2] if per_step else data, args.n, args.model)
        seconds, estimated = [], []
        for _ in range(args.repeats):
            started = time.perf_counter()
            result = run(data, args.n, args.model)
            seconds.append((time.perf_counter() - started) / (len(data) if per_step else 1))
            estimated.append(np.asarray(estimates(result, data), dtype=float).tolist())
        results.append({"what": what, "N": args.n, "seconds": seconds, "estimates": estimated})
    with open(args.out, "w") as out:
        json.dump({"versions": {name: version(name) for name in packages}, "results": results}, out)
