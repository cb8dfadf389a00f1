"""Editing spec texts in tests: every edit must find what it replaces, so that a test can never
silently run on an unchanged spec (a spec edited since the test was written)."""

from __future__ import annotations


def replaced(text: str, old: str, new: str, count: int = 1) -> str:
    """``text`` with ``old`` replaced by ``new``; asserts that ``old`` occurs exactly ``count``
    times (default once), so that the edit really happens and happens where intended."""
    found = text.count(old)
    assert found == count, f"expected {count} occurrence(s) of {old!r} in the spec text, found {found}"
    return text.replace(old, new)
