"""A stage's short name, for plot legends and titles: the long label (the stage table's) stays
in a tooltip. Guarantees: a short name is at most :data:`LIMIT` characters, never empty, and
the short names of one figure are distinct (:func:`short_names` falls back to the long label
for any that would repeat)."""

from __future__ import annotations

import re

LIMIT = 40  # characters of a legend entry: one line of a 400 px plot's legend
_PARENS = re.compile(r"\s*\([^()]*\)")


def short_label(label: str, design: str | None = None) -> str:
    """``label`` without its parenthesised remarks ('leg-by-leg counter-masses (Fig. 2a, eqs.
    8-11)' -> 'leg-by-leg counter-masses'); a compared design's stage ('design label: stage
    label', ``design`` its name) as 'design: stage' ('paper: counter-rotations'); cut at a word
    boundary with '…' beyond :data:`LIMIT` characters."""
    text = label
    if design:
        stage = label.split(": ", 1)[-1]
        text = f"{design.replace('_', ' ')}: {_PARENS.sub('', stage).strip() or stage}"
    else:
        text = _PARENS.sub("", label).strip() or label
    if len(text) <= LIMIT:
        return text
    cut = text[: LIMIT - 1]
    space = cut.rfind(" ")
    return (cut[:space] if space > LIMIT // 2 else cut).rstrip(" ,:;·") + "…"


def short_names(labels: list[str], designs: list[str | None] | None = None) -> list[str]:
    """:func:`short_label` of each of ``labels`` (with its ``designs``, None for the main
    design's), distinct: a short name two labels would share is replaced by their long labels."""
    shorts = [short_label(lab, d) for lab, d in zip(labels, designs or [None] * len(labels))]
    return [s if shorts.count(s) == 1 or labels.count(lab) > 1 else lab for s, lab in zip(shorts, labels)]
