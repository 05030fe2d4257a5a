"""Every claim quotes its paper: the quote is found in the paper's own text, and what the project adds is
a reading named as ours, never the primary one."""

from pathlib import Path

import pytest

from replication.evidence.claims import load_papers
from replication.evidence.quotes import AGREEMENT, find, find_quote, normalise, paper_text

PAPERS_DIR = Path(__file__).resolve().parents[1].parent / "shared" / "papers"  # ../shared/papers beside the clone
CLAIMS = [(paper.key, claim) for paper in load_papers() for claim in paper.claims]


def test_the_papers_are_beside_the_project():
    """The quote tests need the papers' texts: their absence is a failure, never a skip."""
    assert sorted(PAPERS_DIR.glob("*__*.txt")), f"no paper texts in {PAPERS_DIR}: the quotes cannot be checked"


@pytest.mark.parametrize("paper, claim", CLAIMS, ids=[claim.id for _, claim in CLAIMS])
def test_every_claim_quotes_its_paper_where_it_says(paper, claim):
    assert claim.quote.text.strip() and claim.quote.english.strip() and claim.where.strip(), claim.id
    text = paper_text(PAPERS_DIR, paper)
    for piece in find_quote(claim.quote.text, text):
        assert piece.found, f"{claim.id}: quote not in {paper}'s text (best {piece.agreement:.2f}: {piece.there!r})"


@pytest.mark.parametrize("paper, claim", CLAIMS, ids=[claim.id for _, claim in CLAIMS])
def test_what_we_add_is_a_reading_of_ours_never_the_primary_one(paper, claim):
    if claim.untestable:
        assert not claim.readings, f"{claim.id} says why it is not testable and yet has readings"
        return
    assert claim.readings, f"{claim.id} has neither readings nor a reason it cannot be tested"
    assert not claim.readings[0].ours, f"{claim.id}'s primary reading is ours: {claim.readings[0].ours}"
    assert not claim.readings[0].basis, f"{claim.id}'s primary reading is at equal cost, not the paper's"
    for reading in claim.readings:
        assert not reading.basis or reading.ours, f"{claim.id}: {reading.name} is at equal cost but not named ours"


def test_a_quote_is_found_through_ocr_noise_and_a_wrong_one_is_not():
    text = "实验结果表明, 提出的算法在非线性系统状态估计精度要优于粒 子滤波和标准的拟蒙特卡洛粒子滤波算法。"
    assert find("提出的算法在非线性系统状态估计精度要优于粒子滤波", text).agreement == 1.0  # a space inside a word
    assert find("提出的算法在非线性系统状态估计精度要优于粒子滤", "，".join([text])).found
    garbled = text.replace("蒙", "萦")  # one character misread by the OCR
    assert find("标准的拟蒙特卡洛粒子滤波算法", garbled).agreement >= AGREEMENT
    assert not find("提出的算法在线性系统中的速度远远快于卡尔曼滤波器", text).found


def test_full_width_forms_and_case_are_one_text():
    assert normalise("ＧＰＳ－ＱＭＣＰＦ，  ESS") == normalise("gps-qmcpf,ess")


def test_a_quote_broken_by_the_ocr_is_found_piece_by_piece_and_a_short_piece_is_refused():
    text = "PF的误差远高于QMC-PF、TR-SQMC和GPS-QM- 跟踪的实验,分别对比 CPF,其中GPS-QMCPF的误差最小"
    assert all(piece.found for piece in find_quote("PF的误差远高于QMC-PF、TR-SQMC … 其中GPS-QMCPF的误差最小", text))
    with pytest.raises(ValueError, match="shorter than"):
        find_quote("PF的误差远高于QMC-PF … 最小", text)
