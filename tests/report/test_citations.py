"""Citations of the papers (issue 22, point 16): what the stored texts (or a public record with
the same abstract) give, nothing guessed, each missing field said to be missing."""

from balpipe.report import citations
from balpipe.report.site import site_papers


def test_a_paper_with_its_title_block_is_cited_in_full():
    text = citations.cite("002: shaking force and shaking moment balancing in planar serial manipulators")
    assert text.startswith("Paper 002: V. Arakelian, “Shaking Force and Shaking Moment Balancing")
    assert "2025" in text and "DOI 10.11159/icmie25.110." in text
    assert "not" not in text  # nothing missing, nothing to excuse


def test_a_title_from_a_public_record_names_its_source_and_what_it_lacks():
    text = citations.cite("001: general force balance of the 4-RRR")
    assert "“Generic method for deriving the general shaking force balance conditions" in text
    assert "core.ac.uk/works/19417988" in text and "authors, venue and year are not" in text


def test_a_paper_without_a_title_block_falls_back_to_the_specs_own_words_and_says_so():
    text = citations.cite("000: complete shaking force and shaking moment balancing")
    assert text.startswith("Paper 000: “Complete shaking force and shaking moment balancing”.")
    assert "no title block" in text
    assert citations.cite(None) == "" and citations.cite("") == ""


def test_the_index_cites_each_paper_once_in_id_order():
    entries = [{"facets": {"paper": p}} for p in ("002: b", "000: a", "002: b again", "")]
    papers = site_papers(entries)
    assert [p["id"] for p in papers] == ["000", "002"]
    assert papers[1]["text"] == citations.cite("002: b")


def test_a_familys_paper_is_cited_and_drawn_through_its_hooks(monkeypatch):
    """The report holds no paper's data: a paper that a family declares (``Family.papers``) is
    cited from its :class:`Citation` and its own panels come from its hook."""
    from types import SimpleNamespace

    from balpipe import registry
    from balpipe.plugins import Citation, Paper
    from balpipe.report import paper_figures

    panel = ("Fig. 1 of paper 999", "<svg/>", "drawn by the family")
    monkeypatch.setitem(registry.PAPERS, "999", Paper("999", Citation("A title", authors="A. Author", venue="Venue",
                                                                      year="2001"), ("1",), lambda study: [panel]))
    assert citations.cite("999: words of the spec") == "Paper 999: A. Author, “A title”, Venue, 2001."
    assert paper_figures.own_figures(SimpleNamespace(spec=SimpleNamespace(paper="999: x"))) == [panel]
    assert paper_figures.own_figures(SimpleNamespace(spec=SimpleNamespace(paper="998: x"))) == []
    assert registry.PAPERS["002"].citation.doi == "10.11159/icmie25.110"  # paper 002's, declared by serial_arm
