"""The usage errors ``build`` and ``history`` share (one helper, ``cli.paths_jobs_problem``):
the same words, exit 2, the missing paths checked before ``--jobs``."""

import pytest

from balpipe.cli import main


@pytest.mark.parametrize("command", ["build", "history"])
def test_missing_paths_and_bad_jobs_are_usage_errors(tmp_path, capsys, command):
    nope = tmp_path / "nope.yaml"
    assert main([command, str(nope), str(tmp_path), "-j", "0"]) == 2
    err = capsys.readouterr().err
    assert f"balpipe: error: no such file or folder: {nope}\n" in err and "--jobs" not in err
    assert main([command, str(tmp_path), "-j", "0"]) == 2
    assert "balpipe: error: --jobs must be at least 1\n" in capsys.readouterr().err
