"""``python -m replication.report [scale=quick] [experiment=a,b] [pdf=false] [screenshot=true]``:
rebuild reports from stored runs only.

Nothing is run: each experiment's report is redrawn from the records in the
store, ``reports/index.html`` links them under the summary of every published
cell, and ``reports/replication.pdf`` gathers the same tables and figures
(``pdf=false`` skips it).  ``screenshot=true`` also saves headless Chromium's
view of the index as ``reports/screenshot.png`` (where Chromium is installed).
"""

import sys

from hydra import compose, initialize_config_dir

from replication.paths import CONF_DIR, experiment_names, resolve
from replication.report.experiment import write_experiment_report
from replication.report.index import write_index
from replication.runner.cli import fail
from replication.runner.config import ConfigError, expand
from replication.runner.store import Store

SWITCHES = {"pdf": True, "screenshot": False}  # ours, not Hydra's: name=true|false


def main(argv: list[str]) -> None:
    chosen = [a.split("=", 1)[1].split(",") for a in argv if a.startswith("experiment=")]
    names = chosen[-1] if chosen else experiment_names()
    switches = dict(SWITCHES)
    for arg in argv:
        name, _, value = arg.partition("=")
        if name in SWITCHES:
            if value.lower() not in ("true", "false"):
                fail(f"{name} must be true or false, got {value!r}")
            switches[name] = value.lower() == "true"
    overrides = [a for a in argv if not a.startswith("experiment=") and a.partition("=")[0] not in SWITCHES]
    unknown = sorted(set(names) - set(experiment_names()))
    if unknown:
        fail(f"unknown experiment {unknown[0]!r}; known: {', '.join(experiment_names())}")
    with initialize_config_dir(config_dir=str(CONF_DIR), version_base="1.3"):
        for name in names:
            cfg = compose("config", overrides=[f"experiment={name}", *overrides])
            try:
                runs = expand(cfg)
            except ConfigError as error:
                fail(str(error))
            page = write_experiment_report(cfg, runs, Store(resolve(cfg.store), name))
            print(f"{name}: {page}")
        reports = resolve(cfg.reports)
        if switches["pdf"]:
            from replication.report.pdf import write_pdf

            print(f"pdf: {write_pdf(reports, cfg.published_values)}")
        index = write_index(reports, cfg.published_values)
        print(f"index: {index}")
        if switches["screenshot"]:
            from replication.report.render import browser, open_in_browser

            if browser() is None:
                print("screenshot: skipped, no Chromium on the PATH (apt-get install chromium)",
                      file=sys.stderr)
            else:
                seen = open_in_browser(index, reports / "screenshot.png")
                print(f"screenshot: {seen['screenshot']}")
                for line in seen["console"]:
                    print(f"console: {line}", file=sys.stderr)


if __name__ == "__main__":
    main(sys.argv[1:])
