"""Paper 000's idler loop in pymunk: the chained counter-rotations, two of them on moving
carriers (links 6 and 5), cancel the simulated shaking force and moment."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from balpipe import registry
from balpipe.engine import analyse
from balpipe.loader import load
from balpipe.validate import ValidationSettings, validate

SPEC = Path(__file__).resolve().parents[2] / "specs" / "paper000_rpr3_idler_loop.yaml"


def test_chained_planetary_counter_rotations_in_pymunk():
    spec = load(SPEC).spec
    stages = {s.name: s for s in registry.balance(spec).stages}
    t = np.linspace(0.0, spec.motion.duration, 101)
    first = analyse(stages["unbalanced"].model, t)
    full = stages["counter_rotations"].model
    carriers = {j.carrier for j in full.joints if hasattr(j, "carrier")}
    assert {"link5", "link6", "frame"} <= carriers
    an = analyse(full, t)
    v = validate(full, an, (first.max_force, first.max_moment), ValidationSettings(dt=2.5e-4),
                 expect=("force", "moment"))
    assert v.passed, v.reasons
    assert v.force_peak < 1e-3 and v.moment_peak < 1e-2
