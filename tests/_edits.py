"""Editing spec texts in tests: every edit must find what it replaces, so that a test can never
silently run on an unchanged spec (a spec edited since the test was written)."""

from __future__ import annotations


def replaced(text: str, old: str, new: str, count: int = 1) -> str:
    """``text`` with ``old`` replaced by ``new``; asserts that ``old`` occurs exactly ``count``
    times (default once), so that the edit really happens and happens where intended."""
    found = text.count(old)
    assert found == count, f"expected {count} occurrence(s) of {old!r} in the spec text, found {found}"
    return text.replace(old, new)


def stage_steps_kept(text: str, present: str) -> str:
    """Paper 003's spec ``text`` with only the ``validation.stage_dt`` entries (the lines under
    ``  stage_dt:``, ``<trajectory>_<case>: <dt>``) whose trajectory occurs in ``present`` (the
    trajectories the edited spec keeps): a step for a stage that does not exist is refused.
    Without any entry left, no ``stage_dt`` either."""
    out: list[str] = []
    header, kept, inside = None, 0, False
    for line in text.splitlines(keepends=True):
        if line.startswith("  stage_dt:"):
            header, inside = len(out), True
            out.append(line)
        elif inside and line.startswith("    "):
            if line.strip().split("_", 1)[0] in present:
                out.append(line)
                kept += 1
        else:
            inside = False
            out.append(line)
    if header is not None and not kept:
        del out[header]
    return "".join(out)
