"""Issue 43: a build collects Python's garbage cycles less often (``balpipe.runtime.collector``):
the thresholds hold during the build, its forked workers included, and are restored after it;
the site is the same, byte for byte."""

from __future__ import annotations

import gc
import shutil
from pathlib import Path

from balpipe import build as build_module
from balpipe.cli import main
from balpipe.runtime.collector import THRESHOLDS, fewer_collections

ROOT = Path(__file__).resolve().parents[2]


def test_the_thresholds_hold_in_the_block_and_are_restored_after_it():
    before = gc.get_threshold()
    with fewer_collections():
        assert gc.get_threshold() == THRESHOLDS
    assert gc.get_threshold() == before
    try:
        with fewer_collections():
            raise KeyError("x")
    except KeyError:
        pass
    assert gc.get_threshold() == before


def test_a_build_runs_with_them_and_writes_the_same_site(tmp_path, monkeypatch):
    folder = tmp_path / "specs"
    folder.mkdir()
    shutil.copy(ROOT / "specs" / "offset_slider_crank.yaml", folder)
    seen = []
    real = build_module.build

    def recording(*args, **kwargs):
        seen.append(gc.get_threshold())
        return real(*args, **kwargs)

    before = gc.get_threshold()
    monkeypatch.setattr(build_module, "build", recording)
    assert main(["build", str(folder), "-o", str(tmp_path / "a"), "--no-sim"]) == 0
    assert seen == [THRESHOLDS] and gc.get_threshold() == before
    # the same site built again with the default thresholds (by the library's build, outside the command)
    monkeypatch.setattr(build_module, "build", real)
    build_module.build([str(folder)], build_module.Options(out=tmp_path / "b", simulate=False, force=True), jobs=1)
    for name in ("index.html", "offset_slider_crank/results.json", "offset_slider_crank/index.html"):
        assert (tmp_path / "a" / name).read_bytes() == (tmp_path / "b" / name).read_bytes(), name
