"""Issue 13, Layout: each command-line verb is its own module of the ``balpipe.cli`` package
(``add_parser`` and ``run``), ``main`` only dispatches; the entry points keep working."""

from __future__ import annotations

import importlib
import subprocess
import sys

import pytest

from balpipe import cli


@pytest.mark.parametrize("verb", cli.VERBS)
def test_every_verb_is_its_own_module(verb):
    mod = importlib.import_module(f"balpipe.cli.{verb}")
    assert callable(mod.add_parser) and callable(mod.run)
    helps = cli._parser().format_help()
    assert verb in helps


def test_main_dispatches_to_the_verb_module(monkeypatch, capsys):
    from balpipe.cli import schema

    seen = []
    monkeypatch.setattr(schema, "run", lambda args: seen.append(args.command) or 7)
    assert cli.main(["schema"]) == 7 and seen == ["schema"]


def test_entry_points_and_exit_codes():
    for argv in (["-m", "balpipe", "--version"], ["-m", "balpipe.cli", "--version"]):
        r = subprocess.run([sys.executable, *argv], capture_output=True, text=True)
        assert r.returncode == 0 and r.stdout.startswith("balpipe "), r.stderr
    r = subprocess.run([sys.executable, "-m", "balpipe.cli", "frobnicate"], capture_output=True, text=True)
    assert r.returncode == 2 and "invalid choice" in r.stderr and "Traceback" not in r.stderr
    assert (cli.EXIT_OK, cli.EXIT_FAILED, cli.EXIT_USAGE, cli.EXIT_INTERRUPTED, cli.EXIT_TERMINATED) == (0, 1, 2, 130, 143)


def test_interrupt_and_sigterm_exit_codes(monkeypatch, capsys):
    from balpipe.cli import check

    def interrupted(args):
        raise KeyboardInterrupt

    def terminated(args):
        raise cli.Terminated

    monkeypatch.setattr(check, "run", interrupted)
    assert cli.main(["check", "x"]) == 130 and "interrupted" in capsys.readouterr().err
    monkeypatch.setattr(check, "run", terminated)
    assert cli.main(["check", "x"]) == 143 and "terminated" in capsys.readouterr().err
