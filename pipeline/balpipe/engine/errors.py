"""The engine's error: a located failure of the analysis (time and joint)."""

from __future__ import annotations

import numpy as np


class AnalysisError(Exception):
    """The mechanism cannot follow the motion: non-convergence or a singular configuration."""

    def __init__(self, message: str, time: float | None = None, joint: str | None = None):
        super().__init__(message)
        self.time = time
        self.joint = joint
        self.q: np.ndarray | None = None  # positions (3 nb,) where the position analysis stopped, when it did
