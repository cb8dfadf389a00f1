"""Short stage names for legends and titles (balpipe.draw.stage_names): parenthesised remarks
dropped, a compared design's stage as 'design: stage', at most LIMIT characters, distinct."""

from __future__ import annotations

import random
import string

from balpipe.draw.stage_names import LIMIT, short_label, short_names


def test_short_names_of_the_specs_stages():
    assert short_label("leg-by-leg counter-masses (Fig. 2a, eqs. 8-11)") == "leg-by-leg counter-masses"
    assert short_label("complete balancing by the idler loop (paper 000): counter-rotations", "paper") == \
        "paper: counter-rotations"
    assert short_label("force balance only: least-mass counterweights", "force_only") == \
        "force only: least-mass counterweights"
    long = short_label("textbook primary balance (rotating plus one reciprocating mass): crank counterweight "
                       "0.802778 kg at 60 mm", "textbook")
    assert long.startswith("textbook: crank counterweight") and long.endswith("…") and len(long) <= LIMIT
    assert short_label("unbalanced") == "unbalanced"


def test_short_names_are_short_never_empty_and_distinct(rng):
    words = ["".join(random.Random(int(rng.integers(1 << 30))).choices(string.ascii_lowercase, k=int(rng.integers(1, 12))))
             for _ in range(40)]
    for _ in range(200):
        n = int(rng.integers(1, 6))
        labels = [" ".join(rng.choice(words, size=int(rng.integers(1, 9)))) + (" (note)" if rng.random() < 0.5 else "")
                  for _ in range(n)]
        shorts = short_names(labels)
        assert all(s.strip() for s in shorts)
        for s, lab in zip(shorts, labels):
            assert len(s) <= LIMIT or s == lab
        distinct = {lab for lab in labels}
        assert len(set(shorts)) == len(distinct)
    # two labels that shorten alike keep their long labels
    assert short_names(["counterweights (a)", "counterweights (b)"]) == ["counterweights (a)", "counterweights (b)"]
