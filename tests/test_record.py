"""The paper-scale record (issue 35): runs as typed tidy tables that read back as the store's records, a
manifest that names a damaged file and the machines that made it, verification that re-computes runs and
grades them (identical, within tolerance, diverged within the run-to-run spread: issue 56) and judges the
verdicts again, and the report drawn from the record."""

import dataclasses
import hashlib
import json
import subprocess
import sys
from collections import Counter

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest
from conftest import PROJECT_ROOT

from replication.errors import ConfigError
from replication.evidence.figures import FIGURE_KINDS, figure_spec
from replication.evidence.published import load_published
from replication.evidence.tables import TableKind
from replication.record.manifest import Before, Manifest
from replication.record.runs import RUNS_FILE, Record, read_rows
from replication.record.verify import (
    TOLERANCES, Grade, compare, graded, recomputed, rejudged, same_value, sample, verify,
)
from replication.record.write import kept_series, write, write_experiment
from replication.report.figures import draw
from replication.report.figures.style import NothingToDraw
from replication.runner.config import expand, experiment_at_scale
from replication.runner.execute import execute
from replication.runner.machine import Machine
from replication.runner.store import Store
from replication.runner.curves import CURVES, curve_table
from replication.runner.footage import SceneFootage

FOOTAGE = SceneFootage()  # the video the runs saw, as the pages are given it
UNGM = ("scale=paper", "experiment.runs.paper=2", "experiment.model.steps=10")
# bis_pf's 3123 test at its full length, one run per method: the runs whose strip the modes table reads
BALLS = ("scale=paper", "experiment.runs.paper=1", "experiment.model.sweep.scene=[exp1_3123]")


def stored(make_cfg, tmp_path, experiment, overrides):
    cfg = make_cfg(experiment, *overrides)
    runs = expand(cfg)
    store = Store(tmp_path / "experiments", experiment)
    execute(runs, store, n_jobs=1, progress=False)
    return cfg, runs, store


def same_records(a, b) -> bool:
    """Two record tables hold the same runs with the same values (NaN equal to NaN), in any column order."""
    def plain(value):
        return None if isinstance(value, float) and value != value else value
    return (len(a) == len(b) and set(a.columns) == set(b.columns)
            and all(same_value(plain(x), plain(y)) or (plain(x) is None and plain(y) is None)
                    for column in a.columns for x, y in zip(a[column], b[column])))


def test_a_record_reads_back_as_the_store_it_was_written_from(make_cfg, tmp_path):
    cfg, runs, store = stored(make_cfg, tmp_path, "gps_qmcpf", UNGM)
    entry = write_experiment(cfg, tmp_path / "experiments", tmp_path / "record")
    assert (entry.runs, entry.failed, list(entry.files)) == (len(runs), 0, [f"gps_qmcpf/{RUNS_FILE}"])
    assert same_records(Record(tmp_path / "record").load(runs), store.load(runs))
    schema = pq.read_schema(tmp_path / "record" / list(entry.files)[0])
    assert schema.field("method.n_particles").type == pa.int64()  # a swept parameter, as a number
    assert schema.field("condition.N").type == pa.int64() and schema.field("rmse").type == pa.float64()
    assert not {"condition", "data_condition", "run_id"} & set(schema.names)  # no packed labels


def test_the_manifest_names_a_damaged_file_and_keeps_an_unchanged_entry(make_cfg, tmp_path):
    cfg, _, _ = stored(make_cfg, tmp_path, "gps_qmcpf", UNGM)
    record = tmp_path / "record"
    manifest = write([cfg], tmp_path / "experiments", record)
    assert manifest.damaged(record) == [] and Manifest.read(record) == manifest
    older = dataclasses.replace(manifest.experiments["gps_qmcpf"], written="2020-01-01")
    assert Manifest({"gps_qmcpf": older}).with_entry("gps_qmcpf", manifest.experiments["gps_qmcpf"]).experiments[
        "gps_qmcpf"].written == "2020-01-01"  # the same bytes again: the entry and its date stay
    path = record / "gps_qmcpf" / RUNS_FILE
    path.write_bytes(path.read_bytes()[:-1] + b"x")
    assert manifest.damaged(record) == ["gps_qmcpf/runs.parquet"]


def test_an_entry_recorded_again_keeps_what_its_previous_recording_took(make_cfg, tmp_path):
    cfg, _, _ = stored(make_cfg, tmp_path, "gps_qmcpf", UNGM)
    record = tmp_path / "record"
    entry = write([cfg], tmp_path / "experiments", record).experiments["gps_qmcpf"]
    assert entry.before is None and entry.minutes is not None and entry.minutes >= 0
    older = dataclasses.replace(entry, files={"gps_qmcpf/runs.parquet": "0" * 64}, commits=("a" * 40,), wall_s=90.0,
                                first_computed="2026-01-01T10:00:00+00:00", last_computed="2026-01-01T10:01:30+00:00")
    again = Manifest({"gps_qmcpf": older}).with_entry("gps_qmcpf", entry)
    assert again.experiments["gps_qmcpf"].before == Before(("a" * 40,), older.code_digests, older.runs, 90.0, 1.5,
                                                           older.written)
    again.write(record)
    assert Manifest.read(record) == again  # the previous recording reads back as written
    assert dataclasses.replace(entry, universes=3).minutes is None  # a multiverse's universes: no span


def test_failed_runs_are_recorded_with_their_reason_and_a_missing_run_stops_the_writer(make_cfg, tmp_path):
    cfg = make_cfg("gps_qmcpf", *UNGM)
    runs = expand(cfg)
    store = Store(tmp_path / "experiments", "gps_qmcpf")
    execute(runs[1:], store, n_jobs=1, progress=False)
    with pytest.raises(ConfigError, match=f"gps_qmcpf: 1 of {len(runs)} paper-scale runs are not in the store"):
        write_experiment(cfg, tmp_path / "experiments", tmp_path / "record")
    store.write_failure(runs[0], "rmse is not finite")
    entry = write_experiment(cfg, tmp_path / "experiments", tmp_path / "record")
    record = Record(tmp_path / "record")
    assert entry.failed == 1 and record.failures(runs) == Counter({"rmse is not finite": 1})
    assert len(record.load(runs)) == len(runs) - 1


def test_only_the_series_a_table_reads_are_kept_and_its_table_is_the_stores(make_cfg, tmp_path):
    cfg, runs, store = stored(make_cfg, tmp_path, "bis_pf", BALLS)
    experiment = experiment_at_scale(cfg)
    assert kept_series(experiment) == ("strip",)  # the modes table's; per_frame only feeds figures
    write_experiment(cfg, tmp_path / "experiments", tmp_path / "record")
    rows = read_rows(tmp_path / "record" / "bis_pf" / RUNS_FILE)
    assert all("per_frame" not in r for r in rows) and all("strip" in r for r in rows)
    from_record, from_store = Record(tmp_path / "record").load(runs), store.load(runs)
    spec = next(t for t in experiment["report"]["tables"] if t.get("kind") == "modes")
    published = load_published(str(PROJECT_ROOT.parent / "shared" / "reference" / "published_values.csv"))
    built = [TableKind.of(spec, experiment, published, FOOTAGE).build(r).written() for r in (from_record, from_store)]
    assert built[0].equals(built[1]) and len(built[0])
    curve = figure_spec(next(f for f in experiment["report"]["figures"] if f["kind"] == "per_frame_curve"))
    with pytest.raises(NothingToDraw, match="drawn from each run's per_frame, which these records do not hold"):
        draw(from_record, curve, experiment, tmp_path / "curve.png", footage=FOOTAGE)
    kept = Record(tmp_path / "record").curves("bis_pf")  # instead, the curve the figure draws
    curves = {f["name"] for f in experiment["report"]["figures"] if FIGURE_KINDS[f["kind"]].curved}
    assert curve.name in kept and set(kept) <= curves  # off_image: its scenes (the 16 balls) were not run
    table = curve_table(from_store, curve, experiment, FOOTAGE)
    assert list(kept[curve.name].columns) == list(table.columns) and len(table) > 100
    assert np.allclose(kept[curve.name]["mean"], table["mean"], rtol=1e-6)  # single precision
    assert draw(from_record, curve, experiment, tmp_path / "curve.png", curve=kept[curve.name],
                footage=FOOTAGE).exists()


def rewritten(path, column, values):
    """The runs table at ``path`` with ``column`` replaced by ``values`` (as a record edited by hand)."""
    table = pq.read_table(path)
    pq.write_table(table.set_column(table.schema.get_field_index(column), column, pa.array(values)), path)


def test_verify_grades_a_last_digit_within_tolerance_and_a_changed_number_beyond(make_cfg, tmp_path):
    cfg, runs, store = stored(make_cfg, tmp_path, "gps_qmcpf", UNGM)
    record = tmp_path / "record"
    entry = write([cfg], tmp_path / "experiments", record).experiments["gps_qmcpf"]
    assert entry.machine_details and all(isinstance(m, Machine) for m in entry.machine_details)  # said, read back
    found = verify([cfg], Record(record), 6, cheapest=False, n_jobs=1, progress=False)
    assert {r.grade for r in found.runs} == {Grade.IDENTICAL} and all(r.same_machine for r in found.runs)
    path = record / "gps_qmcpf" / RUNS_FILE
    rmse = pq.read_table(path).column("rmse").to_pylist()
    rewritten(path, "rmse", [rmse[0] * (1 + 1e-15), *rmse[1:]])  # one ulp or so
    found = verify([cfg], Record(record), None, cheapest=False, n_jobs=1, progress=False)
    perturbed = next(r for r in found.runs if r.grade is not Grade.IDENTICAL)
    assert perturbed.run.run_id == runs[0].run_id and perturbed.grade is Grade.WITHIN
    assert [r.run.run_id for r in found.failing] == [runs[0].run_id]  # this machine made it: not identical fails
    rewritten(path, "machine_detail", [None] * len(rmse))  # made elsewhere, or before records said where
    found = verify([cfg], Record(record), None, cheapest=False, n_jobs=1, progress=False)
    assert found.count(Grade.WITHIN) == 1 and found.failing == []
    assert "1 within tolerance (largest relative difference 1.1e-15: rmse, gps_qmcpf)" in found.summary()
    rewritten(path, "rmse", [rmse[0] + 1.0, *rmse[1:]])  # a changed number: beyond, and no spread excuses it
    found = verify([cfg], Record(record), None, cheapest=False, n_jobs=1, progress=False)
    (changed,) = [r for r in found.runs if r.grade is not Grade.IDENTICAL]
    assert changed.grade is Grade.DIVERGED and changed.beyond == ("rmse",) and changed.peers == 1
    assert found.failing == [changed] and changed.outside == ("rmse",) and "1 beyond (named above)" in found.summary()
    assert "beyond the run-to-run spread of its cell's 1 other recorded runs in rmse" in changed.line()


def test_grades_by_hand():
    run = None  # graded needs a run only to name it
    recorded = {"repetition": 0, "rmse": 2.0, "mean_ess": 80.0, "resample_count": 12,
                "strip": {"target": 3, "density": [[0.5, 0.25], [0.125, 0.0]]}}
    peers = [recorded, *({**recorded, "repetition": i, "rmse": value} for i, value in enumerate((1.5, 2.5, 3.0), 1))]

    def grade(**now):
        return graded(run, ("x",), recorded, {**recorded, **now}, peers)

    assert grade().grade is Grade.IDENTICAL
    assert grade(rmse=2.0 * (1 + 9e-6)).grade is Grade.WITHIN  # a score: 1e-5 relative
    assert grade(strip={"target": 3, "density": [[0.5, 0.25], [0.1251, 0.0]]}).grade is Grade.WITHIN  # one step
    assert TOLERANCES["count"].admits(12, 12) and not TOLERANCES["count"].admits(12, 13)
    split = grade(rmse=2.7, resample_count=13, strip={"target": 3, "density": [[0.5, 0.25], [0.25, 0.0]]})
    assert split.grade is Grade.DIVERGED and split.beyond == ("rmse", "resample_count", "strip")
    assert split.frame == ("strip", 2)  # the strip parts at its second frame
    assert split.outside == ("resample_count",)  # every recorded run resampled 12 times: no spread to allow 13
    assert grade(rmse=2.9).outside == () and grade(rmse=9.0).outside == () and grade(rmse=30.0).outside == ("rmse",)
    assert graded(run, ("x",), recorded, {"failure": "rmse is not finite"}, peers).outside == ("failure",)
    # a result the record lacks differs where this code made the record, and is new where other code did
    from replication.record.verify import compare

    assert compare(recorded, {**recorded, "fp_duplicate": 2}) == (("fp_duplicate", None, 2),)
    assert compare(recorded, {**recorded, "fp_duplicate": 2}, other_code=True) == ()
    assert compare(recorded, {k: v for k, v in recorded.items() if k != "rmse"}, other_code=True) == (
        ("rmse", 2.0, None),)  # a result the record has and this code lacks still differs


def test_verify_on_the_command_line_prints_the_difference_and_fails(make_cfg, tmp_path):
    settings = ("experiment.runs.paper=1", "experiment.model.steps=5")
    cfg, runs, _ = stored(make_cfg, tmp_path, "gps_qmcpf", ("scale=paper", *settings))
    record = tmp_path / "record"
    write([cfg], tmp_path / "experiments", record)
    path = record / "gps_qmcpf" / RUNS_FILE
    table = pq.read_table(path)
    rmse = [v + 1.0 for v in table.column("rmse").to_pylist()[:1]] + table.column("rmse").to_pylist()[1:]
    pq.write_table(table.set_column(table.schema.get_field_index("rmse"), "rmse", pa.array(rmse)), path)
    command = [sys.executable, "-m", "replication", "verify", f"record={record}", "N=all", "n_jobs=1",
               "experiment=gps_qmcpf", "progress=false", *settings]
    done = subprocess.run(command, cwd=PROJECT_ROOT, capture_output=True, text=True, timeout=300)
    assert done.returncode == 2 and "no longer match the manifest's SHA-256" in done.stderr  # an edited file
    manifest = Manifest.read(record)
    entry = dataclasses.replace(manifest.experiments["gps_qmcpf"],
                                files={"gps_qmcpf/runs.parquet": hashlib.sha256(path.read_bytes()).hexdigest()})
    manifest.with_entry("gps_qmcpf", entry).write(record)
    done = subprocess.run(command, cwd=PROJECT_ROOT, capture_output=True, text=True, timeout=600)
    assert done.returncode == 1, done.stderr
    assert f"gps_qmcpf {runs[0].run_id}: diverged at rmse (recorded" in done.stdout
    assert "it should be identical" in done.stdout  # computed here, as the record was
    assert (f"verified {len(runs)} recorded runs ({len(runs)} distinct) of 1 experiments and universes: "
            f"{len(runs) - 1} identical, 0 within tolerance, 1 diverged; 1 beyond") in done.stdout
    assert "verdicts: re-judging 1 experiments and multiverses" in done.stdout and "verdicts changed" in done.stdout


def test_comparing_records_by_hand():
    assert compare({"rmse": float("nan"), "n": 3, "xs": [1.0, 2.0]}, {"rmse": float("nan"), "n": 3, "xs": [1.0, 2.0],
                                                                     "wall_s": 9.0, "run_id": "x"}) == ()
    assert compare({"rmse": 1.0}, {"rmse": 1.0 + 1e-13}) == (("rmse", 1.0, 1.0 + 1e-13),)  # any bit
    assert compare({"rmse": 1.0}, {"rmse": 1.0, "machine_detail": {"cpu": "another"}}) == ()  # provenance
    assert compare({"rmse": 1.0}, {"rmse": 1.0, "ess": 4.0}) == (("ess", None, 4.0),)  # a new metric
    assert compare({"rmse": 1.0, "ess": None}, {"rmse": 1.0}) == ()  # a value neither has
    assert compare({"strip": {"density": [[0.5, 0.5]]}}, {"strip": {"density": [[0.5, 0.25]]}})[0][0] == "strip"
    assert compare({"failure": "rmse is not finite"}, {"failure": "rmse is not finite"}) == ()
    assert compare({"failure": "rmse is not finite"}, {"rmse": 2.0})[0] == ("failure", "rmse is not finite", None)
    assert compare({"rmse": 1.0}, {"rmse": 1.0, "per_frame": {"cle": [1.0]}}) == ()  # a series not kept


def test_the_sample_takes_every_experiment_and_the_rest_in_proportion():
    pairs = {"a": [(i, {"wall_s": float(10 - i)}) for i in range(10)], "b": [(i, {"wall_s": 1.0}) for i in range(90)]}
    chosen = sample(pairs, 20, cheapest=False)
    assert Counter(id(p) in {id(q) for q in pairs["a"]} for p in chosen) == {True: 2, False: 18}
    assert sample(pairs, 20, cheapest=False) == chosen  # its own seed: the same N, the same runs
    assert [run for run, _ in sample(pairs, 1, cheapest=True)[:1]] == [9]  # a's quickest
    assert len(sample(pairs, None, cheapest=False)) == 100


def test_runs_made_by_other_code_are_named_and_recomputed_runs_compared(make_cfg, tmp_path):
    cfg, runs, store = stored(make_cfg, tmp_path, "gps_qmcpf", UNGM)
    write([cfg], tmp_path / "experiments", tmp_path / "record")
    record = Record(tmp_path / "record")
    assert record.stale(runs) == []
    changed = [dataclasses.replace(run, key="0" * 10) for run in runs[:3]]
    assert record.stale(changed) == changed and len(record.load(changed)) == 3  # still read: the same identity
    quick = make_cfg("gps_qmcpf", "scale=quick", "experiment.runs.quick=1", "experiment.model.steps=10")
    found = recomputed([quick], tmp_path / "experiments", record)["gps_qmcpf"]
    first = [run for run in runs if run.repetition == 0]
    assert found == {"compared": len(first), "identical": len(first), "within": 0, "diverged": 0, "largest": 0.0,
                     "lines": [], "beyond": []}  # a quick run with a recorded run's key: the same


def test_the_report_drawn_from_a_record_shows_its_verdicts_beside_this_machines(make_cfg, tmp_path):
    cfg = make_cfg("hspf_ungm", "scale=paper")  # the shipped experiment as it is (300 runs of 100 steps)
    runs = expand(cfg)
    execute(runs, Store(tmp_path / "experiments", "hspf_ungm"), n_jobs=2, progress=False)
    write([cfg], tmp_path / "experiments", tmp_path / "record")
    reports = tmp_path / "reports"
    from replication.report.__main__ import main as report

    report(["source=record", f"record={tmp_path / 'record'}", f"reports={reports}", "pdf=false"])
    status = json.loads((reports / "record" / "status.json").read_text())
    assert status["runs"] == len(runs) and status["experiments"]["hspf_ungm"]["runs"] == len(runs)
    assert status["experiments"]["hspf_ungm"]["stale"] == 0 and status["experiments"]["hspf_ungm"]["cpu_minutes"] > 0
    from replication.evidence.claims import load_papers
    from replication.evidence.scorecard import Scorecard
    from replication.report.pages.index import write_index
    from replication.report.pages.recorded import recorded

    shown = recorded(reports, load_papers())
    assert shown["runs"] == len(runs) and shown["stale"] == {} and shown["recomputed"] is None
    judged = {claim for claim, row in shown["claims"].items() if row.primary.scale == "paper"}
    assert judged and all(claim.startswith("hspf.") for claim in judged)  # the recorded experiment's claims
    page = write_index(reports, Scorecard.read(reports)).read_text()
    assert "paper scale (recorded at " in page and f"{len(runs)} runs of 1 experiments" in page
    assert 'href="record/hspf_ungm/index.html#claims"' in page


def test_the_shipped_record_is_whole_and_its_quickest_runs_recompute_identically():
    """The record in the repository: every file has its manifest's SHA-256 and holds its runs, and the
    quickest recorded run of each experiment and recorded universe is computed again here (a run several
    universes share, once): identical where this machine took the record's code paths with its libraries,
    elsewhere within tolerance or another draw within the run-to-run spread, with every verdict unchanged."""
    from hydra import compose, initialize_config_dir

    from replication.paths import CONF_DIR
    from replication.report.diff import verdicts

    folder = PROJECT_ROOT / "record"
    manifest = Manifest.read(folder)
    if not manifest.experiments:
        pytest.skip("no record shipped in this checkout")
    assert manifest.damaged(folder) == []
    for name, entry in manifest.experiments.items():
        assert sum(len(read_rows(folder / file)) for file in entry.files if "/curves/" not in file) == entry.runs, name
    # a multiverse's default universe is its experiments' own runs: only the multiverses with more are loaded
    names = [name for name, entry in manifest.experiments.items() if entry.universes != 1]
    with initialize_config_dir(config_dir=str(CONF_DIR), version_base="1.3"):
        cfgs = [compose("config", overrides=[f"experiment={name}", "scale=paper"]) for name in names]
    found = verify(cfgs, Record(folder), 1, cheapest=True, n_jobs=2, progress=False)  # 1 a stratum
    assert [r.run.run_id for r in found.runs if r.same_machine and r.grade is not Grade.IDENTICAL] == []
    assert found.failing == [], "\n".join(r.line() for r in found.failing)
    # elsewhere, the runs that are not identical in place of the recorded ones move no verdict of an
    # experiment (make verify judges the multiverses' too: minutes more)
    def judged(before, after, names, n_jobs):
        assert names, "rejudged asked for the verdicts of no experiment"
        return verdicts(before, after, names, n_jobs)

    assert rejudged(folder, found, 2, judged, multiverses=False) == []
    with pytest.raises(ValueError, match="name the experiments"):  # never read as the whole record, drawn twice
        verdicts(folder, folder, [], 2)


def test_every_recorded_run_is_the_one_this_code_would_make():
    """A change to any file a run executes (its task, filter, or a module they import, such as ``paths.py``)
    gives its runs new keys, and the record's runs of the old keys are stale: shown, never read as this code's.
    Such a change must come with the record rebuilt, so none of the record's parts holds a stale run."""
    from hydra import compose, initialize_config_dir

    from replication.paths import CONF_DIR
    from replication.runner.multiverse import load

    folder = PROJECT_ROOT / "record"
    manifest = Manifest.read(folder)
    if not manifest.experiments:
        pytest.skip("no record shipped in this checkout")
    record, stale = Record(folder), {}
    with initialize_config_dir(config_dir=str(CONF_DIR), version_base="1.3"):
        for name in sorted(manifest.experiments):
            cfg = compose("config", overrides=[f"experiment={name}", "scale=paper"])
            multiverse = "multiverse" in cfg.experiment
            stale[name] = record.stale_universes(load(cfg)) if multiverse else len(record.stale(expand(cfg)))
    assert {name: n for name, n in stale.items() if n} == {}, "run code changed: rebuild these parts of the record"


def test_diff_lists_each_changed_claim_and_cell_before_and_after(tmp_path, capsys):
    """Two drawn report folders whose summaries differ in one claim's verdict and one cell's estimate: diff reads
    what the summaries decide (no claims.csv or summary.csv there) and names both."""
    from replication.evidence.checks import Check, Result
    from replication.evidence.claims import load_papers
    from replication.evidence.published import load_published, published_path
    from replication.evidence.schema import Summary
    from replication.evidence.statistics import Estimate
    from replication.evidence.tables import KEYS, CellResult
    from replication.evidence.verdict import Outcome, Verdict
    from replication.report.diff import main as diff

    paper, claim = next((p, c) for p in load_papers() for c in p.claims if c.id == "ism_pf.accuracy")
    reading = claim.readings[0]
    index, cell = next((i, c) for i, c in load_published(str(published_path(None))).iterrows() if c["paper"] == paper.key)

    def summary(outcome: Outcome, ours: float) -> Summary:
        estimate = Estimate(ours, ours - 0.2, ours + 0.2, 10, "t")
        check = Check("accuracy", Verdict(outcome, "why"), Estimate(0.5, 0.4, 0.6, 10, "t"))
        entry = CellResult(int(index), *(str(cell[k]) for k in KEYS), table_name="t", our_method=cell["method"],
                           our_condition=str(cell["condition"]), runs=10, estimate=estimate,
                           verdict=Verdict(Outcome.REPRODUCED, "close"))
        return Summary(reading.experiment, "t", paper.key, "paper", 10, 10, cells=(entry,),
                       claims={claim.id: {reading.name: Result(Verdict(outcome, "why"), (check,), check)}})

    for name, (outcome, ours) in {"a": (Outcome.REPRODUCED, 4.1), "b": (Outcome.NOT_REPRODUCED, 4.2)}.items():
        (tmp_path / name / reading.experiment).mkdir(parents=True)
        summary(outcome, ours).write(tmp_path / name / reading.experiment)
    with pytest.raises(SystemExit) as status:
        diff([str(tmp_path / "a"), str(tmp_path / "b")])
    assert status.value.code == 1  # as diff(1): something differs
    out = capsys.readouterr().out
    assert f"A: {tmp_path / 'a'}: a drawn report, read as it is" in out
    assert f"{claim.id}: verdict 'reproduced' -> 'not reproduced'" in out
    key = " ".join(str(cell[k]) for k in KEYS if str(cell[k]))
    assert f"{key}: ours '4.1 [3.9, 4.3]' -> '4.2 [4, 4.4]'" in out
    assert ": 1 changed verdict, 1 changed at all; " in out and " cells: 1 changed" in out
    diff([str(tmp_path / "a"), str(tmp_path / "a")])  # the same: nothing differs, exit status 0
    assert ": 0 changed verdict, 0 changed at all; " in capsys.readouterr().out
    with pytest.raises(SystemExit) as status:
        diff([str(tmp_path / "a"), str(tmp_path / "nothing")])
    err = capsys.readouterr().err
    assert status.value.code == 2 and "nothing: no such folder" in err and "an installed copy ships none" in err


def test_diff_of_two_records_names_them_as_given_and_reads_pages_drawn_from_the_same_record(make_cfg, tmp_path,
                                                                                          monkeypatch, capsys):
    """Where reports/record holds a record's pages as this code draws them, diff reads them; another record's
    pages are drawn into a scratch folder that is never named (it is gone afterwards), with a bar.  The pages
    are drawn from this project even by workers a pool started for another one (they keep its environment)."""
    import os
    import shutil

    from joblib import Parallel, delayed

    from replication.paths import HOME_VARIABLE
    from replication.report.__main__ import main as report
    from replication.report.diff import main as diff

    cfg, _, _ = stored(make_cfg, tmp_path, "gps_qmcpf", UNGM)
    write([cfg], tmp_path / "experiments", tmp_path / "record")
    shutil.copytree(tmp_path / "record", tmp_path / "other")  # the same runs in another record (written later)
    manifest = json.loads((tmp_path / "other" / "manifest.json").read_text())
    manifest["experiments"]["gps_qmcpf"]["written"] = "2099-01-01"
    (tmp_path / "other" / "manifest.json").write_text(json.dumps(manifest))
    monkeypatch.setenv(HOME_VARIABLE, str(tmp_path / "elsewhere"))  # a call for another project starts the
    Parallel(n_jobs=2)(delayed(os.getenv)(HOME_VARIABLE) for _ in range(2))  # pool (or an earlier test had)
    monkeypatch.setenv(HOME_VARIABLE, str(tmp_path))  # the project: reports/ and record/ in it
    report(["source=record", "pdf=false", "progress=false"])  # reports/record, drawn from record/ (on that pool)
    capsys.readouterr()
    diff(["record", "other"])  # the same runs: nothing differs (no exit status 1)
    out, err = capsys.readouterr()
    assert f"A: record: a record whose pages {tmp_path / 'reports' / 'record'} holds, drawn from it" in out
    assert "B: other: a record of 1 experiments and multiverses: drawing its pages" in out and "pages: 100%" in err
    assert "0 changed verdict, 0 changed at all" in out
    assert "diff-" not in out + err  # no scratch folder (tempfile's diff-*) named


def test_a_multiverse_is_recorded_universe_by_universe_and_judged_from_the_record_as_from_the_store(tmp_path, capsys):
    from hydra import compose, initialize_config_dir
    from omegaconf import OmegaConf

    from replication.paths import CONF_DIR
    from replication.report.experiments import write_multiverse
    from replication.runner.multiverse import load

    with initialize_config_dir(config_dir=str(CONF_DIR), version_base="1.3"):
        top = OmegaConf.to_container(compose("config", overrides=[
            "experiment=hspf_ungm", "scale=paper", f"store={tmp_path}/store", "progress=false"]), resolve=True)
    hms = {"hms": {"label": "harmony memory size", "alternatives": {
        "paper": {"why": "HMS = 2, section 4.1", "set": {"methods.HSPF.hms": 2}},
        "larger": {"why": "a larger memory", "set": {"methods.HSPF.hms": 4}},
        "largest": {"why": "a larger memory still", "set": {"methods.HSPF.hms": 6}}}}}
    top["experiment"] = {"name": "hspf_test_readings", "paper": "hspf", "title": "test", "choices": hms,
                         "multiverse": {"experiments": ["hspf_ungm"], "runs": {"paper": 5, "quick": 5},
                                        "design": "full"}}
    cfg = OmegaConf.create(top)
    multiverse = load(cfg)
    execute(multiverse.runs_of("hspf_ungm"), Store(tmp_path / "store", "hspf_ungm"), n_jobs=2, progress=False)
    entry = write([cfg], tmp_path / "store", tmp_path / "record").experiments["hspf_test_readings"]
    with initialize_config_dir(config_dir=str(CONF_DIR), version_base="1.3"):  # and one with the experiment too
        experiment = compose("config", overrides=["experiment=hspf_ungm", "scale=paper", f"store={tmp_path}/store"])
    write([experiment, cfg], tmp_path / "store", tmp_path / "both")
    assert entry.runs == sum(len(runs) for runs in multiverse.runs.values())  # a shared run in each universe
    assert sorted(entry.files) == ["hspf_test_readings/universes/default.parquet",
                                   "hspf_test_readings/universes/hms=larger.parquet",
                                   "hspf_test_readings/universes/hms=largest.parquet"]
    record = Record(tmp_path / "record")
    for universe in multiverse.universes:
        runs = multiverse.runs[universe.name, "hspf_ungm"]
        assert same_records(record.universe(multiverse.name, universe.name).load(runs),
                            Store(tmp_path / "store", "hspf_ungm").load(runs))
    larger, largest = [u for u in multiverse.universes if not u.is_default]
    stale = record.universe(multiverse.name, larger.name).stale(multiverse.runs["default", "hspf_ungm"])
    assert {run.method for run in stale} == {"HSPF"}  # its HSPF runs are not the default universe's
    pages = []
    for where, store_of in (("store", None),
                            ("record", lambda name, u: record.universe(multiverse.name, u.name))):
        cfg.reports = str(tmp_path / where)
        pages.append(write_multiverse(cfg, multiverse, (), store_of).parent)
    assert (pages[0] / "cases.csv").read_text() == (pages[1] / "cases.csv").read_text()
    assert {r.grade for r in verify([cfg], record, 4, cheapest=False, n_jobs=2, progress=False).runs} == {
        Grade.IDENTICAL}
    larger_runs = multiverse.runs[larger.name, "hspf_ungm"]  # a universe not all run: left out, the others kept
    Store(tmp_path / "store", "hspf_ungm").path(next(r for r in larger_runs if r.method == "HSPF")).unlink()
    partial = write([cfg], tmp_path / "store", tmp_path / "partial").experiments["hspf_test_readings"]
    assert sorted(partial.files) == ["hspf_test_readings/universes/default.parquet",
                                     "hspf_test_readings/universes/hms=largest.parquet"]
    # the command goes on where a record stops: a universe recorded under this code's keys is not run again
    from replication.cli import multiverse_forecast, universes_left
    from replication.record.layer import recorded_universes

    assert not record.universe(multiverse.name, larger.name).holds(multiverse.runs["default", "hspf_ungm"])
    for folder, scale, skip, expected in (("partial", "paper", True, ["default", largest.name]),
                                          ("record", "paper", True, ["default", larger.name, largest.name]),
                                          ("record", "paper", False, []),
                                          ("record", "quick", True, [])):
        cfg.record, cfg.scale, cfg.skip_recorded = str(tmp_path / folder), scale, skip
        assert sorted(recorded_universes(cfg, multiverse)) == expected, (folder, scale, skip)
    # and says up front what is left and roughly how long, from the recorded times: here the one HSPF run
    cfg.record, cfg.scale, cfg.skip_recorded = str(tmp_path / "partial"), "paper", True
    said = multiverse_forecast(cfg, multiverse, recorded_universes(cfg, multiverse), 2)
    assert said.startswith("hspf_test_readings: 1 runs to compute, about ") and "1 worker(s)" in said, said
    left = universes_left(cfg, multiverse, recorded_universes(cfg, multiverse))  # what dry_run=true counts
    assert {where: len(runs) for where, runs in left.items()} == {
        "stored": len(larger_runs) - 1, "read from the record": 0, "to compute": 1}
    cfg.record = str(tmp_path / "record")
    assert multiverse_forecast(cfg, multiverse, recorded_universes(cfg, multiverse), 2).endswith(": 0 runs to compute")
    # grown by a repetition, with nothing stored, from a record that holds the experiment too (as the project's
    # does: the default universe is its runs): each universe's recorded runs are read from the record, the
    # larger memories' HSPF runs from their universes' files (no experiment's files have them), and only the new
    # repetition's runs that no file holds are computed
    from replication.record.layer import universes_beneath

    cfg.experiment.multiverse.runs.paper, cfg.store, cfg.record = 6, str(tmp_path / "empty"), str(tmp_path / "both")
    grown = load(cfg)
    left = universes_left(cfg, grown, *universes_beneath(cfg, grown))
    assert list(universes_beneath(cfg, grown)[0]) == ["default"]  # read whole: the experiment's own runs
    distinct = {run.run_id for universe in (larger, largest) for run in grown.runs[universe.name, "hspf_ungm"]}
    assert {where: len(runs) for where, runs in left.items()} == {
        "stored": 0, "read from the record": len(distinct) - 2, "to compute": 2}
    assert [(run.method, run.repetition) for run in left["to compute"].values()] == [("HSPF", 5)] * 2
    # and once computed, the grown multiverse is recorded from the record's rows and those stored runs, every
    # universe's rows read before the first universe's file is rewritten (which changes the multiverse's SHA-256s)
    execute(list(left["to compute"].values()), Store(tmp_path / "empty", "hspf_ungm"), n_jobs=1, progress=False)
    capsys.readouterr()
    grown_entry = write([cfg], tmp_path / "empty", tmp_path / "both").experiments["hspf_test_readings"]
    assert grown_entry.runs == entry.runs + 6  # a repetition more of each larger memory's 3 methods
    assert "SHA-256" not in capsys.readouterr().err


def test_every_curved_figure_kind_has_its_curve_table_and_no_other_kind_does():
    """A figure kind declares that it draws a curve table (``curved``); the table is computed below the report
    (:data:`replication.runner.curves.CURVES`): the two lists name the same kinds."""
    assert {name for name, kind in FIGURE_KINDS.items() if kind.curved} == set(CURVES)
