"""Every example of docs/loads.md builds and does what the page says."""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path

import numpy as np
import pytest

from balpipe import loader, study
from balpipe.engine import analyse
from balpipe.loader import load_text
from balpipe.spec_parts import SpecFieldError

DOC = Path(__file__).resolve().parents[1] / "docs" / "loads.md"
TEXT = DOC.read_text()
BLOCKS = re.findall(r"```yaml\n(.*?)```", TEXT, re.S)
CSV = re.findall(r"```csv\n(.*?)```", TEXT, re.S)


def _peak(x) -> float:
    return float(np.max(np.abs(x)))


def test_the_page_has_its_examples():
    assert len(BLOCKS) == 4 and len(CSV) == 1


def test_internal_loads_change_the_torque_not_the_shaking_load():
    st = study.run(load_text(BLOCKS[0], "doc.yaml")[0])
    assert st.ok
    an = st.unbalanced.analysis
    model = st.unbalanced.stage.model
    bare = analyse(dataclasses.replace(model, loads=()), an.t)
    assert _peak(an.force - bare.force) <= 1e-12 * _peak(bare.force)
    assert _peak(an.moment - bare.moment) <= 1e-12 * _peak(bare.moment)
    F, M = an.frame_load
    assert _peak(F - an.force) <= 1e-9 * _peak(F) and _peak(M - an.moment) <= 1e-9 * _peak(M)
    assert _peak(an.efforts["crank"] - bare.efforts["crank"]) > 0.1 * _peak(bare.efforts["crank"])
    # the spring's preload is its tension at the motion's start
    assert an.loads["spring"]["tension"][0] == pytest.approx(20.0, rel=1e-12)


def test_gas_pressure_and_piston_friction():
    st = study.run(load_text(BLOCKS[1], "doc.yaml")[0])
    an = st.unbalanced.analysis
    assert np.allclose(an.loads["gas"]["tension"], -2e5 * 50e-4, rtol=1e-14, atol=0)
    rings = an.loads["rings"]
    moving = np.abs(rings["rate"]) > 1e-9
    assert np.allclose(np.abs(rings["force"][moving]), 0.1 * rings["normal"][moving], rtol=1e-12)
    assert np.all(rings["force"][moving] * rings["rate"][moving] < 0)  # against the sliding
    N = np.abs(an.reactions["guide"]["N"])
    assert np.allclose(rings["normal"], N, rtol=1e-12)


def test_external_table_force_is_in_the_frame_load(tmp_path):
    (tmp_path / "cutting.csv").write_text(CSV[0])
    (tmp_path / "spec.yaml").write_text(BLOCKS[2])
    st = study.run(loader.load(tmp_path / "spec.yaml").spec)
    an = st.unbalanced.analysis
    cut = an.loads["cutting"]
    assert _peak(cut["Fx"]) == pytest.approx(1500.0, rel=1e-12) and _peak(cut["Fy"]) == 0.0
    F, _ = an.frame_load
    ext = np.stack([cut["Fx"], cut["Fy"]], axis=1)
    assert _peak(F - an.force - ext) <= 1e-9 * _peak(F)


def test_friction_without_a_pin_is_the_error_the_page_quotes():
    with pytest.raises(SpecFieldError) as err:
        study.run(load_text(BLOCKS[3], "doc.yaml")[0])
    assert err.value.path == ("loads", 0, "pin_radius")
    quoted = re.search(r"`loads\[0\].pin_radius: (.*?)`", TEXT, re.S).group(1)
    assert err.value.message == " ".join(quoted.split())
