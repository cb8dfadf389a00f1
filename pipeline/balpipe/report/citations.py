"""The papers the specs reproduce, cited as far as the papers themselves say.

Only what the stored paper texts give is written here (``/work/shared/papers``: paper 002
prints its authors, venue, year and DOI on its first page; the others are stored from their
abstracts on, without a title block). A field the paper does not give is left empty and the
citation says so, instead of a guess. A spec names its paper as ``"NNN: title"`` (``paper``).
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Citation:
    id: str
    title: str
    authors: str = ""
    venue: str = ""
    year: str = ""
    doi: str = ""

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
        if not (self.authors and self.venue and self.year):
            out += (" (Title as the spec describes the paper: its stored text has no title block, authors,"
                    " venue or year.)")
        return out


PAPERS = {
    "002": Citation("002", "Shaking Force and Shaking Moment Balancing in Planar Serial Manipulators",
                    authors="V. Arakelian",
                    venue="Proceedings of the 11th World Congress on Mechanical, Chemical, and Material "
                          "Engineering (MCM'25), Paris, France, Paper No. ICMIE 110",
                    year="2025", doi="10.11159/icmie25.110"),
}


def paper_id(paper: str | None) -> str:
    """'000: complete shaking ...' -> '000'; '' without a paper."""
    return (paper or "").split(":", 1)[0].strip()


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
