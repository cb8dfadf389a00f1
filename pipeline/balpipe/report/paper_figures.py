"""The papers' figures one for one: which of a paper's figure numbers a page
reproduces, read from its figure titles ("Fig. 8 of paper 000", "Figs. 2a, 4a, 6b", "Figs. 3-4"),
and the panels of a spec's paper that its family draws as the paper numbers them
(:attr:`balpipe.plugins.Paper.own_figures`).

The papers' figures are their families': the methods' and templates' hooks
(:attr:`plugins.Method.figures`, :attr:`plugins.Template.figures`) and the papers' own
(:class:`balpipe.plugins.Paper`). :data:`FIGURES` is the table of the papers' figures that the
site reproduces, from the families' :attr:`Paper.figures`; a test holds the pages to it.
"""

from __future__ import annotations

import re

from ..registry import PAPERS
from ..spec_parts import paper_id

#: per paper, the figure numbers its pages reproduce (a number covers its panels: "6" by "6a")
FIGURES = {pid: p.figures for pid, p in sorted(PAPERS.items()) if p.figures}

_FIGS = re.compile(r"\bFigs?\.\s*((?:\d+[a-z]?(?:\s*[-–]\s*\d+[a-z]?)?)(?:\s*(?:,|and)\s*\d+[a-z]?(?:\s*[-–]\s*\d+[a-z]?)?)*)")
_ONE = re.compile(r"(\d+)([a-z]?)(?:\s*[-–]\s*(\d+)([a-z]?))?")


def numbers_in(title: str) -> list[str]:
    """Figure numbers a title names: 'Figs. 2a, 4a, 6b' -> ['2a', '4a', '6b']; 'Figs. 3-4' ->
    ['3', '4']; 'Fig. 8 of paper 000' -> ['8']."""
    out: list[str] = []
    for m in _FIGS.finditer(title):
        for a, pa, b, pb in _ONE.findall(m.group(1)):
            if b and not pa and not pb:
                out += [str(k) for k in range(int(a), int(b) + 1)]
            else:
                out += [a + pa] + ([b + pb] if b else [])
    return out


def covered(wanted: str, found: list[str]) -> bool:
    """A wanted figure number is covered by itself or, for a bare number, by one of its panels."""
    return wanted in found or (wanted.isdigit() and any(re.fullmatch(wanted + "[a-z]", f) for f in found))


def listed(titles: list[str]) -> list[str]:
    """The distinct figure numbers of a page's titles, in numeric order."""
    nums = {n for t in titles for n in numbers_in(t)}
    return sorted(nums, key=lambda n: (int(re.match(r"\d+", n).group()), n))


def own_figures(study) -> list[tuple[str, str, str]]:
    """The panels of the spec's paper that its family draws as the paper numbers them
    (:attr:`balpipe.plugins.Paper.own_figures`), (title, svg or html, caption); none for a spec
    without a paper or a paper without them."""
    paper = PAPERS.get(paper_id(study.spec.paper))
    if paper is None or paper.own_figures is None:
        return []
    return list(paper.own_figures(study))
