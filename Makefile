# make replicate   set up, run every experiment at SCALE (quick by default), write reports/index.html
# make pdf         reports/replication.pdf: the scorecard, tables and figures of every report drawn (after make replicate)
# make test        set up and run the test suite on JOBS (2) workers, but its end-to-end tests and the long
#                  paper-scale runs (marked e2e and slow)
# make test-e2e    the end-to-end tests (marked e2e: subprocesses, killed runners, clusters); CI runs both
# make report      redraw every report from the stored runs, running nothing
# make benchmark   time the SMC core on this machine, and against particles, Stone Soup and filterpy, each in its own venv under .peers/ (reports/benchmark/)
#                  (where one run's time goes: python benchmarks/profile_run.py EXPERIMENT METHOD [TEXT] [--scale paper])
# make readings    run every paper's multiverse (conf/experiment/*_readings.yaml) at SCALE (at paper: what the record
#                  lacks, universe by universe, then recorded); on a cluster: ADDRESS=tcp://host:8786 (dask, the
#                  default BACKEND) or BACKEND=ray ADDRESS=head-host:6379 (docs/reproducibility.md, "On many machines")
# make docs        the API reference from the docstrings (pdoc), into reports/api/
# make calibrate   simulate every verdict rule's error rates (reports/calibration.csv; kept while the deciding code it simulates is unchanged)
# make record      write the paper-scale record (record/) from a store holding every paper-scale run (make replicate SCALE=paper does),
#                  profile its three costliest experiments into it (record/profile.json), and render each
#                  paper's findings from it (docs/findings/, from docs/findings/templates/)
# make findings    render each paper's findings from the record into docs/findings/ (after editing a template)
# make verify      re-compute N (200) recorded runs here (it says first how many, then roughly how long), grade each
#                  against the record (identical, within tolerance, diverged) and judge the verdicts again; N=20 for
#                  fewer (each experiment and universe still gives one: about 100), N=all for every one
# SCALE=paper      the papers' run counts, e.g. make replicate SCALE=paper JOBS=2

PYTHON ?= python3
VENV ?= .venv
BIN := $(VENV)/bin
SCALE ?= quick
JOBS ?= 2
N ?= 200
BACKEND ?= dask
ADDRESS ?=
CLUSTER := $(if $(ADDRESS),parallel.backend=$(BACKEND) parallel.address=$(ADDRESS))
EXPERIMENTS := $(sort $(basename $(notdir $(wildcard conf/experiment/*.yaml))))
READINGS := $(sort $(basename $(notdir $(wildcard conf/experiment/*_readings.yaml))))
# The multiverses run with make replicate at the quick scale (a small design each); at paper scale
# their Sobol designs take hours, so they are make readings SCALE=paper's.
REPLICATE := $(if $(filter paper,$(SCALE)),$(filter-out $(READINGS),$(EXPERIMENTS)),$(EXPERIMENTS))
comma := ,
empty :=
space := $(empty) $(empty)

.PHONY: setup browser test test-e2e test-all replicate pdf readings report benchmark docs calibrate record verify findings

setup: $(VENV)/.installed

$(VENV)/.installed: pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[test,docs]'
	# TrackEval (HOTA) pulls in opencv-python beside opencv-python-headless; both unpack into cv2/.
	# Reinstalling the headless build last makes its cv2 the one imported (no libGL or X11 needed).
	$(BIN)/python -m pip install --quiet --force-reinstall --no-deps \
		"opencv-python-headless==$$($(BIN)/python -c 'import importlib.metadata as m; print(m.version("opencv-python-headless"))')"
	touch $@

# The report's headless-browser test uses Debian's chromium: installed here when apt-get
# can (as root); elsewhere that one test is skipped and says why.
browser:
	@command -v chromium >/dev/null 2>&1 || { [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1 \
		&& apt-get update -qq && apt-get install -y -qq chromium >/dev/null; } \
		|| echo "chromium not installed: the headless-browser report test will be skipped"

test: setup browser
	$(BIN)/python -m pytest -m "not slow and not e2e" -n $(JOBS) --dist loadgroup --durations=15

test-e2e: setup browser
	$(BIN)/python -m pytest -m "e2e and not slow" -n $(JOBS) --dist loadgroup --durations=15

test-all: setup browser
	$(BIN)/python -m pytest -n $(JOBS) --dist loadgroup

# One Hydra multirun over every experiment: one process and one pool of workers for all of them,
# instead of starting Python, numba and the workers again per experiment (about two minutes at quick scale).
# The shipped record's pages first (the verdicts at the papers' scale, in about a minute), then this
# machine's runs, then which of them are recorded runs and whether they agree.  At SCALE=paper the runs the
# record holds as this code computes them are read from it, not computed (skip_recorded=false in conf/config.yaml
# computes all), and the record is rewritten with the runs just made (a file whose runs did not change keeps its bytes).
# The runs draw no report as they go (draw=false): every experiment's is drawn after them, JOBS at a time,
# instead of one at a time between experiments while the workers wait.  The PDF is make pdf's.
replicate: setup
	$(BIN)/python -m replication report source=record pdf=false
	$(BIN)/python -m replication --multirun experiment=$(subst $(space),$(comma),$(REPLICATE)) scale=$(SCALE) n_jobs=$(JOBS) draw=false
	$(if $(filter paper,$(SCALE)),$(MAKE) record)
	$(BIN)/python -m replication report scale=$(SCALE) n_jobs=$(JOBS) pdf=false
	$(BIN)/python -m replication verify against=store scale=$(SCALE)
	$(BIN)/python benchmarks/benchmark.py
	$(BIN)/python -m replication.report.calibration

pdf: setup
	$(BIN)/python -m replication.report.pdf

# At SCALE=paper the universes the record holds as this code computes them are read from it, not run
# again, and every universe run whole is recorded: stopped part-way, the next call goes on from there.
readings: setup
	$(BIN)/python -m replication --multirun experiment=$(subst $(space),$(comma),$(READINGS)) scale=$(SCALE) n_jobs=$(JOBS) $(CLUSTER)
	$(if $(filter paper,$(SCALE)),$(BIN)/python -m replication record experiment=$(subst $(space),$(comma),$(READINGS)) && $(BIN)/python -m replication findings)
	$(BIN)/python -m replication.report.pdf

record: setup
	$(BIN)/python -m replication record
	$(BIN)/python benchmarks/profile_run.py --record
	$(BIN)/python -m replication findings

findings: setup
	$(BIN)/python -m replication findings

verify: setup
	$(BIN)/python -m replication verify N=$(N) n_jobs=$(JOBS)

benchmark: setup
	$(BIN)/python benchmarks/benchmark.py --instructions --profiles
	$(BIN)/python benchmarks/peers.py

report: setup
	$(BIN)/python -m replication.report scale=$(SCALE)

calibrate: setup
	$(BIN)/python -m replication.report.calibration

docs: setup
	$(BIN)/python -m pdoc -o reports/api replication
	@echo "API reference: reports/api/replication.html"
