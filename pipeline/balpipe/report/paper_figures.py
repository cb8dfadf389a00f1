"""The papers' figures one for one: which of a paper's figure numbers a page
reproduces, read from its figure titles ("Fig. 8 of paper 000", "Figs. 2a, 4a, 6b", "Figs. 3-4"),
and the panels that the generic pages did not draw as the paper numbers them:

- paper 004, Figs. 10a, 10b, 11, 12: shaking force along x and along y, shaking moment (N m) of
  the unbalanced manipulator, and the shaking moment after shaking force balancing.

The other papers' figures are their methods' hooks (:attr:`plugins.Method.figures`: paper 000 in
``families.rpr3.figures``, papers 002 and 003 in ``families.serial_arm.figures``).

:data:`FIGURES` is the table of the papers' figures that the site reproduces; a test holds the
pages to it.
"""

from __future__ import annotations

import re

import numpy as np

from ..balancing.base import style_index
from ..draw import live
from ..spec_parts import paper_id

#: per paper, the figure numbers its pages reproduce (a number covers its panels: "6" by "6a")
FIGURES = {
    "000": ("4", "8"),
    "001": ("2", "3", "4", "6a", "6b", "6c"),  # Fig. 6's three panels are three designs, one spec each
    "002": ("2",),
    "003": ("2", "3", "4"),
    "004": ("10a", "10b", "11", "12"),
}

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


def _series(t, curves: list[tuple[str, np.ndarray, int]], ylabel: str, prefix: str) -> str:
    """A time series in the page's stage styles: each curve (label, values, k) drawn in
    ``figures.style(k)``, k the stage's place in the page's stage table, so that one line style
    means one stage on the whole page; interactive, on screen and in print
    (:func:`balpipe.draw.live.html`, element ``#live-<prefix>``)."""
    curves_of = live.Curves(t, [(label, {"y": y}) for label, y, _ in curves],
                            [{"key": "y", "title": "", "axis": ylabel}], [], styles=[k for _, _, k in curves])
    return live.html(prefix, curves_of)


def _k(study, stage) -> int:
    """The stage's style index on the page (:func:`balancing.base.style_index`)."""
    return style_index(study.stages, stage)


def own_figures(study) -> list[tuple[str, str, str]]:
    """The panels drawn here as the paper numbers them, (title, svg, caption)."""
    if paper_id(study.spec.paper) == "004":
        return _paper004(study)
    return []


def _paper004(study) -> list[tuple[str, str, str]]:
    un = study.unbalanced
    an = un.analysis
    force_only = next((s for s in study.stages if s.stage.balances == "force" and s.stage.design is None), None)
    k0 = _k(study, un)
    out = [
        ("Fig. 10a of paper 004: shaking force along x (N)",
         _series(an.t, [(un.stage.label, an.force[:, 0], k0)], "F_x (N)", "p004fig10a"),
         "The unbalanced manipulator, from the analysis of this spec."),
        ("Fig. 10b of paper 004: shaking force along y (N)",
         _series(an.t, [(un.stage.label, an.force[:, 1], k0)], "F_y (N)", "p004fig10b"),
         "The unbalanced manipulator, from the analysis of this spec."),
        ("Fig. 11 of paper 004: shaking moment (N m)",
         _series(an.t, [(un.stage.label, an.moment, k0)], "M (N m)", "p004fig11"),
         "The unbalanced manipulator, about the moment point of the spec."),
    ]
    if force_only is not None:
        a2 = force_only.analysis
        out.append(("Fig. 12 of paper 004: shaking moment after shaking force balancing (N m)",
                    _series(a2.t, [(force_only.stage.label, a2.moment, _k(study, force_only))], "M (N m)", "p004fig12"),
                    f"Stage '{force_only.stage.label}' (force balanced by counterweights), in its line style of this "
                    "page: the moment grows, as the paper says."))
    return out
