"""``balpipe check`` does less than ``build`` for the same verdicts (issue 23, "check in a
blink"): the page-only diagnostics (condition numbers, dead centres) are skipped, and the
engine's revolute rows, evaluated for every joint at once, are the per-joint arithmetic to the
last bit (``build``'s output is unchanged). The stages of one geometry sharing its motion on the
general path, for both commands: tests/engine/test_engine_shared.py."""

from __future__ import annotations

import numpy as np
import pytest

from balpipe import engine, registry
from balpipe.engine import analyse, compiled, constraints
from balpipe.engine.constraints import with_frame
from balpipe.loader import load
from balpipe.runner import analyse as run_analyse
from balpipe.mechanics.sampling import spread_indices, time_grid
from balpipe.study import gravity_vector

RRR4 = "specs/paper001_4rrr.yaml"  # redundant actuation: the general (dense) path


def _stages(path: str):
    spec = load(path).spec
    return spec, registry.balance(spec).stages


def _drawn_design(name: str) -> bool:
    """Paper 001's drawn designs (Figs. 3, 4b): their parameters, and their derived peak forces."""
    return name.startswith(("peak_force_ratio_", "added_mass_fig", "eq17_residual_fig", "finder_residual_fig"))


#: the finder's count for translating-platform motions (special kinematics): shown, used by no stage
TRANSLATING = ("translating_conditions", "translating_gap", "translating_in_printed_span",
               "printed_reduced_conditions", "printed_reduced_in_translating")


def test_check_path_skips_the_page_diagnostics_but_not_the_stages(studies):
    loaded = load("specs/paper001_4rrr_fig6a.yaml")
    quick = run_analyse(loaded, page=False)
    full = studies("paper001_4rrr_fig6a.yaml")  # run_analyse(loaded)'s study, made once per run (the page tests')
    assert full.spec == loaded.spec
    assert quick.checks["max_condition_number"] is None and quick.warnings == []
    assert full.checks["max_condition_number"] > 1.0
    assert [s.stage.name for s in quick.stages] == [s.stage.name for s in full.stages]
    for a, b in zip(quick.stages, full.stages):
        assert a.max_effort == pytest.approx(b.max_effort, rel=1e-9)
    drawn = [p.name for p in full.balance.parameters if _drawn_design(p.name)]
    assert drawn and not loaded.spec.references  # page only: left out without references
    assert "topologies" in full.balance.details and "topologies" not in quick.balance.details
    assert "finder_translating" in full.balance.details and "finder_translating" not in quick.balance.details
    assert set(TRANSLATING) <= {p.name for p in full.balance.parameters}
    assert [p.name for p in quick.balance.parameters] == [p.name for p in full.balance.parameters
                                                          if p.name not in drawn and p.name not in TRANSLATING]
    values = {p.name: p.value for p in full.balance.parameters}
    for p in quick.balance.parameters:
        assert p.value == pytest.approx(values[p.name], rel=1e-6, abs=1e-9), p.name


def test_check_path_computes_what_a_reference_may_name(tmp_path):
    """A reference may name a drawn design's parameter: with references the check computes them."""
    src = open("specs/paper001_4rrr_fig6a.yaml", encoding="utf-8").read()
    path = tmp_path / "fig6a_ref.yaml"
    path.write_text(src + "references:\n  - {name: peak_force_ratio_fig4b, published: 1.0, expect: differ}\n"
                    "  - {name: added_mass_fig3a, published: 1.0, expect: differ}\n", encoding="utf-8")
    quick = run_analyse(load(path), page=False)
    assert [r["name"] for r in quick.references] == ["peak_force_ratio_fig4b", "added_mass_fig3a"]
    assert any(_drawn_design(p.name) for p in quick.balance.parameters)
    assert any(p.name in TRANSLATING for p in quick.balance.parameters)


def test_check_path_keeps_derived_parameters_that_references_may_name():
    loaded = load("specs/paper003_com_planning.yaml")
    assert loaded.spec.references and any(r.name.startswith(("force_reduction", "moment_reduction"))
                                          for r in loaded.spec.references)
    quick = run_analyse(loaded, page=False)
    assert any(p.name == "force_reduction_min" for p in quick.balance.parameters)
    assert [r["name"] for r in quick.references] == [r.name for r in loaded.spec.references]


@pytest.mark.parametrize("path", [RRR4, "specs/paper000_rpr3_idler_loop.yaml", "specs/paper004_five_bar.yaml",
                                  "specs/custom_stephenson_six_bar_120rpm.yaml"])
def test_revolute_rows_at_once_equal_the_joints_one_at_a_time_to_the_bit(path, monkeypatch):
    spec, stages = _stages(path)
    t = time_grid(spec)
    rng = np.random.default_rng(7)
    for s in stages:
        c = compiled(s.model)
        assert constraints.revolute_rows(c) is not None
        q = c.q0[None, :] + rng.normal(scale=0.3, size=(len(t), len(c.q0)))
        qx, vx = with_frame(q), with_frame(rng.normal(size=q.shape))

        def rows():
            return (constraints.residual(c, qx, t), constraints.jacobian(c, qx),
                    constraints.acceleration_rhs(c, qx, vx, t))

        fast = rows()
        with monkeypatch.context() as m:
            m.setattr(constraints, "revolute_rows", lambda c: None)
            slow = rows()
        for a, b in zip(fast, slow):
            assert a.tobytes() == b.tobytes(), s.name  # signed zeros included


@pytest.mark.parametrize("n", [1, 2, 3, 5, 16, 17, 18, 33, 501, 1000])
@pytest.mark.parametrize("keep", [1, 2, 9, 17])
def test_spread_indices_are_np_unique_of_the_rounded_linspace(n, keep):
    expected = np.unique(np.linspace(0, n - 1, min(n, keep)).round().astype(int))
    got = spread_indices(n, keep)
    assert got.dtype == expected.dtype and np.array_equal(got, expected)


def test_prepare_builds_the_spec_validator_before_a_pool_forks():
    """``balpipe check`` with a pool builds the spec's validator (deferred by pydantic to the first
    spec validated) once in the parent: the workers inherit it."""
    import subprocess
    import sys

    probe = ("from balpipe.spec import Spec\nfrom balpipe import loader\nbefore = Spec.__pydantic_complete__\n"
             "loader.prepare()\nprint(before, Spec.__pydantic_complete__)")
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, timeout=120).stdout.split()
    assert out == ["False", "True"]


def test_check_leaves_the_collector_as_it_found_it(capsys):
    """check freezes the objects it loaded before checking (gc.freeze: the collector and forked
    workers leave them alone) and unfreezes them when it returns, for a caller in the same process."""
    import gc

    from balpipe.cli import main

    assert gc.get_freeze_count() == 0
    try:
        main(["check", "specs/scott_russell.yaml"])
    except SystemExit as exc:
        assert exc.code in (0, None)
    assert gc.get_freeze_count() == 0
    assert "specs/scott_russell.yaml: ok" in capsys.readouterr().out


def test_check_loads_its_modules_with_the_collector_off_and_freezes_them(capsys):
    """In a fresh interpreter, check imports the loader and the runner with the collector off
    and freezes what they made before it reads a spec (no collection scans them: a one-spec
    check's collections 0.015 -> 0.002 s of CPU); a usage error leaves the collector as it was."""
    import gc
    import subprocess
    import sys

    from balpipe.cli import main

    probe = ("import gc, sys\nfrom balpipe.cli import check\nseen = []\nreal = check._check\n"
             "check._check = lambda *a: seen.append((gc.get_freeze_count(), gc.isenabled(), 'balpipe.runner' in sys.modules))"
             " or real(*a)\nfrom balpipe.cli import main\ncode = main(['check', 'specs/scott_russell.yaml'])\n"
             "print(code, seen[0][0] > 10000, seen[0][1], seen[0][2], gc.get_freeze_count())")
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, timeout=120).stdout
    assert out.splitlines()[-1].split() == ["0", "True", "True", "True", "0"]
    assert main(["check", "--jobs", "0", "specs/scott_russell.yaml"]) == 2
    assert gc.get_freeze_count() == 0 and gc.isenabled()
    capsys.readouterr()


def test_velocities_and_accelerations_factorise_a_redundant_jacobian_once_to_the_bit(monkeypatch):
    """With redundant drivers the engine's general path solves for q' and q'' with one
    factorisation of the Jacobian: its normal equations (engine/normal.py: one inverse of J^T J,
    no QR), the same values as QR's to round-off; where they do not hold, one QR factorisation
    (it used to factorise the same matrix twice): the same bits as two."""
    from balpipe.engine import kinematics

    spec, stages = _stages(RRR4)
    t = time_grid(spec)
    engine.clear_cache()
    c = compiled(stages[0].model)
    q = analyse(stages[0].model, t).q.reshape(len(t), -1)
    J = constraints.jacobian(c, with_frame(q))[:, :, 3:]
    assert J.shape[1] > J.shape[2]  # redundant
    calls = []
    real_qr = np.linalg.qr
    monkeypatch.setattr(np.linalg, "qr", lambda *a, **k: calls.append(1) or real_qr(*a, **k))
    v0, a0 = kinematics._vel_acc(c, q, t)
    assert calls == []  # the normal equations
    monkeypatch.setattr(kinematics, "factor", lambda J, G=None: None)  # the QR branch
    v, a = kinematics._vel_acc(c, q, t)
    assert len(calls) == 1
    for mine, ref in ((v0, v), (a0, a)):
        assert np.abs(mine - ref).max() <= 1e-13 * np.abs(ref).max()
    monkeypatch.setattr(kinematics, "_factors", lambda J: None)  # each solve factorises again
    v2, a2 = kinematics._vel_acc(c, q, t)
    assert len(calls) == 3
    assert v.tobytes() == v2.tobytes() and a.tobytes() == a2.tobytes()