"""The constants that decide, as one ``inference`` setting (``conf/config.yaml``): every test, interval and verdict
reads them here, and the rules every page prints are written from them (:func:`rules`).

The shipped values are read from ``conf/config.yaml``; an entry point that composes a config (a run, a report,
the calibration) applies its ``inference`` block, overrides and all, with :func:`configure` before it decides.
"""

from dataclasses import asdict, dataclass, fields

import yaml

from replication.errors import ConfigError
from replication.paths import CONF_DIR


@dataclass
class Inference:
    alpha: float  # the one-sided level of every decision
    level: float  # the coverage of every interval shown beside a number
    power: float  # the power at which the smallest detectable effect is quoted
    equivalence_alpha: float  # each side of the t-based equivalence test of a published mean
    size_alpha: float  # the test of ours against the paper's size, the paper's own noise estimated from ours
    growth_alpha: float  # each side of the t-test of a growth exponent (least squares on logs)
    tolerance: float  # a published number is reproduced within +-tolerance of it where its table states none
    min_runs: int  # no verdict from fewer runs
    min_sequences: int  # no ranking verdict over fewer sequences
    bootstrap_resamples: int  # the two-level bootstrap that describes a ranking (P(best), rank intervals)
    bootstrap_seed: int  # its own stream: a report is a pure function of the records

    def as_dict(self) -> dict:
        return asdict(self)


def _shipped() -> dict:
    return yaml.safe_load((CONF_DIR / "config.yaml").read_text())["inference"]


INFERENCE = Inference(**_shipped())


def configure(values) -> Inference:
    """Set this process's inference setting from a config's ``inference`` block (a mapping); an unknown key or
    a value out of range is a ConfigError."""
    known = {f.name: f.type for f in fields(Inference)}
    unknown = set(values) - set(known)
    if unknown:
        raise ConfigError(f"inference: unknown setting(s) {sorted(unknown)}; known: {sorted(known)}")
    chosen = {**INFERENCE.as_dict(), **{k: (int if known[k] is int else float)(v) for k, v in values.items()}}
    if not all(0 < chosen[k] < 1 for k in ("alpha", "level", "power", "equivalence_alpha", "size_alpha", "growth_alpha",
                                           "tolerance")):
        raise ConfigError("inference: alpha, level, power, equivalence_alpha, size_alpha, growth_alpha and tolerance "
                          "lie strictly in (0, 1)")
    if chosen["min_runs"] < 2 or chosen["min_sequences"] < 2 or chosen["bootstrap_resamples"] < 1:
        raise ConfigError("inference: min_runs and min_sequences are at least 2, bootstrap_resamples at least 1")
    for name, value in chosen.items():
        setattr(INFERENCE, name, value)
    return INFERENCE


def _percent(value: float) -> str:
    return f"{100 * value:g} %"


def rules() -> tuple[str, ...]:
    """The rules in words, one short paragraph per kind of test, written from :data:`INFERENCE`; every page
    prints them."""
    s = INFERENCE
    runs = s.min_runs
    return (
        f"Every decision is a one-sided test at {_percent(s.alpha)}, and every interval that decides is exact or "
        "holds its level at the run counts used: reports/calibration.csv simulates each rule through the code that "
        f"applies it. With {runs} paired runs the smallest one-sided p-value of an exact test is 1/{2 ** runs}.",
        "Two methods (a claim's check): Student's paired t-test on common random numbers, McNemar's exact (sign) "
        "test for yes/no outcomes. Where the claim or its published cells quote a size, the paper's own gap (a "
        "difference, or a ratio in Fieller's linear form) is tested against ours, so that 'the effect the paper "
        "reports is absent here' and 'the sign agrees, the size does not' are verdicts. The paper's gap is itself "
        "a mean over its runs (stated, else the fewest that give its rates, else as many as ours; said beside "
        "each check), its noise taken from our runs' spread; that test runs at "
        f"{_percent(s.size_alpha)} so that heavy-tailed runs still hold {_percent(s.alpha)}, and runs all at one "
        "value for both methods decide nothing.",
        "A claim: reproduced when every check shows the claimed direction (an intersection-union test, no "
        "correction needed); not reproduced when some check's evidence against it (the other direction, or the "
        "paper's size absent) survives Holm's correction across the reading's checks; else inconclusive, with the "
        f"smallest effect the runs detect at {_percent(s.power)} power.",
        "A bound (frames per second, say): the exact sign test of the median, the exact binomial test of a rate, the "
        "t-test of a mean. A growth exponent (time against the number of targets, on logs): the t-test of the "
        f"least-squares slope at {_percent(s.growth_alpha)} each side, so that skewed noise holds {_percent(s.alpha)}. "
        "'X is best': X against each competitor, the paired t-test over the sequences, reproduced "
        "when it beats all and not reproduced when one is better after Holm; P(best) describes and decides nothing.",
        f"A published number counts as ours within +-{_percent(s.tolerance)} of it unless its table states another "
        "tolerance: reproduced only where equivalence is shown (two one-sided t-tests, each at "
        f"{_percent(s.equivalence_alpha)} so that skewed runs hold {_percent(s.alpha)}; our interval widened for the "
        "paper's own Monte Carlo noise where its run count is known), not reproduced where our "
        f"{_percent(s.level)} interval lies wholly outside the band (a rate with its run count known: Fisher's exact "
        "test) or the number is below the Bayes floor (the point-mass filter's RMSE, which no filter beats on "
        "average); else inconclusive: a wide interval that merely contains the paper's number shows nothing. A "
        f"rating is reproduced when the {_percent(s.level)} Clopper-Pearson interval meets only the paper's band.",
        "A reading: a verdict depends on the paper's open choices only where a choice's paired effect on the "
        "deciding statistic is significant (two-sided, Holm across the choices) and its verdict changes with it.",
        f"Not testable: a timing (machine-dependent: the ratio ours / theirs is shown), fewer than {runs} runs, "
        "every run tied (no interval), or no data.",
    )
