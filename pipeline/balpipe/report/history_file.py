"""A study page's recorded history (``history.json``, written by ``balpipe history``): its file
names, reading it, and the build's input hash extended by it. Kept apart from the history page's
rendering (:mod:`balpipe.report.history_page`) so that a build with nothing changed reads it
without loading jinja2 or matplotlib."""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

HISTORY_FILE = "history.json"
HISTORY_PAGE = "history.html"


def load(folder: Path) -> tuple[str, dict] | None:
    """The raw text and the data of ``folder/history.json``, or None."""
    try:
        text = (folder / HISTORY_FILE).read_text(encoding="utf-8")
        return text, json.loads(text)
    except (OSError, ValueError):
        return None


def mix_hash(h: str, folder: Path) -> str:
    """The build's input hash, extended by the content of ``history.json`` when there is one."""
    got = load(folder)
    if got is None:
        return h
    return hashlib.sha256((h + "\n" + got[0]).encode()).hexdigest()[:16]
