"""Every claim at a glance: the deciding number over the paper's own, on hand cases, and the figure drawn
from a scorecard's rows."""

import math

import matplotlib.image as mpimg
import pytest

from replication.evidence.checks import Check

from replication.evidence.claims import load_papers
from replication.evidence.scorecard import ClaimRow, ReadingResult
from replication.evidence.statistics import Estimate
from replication.evidence.verdict import Outcome, Verdict
from replication.report.pages import glance


def _check(value, low, high, paper):
    return Check("A - B", Verdict(Outcome.NOT_REPRODUCED), Estimate(value, low, high, 100, "paired t"), paper=paper)


def test_ours_over_the_papers_keeps_the_interval_in_order():
    # ism_pf.accuracy's shape: ours -22.66 [-25.14, -20.18] pp against the paper's +15 pp
    r = glance.relative(_check(-22.66, -25.14, -20.18, 15.0))
    assert (r.value, r.low, r.high) == pytest.approx((-22.66 / 15, -25.14 / 15, -20.18 / 15))
    # a paper's gap below zero (lower is better, say) flips the interval's ends, never its order
    r = glance.relative(_check(-1.0, -1.5, -0.5, -2.0))
    assert (r.value, r.low, r.high) == pytest.approx((0.5, 0.25, 0.75))
    # no number of the paper's (a sign-only claim), a zero one, or no estimate: nothing to place
    assert glance.relative(_check(1.0, 0.5, 1.5, None)) is None
    assert glance.relative(_check(1.0, 0.5, 1.5, 0.0)) is None
    assert glance.relative(Check("A vs B", Verdict(Outcome.REPRODUCED), paper=2.0)) is None
    # an undefined interval keeps the point and no bar
    r = glance.relative(_check(3.0, math.nan, math.nan, 2.0))
    assert r.value == 1.5 and math.isnan(r.low) and math.isnan(r.high)


def test_the_figure_has_a_line_per_claim_and_a_heading_per_paper(tmp_path):
    papers = load_papers()
    rows = {p.key: [ClaimRow(c, (ReadingResult(c.readings[0], Verdict(Outcome.REPRODUCED), _check(2.0, 1.0, 3.0, 2.0),
                                               (), "quick"),)) for c in p.claims] for p in papers}
    recorded = {row.claim.id: row for claims in rows.values() for row in claims}
    lines = glance.lines(papers, rows, recorded)
    assert [line.id for line in lines["ism_pf"]] == [c.id for c in papers[0].claims]
    first = lines["ism_pf"][0]
    assert first.recorded.relative.value == 1.0 and first.here.scale == "quick"
    path = glance.draw(lines, tmp_path / glance.FIGURE)
    height = mpimg.imread(path).shape[0]
    entries = sum(len(p.claims) for p in papers) + len(papers)
    assert height == round(100 * (1.4 + glance.ROW * entries))  # dpi 100: the rows set the height
