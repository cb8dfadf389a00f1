"""The build's process pool starts the costliest specs first (longest processing time first, issue
23: the slowest spec no longer starts last) and still hands the results back in the specs' order."""

from __future__ import annotations

import time
from pathlib import Path

import pytest

from balpipe.runtime import pool
from balpipe.build import spec_cost


@pytest.fixture
def ctrl_c_raises():
    """SIGINT's Python handler (KeyboardInterrupt) set here, not inherited: a runner started as a
    background job of a non-interactive shell ignores SIGINT, and so would these tests."""
    import signal

    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


def _logged(item: tuple[str, str]) -> str:
    name, log = item
    with open(log, "a") as f:
        f.write(name + "\n")
    time.sleep(0.3)
    return name.upper()


def test_the_costliest_items_start_first_and_results_keep_the_items_order(tmp_path):
    log = str(tmp_path / "log")
    items = [("a", log), ("bbbbb", log), ("cc", log), ("dddd", log)]
    out = list(pool.in_order(_logged, items, 2, cost=lambda item: len(item[0])))
    assert out == ["A", "BBBBB", "CC", "DDDD"]
    started = Path(log).read_text().split()
    assert set(started[:2]) == {"bbbbb", "dddd"} and started[-1] == "a"
    # one process: in the items' order, the cost unused
    Path(log).unlink()
    assert list(pool.in_order(_logged, items, 1, cost=lambda item: len(item[0]))) == out
    assert Path(log).read_text().split() == ["a", "bbbbb", "cc", "dddd"]


def test_a_spec_costs_its_text_length(tmp_path):
    short, long = tmp_path / "short.yaml", tmp_path / "long.yaml"
    short.write_text("name: x\n")
    long.write_text("name: x\n" + "# more\n" * 50)
    assert spec_cost(long) > spec_cost(short) > 0 and spec_cost(tmp_path / "gone.yaml") == 0.0


def test_without_the_simulation_a_spec_costs_its_methods_work_too():
    """--no-sim: the 4-RRR's short spec (2-3 s of balancing and design analyses) and paper 003's
    start before the longest texts of plain specs; with the simulation the text alone orders them;
    an unreadable or unknown spec costs its text (or nothing), never an error."""
    specs = Path(__file__).resolve().parents[2] / "specs"
    heavy = [specs / "paper001_4rrr_fig6a.yaml", specs / "paper003_com_planning.yaml"]
    plain = [specs / "custom_stephenson_six_bar_120rpm.yaml", specs / "custom_3rrr_motors.yaml"]
    assert min(spec_cost(p, simulate=False) for p in heavy) > max(spec_cost(p, simulate=False) for p in plain)
    assert spec_cost(heavy[0]) < spec_cost(plain[0])  # by the text: the order with the simulation
    assert spec_cost(Path(__file__).parents[1] / "does_not_exist.yaml", simulate=False) == 0.0


def test_an_unknown_method_costs_only_its_text(tmp_path):
    p = tmp_path / "x.yaml"
    p.write_text("mechanism: {template: nowhere}\nbalancing: {method: nothing}\n" + "# pad\n" * 100)
    assert spec_cost(p, simulate=False) == p.stat().st_size / 5000.0
    p.write_text("mechanism: [unclosed\n")
    assert spec_cost(p, simulate=False) == p.stat().st_size / 5000.0


def _interrupt_main_thread() -> None:
    """Ctrl-C to this process's main thread (where Python runs its handler), as a terminal sends it."""
    import signal
    import threading

    signal.pthread_kill(threading.main_thread().ident, signal.SIGINT)


def test_a_ctrl_c_while_workers_are_forked_is_held_then_delivered(ctrl_c_raises):
    """While the pools fork their workers Ctrl-C is held back, not ignored: it arrives when the
    workers are set up (once ignoring it lost a Ctrl-C pressed at that moment)."""
    reached = False
    with pytest.raises(KeyboardInterrupt):
        with pool.sigint_held():
            _interrupt_main_thread()
            time.sleep(0.05)
            reached = True  # held: nothing raised inside the block
    assert reached


def _sleep(item: tuple[float, str]) -> float:
    seconds, done = item
    time.sleep(seconds)
    Path(done).write_text("finished")  # only a worker that was not stopped gets here
    return seconds


def test_a_ctrl_c_during_the_pools_start_stops_its_workers_at_once(monkeypatch, ctrl_c_raises, tmp_path):
    """A Ctrl-C pressed while ``in_order`` forks its workers interrupts it as soon as they are
    forked, and the workers are stopped then, not when their 30 s of work ends: once it has
    propagated, no worker is alive and none finished its item."""
    import multiprocessing

    import contextlib

    real = pool.sigint_held

    @contextlib.contextmanager
    def pressed_meanwhile():
        with real():
            yield
            _interrupt_main_thread()

    monkeypatch.setattr(pool, "sigint_held", pressed_meanwhile)
    marks = [str(tmp_path / f"done{k}") for k in range(2)]
    with pytest.raises(KeyboardInterrupt):
        list(pool.in_order(_sleep, [(30.0, m) for m in marks], 2))
    assert not multiprocessing.active_children()
    assert not any(Path(m).exists() for m in marks)


def test_the_pools_fork_on_linux_whatever_pythons_default():
    """Workers inherit what the parent loaded (Python 3.14 defaults to forkserver on Linux)."""
    import sys

    import pytest

    if sys.platform != "linux":
        pytest.skip("fork is the start method on Linux only")
    assert pool._context().get_start_method() == "fork"


def test_the_pools_last_task_makes_the_sites_schema(tmp_path, monkeypatch):
    """Issue 43: with a pool, the site's schema is the pool's last task (the first worker left
    without a spec makes it while another builds its last: this process no longer makes it after
    them), and the file is the one this process would write; one process makes it at the end."""
    import shutil

    from balpipe import build
    from balpipe.cli import main

    folder = tmp_path / "specs"
    folder.mkdir()
    root = Path(__file__).resolve().parents[2] / "specs"
    for name in ("offset_slider_crank.yaml", "scott_russell.yaml"):
        shutil.copy(root / name, folder / name)
    tasks: list[list] = []
    real = pool.in_order

    def recording(fn, items, jobs, *args, cost=None):
        tasks.append([items[i] for i in sorted(range(len(items)), key=lambda i: -cost(items[i]))])
        return real(fn, items, jobs, *args, cost=cost)

    monkeypatch.setattr(pool, "in_order", recording)
    assert main(["build", str(folder), "-o", str(tmp_path / "two"), "--no-sim", "-j", "2"]) == 0
    assert tasks[-1][-1] == build.SCHEMA_TASK and len(tasks[-1]) == 3
    text = (tmp_path / "two" / "balpipe.schema.json").read_text()
    assert text == build.schema_text() and '"title": "balpipe spec"' in text
    assert main(["build", str(folder), "-o", str(tmp_path / "one"), "--no-sim", "-j", "1"]) == 0
    assert build.SCHEMA_TASK not in tasks[-1]
    assert (tmp_path / "one" / "balpipe.schema.json").read_text() == text
