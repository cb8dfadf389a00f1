"""The papers the specs reproduce, cited as far as the papers themselves say.

Only what the stored paper texts give, or what a public record whose abstract is the stored
text's word for word gives, is written here (``/work/shared/papers``: paper 002 prints its
authors, venue, year and DOI on its first page; the others are stored from their abstracts on,
without a title block). Paper 001's title is the CORE record's (https://core.ac.uk/works/19417988,
the same abstract); its authors, venue and year are not in that record's text that we could
check, so they stay empty. A field that no such source gives is left empty and the citation says
so, instead of a guess. A spec names its paper as ``"NNN: title"`` (``paper``).
"""

from __future__ import annotations

from dataclasses import dataclass

from ..spec_parts import paper_id  # noqa: F401  (citations.paper_id, as before)


@dataclass(frozen=True)
class Citation:
    id: str
    title: str
    authors: str = ""
    venue: str = ""
    year: str = ""
    doi: str = ""

    source: str = ""  # where a field not printed in the stored paper comes from

    def text(self) -> str:
        """'V. Arakelian, "Title", Venue, 2025. DOI 10.x/y', missing fields named as missing."""
        parts = [self.authors] if self.authors else []
        parts.append(f"“{self.title}”")
        if self.venue:
            parts.append(self.venue)
        if self.year:
            parts.append(self.year)
        out = ", ".join(parts) + "."
        if self.doi:
            out += f" DOI {self.doi}."
        if self.source:
            out += f" (Title from {self.source}; its authors, venue and year are not in the part of that record we could read.)"
        elif not (self.authors and self.venue and self.year):
            out += (" (Title as the spec describes the paper: its stored text has no title block, authors,"
                    " venue or year.)")
        return out


PAPERS = {
    "001": Citation("001", "Generic method for deriving the general shaking force balance conditions of parallel "
                           "manipulators with application to a redundant planar 4-RRR parallel manipulator",
                    source="the CORE record core.ac.uk/works/19417988, whose abstract is the paper's"),
    "002": Citation("002", "Shaking Force and Shaking Moment Balancing in Planar Serial Manipulators",
                    authors="V. Arakelian",
                    venue="Proceedings of the 11th World Congress on Mechanical, Chemical, and Material "
                          "Engineering (MCM'25), Paris, France, Paper No. ICMIE 110",
                    year="2025", doi="10.11159/icmie25.110"),
}


def cite(paper: str | None) -> str:
    """The citation of a spec's ``paper`` field: the table's, else the spec's own title."""
    pid = paper_id(paper)
    if not pid:
        return ""
    c = PAPERS.get(pid)
    if c is None:
        title = (paper or "").split(":", 1)[-1].strip()
        c = Citation(pid, title[:1].upper() + title[1:])
    return f"Paper {pid}: {c.text()}"
