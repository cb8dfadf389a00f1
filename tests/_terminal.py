"""Start ``python -m balpipe`` as a terminal's foreground job would be: SIGINT at its default;
wait for a started process to get somewhere (a line on its stderr, a child process).

A non-interactive shell starts a background command (``cmd &``) with SIGINT ignored, its
children inherit that, and Python then installs no KeyboardInterrupt handler: a Ctrl-C test run
under such a shell would see the build ignore the signal (seen when the README's test command
ran from a script started with ``&``). The launcher resets SIGINT to its default and execs
balpipe, so Python installs its handler as it does in a terminal (no ``preexec_fn``, which is
unsafe in the threaded xdist workers)."""

from __future__ import annotations

import os
import sys

_LAUNCH = ("import os, signal, sys; signal.signal(signal.SIGINT, signal.SIG_DFL); "
           "os.execv(sys.executable, [sys.executable, '-m', 'balpipe', *sys.argv[1:]])")


def balpipe_command(*args) -> list[str]:
    """The argv of ``python -m balpipe ARGS`` with SIGINT at its default."""
    return [sys.executable, "-c", _LAUNCH, *map(str, args)]


class StderrLines:
    """The stderr of a started process, read line by line by a thread, so that a test can wait
    for a line that says how far the process got (instead of sleeping a fixed time, too short
    on a busy machine and wasted on a quiet one)."""

    def __init__(self, process):
        import threading

        self._lines: list[str] = []
        self._done = False
        self._changed = threading.Condition()
        self._thread = threading.Thread(target=self._read, args=(process.stderr,), daemon=True)
        self._thread.start()

    def _read(self, stream) -> None:
        for line in stream:
            with self._changed:
                self._lines.append(line)
                self._changed.notify_all()
        with self._changed:
            self._done = True
            self._changed.notify_all()

    def wait_for(self, text: str, timeout: float = 300.0) -> str:
        """The first line that contains ``text``, once it is written; AssertionError (with what
        was written) when the stream ends or ``timeout`` seconds pass without it."""
        import time

        end = time.monotonic() + timeout
        with self._changed:
            while True:
                found = next((ln for ln in self._lines if text in ln), None)
                if found is not None:
                    return found
                left = end - time.monotonic()
                assert not self._done and left > 0, f"no line with {text!r} on stderr: {''.join(self._lines)!r}"
                self._changed.wait(left)

    def text(self, timeout: float = 120.0) -> str:
        """Everything written, once the stream has ended."""
        self._thread.join(timeout)
        assert not self._thread.is_alive(), "stderr still open"
        return "".join(self._lines)


def wait_for_children(process, count: int = 1, cpu: float = 0.2, timeout: float = 300.0,
                      fallback: float = 5.0) -> None:
    """Wait until the started ``process`` is inside the work of its forked children: ``count``
    children of its own (Linux: ``/proc/PID/task/*/children``) have each run ``cpu`` seconds
    (their work, not their start) and its main thread sleeps (waiting for their results). Not
    at the forks themselves: a Ctrl-C that lands in Python's after-fork handlers in the parent is
    lost ("Exception ignored in: _releaseLock"). AssertionError when the process ends or
    ``timeout`` seconds pass first. Without that file (not Linux), ``fallback`` seconds instead."""
    import time
    from pathlib import Path

    if not Path(f"/proc/{os.getpid()}/task/{os.getpid()}/children").exists():
        time.sleep(fallback)
        return
    tick = os.sysconf("SC_CLK_TCK")

    def busy(pid: str) -> bool:  # utime + stime, fields 14 and 15 after the command's parentheses
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / tick >= cpu

    end = time.monotonic() + timeout
    while time.monotonic() < end:
        assert process.poll() is None, f"process {process.pid} ended before its children worked"
        try:
            kids = [k for f in Path(f"/proc/{process.pid}/task").glob("*/children") for k in f.read_text().split()]
            main = Path(f"/proc/{process.pid}/task/{process.pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
            if len(kids) >= count and sum(busy(k) for k in kids) >= count and main == "S":
                return
        except (OSError, IndexError, ValueError):  # a child or thread that ended between the reads
            pass
        time.sleep(0.05)
    raise AssertionError(f"process {process.pid}: no {count} children at work within {timeout} s")
