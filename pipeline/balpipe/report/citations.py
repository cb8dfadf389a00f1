"""The citation of a spec's paper: the one its family declares (:class:`balpipe.plugins.Paper`,
found through :data:`balpipe.registry.PAPERS`), else the spec's own title, said to be.

The report holds no paper's data: each family cites the papers it reproduces, as far as the
papers themselves say (:class:`balpipe.plugins.Citation`). A spec names its paper as
``"NNN: title"`` (``paper``).
"""

from __future__ import annotations

from ..plugins import Citation
from ..registry import PAPERS
from ..spec_parts import paper_id  # noqa: F401  (citations.paper_id, as before)


def citation_of(paper: str | None) -> Citation | None:
    """The :class:`Citation` of a spec's ``paper`` field: its family's, else one of the spec's
    own title; None without a paper."""
    pid = paper_id(paper)
    if not pid:
        return None
    declared = PAPERS.get(pid)
    if declared is not None and declared.citation is not None:
        return declared.citation
    title = (paper or "").split(":", 1)[-1].strip()
    return Citation(title[:1].upper() + title[1:])


def cite(paper: str | None) -> str:
    """The citation text of a spec's ``paper`` field (:func:`citation_of`), '' without one."""
    c = citation_of(paper)
    return f"Paper {paper_id(paper)}: {c.text()}" if c is not None else ""
