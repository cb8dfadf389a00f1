"""Long pages collapsed: every ``<h2>`` section of a study page between the ``<!--sections-->``
and ``<!--/sections-->`` markers becomes a ``<details>`` whose summary line is its heading, except
the few that answer the page's first question (:data:`OPEN`) and those that hold one of a paper's
figures (a heading naming "Fig. N", :func:`balpipe.report.paper_figures.numbers_in`): those are open
at load. The table of contents links every heading; a Contents entry, a deep link and a change of
the page's ``#fragment`` open the section that holds the target and scroll to it, and "open all" /
"close all" beside the Contents act on every section (``templates/sections.js``); printing opens
them all (``templates/fit_tables.js``). Sections nested in a ``<section>`` element (the history) move with
it as one block.
"""

from __future__ import annotations

import re

from .paper_figures import numbers_in

#: headings left open: the stage table, the shaking loads, what balancing costs the actuators and
#: the published numbers against the computed ones (the verdict and the design card are above the
#: sections); the paper's figures are open too (:func:`opens`)
OPEN = ("Balancing stages", "What balancing costs the actuators", "Shaking force and shaking moment",
        "Published vs computed")
START, END = "<!--sections-->", "<!--/sections-->"
_TOKEN = re.compile(r"<section\b|</section>|<h2\b")
_TITLE = re.compile(r"<h2[^>]*>(.*?)</h2>", re.S)
_TAG = re.compile(r"<[^>]+>")


def _cuts(body: str) -> list[int]:
    """Offsets of the top-level ``<h2`` and ``<section`` starts (a section is one block)."""
    cuts, depth = [], 0
    for m in _TOKEN.finditer(body):
        tok = m.group()
        if tok == "</section>":
            depth -= 1
        elif depth == 0:
            cuts.append(m.start())
            if tok == "<section":
                depth += 1
        elif tok == "<section":
            depth += 1
    return cuts


def opens(title: str, keep_open: tuple[str, ...] = OPEN) -> bool:
    """Whether the section headed ``title`` is open at load: one of ``keep_open``, or a paper's
    figure ("Fig. 8 of paper 000", "Figs. 10a-12")."""
    return title in keep_open or bool(numbers_in(title))


def collapse(page: str, keep_open: tuple[str, ...] = OPEN) -> str:
    """The page with its sections in ``<details class="section">`` (unchanged without markers)."""
    if START not in page or END not in page:
        return page
    head, rest = page.split(START, 1)
    body, tail = rest.split(END, 1)
    cuts = _cuts(body)
    if not cuts:
        return head + body + tail
    out = [body[:cuts[0]]]
    for a, b in zip(cuts, cuts[1:] + [len(body)]):
        block = body[a:b]
        m = _TITLE.match(block) if block.startswith("<h2") else _TITLE.search(block)
        title = _TAG.sub("", m.group(1)).strip() if m else ""
        if block.startswith("<h2") and m:
            heading, content = block[:m.end()], block[m.end():]
            state = " open" if opens(title, keep_open) else ""
            out.append(f'<details class="section"{state}><summary>{heading}</summary>{content}</details>\n')
        elif m:  # a <section> with its own heading (the history)
            out.append(f'<details class="section"><summary class="h2">{title}</summary>{block}</details>\n')
        else:
            out.append(block)
    return head + "".join(out) + tail
