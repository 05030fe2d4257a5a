"""Every kind named in YAML with options of its own (a table, a figure, a claim's test) declares them as typed
fields: each shipped spec is one of them, and an unknown kind or a misspelled option is refused in one line
naming the file, the entry and the options the kind takes, before any run."""

from dataclasses import dataclass

import pytest
import yaml
from hydra import compose, initialize_config_dir

from replication.errors import ConfigError
from replication.evidence.claim_tests import CLAIM_TESTS, claim_spec
from replication.evidence.claims import load_own_papers, load_papers
from replication.evidence.figures import FIGURE_KINDS, MetricVsCondition, figure_spec
from replication.evidence.tables import TABLE_KINDS, table_spec
from replication.kinds import Registry
from replication.paths import CONF_DIR, experiment_names
from replication.report.figures import DRAWINGS
from replication.specs import Spec


def composed(name: str, tmp_path, *overrides: str):
    out = [f"store={tmp_path / 'experiments'}", f"reports={tmp_path / 'reports'}", "outside_project=true"]
    with initialize_config_dir(config_dir=str(CONF_DIR), version_base="1.3"):
        return compose("config", overrides=[f"experiment={name}", *out, *overrides])


def test_every_kind_is_in_one_registry_and_every_figure_kind_is_drawn():
    assert all(isinstance(kinds, Registry) for kinds in (TABLE_KINDS, FIGURE_KINDS, CLAIM_TESTS))
    assert {"comparison", "summary", "ranking", "modes"} <= set(TABLE_KINDS)
    assert {"order", "threshold", "uniformity"} <= set(CLAIM_TESTS)
    assert set(DRAWINGS) == set(FIGURE_KINDS.values())  # a kind without its drawing, or a drawing of no kind
    assert FIGURE_KINDS["per_frame_curve"].curved and not FIGURE_KINDS["ranking"].curved


def test_every_shipped_spec_is_typed_and_passes_the_check(tmp_path):
    """Each experiment's tables and figures at both scales, through the check a request passes."""
    from replication.runner.validate import check_report, report_specs

    seen = set()
    for name in experiment_names():
        cfg = composed(name, tmp_path)
        for scale in ("quick", "paper"):
            cfg.scale = scale
            check_report(cfg)
            if "multiverse" not in cfg.experiment:
                tables, figures = report_specs(cfg)
                seen |= {spec.kind for spec in tables + figures}
    assert len(seen) >= 20
    readings = [r for paper in load_papers() for c in paper.claims for r in c.readings]
    assert len({type(r.test) for r in readings}) == len(CLAIM_TESTS) and all(isinstance(r.test, Spec) for r in readings)


def test_a_spec_is_a_typed_value():
    spec = figure_spec({"name": "f", "kind": "metric_vs_condition", "metric": "rmse", "x": "N", "log_y": True})
    assert isinstance(spec, MetricVsCondition) and spec.log_y and spec.log_x and spec.by is None
    table = table_spec({"name": "t", "kind": "discrepancy", "dims": [2, 3]})
    assert table.dims == (2, 3) and table.n == 400
    assert claim_spec({"test": "order", "metric": "rmse", "order": ["A", "B"]}).tolerance == 0.0


@dataclass(frozen=True)
class Bad:
    """A spec written wrong in a shipped experiment (``entry``: which of its tables or figures, the override
    setting it) and what its one line must say."""

    experiment: str
    override: str
    said: tuple[str, ...]


BAD = [
    Bad("hspf_ungm_sweep", "+experiment.report.figures.0.logy=true",
        ("experiment/hspf_ungm_sweep.yaml: figure", "(metric_vs_condition): unknown option 'logy'; known options: name, ",
         "log_y")),
    Bad("hspf_ungm_sweep", "experiment.report.figures.0.kind=line_chart",
        ("experiment/hspf_ungm_sweep.yaml: figure", "unknown figure kind 'line_chart'; known figure kinds: ",
         "metric_vs_condition")),
    Bad("hspf_ungm_sweep", "+experiment.report.figures.0.log_y=often",
        ("(metric_vs_condition): log_y must be true or false, got 'often'",)),
    Bad("hspf_ungm", "+experiment.report.tables.0.show_varience=true",
        ("experiment/hspf_ungm.yaml: table", "(comparison): unknown option 'show_varience'; known options: ", "show_variance")),
    Bad("hspf_ungm", "+experiment.report.tables.0.kind=histogram",
        ("experiment/hspf_ungm.yaml: table", "unknown table kind 'histogram'; known table kinds: ", "comparison")),
    Bad("hspf_ungm", "~experiment.report.tables.0.metric", ("(comparison): lacks the option 'metric'; known options",)),
    Bad("hspf", "+experiment.report.tabels=[]", ("unknown key report.tabels; report takes tables, figures",)),
]


@pytest.mark.parametrize("bad", BAD, ids=lambda bad: bad.override)
def test_a_bad_table_or_figure_spec_is_one_line_before_any_run(bad, tmp_path, monkeypatch):
    """Through the check a request passes (:func:`~replication.runner.validate.prepare`), which expands no run."""
    from replication.runner import validate

    cfg = composed(bad.experiment, tmp_path, bad.override, "scale=quick")
    monkeypatch.setattr(validate, "expand", lambda *a: pytest.fail("runs expanded before the report was checked"))
    with pytest.raises(ConfigError) as error:
        validate.prepare(cfg)
    line = str(error.value)
    assert "\n" not in line and all(part in line for part in bad.said), line


@pytest.mark.parametrize("reading, said", [
    ("{name: r, experiment: hspf_ungm, test: order, metric: rmse, order: [HSPF, PF], tolerence: 0.1}",
     "claim mine.x, reading r (order): unknown option 'tolerence'; known options: name, experiment, ours, test, "),
    ("{name: r, experiment: hspf_ungm, test: faster, metric: rmse}",
     "claim mine.x, reading r: unknown claim test 'faster'; known claim tests: "),
    ("{name: r, experiment: hspf_ungm, test: threshold, method: HSPF, metric: rmse, at_most: low}",
     "claim mine.x, reading r (threshold): at_most must be a number or null, got 'low'"),
])
def test_a_bad_claim_test_is_one_line_before_any_run(reading, said, tmp_path, monkeypatch):
    """A user's own claims file (``claims_dir``) with a misspelled option or an unknown test: refused by the
    check a request passes, naming the file, the claim and reading, and the options known."""
    from replication.runner import validate

    claims = tmp_path / "claims"
    claims.mkdir()
    (claims / "mine.yaml").write_text(yaml.safe_dump(yaml.safe_load(
        "paper: mine\norder: 7\ntitle: t\nauthors: a\nvenue: v\nclaims:\n  - id: mine.x\n    claim: c\n"
        f"    where: s\n    readings:\n      - {reading}\n")))
    with pytest.raises(ConfigError, match="mine.yaml: " + said.replace("(", r"\(").replace(")", r"\)")):
        load_own_papers(claims)
    cfg = composed("hspf_ungm", tmp_path, f"claims_dir={claims}", "scale=quick")
    monkeypatch.setattr(validate, "expand", lambda *a: pytest.fail("runs expanded before the claims were checked"))
    with pytest.raises(ConfigError) as error:
        validate.prepare(cfg)
    assert "\n" not in str(error.value) and said in str(error.value)
