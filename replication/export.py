"""Tracking results in the result layouts of the OTB and GOT-10k toolkits, for other toolkits to re-score.

``export_results("hspf", "quick", "reports/quick/hspf/results", layout="got10k")`` reads the stored runs
of a tracking experiment and writes every run on a real OTB sequence, one box per frame, as the GOT-10k
toolkit (Huang, Zhao and Huang, TPAMI 2021; ``got10k.experiments``) records a tracker's results:

* ``layout="otb"``: ``<out>/OTB2015/<tracker>/<sequence>.txt`` and the per-frame times in
  ``<tracker>/times/<sequence>_time.txt`` (``ExperimentOTB``'s layout): one run per sequence, the
  first repetition, as OTB's one-pass evaluation runs each sequence once;
* ``layout="got10k"``: ``<out>/GOT-10k/<tracker>/<sequence>/<sequence>_001.txt``, ``_002.txt``, ...
  one file per repetition, and ``<sequence>_time.txt`` with a column of times per repetition
  (``ExperimentGOT10k``'s layout).

``<out>`` is what the toolkit calls ``result_dir``.  A box is a line ``x,y,w,h`` with 3 decimals in
OTB's 1-based pixel coordinates, as in its ``groundtruth_rect.txt`` (ours are 0-based, so x and y are
written plus 1; :mod:`replication.scenes.otb` reads the ground truth the other way); the first line is
the given true box.  Times are seconds per frame with 8 decimals; the first frame's is ``nan`` (the
initialisation is not timed), which both toolkits drop with every non-positive time.  ``<tracker>`` is
the method with the conditions other than the scene (``PF_N=10``); ``<sequence>`` is OTB's name
(``Jogging-2``, which the GOT-10k toolkit's OTB reader calls ``Jogging.2``).  A file holds the frames
the run tracked: the first 100 at the quick scale.  Every exported tracker's folder is written anew.

    python -m replication.export experiment=hspf [scale=quick|paper] [layout=otb|got10k] [out=DIR] [key=value ...]

writes both layouts unless ``layout`` names one, under the report's folder's ``results`` (as the report
does: ``<reports>/quick/<experiment>/results`` at the quick scale, the default) unless ``out`` says where;
``key=value`` are config overrides (``store=/path``).
"""

import re
import shutil
import sys
from collections import defaultdict
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd
from hydra.errors import HydraException
from omegaconf.errors import OmegaConfBaseException

from replication import atomic
from replication.arguments import read
from replication.errors import ConfigError, fail
from replication.paths import experiment_names, resolve
from replication.run import Run
from replication.runner.results import stored_records
from replication.scenes.factory import OTB, scene_kind
from replication.scales import default_scale, report_folder

LAYOUTS = {"otb": "OTB2015", "got10k": "GOT-10k"}  # layout: the toolkit's folder under its result_dir


def tracker_name(run: Run) -> str:
    """The method, with the run's conditions other than the scene: ``PF``, ``PF_N=10``."""
    labels = [f"{name}={value}" for name, value in run.condition.without("scene").values]
    return re.sub(r"[^\w.+=-]", "_", "_".join([run.method, *labels]))


def on_otb(run: Run) -> bool:
    return run.task == "tracking" and scene_kind(run.model.get("scene_spec", {})) is OTB


def write_results(runs: list[Run], records: pd.DataFrame, out_dir: str | Path, layout: str) -> list[Path]:
    """Write the stored ``records`` of ``runs`` on OTB sequences in ``layout`` under ``out_dir``; the box files."""
    if layout not in LAYOUTS:
        raise ConfigError(f"unknown layout {layout!r}; choose one of {', '.join(LAYOUTS)}")
    chosen = {run.run_id: run for run in runs if on_otb(run)}
    tracks = defaultdict(list)  # (tracker, sequence) -> [(repetition, boxes, seconds)]
    for record in records.to_dict("records"):
        run = chosen.get(record["run_id"])
        if run is not None:
            boxes = np.asarray(record["per_frame"]["box"], dtype=float)[:, 0]  # an OTB sequence has one target
            boxes[:, :2] += 1.0  # OTB's 1-based pixels
            seconds = np.asarray(record["per_frame"]["seconds"], dtype=float)  # None (frame 1) -> nan
            tracks[tracker_name(run), run.model["scene_spec"]["name"]].append((run.repetition, boxes, seconds))
    root = Path(out_dir) / LAYOUTS[layout]
    for tracker in {tracker for tracker, _ in tracks}:
        shutil.rmtree(root / tracker, ignore_errors=True)
    written = []
    for (tracker, sequence), repetitions in sorted(tracks.items()):
        repetitions.sort(key=lambda item: item[0])
        if layout == "otb":
            _, boxes, seconds = repetitions[0]
            written.append(root / tracker / f"{sequence}.txt")
            _save(written[-1], boxes, "%.3f")
            _save(root / tracker / "times" / f"{sequence}_time.txt", seconds, "%.8f")
        else:
            folder = root / tracker / sequence
            for repetition, boxes, _ in repetitions:
                written.append(folder / f"{sequence}_{repetition + 1:03d}.txt")
                _save(written[-1], boxes, "%.3f")
            _save(folder / f"{sequence}_time.txt", np.column_stack([s for _, _, s in repetitions]), "%.8f")
    return written


def export_results(experiment: str, scale: str, out_dir: str | Path, layout: str = "otb",
                   overrides: tuple[str, ...] = ()) -> list[Path]:
    """Write the stored runs of tracking ``experiment`` at ``scale`` in ``layout`` under ``out_dir``
    (the toolkit's ``result_dir``); the box files written.  ``overrides`` are config overrides."""
    records, runs = stored_records(experiment, scale, *overrides)
    if any(run.task != "tracking" for run in runs):
        raise ConfigError(f"experiment {experiment!r} is not a tracking experiment (task: {runs[0].task})")
    return write_results(runs, records, out_dir, layout)


def _save(path: Path, values: np.ndarray, fmt: str) -> None:
    atomic.save(path, lambda tmp: np.savetxt(tmp, values, fmt=fmt, delimiter=","))


@dataclass(frozen=True)
class Options:
    """The export's own settings; every other key=value is a setting of the config (store=, experiment.*)."""

    experiment: str | None = None
    scale: str | None = None
    layout: str | None = None  # one of LAYOUTS (every one by default)
    out: str | None = None
    reports: str | None = None  # where out= is by default (and a setting of the config)


def main(argv: list[str]) -> None:
    options, overrides = read(argv, Options, "export", handed=("*",))
    name = options.experiment
    if name not in experiment_names():
        fail(f"name a tracking experiment: experiment=<name>; known: {', '.join(experiment_names())}")
    scale = options.scale or default_scale()
    layouts = [options.layout] if options.layout is not None else list(LAYOUTS)
    out = Path(options.out or report_folder(resolve(options.reports or "reports"), name, scale) / "results")
    overrides = [*overrides, *([f"reports={options.reports}"] if options.reports is not None else [])]
    try:
        for layout in layouts:
            written = export_results(name, scale, out, layout, tuple(overrides))
            if not written:
                fail(f"no stored run of {name} at scale {scale} is on an OTB sequence: "
                     f"run python -m replication experiment={name} scale={scale} first")
            print(f"{name}: {len(written)} result files in the {layout} layout under {out / LAYOUTS[layout]}")
    except (ConfigError, HydraException, OmegaConfBaseException) as error:  # a bad layout, key or value
        fail(str(error).splitlines()[0])


if __name__ == "__main__":
    main(sys.argv[1:])
