"""The analysis grid of a spec: its time samples and its gravity vector (every layer that
analyses a spec samples it the same way)."""

from __future__ import annotations

from typing import Any

import numpy as np


def time_grid(spec: Any) -> np.ndarray:
    """``analysis.samples`` instants from 0 to ``motion.duration``, both included."""
    return np.linspace(0.0, spec.motion.duration, spec.analysis.samples)


def gravity_vector(spec: Any) -> tuple[float, float]:
    """(0, -g) when ``analysis.gravity`` is on, else (0, 0)."""
    return (0.0, -spec.analysis.g) if spec.analysis.gravity else (0.0, 0.0)


def spread_indices(n: int, keep: int) -> np.ndarray:
    """The indices of ``keep`` samples spread evenly over ``n`` (the first and the last
    included), rounded, increasing, without repeats: ``np.unique`` of the rounded
    ``linspace``, without the ``numpy.ma`` import (90 ms) that ``np.unique`` makes."""
    idx = np.linspace(0, n - 1, min(n, keep)).round().astype(int)
    keep_mask = np.ones(len(idx), dtype=bool)
    keep_mask[1:] = idx[1:] != idx[:-1]  # linspace is non-decreasing: repeats are neighbours
    return idx[keep_mask]
