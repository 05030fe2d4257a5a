"""One schema for summary.json (typed values out, the same typed values back) and one inference setting that
every rule reads."""

import math

import numpy as np
import pytest

from replication.errors import ConfigError
from replication.evidence.checks import Check, Result
from replication.evidence.schema import RobustnessResult, Summary, dump, load
from replication.evidence.settings import INFERENCE, configure, rules
from replication.evidence.statistics import Estimate
from replication.evidence.tables import CellResult
from replication.evidence.verdict import BAYES_FLOOR, Outcome, Verdict, decide, too_few


def _summary() -> Summary:
    check = Check("A - B", Verdict(Outcome.REPRODUCED, "p = 0.01", 0.01, 0.9), Estimate(1.5, 0.2, math.nan, 7, "t"),
                  unit=" px", reference=0.0, per_run={0: 1.0, 3: 2.0})
    cell = CellResult(4, "bis_pf", "2", "exp2", "BIS-PF", "error", "", "t2", "BIS-PF", "scene=x", 10, 0.91,
                      Estimate(1.3, 1.1, 1.5, 10, "t"), verdict=Verdict(Outcome.NOT_REPRODUCED, "below", None, 0.001,
                                                                         BAYES_FLOOR),
                      at_tolerance={"0.05": Outcome.NOT_REPRODUCED, "0.2": Outcome.INCONCLUSIVE})
    rating = CellResult(5, "bis_pf", "3", "exp2", "MCMC", "stability", "", "t3", "MCMC", "", 10, None,
                        Estimate(0.4, 0.1, 0.7, 10, "Clopper-Pearson"), rating="fair")
    robust = RobustnessResult(False, "depends on the reading", "A - B", 4, ("x=b (+1)",), "x=b",
                              Verdict(Outcome.REPRODUCED), "1.5 px")
    return Summary("bis_pf", "BIS-PF", "bis_pf", "paper", 40, 40, {"not finite: rmse=nan": 2}, (cell, rating),
                   {"bis_pf.error": {"identity-free": Result(check.verdict, (check,), check)}}, ("runs: 5",),
                   ({"name": "t2", "title": "Table 2", "csv": "t2.csv", "note": ""},), (), {"bis_pf.error": robust})


def test_a_summary_comes_back_as_the_typed_values_it_was_written_from(tmp_path):
    summary = _summary()
    back = Summary.read(summary.write(tmp_path))
    assert dump(back) == dump(summary)
    cell, rating = back.cells
    assert cell.verdict.outcome is Outcome.NOT_REPRODUCED and cell.verdict.tag == BAYES_FLOOR
    assert cell.at_tolerance == {"0.05": Outcome.NOT_REPRODUCED, "0.2": Outcome.INCONCLUSIVE}
    assert cell.paper_number == 0.91 and cell.ours == "1.3 [1.1, 1.5]" and rating.ours == "fair"
    result = back.claims["bis_pf.error"]["identity-free"]
    assert isinstance(result, Result) and result.deciding == result.checks[0]
    assert result.deciding.per_run == {0: 1.0, 3: 2.0}  # integer repetitions, not the strings JSON keys are
    assert math.isnan(result.deciding.estimate.high) and result.deciding.number == "1.5 px"
    assert back.multiverse["bis_pf.error"].best_case_verdict.outcome is Outcome.REPRODUCED
    assert back.verdicts == {"not reproduced": 1}
    assert "NaN" not in (tmp_path / "summary.json").read_text()  # plain JSON


def test_load_rebuilds_nested_and_optional_values():
    assert load(tuple[int, ...], [1, 2]) == (1, 2)
    assert load(dict[int, float], {"1": None})[1] != load(dict[int, float], {"1": None})[1]  # NaN
    assert load(Verdict | None, None) is None
    assert load(Outcome, "inconclusive") is Outcome.INCONCLUSIVE
    assert dump(np.float64(np.inf)) is None and dump(np.int64(3)) == 3


@pytest.fixture
def shipped_inference():
    before = INFERENCE.as_dict()
    yield
    configure(before)


def test_the_inference_setting_decides_and_writes_the_rules(shipped_inference):
    p_for, p_against = np.array([[0.07]]), np.array([[0.9]])
    assert decide(p_for, p_against)[1][0] == 2  # inconclusive at 5 %
    assert "one-sided test at 5 %" in rules()[0] and "fewer than 5 runs" in rules()[-1]
    configure({"alpha": 0.10, "min_runs": 3})
    assert decide(p_for, p_against)[1][0] == 0  # reproduced at 10 %
    assert "one-sided test at 10 %" in rules()[0] and "fewer than 3 runs" in rules()[-1]
    assert too_few(4) is None and too_few(2).outcome is Outcome.NOT_TESTABLE
    with pytest.raises(ConfigError, match="unknown setting"):
        configure({"alfa": 0.1})
    with pytest.raises(ConfigError, match="strictly in"):
        configure({"alpha": 1.5})
    assert INFERENCE.alpha == 0.10  # a refused setting changes nothing
