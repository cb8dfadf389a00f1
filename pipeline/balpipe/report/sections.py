"""Long pages collapsed: every ``<h2>`` section of a study page between the ``<!--sections-->``
and ``<!--/sections-->`` markers becomes a ``<details>`` whose summary line is its heading, except
the few that answer the page's first question (:data:`OPEN`). The table of contents still links
every heading (a browser opens the section it jumps to) and printing opens them all
(``templates/fit_tables.js``). Sections nested in a ``<section>`` element (the history) move with
it as one block.
"""

from __future__ import annotations

import re

#: headings left open: the stage table and the shaking loads (the verdict and the design card
#: are above the sections)
OPEN = ("Balancing stages", "Shaking force and shaking moment")
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
            state = " open" if title in keep_open else ""
            out.append(f'<details class="section"{state}><summary>{heading}</summary>{content}</details>\n')
        elif m:  # a <section> with its own heading (the history)
            out.append(f'<details class="section"><summary class="h2">{title}</summary>{block}</details>\n')
        else:
            out.append(block)
    return head + "".join(out) + tail
