"""A paper's multiverse: designs over its open choices, overrides that only touch what exists, the
default universe equal to the experiments as they stand, and each claim's robustness across cases."""

import numpy as np
import pandas as pd
import pytest
from hydra import compose, initialize_config_dir
from omegaconf import OmegaConf

from replication.errors import ConfigError
from replication.evidence.verdict import Outcome, Verdict
from replication.paths import CONF_DIR, experiment_names
from replication.evidence.checks import Check, Result
from replication.evidence.claim_tests import claim_spec
from replication.evidence.claims import EQUAL_N, Claim, Quote, Reading, load_papers
from replication.evidence.multiverse import BASIS, READING, Case, Robustness
from replication.evidence.robustness import Pairing
from replication.evidence.schema import Summary
from replication.evidence.statistics import Estimate
from replication.report.experiments import write_multiverse
from replication.runner.config import expand
from replication.runner.execute import execute
from replication.runner.multiverse import apply, choices_of, design, load, matches
from replication.runner.store import Store

TWO_BY_THREE = {
    "a": {"label": "first", "alternatives": {"a0": {"why": "x", "set": {"p": 0}}, "a1": {"why": "y", "set": {"p": 1}}}},
    "b": {"label": "second", "alternatives": {f"b{i}": {"why": "z", "set": {"q": i}} for i in range(3)}},
}


def test_designs_start_from_the_default_and_cover_what_they_say():
    choices = choices_of(TWO_BY_THREE)
    full = design(choices, "full", seed=1)
    assert len(full) == 6 and full[0].is_default and len({u.name for u in full}) == 6
    assert [u.name for u in design(choices, "one_at_a_time", seed=1)] == ["default", "a=a1", "b=b1", "b=b2"]
    sobol = design(choices, {"sobol": 8}, seed=1)
    assert sobol[0].is_default and set(sobol) <= set(full)
    assert design(choices, {"sobol": 8}, seed=1) == sobol  # seeded
    assert [u.name for u in design(choices, {"one_at_a_time": ["b"]}, seed=1)] == ["default", "b=b1", "b=b2"]
    assert len(design(choices, {"full": ["a"]}, seed=1)) == 2
    for bad in ("all", {"sobol": 6}, {"lhs": 4}, {"full": ["c"]}, {"one_at_a_time": []}):
        with pytest.raises(ConfigError, match="design"):
            design(choices, bad, seed=1)


def test_a_choice_added_outside_a_sobol_designs_over_leaves_its_points_and_a_list_is_the_union():
    """Adding a choice to a paper's readings must not redraw the universes already run: a Sobol design ``over``
    the old choices keeps their points (the new choice at its default there), and a list of designs adds the
    new choice's own universes beside them."""
    choices = choices_of(TWO_BY_THREE)
    before = design(choices, {"sobol": 8}, seed=1)
    grown = choices_of({**TWO_BY_THREE, "c": {"alternatives": {"c0": {"why": "x", "set": {"r": 0}},
                                                                "c1": {"why": "y", "set": {"r": 1}}}}})
    kept = design(grown, {"sobol": 8, "over": ["a", "b"]}, seed=1)
    assert [u.name for u in kept] == [u.name for u in before]  # the same universes, named alike
    assert all(dict(u.picks)["c"] == "c0" for u in kept)
    union = design(grown, [{"sobol": 8, "over": ["a", "b"]}, {"one_at_a_time": ["c"]}], seed=1)
    assert [u.name for u in union] == [u.name for u in before] + ["c=c1"]  # the default once
    for bad in ({"sobol": 8, "over": ["d"]}, {"sobol": 8, "over": []}, {"sobol": 8, "of": ["a"]}):
        with pytest.raises(ConfigError, match="design"):
            design(grown, bad, seed=1)


def test_a_choices_default_never_overrides_another_choices_reading_of_the_same_path():
    """Patience in frames (one choice) or in seconds (another): the frames' reading sets seconds to None, and the
    seconds' default, whatever the choices' order, does not set it back."""
    from replication.runner.multiverse import Universe, universe_values

    spec = {"seconds": {"alternatives": {"s14": {"why": "x", "set": {"d.seconds": 1.4}},
                                         "s07": {"why": "y", "set": {"d.seconds": 0.7}}}},
            "frames": {"alternatives": {"given": {"why": "x", "set": {"d.frames": None}},
                                        "f10": {"why": "y", "set": {"d.frames": 10, "d.seconds": None}}}}}
    for order in (list(spec), list(reversed(spec))):
        choices = choices_of({name: spec[name] for name in order})
        picked = [c.alternatives[1] if c.name == "frames" else c.default for c in choices]
        assert universe_values(choices, Universe.of(choices, picked)) == {"d.seconds": None, "d.frames": 10}
        picked = [c.alternatives[1] if c.name == "seconds" else c.default for c in choices]
        assert universe_values(choices, Universe.of(choices, picked)) == {"d.seconds": 0.7, "d.frames": None}


def test_a_choice_needs_two_alternatives_each_with_its_why():
    with pytest.raises(ConfigError, match="at least two"):
        choices_of({"a": {"alternatives": {"only": {"why": "x", "set": {"p": 0}}}}})
    with pytest.raises(ConfigError, match="why"):
        choices_of({"a": {"alternatives": {"a0": {"set": {"p": 0}}, "a1": {"why": "y", "set": {"p": 1}}}}})


def test_an_override_touches_only_paths_that_exist():
    config = {"methods": {"ISM": {"bests": "stored", "c1": 0.8}, "PF": {"n": 10}},
              "scenes": {"s": {"targets": [{"v": 1}, {"v": 2}]}}}
    assert [key for _, key in matches(config, "methods.*.bests")] == ["bests"]
    assert len(matches(config, "scenes.s.targets.*.v")) == 2 and matches(config, "scenes.s.targets.5.v") == []
    changed, matched = apply(config, {"methods.*.bests": "rescored", "methods.*.absent": 1,
                                      "scenes.s.targets.1.v": 9})
    assert changed["methods"]["ISM"]["bests"] == "rescored" and "bests" not in changed["methods"]["PF"]
    assert changed["scenes"]["s"]["targets"] == [{"v": 1}, {"v": 9}]
    assert matched == ["methods.*.bests", "scenes.s.targets.1.v"]
    assert config["methods"]["ISM"]["bests"] == "stored"  # the original is left as it was


def _multiverse_cfg(tmp_path, choices: dict, design_spec="full", experiments=("hspf_ungm",)):
    with initialize_config_dir(config_dir=str(CONF_DIR), version_base="1.3"):
        cfg = compose("config", overrides=["experiment=hspf_ungm", "scale=quick", f"store={tmp_path}/store",
                                           f"reports={tmp_path}/reports", "progress=false"])
    top = OmegaConf.to_container(cfg, resolve=True)
    top["experiment"] = {"name": "hspf_test_readings", "paper": "hspf", "title": "test",
                         "multiverse": {"experiments": list(experiments), "runs": {"paper": 5, "quick": 5},
                                        "design": design_spec},
                         "choices": choices}
    return OmegaConf.create(top)


HMS = {"hms": {"label": "harmony memory size", "alternatives": {
    "paper": {"why": "HMS = 2, section 4.1", "set": {"methods.HSPF.hms": 2}},
    "larger": {"why": "a larger memory", "set": {"methods.HSPF.hms": 4}}}}}


def test_the_default_must_be_the_config_as_it_stands_and_every_path_must_exist(tmp_path):
    wrong_default = {"hms": {"alternatives": {"a": {"why": "x", "set": {"methods.HSPF.hms": 3}},
                                              "b": {"why": "y", "set": {"methods.HSPF.hms": 4}}}}}
    with pytest.raises(ConfigError, match="default alternative must be what hspf_ungm says today"):
        load(_multiverse_cfg(tmp_path, wrong_default))
    absent = {"hms": {"alternatives": {"a": {"why": "x", "set": {"methods.HSPF.nope": 3}},
                                       "b": {"why": "y", "set": {"methods.HSPF.nope": 4}}}}}
    with pytest.raises(ConfigError, match="no such key"):
        load(_multiverse_cfg(tmp_path, absent))


def test_a_multiverse_reuses_the_default_runs_and_judges_every_claim_in_every_universe(tmp_path):
    cfg = _multiverse_cfg(tmp_path, HMS, experiments=("hspf_ungm", "hspf_ungm_cost"))
    multiverse = load(cfg)
    assert [u.name for u in multiverse.universes] == ["default", "hms=larger"]
    default = {r.run_id for r in multiverse.runs["default", "hspf_ungm"]}
    larger = {r.run_id for r in multiverse.runs["hms=larger", "hspf_ungm"]}
    # the default universe is the base experiment itself, at its own 20 runs (the primary verdict's data);
    # the other universe runs the multiverse's 5 of each
    with initialize_config_dir(config_dir=str(CONF_DIR), version_base="1.3"):
        base = expand(compose("config", overrides=["experiment=hspf_ungm", "scale=quick"]))
    assert default == {r.run_id for r in base} and len(default) == 3 * 20 and len(larger) == 3 * 5
    # PF and the grid are the same in both universes (their first 5 runs), HSPF differs
    assert {i.split("__")[0] for i in larger - default} == {"HSPF"} and len(default & larger) == 10
    assert len(multiverse.runs_of("hspf_ungm")) == 65
    for name in multiverse.experiments:
        runs = multiverse.runs_of(name)
        assert execute(runs, Store(tmp_path / "store", name), n_jobs=1, backend="threading", progress=False) \
            == len(runs)
    page = write_multiverse(cfg, multiverse)
    claim = Summary.read(page.parent / "summary.json").multiverse["hspf.ungm"]
    readings = [r.name for p in load_papers() for c in p.claims if c.id == "hspf.ungm" for r in c.readings
                if r.experiment in multiverse.experiments]  # the equal-cost ones on hspf_ungm_cost included
    assert 0 < len(readings) and claim.cases == 2 * len(readings)  # every universe with every reading it runs
    cases = pd.read_csv(page.parent / "cases.csv")
    assert {("hms", "paper"), ("hms", "larger")} <= set(zip(["hms"] * len(cases), cases["hms"]))
    # equal cost is a named choice: each universe scored at equal N, equal evaluations and equal time
    ours = cases[cases["claim_id"] == "hspf.ungm"]
    assert set(zip(ours["universe"], ours[BASIS])) == {
        (u, b) for u in ("default", "hms=larger")
        for b in (EQUAL_N, "equal likelihood evaluations per step", "equal time per step (ms)")}
    assert (page.parent / "readings.png").exists() and (page.parent / "cases.csv").exists()


def _case(universe: str, picks: dict, outcome: Outcome, reading: str = "r1", held: int = 1,
          per_run: dict | None = None, timed: bool = False) -> Case:
    checks = tuple(Check("A - B" if i == 0 else "other", Verdict(Outcome.REPRODUCED if i < held else outcome),
                         per_run=dict(per_run or {}) if i == 0 else {}, timed=timed) for i in range(2))
    deciding = Check("A - B", Verdict(outcome), Estimate(1.0, 0.5, 1.5, 10, "t"), timed=timed)
    return Case(universe, (*picks.items(), (READING, reading)), Result(Verdict(outcome), checks, deciding))


CLAIM = Claim("p.c", "p", "A beats B", Quote("A schlägt B", "A beats B"), "Table 1", {}, (Reading("r1", "e", claim_spec({"test": "order", "metric": "rmse", "order": ["A", "B"]})),))
RUNS = dict(enumerate(np.random.default_rng(4).normal(0.3, 1.0, 10)))


def _shifted(by: float, noise: float = 0.05) -> dict:
    rng = np.random.default_rng(int(by * 100) + 1)
    return {r: v + by + noise * rng.standard_normal() for r, v in RUNS.items()}


def test_robust_when_every_testable_case_agrees():
    cases = (_case("default", {"x": "a"}, Outcome.NOT_REPRODUCED), _case("x=b", {"x": "b"}, Outcome.NOT_REPRODUCED),
             _case("x=c", {"x": "c"}, Outcome.NOT_TESTABLE))
    robustness = Robustness(CLAIM, cases)
    assert robustness.robust is True and robustness.flipped_by == []
    assert robustness.summary.startswith("robust: no open choice moves the verdict")


def test_a_verdict_that_reads_differently_with_no_effect_behind_it_is_noise():
    # x=b's runs are the default's (common random numbers) plus a little noise: its different verdict from
    # a few runs is no effect of the choice
    cases = (_case("default", {"x": "a"}, Outcome.INCONCLUSIVE, per_run=RUNS),
             _case("x=b", {"x": "b"}, Outcome.REPRODUCED, per_run=_shifted(0.0)))
    robustness = Robustness(CLAIM, cases)
    (effect,) = robustness.effects
    assert effect.flips == 1 and not effect.significant and not effect.moves
    assert robustness.robust is True and "largest effect on A - B: x=b" in robustness.summary


def test_a_choice_with_a_real_effect_that_moves_the_verdict_makes_it_depend_on_the_reading():
    cases = (_case("default", {"x": "a", "y": "a"}, Outcome.NOT_REPRODUCED, per_run=RUNS),
             _case("x=b", {"x": "b", "y": "a"}, Outcome.REPRODUCED, per_run=_shifted(1.0)),
             _case("y=b", {"x": "a", "y": "b"}, Outcome.INCONCLUSIVE, held=0, per_run=_shifted(0.0)),
             _case("y=b'", {"x": "a", "y": "b"}, Outcome.INCONCLUSIVE, reading="r2", held=1))
    robustness = Robustness(CLAIM, cases)
    assert robustness.robust is False
    moving = robustness.moving
    assert [(e.choice, e.alternative) for e in moving] == [("x", "b")]
    assert moving[0].effect.value == pytest.approx(1.0, abs=0.05) and moving[0].significant
    assert robustness.best_case.universe == "x=b"
    assert "moved by x=b (+1" in robustness.summary and "best case for the paper: reproduced" in robustness.summary
    # between two inconclusive cases the one with more checks holding is closer
    assert Robustness(CLAIM, cases[2:]).best_case.universe == "y=b'"


def test_a_time_that_moves_between_universes_is_no_effect_of_the_reading():
    """Each universe's runs were timed when they ran: x=b's were slowed by a third (load) and x=c's verdict
    conflicts with the default's.  No paired effect is estimated from times; x=b, which agrees, does not move
    the verdict however far its times moved, and x=c does, as a conflicting decisive verdict."""
    times = {r: 20 + v for r, v in RUNS.items()}  # ms per frame
    slowed = {r: 3 * v for r, v in times.items()}
    cases = (_case("default", {"x": "a"}, Outcome.REPRODUCED, per_run=times, timed=True),
             _case("x=b", {"x": "b"}, Outcome.REPRODUCED, per_run=slowed, timed=True),
             _case("x=c", {"x": "c"}, Outcome.NOT_REPRODUCED, per_run=slowed, timed=True))
    effects = {e.alternative: e for e in Robustness(CLAIM, cases).effects}
    assert all(e.effect is None and e.paired is Pairing.TIMES and e.paired.said for e in effects.values())
    assert not effects["b"].moves and effects["c"].moves
    assert Robustness(CLAIM, cases[:2]).summary == "robust: no open choice moves the verdict (1 alternatives, 2 cases)"
    # the same numbers as a statistic measured the same way in every universe: x=b's effect is real
    untimed = tuple(_case(c.universe, dict(c.picks[:1]), c.verdict.outcome, per_run=p)
                    for c, p in zip(cases[:2], (times, slowed)))
    (effect,) = Robustness(CLAIM, untimed).effects
    assert effect.paired is Pairing.TWIN and effect.effect is not None and effect.significant


def test_equal_cost_is_a_named_choice_of_its_own_twinned_with_its_universe_at_equal_n():
    """Scoring at equal evaluations or equal time is an alternative of BASIS, each case compared with its own
    universe's default reading at equal N; it is not counted again among the scoring readings."""
    def scored(universe, x, basis, reading, outcome):
        case = _case(universe, {"x": x}, outcome, reading=reading)
        return Case(case.universe, ((("x", x)), (BASIS, basis), (READING, reading)), case.result)

    cases = (scored("default", "a", EQUAL_N, "r1", Outcome.REPRODUCED),
             scored("default", "a", EQUAL_N, "r2", Outcome.REPRODUCED),
             scored("default", "a", "equal time per step (ms)", "r-time", Outcome.NOT_REPRODUCED),
             scored("x=b", "b", EQUAL_N, "r1", Outcome.INCONCLUSIVE),
             scored("x=b", "b", "equal time per step (ms)", "r-time", Outcome.REPRODUCED))
    robustness = Robustness(CLAIM, cases)
    effects = {(e.choice, e.alternative): e for e in robustness.effects}
    assert set(effects) == {("x", "b"), (BASIS, "equal time per step (ms)"), (READING, "r2")}
    at_time = effects[BASIS, "equal time per step (ms)"]
    # default: reproduced vs not reproduced (a conflict); x=b: its own r1 (inconclusive) vs reproduced (none)
    assert (at_time.flips, at_time.compared) == (1, 2) and at_time.moves
    assert "compared at equal time per step (ms) (1 of 2 decisive verdicts conflict)" in robustness.flipped_by
    assert Reading("r", "e", claim_spec({"test": "order", "metric": "rmse", "order": ["A", "B"]})).compared_at == EQUAL_N
    equal_cost = {"test": "equal_cost", "cost": "ms_per_step", "metric": "rmse", "method": "A", "baseline": "B"}
    assert Reading("r", "e", claim_spec(equal_cost)).compared_at == "equal time per step (ms)"


def test_every_multiverse_config_loads_with_its_defaults_equal_to_the_experiments(tmp_path):
    names = [n for n in experiment_names() if n.endswith("_readings")]
    for name in names:
        with initialize_config_dir(config_dir=str(CONF_DIR), version_base="1.3"):
            cfg = compose("config", overrides=[f"experiment={name}", "scale=quick"])
        multiverse = load(cfg)
        assert multiverse.universes[0].is_default and len(multiverse.universes) > 1, name
        for choice in multiverse.choices:
            assert all(a.why for a in choice.alternatives), (name, choice.name)


def test_the_scorecard_marks_a_claim_robust_or_reading_dependent_from_its_multiverse():
    import pandas as pd

    from replication.evidence.scorecard import claim_rows, claims_frame

    papers = [p for p in load_papers() if p.key == "hspf"]
    cases = (_case("default", {"x": "a"}, Outcome.NOT_REPRODUCED, per_run=RUNS),
             _case("x=b", {"x": "b"}, Outcome.REPRODUCED, per_run=_shifted(1.0)))
    stored = Robustness(papers[0].claims[0], cases).as_result()
    rows = claim_rows(papers, {"hspf_readings": Summary("hspf_readings", "", "hspf", "quick", 0, 0,
                                                        multiverse={papers[0].claims[0].id: stored})})
    first, second = rows["hspf"][:2]
    assert first.robust is False and first.robustness.startswith("depends on the reading")
    assert second.multiverse is None and second.robust is None
    frame = claims_frame(rows, pd.DataFrame({"claim": []}), {})
    row = frame.iloc[0]
    assert not row["robust"] and row["robust"] is not None
    assert row["flipped_by"].startswith("x=b (+1") and row["best_case"] == "x=b (scored by: r1)"
    assert row["best_case_verdict"] == "reproduced" and row["cases"] == 2 and row["multiverse"] == "hspf_readings"


def test_a_flip_is_blamed_on_the_choice_that_changes_it_not_on_those_that_ride_along():
    """Scored by r2 the claim holds in every universe, whatever x is: r2 flips it, x does not."""
    cases = tuple(_case(f"x={x}", {"x": x}, outcome, reading=r) for x in ("a", "b")
                  for r, outcome in (("r1", Outcome.NOT_REPRODUCED), ("r2", Outcome.REPRODUCED)))
    robustness = Robustness(CLAIM, cases)
    assert [(e.choice, e.alternative, e.flips, e.compared) for e in robustness.moving] == [(READING, "r2", 2, 2)]
    assert "scored by 'r2' (2 of 2 decisive verdicts conflict)" in robustness.summary


def test_a_choice_that_leaves_the_runs_as_they_are_has_no_effect_exactly():
    from replication.evidence.robustness import paired_effect

    effect, p = paired_effect(RUNS, dict(RUNS))
    assert (effect.value, effect.low, effect.high, p) == (0.0, 0.0, 0.0, 1.0) and effect.method == "the same runs"
    effect, p = paired_effect({0: 1.0}, {0: 2.0})  # one shared run: nothing to pair
    assert effect is None and np.isnan(p)


@pytest.mark.e2e  # a subprocess: make test-e2e runs it, make test does not
def test_the_command_runs_a_multiverse_universe_by_universe(cli, tmp_path):
    """Every experiment's runs of one universe are stored before the next universe starts, the default
    first: a multiverse stopped part-way (a session's end) leaves whole universes, which the record takes
    one by one (``replication.record.write.write_multiverse``)."""
    result = cli("experiment=hspf_readings", "scale=quick", "progress=false")
    assert result.returncode == 0, result.stderr
    lines = [line for line in result.stdout.splitlines() if ": universe " in line]
    done = [line.split(": universe ")[1].split(":")[:2] for line in lines]  # [["k/n (name)", " experiment"], ...]
    universes = [u for u, _ in done]
    assert universes[0].startswith("1/") and "(default)" in universes[0]
    assert universes == sorted(universes, key=lambda u: int(u.split("/")[0]))  # never back to an earlier universe
    n = int(universes[0].split("/")[1].split()[0])
    experiments = ["hspf_ungm", "hspf_ungm_cost"]  # hspf_readings.yaml's experiments at the quick scale
    assert [e.strip() for _, e in done] == experiments * n  # each universe: every experiment, in turn
    assert f"{n} universes of" in result.stdout and "distinct runs" in result.stdout
