"""A table of contents for a long page: every ``<h2>`` gets a stable id (from its text) and a
``<nav class="toc">`` list of links replaces the ``<!--toc-->`` marker. Static, no script."""

from __future__ import annotations

import html
import re

_H2 = re.compile(r"<h2(?P<attrs>[^>]*)>(?P<body>.*?)</h2>", re.S)
_ID = re.compile(r'\bid="([^"]+)"')
_TAG = re.compile(r"<[^>]+>")


def slugify(text: str) -> str:
    s = re.sub(r"[^a-z0-9]+", "-", text.lower()).strip("-")
    return s or "section"


def add_toc(page: str, marker: str = "<!--toc-->") -> str:
    """Number-free TOC of the page's h2 headings, inserted at ``marker`` (unchanged page
    without the marker)."""
    if marker not in page:
        return page
    taken = set(re.findall(r'\bid="([^"]+)"', page))  # ids already in the page stay unique
    seen: dict[str, int] = {}
    items: list[tuple[str, str]] = []

    def repl(m: re.Match) -> str:
        attrs, body = m.group("attrs"), m.group("body")
        title = html.unescape(_TAG.sub("", body)).strip()
        found = _ID.search(attrs)
        if found:
            ident = found.group(1)
        else:
            base = slugify(title)
            ident = base if base not in taken else f"{base}-section"
            while ident in taken:
                seen[base] = seen.get(base, 1) + 1
                ident = f"{base}-{seen[base]}"
            taken.add(ident)
            attrs = f' id="{ident}"{attrs}'
        items.append((ident, title))
        return f"<h2{attrs}>{body}</h2>"

    page = _H2.sub(repl, page)
    links = "".join(f'<li><a href="#{ident}">{html.escape(title)}</a></li>' for ident, title in items)
    nav = f'<nav class="toc" aria-label="Contents"><strong>Contents</strong><ol>{links}</ol></nav>'
    return page.replace(marker, nav, 1)
