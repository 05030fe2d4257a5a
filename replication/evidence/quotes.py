"""Where a claim's quote stands in its paper's text.

The papers' texts (``../shared/papers/<paper>__*.txt``) are OCR'd and partly
garbled ("OMC" for QMC, "P℉" for PF, spaces inside words, full-width and
half-width punctuation mixed), so a quote is looked for after
:func:`normalise` (Unicode NFKC, whitespace removed, case folded) and allowed a
stated fuzzy tolerance: the best window of the text of the quote's length
must agree with it in at least :data:`AGREEMENT` of its characters (difflib's
ratio, 2 x matches / total length).  Where the OCR broke a sentence (two
columns run together, a line carried to another page), the quote marks the
break with an ellipsis "…" and each piece must be found on its own
(:func:`find_quote`).
"""

import difflib
import unicodedata
from dataclasses import dataclass
from pathlib import Path

AGREEMENT = 0.9  # a quote is found where some window of the text agrees with it in 90 % of its characters
ANCHOR = 4  # the length of the quote's pieces looked up to place candidate windows
BREAK = "…"  # where a quote skips what the OCR put inside its sentence
SHORTEST = 8  # the fewest normalised characters a piece of a quote may have (a shorter one is found anywhere)


@dataclass(frozen=True)
class Found:
    """The best place of a quote in a text: how well it agrees (1: verbatim after normalising) and the
    normalised text there."""

    agreement: float
    at: int
    there: str

    @property
    def found(self) -> bool:
        return self.agreement >= AGREEMENT


def normalise(text: str) -> str:
    """NFKC (full-width forms to ASCII, ligatures split), every whitespace removed, case folded."""
    return "".join(unicodedata.normalize("NFKC", text).split()).casefold()


def find(quote: str, text: str) -> Found:
    """The window of ``text`` that best agrees with ``quote``, both normalised: the exact place where the
    quote occurs verbatim, else the best of the windows placed by each of its ``ANCHOR``-character pieces."""
    quote, text = normalise(quote), normalise(text)
    if not quote:
        return Found(0.0, -1, "")
    exact = text.find(quote)
    if exact >= 0:
        return Found(1.0, exact, quote)
    best = Found(0.0, -1, "")
    starts = set()
    for offset in range(0, max(1, len(quote) - ANCHOR + 1)):
        piece = quote[offset:offset + ANCHOR]
        at = text.find(piece)
        while at >= 0:
            starts.add(max(0, at - offset))
            at = text.find(piece, at + 1)
    matcher = difflib.SequenceMatcher(autojunk=False)
    matcher.set_seq2(quote)
    for start in sorted(starts):
        window = text[start:start + len(quote)]
        matcher.set_seq1(window)
        if matcher.real_quick_ratio() <= best.agreement or matcher.quick_ratio() <= best.agreement:
            continue
        agreement = matcher.ratio()
        if agreement > best.agreement:
            best = Found(agreement, start, window)
    return best


def find_quote(quote: str, text: str) -> list[Found]:
    """Each piece of ``quote`` (split at :data:`BREAK`) at its best place in ``text``; ValueError for a
    piece shorter than :data:`SHORTEST` characters, which would be found by chance."""
    pieces = [piece for piece in quote.split(BREAK) if piece.strip()]
    short = [piece for piece in pieces if len(normalise(piece)) < SHORTEST]
    if short or not pieces:
        raise ValueError(f"quote piece {short[0] if short else quote!r} is shorter than {SHORTEST} characters")
    return [find(piece, text) for piece in pieces]


def paper_text(papers_dir: Path, paper: str) -> str:
    """The text of ``paper`` (its file ``<paper>__*.txt`` in ``papers_dir``); FileNotFoundError naming what
    is missing where there is none."""
    found = sorted(Path(papers_dir).glob(f"{paper}__*.txt"))
    if not found:
        raise FileNotFoundError(f"no text of paper {paper!r} in {papers_dir} (expected {paper}__*.txt)")
    return found[0].read_text(encoding="utf-8")
