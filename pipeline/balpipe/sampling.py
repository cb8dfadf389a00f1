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
