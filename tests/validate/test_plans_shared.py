"""The torque-driven plans of one mechanism share its frame motion (issue 43).

A plan (:func:`balpipe.validate.torque._plan`) analyses the model with pymunk's floor parts on the
simulation's step times, with the drivers' laws continued outside the analysed interval
(:func:`balpipe.validate.extend.continued`). The engine keys a geometry's frame motion by its laws'
identities, and every plan used to continue the laws anew: each plan of each stage solved the
motion again (the 4-RRR's dense path its rates and multipliers' factorisations too). The continued
laws are now one object per law and interval, so the plans after the first place their centres of
mass in the motion already solved, with the same efforts, bit for bit, as a plan solved cold.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from balpipe import study as study_mod
from balpipe.engine import clear_cache, shared, warmstart
from balpipe.loader import load
from balpipe.motion import Polynomial
from balpipe.validate.extend import ContinuedLaw, continued, continued_law
from balpipe.validate.torque import _plan
from balpipe.validation_stage import settings_for

ROOT = Path(__file__).resolve().parents[2]


def test_a_law_continued_over_one_interval_is_one_object():
    law = Polynomial.from_boundary((0.0, 2.0, 0.0), (1.0, 0.5, 0.0), 0.5)
    c = continued_law(law, 0.0, 0.5, False)
    assert continued_law(law, 0.0, 0.5, False) is c and c == ContinuedLaw(law, 0.0, 0.5, False)
    assert continued_law(law, 0.0, 0.6, False) is not c and continued_law(law, 0.0, 0.5, True) is not c
    other = Polynomial.from_boundary((0.0, 2.0, 0.0), (1.0, 0.5, 0.0), 0.5)
    assert continued_law(other, 0.0, 0.5, False).law is other


def _solves() -> tuple[int, int]:
    return warmstart.STATS["continuation"], shared.STATS["solved"]


@pytest.mark.parametrize("path", [ROOT / "tests" / "fixtures" / "six_bar_polynomial_speed.yaml",  # the block path
                                  ROOT / "specs" / "paper001_4rrr.yaml"])  # redundant drivers: the dense path
def test_the_stages_plans_share_the_frame_motion_with_the_same_efforts(path):
    st = study_mod.run(load(path).spec)
    settings = settings_for(st)
    first, last = st.stages[0], st.stages[-1]
    assert all(continued(last.stage.model, last.analysis).drivers[i].law is d.law
               for i, d in enumerate(continued(first.stage.model, first.analysis).drivers))
    clear_cache()
    cold = _plan(last.stage.model, last.analysis, settings, None, None).efforts
    clear_cache()
    _plan(first.stage.model, first.analysis, settings, None, None)
    before = _solves()
    warm = _plan(last.stage.model, last.analysis, settings, None, None).efforts
    assert _solves() == before  # no motion solved again
    assert cold.keys() == warm.keys() and all(np.array_equal(cold[k], warm[k]) for k in cold)
