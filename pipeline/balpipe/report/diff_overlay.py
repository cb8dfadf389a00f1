"""The two designs of ``balpipe diff``, one stage at a time, overlaid in the pages' interactive
plots (:mod:`balpipe.draw.live`: hover, zoom, a legend entry hides its curve): shaking force Fx,
Fy, |F| and moment M of the old design (grey, dashed) and the new one (black, solid), over time.

Two designs of different durations or samplings are drawn over the union of their sample times,
each curve ending where its motion ends (null beyond: a gap, never extrapolated). A load that is
round-off in both designs is drawn as zero (its numbers are the round-off of the computation, not
a signal); the page's caption says so.
"""

from __future__ import annotations

import numpy as np

from ..draw.live import Curves
from .live_plots import LOADS

OLD_STYLE = {"color": "#8c8c8c", "linestyle": "--", "linewidth": 1.6}
NEW_STYLE = {"color": "#000000", "linestyle": "-", "linewidth": 1.3}


def _on(t: np.ndarray, tk: np.ndarray, y: np.ndarray) -> np.ndarray:
    """``y`` sampled at ``tk`` read at ``t``: the same samples when the grids agree, else linear
    between samples and NaN (null) outside the motion."""
    if len(tk) == len(t) and np.array_equal(tk, t):
        return np.asarray(y, dtype=float)
    return np.interp(t, tk, y, left=np.nan, right=np.nan)


def overlay(old, new, round_off: tuple[bool, bool] = (False, False)) -> Curves:
    """The stage's curves in both designs (analyses ``old`` and ``new``); ``round_off``: (force,
    moment) round-off in both designs, drawn as zero."""
    t_old, t_new = np.asarray(old.t, dtype=float), np.asarray(new.t, dtype=float)
    t = t_old if len(t_old) == len(t_new) and np.array_equal(t_old, t_new) else np.union1d(t_old, t_new)
    curves = []
    for label, an, tk in (("old design", old, t_old), ("new design", new, t_new)):
        values = {}
        for key, _, _, fn in LOADS:
            quiet = round_off[1] if key == "M" else round_off[0]
            y = _on(t, tk, np.asarray(fn(an.force, an.moment), dtype=float))
            values[key] = np.where(np.isnan(y), np.nan, 0.0) if quiet else y
        curves.append((label, values))
    return Curves(t, curves, [{"key": key, "title": title, "axis": axis} for key, title, axis, _ in LOADS], [],
                  styles=[OLD_STYLE, NEW_STYLE], grid=True)


#: where a reader without JavaScript finds the diff's numbers
DIFF_NUMBERS = "the stages' peaks are in the tables above, the samples in each design's timeseries.csv"
