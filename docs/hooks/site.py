"""MkDocs hook of the docs site (mkdocs.yml). The pages in docs/ are written to be read on the
repository too: on the site, a link to the README (``../README.md``, the repository's front page)
goes to the site's home page (``index.md``). And the gallery page (``gallery.md``, not in docs/:
:data:`GENERATED`) is made here at each build from ``specs/``, so it is never out of date: one entry per spec with its name, what it shows and a link to its study page in the
report site, which CI publishes beside the docs (``<site>/<slug>/index.html``, the docs in
``<site>/docs/``; the page's folder name is ``balpipe build``'s own,
:func:`balpipe.site_files.spec_files.slug_for`). The links leave the docs site, so they are HTML
anchors, which MkDocs does not check; the test checks that each names a spec's page.
"""

from __future__ import annotations

import html
import re
from pathlib import Path

import yaml

#: from the gallery page (docs/gallery/ on the site) to the report site's root
TO_SITE = "../../"
#: the pages this hook makes (tests/test_docs.py lets docs/ pages link them)
GENERATED = ("gallery.md",)


def _specs(root: Path) -> list[Path]:
    return sorted((root / "specs").glob("*.yaml"))


def _first_sentence(text: str) -> str:
    text = " ".join((text or "").split())
    m = re.match(r"(.+?[.!?])(\s|$)", text)
    return m.group(1) if m else text


def gallery(root: Path) -> str:
    """The gallery page's Markdown: a table of every spec of ``root/specs``."""
    from balpipe.site_files.spec_files import slug_for

    rows = []
    for p in _specs(root):
        data = yaml.safe_load(p.read_text(encoding="utf-8")) or {}
        mech = (data.get("mechanism") or {}).get("template", "")
        method = (data.get("balancing") or {}).get("method", "none")
        href = f"{TO_SITE}{slug_for(Path('specs') / p.name)}/index.html"
        rows.append(f'<tr><td><a class="study" href="{html.escape(href)}">{html.escape(str(data.get("name", p.stem)))}</a>'
                    f'<br><code>specs/{html.escape(p.name)}</code></td><td>{html.escape(mech)}</td>'
                    f'<td>{html.escape(method)}</td><td>{html.escape(_first_sentence(data.get("description", "")))}</td></tr>')
    return ("# Gallery\n\nEvery example study of `specs/`, each with its page in the report site (built by CI with the "
            "pymunk validation; locally: `python -m balpipe build specs/`, then `reports/index.html`). The pages show "
            "the balancing stages, the shaking loads over the motion, the parts the method adds and the checks; "
            "[reading a page](pages.md) explains them.\n\n"
            "<table><thead><tr><th>study</th><th>mechanism</th><th>method</th><th>what it shows</th></tr></thead>"
            "<tbody>\n" + "\n".join(rows) + "\n</tbody></table>\n")


def on_files(files, config):
    from mkdocs.structure.files import File

    root = Path(config["config_file_path"]).parent
    files.append(File.generated(config, GENERATED[0], content=gallery(root)))
    return files


def on_page_markdown(markdown: str, page, config, files) -> str:
    return markdown.replace("](../README.md)", "](index.md)")
