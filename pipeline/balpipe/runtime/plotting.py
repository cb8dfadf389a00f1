"""matplotlib in balpipe's command-line processes: without the docstrings it writes for ``help()``.

When a module of matplotlib defines an artist class (a line, a text, a patch: some 80 classes
as ``matplotlib.pyplot`` is imported), ``Artist.__init_subclass__`` writes the docstring of the
class's ``set`` method from an inspection of every property (``matplotlib.artist.kwdoc``), and
the plotting functions' docstrings are filled in the same way: 0.12 s of CPU in every process
that imports pyplot (the build's workers each import it), for text only ``help()`` reads. A
command of the CLI (:func:`balpipe.cli.main`) asks for that text not to be written in its
processes (:func:`lean_docstrings`); :func:`prepare`, called by balpipe's modules before their
first import of pyplot, then replaces ``kwdoc`` by one that returns no text. Nothing a figure
draws or writes reads those docstrings: the SVG files are the same bytes
(tests/runtime/test_plotting.py). In Python code (the API, a notebook) matplotlib is left as it
is, and so is a matplotlib that was imported before.
"""

from __future__ import annotations

import sys

_state = {"lean": False}


def lean_docstrings() -> None:
    """This process, and the processes it forks, import matplotlib without its artists'
    property docstrings (:func:`prepare`)."""
    _state["lean"] = True


def prepare() -> None:
    """Before an import of pyplot: where :func:`lean_docstrings` was asked and no artist class
    is defined yet (``matplotlib.lines`` not imported), ``matplotlib.artist.kwdoc`` returns ''."""
    if not _state["lean"] or "matplotlib.lines" in sys.modules:
        return
    import matplotlib.artist

    matplotlib.artist.kwdoc = _no_text


def _no_text(artist: object) -> str:
    """``matplotlib.artist.kwdoc``'s stand-in: the property listing of ``artist``'s docstrings, empty."""
    return ""
