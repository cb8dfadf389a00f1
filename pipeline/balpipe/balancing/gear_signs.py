"""Counter-rotations found, not guessed: the gear signs with which counter-rotating discs cancel
a shaking moment, searched in one step.

A disc d on carrier c geared to g turns at w_c + k_d (w_g - w_c) and adds J_d times that to the
angular momentum; its inertia J_d >= 0 is solved by least squares (:mod:`.moment_balance`). A
disc turning the wrong way needs a negative inertia, and reversing one disc's sign changes the
least-squares inertias of the others that share its angular velocities, so signs fixed one disc
at a time can go round in a circle. Here every combination of signs (the spec's magnitudes kept)
is balanced in full, fewest reversals first, and the first that cancels the moment with
non-negative inertias is named: 2^n balances for n discs, at most 2^:data:`MAX_DISCS`.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Sequence

MAX_DISCS = 6  # 64 balances at most


def sign_combinations(ratios: Sequence[float]) -> list[tuple[float, ...]]:
    """Every ratio vector with the magnitudes of ``ratios`` and other signs, fewest reversals
    first (then in lexicographic order of the reversed discs), the given one excluded."""
    n = len(ratios)
    out = []
    for flips in range(1, n + 1):
        for idx in itertools.combinations(range(n), flips):
            out.append(tuple(-r if k in idx else r for k, r in enumerate(ratios)))
    return out


def working_ratios(ratios: Sequence[float], cancels: Callable[[tuple[float, ...]], bool]) -> tuple[float, ...] | None:
    """The first sign combination (:func:`sign_combinations`) for which ``cancels(ratios)`` (a
    full moment balance with those ratios cancels the moment with non-negative inertias), or None
    (none does, or there are more than :data:`MAX_DISCS` discs)."""
    if not ratios or len(ratios) > MAX_DISCS:
        return None
    for candidate in sign_combinations(ratios):
        if cancels(candidate):
            return candidate
    return None


def named(names: Sequence[str], ratios: Sequence[float]) -> str:
    """'disc_crank: -1, disc_rocker: +2' (every disc, so that one edit sets them all)."""
    return ", ".join(f"{n}: {r:+g}" for n, r in zip(names, ratios))
