"""balpipe's engine runs on one BLAS thread whatever was imported first: ``OPENBLAS_NUM_THREADS``
is read only when numpy loads, so after ``import numpy`` the setting of ``import balpipe``
comes too late, and the runner limits the threads where it runs (threadpoolctl,
:mod:`balpipe.runtime.threads`). Each case runs in a fresh interpreter whose environment names
no thread count, as a notebook's would."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

PROBE = """
import json, sys
import numpy  # first: its BLAS reads the environment now, before balpipe sets anything
from threadpoolctl import threadpool_info, threadpool_limits
threadpool_limits(limits=2, user_api="blas")  # a BLAS on two threads, as on any multi-core machine
import balpipe
from balpipe import study

seen = {}
real_run = study.run

def spy(*args, **kwargs):  # the runner's call into the engine
    seen["inside"] = sorted({p["num_threads"] for p in threadpool_info() if p["user_api"] == "blas"})
    return real_run(*args, **kwargs)

study.run = spy
st = balpipe.run(balpipe.load(sys.argv[1]))
seen["after"] = sorted({p["num_threads"] for p in threadpool_info() if p["user_api"] == "blas"})
seen["force"] = st.results()["stages"][0]["max_shaking_force"]
print(json.dumps(seen))
"""


def _probe(env_extra: dict[str, str]) -> dict:
    env = {k: v for k, v in os.environ.items() if k not in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")}
    env.update(env_extra)
    r = subprocess.run([sys.executable, "-c", PROBE, str(ROOT / "specs" / "offset_slider_crank.yaml")], env=env,
                       capture_output=True, text=True, timeout=300, cwd=ROOT)
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout.strip().splitlines()[-1])


def test_numpy_imported_first_the_engine_still_runs_on_one_blas_thread():
    seen = _probe({})
    assert seen["inside"] == [1]  # limited where the engine runs
    assert seen["after"] == [2]  # the caller's own setting, restored
    assert seen["force"] > 0


def test_a_thread_count_the_user_set_is_kept():
    """OPENBLAS_NUM_THREADS set by the user (before balpipe) is the engine's too."""
    assert _probe({"OPENBLAS_NUM_THREADS": "3"})["inside"] == [3]


def test_the_command_line_loads_every_blas_with_balpipes_setting_and_scans_nothing():
    """``balpipe check`` imports balpipe before any BLAS library: each loads with the variables'
    one thread, so the runner's limit has nothing to do and threadpoolctl (its scan of the loaded
    libraries, 2 ms a spec) is not even imported; a process that loaded numpy first still scans."""
    env = {k: v for k, v in os.environ.items() if k not in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")}
    spec = str(ROOT / "specs" / "offset_slider_crank.yaml")
    probe = ("import sys{first}; from balpipe.cli import entry; sys.argv = ['balpipe', 'check', sys.argv[1]]; "
             "import atexit; atexit.register(lambda: print('threadpoolctl' in sys.modules, file=sys.stderr)); entry()")
    for first, scanned in (("", "False"), ("; import numpy", "True")):
        r = subprocess.run([sys.executable, "-c", probe.format(first=first), spec], env=env, capture_output=True,
                           text=True, timeout=300, cwd=ROOT)
        assert r.returncode == 0, r.stderr
        assert r.stderr.strip().splitlines()[-1] == scanned
