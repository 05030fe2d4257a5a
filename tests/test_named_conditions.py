"""Conditions named in claims, tables and figures: mappings of values, matched with the runs' conditions as
values (issue 55), and refused before any run where they are labels or match no run."""

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from hydra import compose, initialize_config_dir

from conftest import typed

from replication.condition import Condition
from replication.errors import ConfigError
from replication.evidence.claims import evaluate, load_own_papers
from replication.evidence.named_conditions import as_mapping, holds, matching, same
from replication.evidence.verdict import Outcome
from replication.evidence.tables import Compared, matched
from replication.paths import CONF_DIR, experiment_names
from replication.runner.config import experiment_at_scale, planned
from replication.runner.validate import check_conditions, named_conditions

HEAD = "paper: mine\norder: 7\ntitle: t\nauthors: a\nvenue: v\nclaims:\n"


def _claims(folder, readings: dict[str, str]):
    """A user's claims file with one claim per reading (``{claim id: the reading's YAML flow mapping}``)."""
    folder.mkdir(exist_ok=True)
    (folder / "mine.yaml").write_text(HEAD + "".join(
        f"  - id: {claim}\n    claim: c\n    source: s\n    readings:\n      - {reading}\n"
        for claim, reading in readings.items()))
    return load_own_papers(folder)


def _records(column=lambda n: n) -> pd.DataFrame:
    """A better than B by 0.3 at scene x, N = 10 (common random numbers, 20 runs), tied elsewhere; ``column``:
    the record's type for N (an int, as the store gives it, or the text or float another reader might)."""
    rng = np.random.default_rng(7)
    rows = []
    for scene, n in (("x", 10), ("x", 20), ("y", 10)):
        base = rng.normal(5.0, 1.0, 20)
        for r in range(20):
            for method, effect in (("A", -0.3 if (scene, n) == ("x", 10) else 0.0), ("B", 0.0)):
                rows.append({"method": method, "condition": f"scene={scene};N={n}", "data_condition": f"scene={scene}",
                             "repetition": r, "rmse": base[r] + effect + 0.05 * rng.standard_normal()})
    records = typed(pd.DataFrame(rows))
    return records.assign(**{"condition.N": records["condition.N"].map(column)})


def _results(tmp_path, records, **readings) -> dict:
    papers = _claims(tmp_path / "claims", {f"mine.{k}": v for k, v in readings.items()})
    return evaluate("e", {"methods": {"A": {}, "B": {}}}, records, {}, papers=papers)


def test_a_mapping_in_either_order_gives_the_same_verdict_on_the_same_runs(tmp_path):
    """The label ``scene=x;N=10`` found the runs, ``N=10;scene=x`` silently none; as values both find them."""
    order = "{{name: r, experiment: e, test: order, metric: rmse, order: [A, B], conditions: [{}]}}"
    for column in (int, str, float):  # the record's N as the store writes it, as text, as a float
        results = _results(tmp_path, _records(column), written=order.format("{scene: x, N: 10}"),
                           turned=order.format("{N: 10, scene: x}"))
        written, turned = results["mine.written"]["r"], results["mine.turned"]["r"]
        assert written.verdict == turned.verdict and written.verdict.outcome is Outcome.REPRODUCED, column
        assert [c.what for c in written.checks] == [c.what for c in turned.checks] == ["A - B at scene=x;N=10"]
        assert written.checks[0].per_run == turned.checks[0].per_run


def test_a_mapping_naming_some_variables_checks_each_condition_it_picks(tmp_path):
    """``{scene: x}`` picks N = 10 and N = 20: a check at each (as a reading naming none checks every one), so
    the effect at N = 10 holds and the tie at N = 20 leaves the reading inconclusive."""
    results = _results(tmp_path, _records(), some="{name: r, experiment: e, test: order, metric: rmse, order: [A, B], "
                                                  "conditions: [{scene: x}]}",
                       one="{name: r, experiment: e, test: threshold, metric: rmse, method: B, at_most: 100.0, "
                           "condition: {N: 20}}")
    some = results["mine.some"]["r"]
    assert [c.what for c in some.checks] == ["A - B at scene=x;N=10", "A - B at scene=x;N=20"]
    assert [c.verdict.outcome for c in some.checks] == [Outcome.REPRODUCED, Outcome.INCONCLUSIVE]
    one = results["mine.one"]["r"]  # a threshold named one condition: its check says none
    assert [c.what for c in one.checks] == ["B mean rmse <= 100"] and one.checks[0].estimate.runs == 20


def test_values_are_compared_as_the_records_types():
    assert same(400, 400) and same(400.0, 400) and same(np.int64(400), 400) and same(400, "400")
    assert same("4", 4) and same("Girl", "Girl") and same(0.5, 0.5) and same("0.5", 0.5)
    assert not same(400, 401) and not same("4", 4.5) and not same(400, "Girl") and not same("Girl", "girl")
    assert same(True, True) and not same(True, 1) and not same(1, True) and not same(np.bool_(False), 0)
    assert not same(None, None) and not same(float("nan"), 400)  # a run without the variable has no value
    records = pd.DataFrame({"condition.N": pd.Series([100, None, 400], dtype=object),
                            "condition.scene": ["a", "a", "b"]})
    assert matching(records, {"N": 400}).tolist() == [False, False, True]
    assert matching(records, {"scene": "a"}).tolist() == [True, True, False]
    assert matching(records, {"scene": "a", "N": 100}, {"scene": "b"}).tolist() == [True, False, True]
    assert matching(records, {}).all() and not matching(records).any()
    assert holds(Condition.of([("n_particles", 400), ("scene", "b")]).columns(), {"scene": "b", "N": 400})


def test_a_condition_written_as_its_label_is_refused_in_one_line(tmp_path):
    with pytest.raises(ConfigError) as refused:
        as_mapping("scene=exp2_16_targets;N=400", "claim c")
    assert str(refused.value) == ("claim c: write the condition 'scene=exp2_16_targets;N=400' as a mapping, "
                                  "{scene: exp2_16_targets, N: 400}")
    with pytest.raises(ConfigError, match=r"mine.yaml: claim mine.x, reading r: write the condition 'N=10;scene=x' "
                                          r"as a mapping, \{N: 10, scene: x\}$"):
        _claims(tmp_path, {"mine.x": '{name: r, experiment: e, test: order, metric: rmse, order: [A, B], '
                                     'conditions: ["N=10;scene=x"]}'})
    with pytest.raises(ConfigError, match=r"^table 't': match is a list: write 'scene=a' as - "
                                          r"\{ours: \{scene: a\}, paper: \{experiment: a\}\}$"):
        matched(Compared(name="t", match={"scene=a": {"experiment": "a"}}))
    with pytest.raises(ConfigError, match=r"^experiment/bis_pf.yaml: figure 'encounters': conditions: write the "
                                          r"condition 'scene=exp2_16_targets' as a mapping, \{scene: exp2_16_targets\}$"):
        check_conditions(_cfg("experiment=bis_pf", 'experiment.report.figures.2.conditions=["scene=exp2_16_targets"]'))


def _cfg(*overrides):
    with initialize_config_dir(config_dir=str(CONF_DIR), version_base="1.3"):
        return compose("config", overrides=list(overrides))


def test_a_condition_no_run_has_is_refused_before_any_run(tmp_path, cli):
    """The request stops at its checks, in one line naming the file, the entry and each variable's values."""
    _claims(tmp_path / "claims", {"mine.x": "{name: r, experiment: gps_qmcpf, test: order, metric: rmse, "
                                            "order: [GPS-QMCPF, PF], conditions: [{N: 500}, {N: 50}]}"})
    done = cli("experiment=gps_qmcpf", "scale=quick", f"claims_dir={tmp_path / 'claims'}", timeout=120)
    assert done.returncode == 2, done.stderr
    assert done.stderr.strip().splitlines() == [
        f"error: {tmp_path / 'claims' / 'mine.yaml'}: claim mine.x, reading r: {{N: 50}} matches no run of gps_qmcpf; "
        "its runs take N: 500, 200, 100"]
    assert not (tmp_path / "experiments").exists()  # nothing run, nothing stored
    with pytest.raises(ConfigError, match=r"^experiment/bis_pf.yaml: figure 'encounters': conditions: \{scene: exp9\} "
                                          r"matches no run of bis_pf; its runs take scene: exp1_3123, exp2_16_targets, "
                                          r"exp3_36_targets$"):
        check_conditions(_cfg("experiment=bis_pf", "experiment.report.figures.2.conditions.0.scene=exp9"))


def test_a_claim_condition_the_quick_scale_lacks_is_no_error_there(tmp_path):
    """bis_pf_pets runs TUD-Campus at paper scale only: a claim on it is checked where it runs, and the quick
    scale leaves the check out (the reading is not testable there) rather than refuse the request."""
    _claims(tmp_path / "claims", {"mine.x": "{name: r, experiment: bis_pf_pets, test: order, metric: mota, "
                                            "order: [BIS-PF, MIPF], conditions: [{scene: tud_campus}]}"})
    for scale in ("paper", "quick"):
        check_conditions(_cfg("experiment=bis_pf_pets", f"scale={scale}", f"claims_dir={tmp_path / 'claims'}"))


@pytest.mark.parametrize("scale", ["paper", "quick"])
def test_every_shipped_condition_matches_runs_of_its_experiment(scale):
    """Every condition a shipped claim, table or figure names matches runs of its experiment as the runner
    expands it, at paper scale; at quick scale too, but for a claim's (the quick scale may run fewer
    conditions: a claim is checked where its condition runs)."""
    files = set()
    for name in experiment_names():
        cfg = _cfg(f"experiment={name}", f"scale={scale}")
        if "multiverse" in cfg.experiment:
            continue
        check_conditions(cfg)
        ran = {str(c): c for _, c, *_ in planned(experiment_at_scale(cfg))}.values()
        paper = {str(c): c for _, c, *_ in planned(experiment_at_scale(cfg, "paper"))}.values()
        for where, wanted in named_conditions(cfg):
            assert any(holds(c.columns(), wanted) for c in paper), (name, where, wanted)
            assert "claim" in where or any(holds(c.columns(), wanted) for c in ran), (name, scale, where, wanted)
            files.add("/".join(Path(where.split(":")[0]).parts[-2:]))
    assert files == {"claims/bis_pf.yaml", "claims/fusion_pf.yaml", "claims/gps_qmcpf.yaml", "claims/hspf.yaml",
                     "claims/ism_pf.yaml", "experiment/bis_pf.yaml", "experiment/bis_pf_pets.yaml",
                     "experiment/fusion_pf.yaml", "experiment/ism_pf.yaml"}  # every file that names a condition was read
