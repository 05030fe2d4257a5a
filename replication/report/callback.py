"""Draw a multirun's sweep when the multirun ends (a Hydra callback, named in ``conf/config.yaml``).

``pf-replicate -m experiment=ism_pf experiment.methods.PF.n_particles=5,10,20`` runs one job per
value; at its end :class:`SweepReport` runs ``pf-replicate report ... sweep=<key>=<values>`` with
the same settings, so nobody types the sweep twice (where that fails, a metric to draw not being
named, say, one line gives the command to finish it).  A multirun over several experiments
(``make replicate``) writes each experiment's report in its job, and nothing more here.
"""

import subprocess
import sys
from typing import Any

from hydra.core.override_parser.overrides_parser import OverridesParser
from hydra.experimental.callback import Callback
from omegaconf import DictConfig


def sweep_request(task_overrides: list[str]) -> list[str] | None:
    """The report's arguments for a multirun's overrides, or None when there is no single sweep of
    one experiment's setting to draw."""
    overrides = OverridesParser.create().parse_overrides(task_overrides)
    sweeps = [o for o in overrides if o.is_sweep_override()]
    if len(sweeps) != 1 or sweeps[0].key_or_group == "experiment":
        return None
    fixed = [o.input_line for o in overrides if not o.is_sweep_override()]
    swept = sweeps[0]
    values = ",".join(str(v) for v in swept.sweep_string_iterator())
    return [*fixed, f"sweep={swept.key_or_group}={values}"]


class SweepReport(Callback):
    def on_multirun_end(self, config: DictConfig, **kwargs: Any) -> None:
        arguments = sweep_request(list(config.hydra.overrides.task))
        if arguments is None:
            return
        command = ["report", *arguments, "pdf=false"]
        done = subprocess.run([sys.executable, "-m", "replication", *command], check=False, stdout=sys.stdout,
                              stderr=subprocess.PIPE, text=True)
        if done.returncode:  # the runs are stored: say how to draw them rather than fail the multirun
            why = done.stderr.strip().splitlines()[-1].removeprefix("error: ") if done.stderr.strip() else "failed"
            print(f"sweep not drawn ({why}): pf-replicate {' '.join(command)}", file=sys.stderr)
