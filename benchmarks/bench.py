"""balpipe benchmarks, run by hand: ``python benchmarks/bench.py [--quick]``.

Prints tables, asserts nothing about speed (see benchmarks/README.md for measured figures):

1. wall time of ``balpipe build SPECS -o <tmp> --force``, once with ``--no-sim`` and once with
   the pymunk simulation, and the time per spec reported by the build's progress lines;
2. the engine's throughput, time samples per second of :func:`balpipe.engine.analyse`
   (compilation, position/velocity/acceleration analysis, inverse dynamics, both shaking-load
   routes), on the Scott-Russell slider-crank's stages (specs/scott_russell.yaml) and on the
   planar 3R arm of paper 003 (link data from the paper, 5 kg payload at the tip);
3. if Pinocchio is installed (``pip install pin``), ``pinocchio.rnea`` on the same 3R arm and
   the same joint samples: agreement of the joint torques with balpipe's driver efforts and the
   throughput ratio balpipe / Pinocchio;
4. the pymunk validation time per stage and per spec: :func:`balpipe.validate.validate` (and
   ``free_floating`` for the specs that ask for the reactionless demonstration) called directly
   when the module has that API, and always the difference between the two builds of (1).

The default run takes well under a minute on a 2-core machine (plus whatever the simulated
build costs); ``--quick`` (~15 s) skips the simulated build and the 10^4-sample runs.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import os
import platform
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent

from balpipe import engine, registry  # noqa: E402
from balpipe.engine import analyse  # noqa: E402
from balpipe.loader import load  # noqa: E402
from balpipe.model import FRAME, Attachment, Body, Driver, Model, Revolute  # noqa: E402
from balpipe.motion import PointToPoint, quintic  # noqa: E402
from balpipe.study import gravity_vector  # noqa: E402


# ------------------------------------------------------------------------------------------
# Output helpers


def table(headers: list[str], rows: list[list], title: str | None = None) -> None:
    cells = [[str(c) for c in r] for r in rows]
    widths = [max(len(h), *(len(r[k]) for r in cells)) if cells else len(h) for k, h in enumerate(headers)]
    if title:
        print(f"\n{title}")
    line = "  ".join(h.ljust(w) if k == 0 else h.rjust(w) for k, (h, w) in enumerate(zip(headers, widths)))
    print(line)
    print("-" * len(line))
    for r in cells:
        print("  ".join(c.ljust(w) if k == 0 else c.rjust(w) for k, (c, w) in enumerate(zip(r, widths))))


def fmt_rate(x: float) -> str:
    return f"{x:,.0f}"


def fmt_s(x: float | None) -> str:
    return "-" if x is None else f"{x:.3f}"


def best_of(fn, repeats: int, min_total: float = 0.0) -> float:
    """Best wall time of ``fn()`` over ``repeats`` calls (more calls while the total stays under
    ``min_total`` seconds, to steady very short timings)."""
    best = math.inf
    spent = 0.0
    k = 0
    while k < repeats or spent < min_total:
        t0 = time.perf_counter()
        fn()
        dt = time.perf_counter() - t0
        best = min(best, dt)
        spent += dt
        k += 1
        if k >= 50 * max(1, repeats):
            break
    return best


# ------------------------------------------------------------------------------------------
# 1 + 4. Whole builds

MIN_TOTAL = 1.0  # seconds spent per timing at least (best-of keeps running until then)

PROGRESS = re.compile(r"^\[(\d+)/(\d+)\] (.+?): (\S+) \(([\d.]+) s\)$")


def run_build(specs: Path, simulate: bool, jobs: int) -> dict:
    """Run ``balpipe build`` in a fresh temporary folder; parse the per-spec progress lines."""
    with tempfile.TemporaryDirectory(prefix="balpipe-bench-") as out:
        cmd = [sys.executable, "-m", "balpipe", "build", _short(str(specs)), "-o", out, "--force", "-j", str(jobs)]
        if not simulate:
            cmd.append("--no-sim")
        t0 = time.perf_counter()
        proc = subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT)
        wall = time.perf_counter() - t0
        per_spec, messages, last = {}, {}, None
        for line in proc.stderr.splitlines():
            m = PROGRESS.match(line.strip())
            if m:
                last = _short(m.group(3))
                per_spec[last] = (m.group(4), float(m.group(5)))
            elif line.startswith("    ") and last is not None and last not in messages and line.strip():
                messages[last] = line.strip()
        validation = {}
        for res in sorted(Path(out).glob("*/results.json")):
            try:
                data = json.loads(res.read_text(encoding="utf-8"))
            except (OSError, ValueError):
                continue
            validation[_short(data.get("source", res.parent.name))] = _stage_sim_times(data)
        summary = (proc.stderr.strip().splitlines() or [""])[-1].replace(out, "<tmpdir>")
    shown = " ".join(c if c != out else "<tmpdir>" for c in cmd[2:])
    return {"cmd": "python -m " + shown, "wall": wall, "rc": proc.returncode, "per_spec": per_spec,
            "messages": messages, "validation": validation, "summary": summary}


def _short(path: str) -> str:
    try:
        return str(Path(path).resolve().relative_to(ROOT))
    except ValueError:
        return path


def _stage_sim_times(data: dict) -> list[tuple[str, float]]:
    """(stage, seconds) from results.json's validation entries, when present: the top-level
    ``validation`` mapping (stage name -> entry) or a ``validation`` entry inside each stage.

    The entry's layout is not fixed yet: take the first numeric key that names a run time."""
    entries = []
    top = data.get("validation")
    if isinstance(top, dict):
        entries += [(name, v) for name, v in top.items() if isinstance(v, dict)]
    for st in data.get("stages", []):
        if isinstance(st.get("validation"), dict):
            entries.append((st.get("name", "?"), st["validation"]))
    out, seen = [], set()
    for name, v in entries:
        sec = _run_time(v)
        if sec is not None and name not in seen:
            seen.add(name)
            out.append((name, sec))
    return out


def _run_time(entry: dict, depth: int = 0) -> float | None:
    for key, val in entry.items():
        k = key.lower()
        if isinstance(val, (int, float)) and not isinstance(val, bool) and (
            "wall" in k or "run_time" in k or "runtime" in k or k.endswith("seconds") or k == "time_s"
        ):
            return float(val)
    if depth < 1:
        for val in entry.values():
            if isinstance(val, dict):
                sec = _run_time(val, depth + 1)
                if sec is not None:
                    return sec
    return None


def bench_builds(specs: Path, quick: bool, jobs: int) -> dict:
    print(f"\n== 1. balpipe build ({specs}, -j {jobs}) ==")
    runs = {"no-sim": run_build(specs, simulate=False, jobs=jobs)}
    if quick:
        print("(--quick: the build with the simulation is skipped)")
    else:
        runs["sim"] = run_build(specs, simulate=True, jobs=jobs)
    for name, r in runs.items():
        print(f"{name:7s} {r['wall']:7.2f} s wall, exit {r['rc']}: {r['cmd']}")
        print(f"        {r['summary']}")
        for spec, msg in r["messages"].items():
            msg = msg[len(spec) + 2:] if msg.startswith(spec + ": ") else msg
            print(f"        {spec}: {msg[:160]}")
    names = sorted({s for r in runs.values() for s in r["per_spec"]})
    rows = []
    for s in names:
        row = [s]
        for key in ("no-sim", "sim"):
            if key not in runs:
                continue
            status, sec = runs[key]["per_spec"].get(s, ("-", None))
            row += [fmt_s(sec), status]
        if "sim" in runs:
            a = runs["no-sim"]["per_spec"].get(s, (None, None))
            b = runs["sim"]["per_spec"].get(s, (None, None))
            ok = a[0] in ("ok", "failed") and b[0] in ("ok", "failed")
            row.append(fmt_s(b[1] - a[1]) if ok else "n/a")
        rows.append(row)
    if rows:
        total = ["total (sum of specs)"]
        for key in ("no-sim", "sim"):
            if key in runs:
                total += [fmt_s(sum(v[1] for v in runs[key]["per_spec"].values())), ""]
        if "sim" in runs:
            total.append("")
        rows.append(total)
    headers = ["spec", "no-sim s", "status"]
    if "sim" in runs:
        headers += ["sim s", "status", "sim - no-sim s"]
    table(headers, rows, "Per spec (seconds from the build's progress lines; one run each):")
    return runs


def report_validation(runs: dict | None) -> None:
    print("\n== 4. pymunk validation time ==")
    direct = validation_direct(ROOT / "specs")
    if runs is None or "sim" not in runs:
        print("\nthrough the build: skipped (it needs the build with the simulation: run without --quick / --no-build)")
        return
    sim = runs["sim"]
    print("\nthrough the build: the 'sim - no-sim' column of section 1 (simulation of every stage, the "
          "reactionless demonstration and their figures)")
    if any(st not in ("ok", "failed") for st, _ in sim["per_spec"].values()):
        print("  the build with the simulation did not complete every spec (status above): n/a for those")
    stage_rows = [[src, stg, fmt_s(sec)] for src, lst in sim["validation"].items() for stg, sec in lst]
    if stage_rows:
        table(["spec", "stage", "simulation s"], stage_rows, "Per stage (from results.json's validation entries):")
    elif not direct:
        print("  per stage: results.json has no per-stage validation run time")


def validation_direct(specs: Path) -> bool:
    """Time balpipe.validate.validate (and free_floating where the spec asks for the
    reactionless demonstration) on every stage of every spec. Returns False when the module's
    API does not fit (it is still being written): the build difference is then the figure."""
    import dataclasses
    import inspect

    try:
        from balpipe import validate as V
        from balpipe import study as study_mod
        from balpipe.build import find_specs
    except Exception as exc:
        print(f"direct: balpipe.validate cannot be imported ({exc!r}); timed through the build only")
        return False
    missing = [n for n in ("validate", "ValidationSettings") if not hasattr(V, n)]
    params = list(inspect.signature(V.validate).parameters) if hasattr(V, "validate") else []
    if missing or params[:3] != ["model", "analysis", "unbalanced_peaks"]:
        print(f"direct: balpipe.validate's API is not the expected one (missing {missing}, validate{tuple(params)}); "
              "timed through the build only")
        return False
    setting_names = {f.name for f in dataclasses.fields(V.ValidationSettings)}
    rows = []
    for path in find_specs([str(specs)]):
        try:
            spec = load(path).spec
            if not spec.validation.enabled:
                rows.append([_short(str(path)), "(validation disabled)", *["-"] * 8])
                continue
            st = study_mod.run(spec)
        except Exception as exc:
            rows.append([_short(str(path)), f"(not analysed: {type(exc).__name__})", *["-"] * 8])
            continue
        # the settings the build uses (balpipe.validation_stage.settings_for)
        want = {"dt": spec.validation.dt, "iterations": spec.validation.iterations,
                "tolerance": spec.validation.tolerance}
        settings = V.ValidationSettings(**{k: v for k, v in want.items() if k in setting_names})
        reactionless = spec.validation.reactionless
        if reactionless is None:
            reactionless = spec.paper is not None
        peaks = (st.unbalanced.analysis.max_force, st.unbalanced.analysis.max_moment)
        total = 0.0
        for sr in st.stages:
            expect = tuple(w for w in ("force", "moment") if w in sr.stage.balances)
            t0 = time.perf_counter()
            try:
                v = V.validate(sr.stage.model, sr.analysis, peaks, settings, expect)
                wall = time.perf_counter() - t0
                status = "pass" if v.passed else "fail"
                steps, pym = getattr(v, "steps", "-"), getattr(v, "timing", {}).get("simulation_s")
            except Exception as exc:
                wall, status, steps, pym = time.perf_counter() - t0, f"error {type(exc).__name__}", "-", None
                v = None
            ff, stage_total = "-", wall
            if reactionless and hasattr(V, "free_floating"):
                t1 = time.perf_counter()
                try:
                    V.free_floating(sr.stage.model, sr.analysis, settings=settings)
                    ff = fmt_s(time.perf_counter() - t1)
                except Exception as exc:
                    ff = f"{time.perf_counter() - t1:.3f} ({type(exc).__name__})"
                stage_total += time.perf_counter() - t1
            tq = "-"
            try:
                from balpipe.validate.torque import torque_driven

                t2 = time.perf_counter()
                r = torque_driven(sr.stage.model, sr.analysis, settings, dt=getattr(v, "dt", None),
                                  iterations=getattr(v, "iterations", None))
                tq = f"{time.perf_counter() - t2:.3f} ({r.status}, {r.tracking_error_max:.1e})"
                stage_total += time.perf_counter() - t2
            except Exception as exc:  # the module may not exist on an older checkout
                tq = f"({type(exc).__name__})"
            total += stage_total
            rows.append([_short(str(path)), sr.stage.name, len(sr.analysis.t), steps, fmt_s(wall),
                         fmt_s(pym) if pym is not None else "-", ff, tq, fmt_s(stage_total), status])
        rows.append([_short(str(path)), "all stages", "", "", "", "", "", "", fmt_s(total), ""])
    table(["spec", "stage", "samples", "steps", "validate s", "of which pymunk s", "free-floating s",
           "torque-driven s (verdict, tracking)", "stage s", "validator says"], rows,
          "direct: balpipe.validate.validate per stage with the spec's settings (one run each; 'free-floating' = "
          "the reactionless demonstration, run for paper specs; 'torque-driven' = the inverse-dynamics run and "
          "its calibration run; 'stage s' = all):")
    return True


# ------------------------------------------------------------------------------------------
# 2. Engine throughput

# Paper 003, Sec. 3: planar 3R arm in a horizontal plane, payload 5 kg as a point mass at C.
ARM = {
    "lengths": (0.5, 0.3, 0.1),  # l_OA, l_AB, l_BC [m]
    "com": (0.289, 0.098, 0.05),  # r1, r2, r3 [m] from each link's proximal joint
    "mass": (24.4, 8.3, 2.0),  # [kg]
    "inertia": (1.246, 0.057, 0.025),  # centroidal, about the axis normal to the plane [kg m^2]
    "payload": 5.0,  # [kg] at C, the tip of link 3
}
# Joint motion (our choice; the paper plans its trajectories on the centre of mass): each joint
# on the 3-4-5 law over T = 1 s, away from the stretched singularity.
ARM_MOTION = {"q0": (0.6, 1.2, -0.4), "qf": (1.6, 0.4, 1.0), "duration": 1.0}


def arm_model() -> Model:
    L, r, m, I = ARM["lengths"], ARM["com"], ARM["mass"], ARM["inertia"]
    names = ("link1", "link2", "link3")
    bodies = []
    for k, n in enumerate(names):
        att = (Attachment("payload", ARM["payload"], (L[2], 0.0), 0.0, "payload"),) if k == 2 else ()
        bodies.append(Body(n, m[k], (r[k], 0.0), I[k], points={"p": (0.0, 0.0), "d": (L[k], 0.0)},
                           attachments=att, outline=("p", "d")))
    joints = (
        Revolute("O", FRAME, "link1", (0.0, 0.0), (0.0, 0.0)),
        Revolute("A", "link1", "link2", (L[0], 0.0), (0.0, 0.0)),
        Revolute("B", "link2", "link3", (L[1], 0.0), (0.0, 0.0)),
    )
    q0, qf, T = ARM_MOTION["q0"], ARM_MOTION["qf"], ARM_MOTION["duration"]
    drivers = tuple(
        Driver(f"q{k + 1}", ("joint", j.name), PointToPoint(q0[k], qf[k], T, quintic)) for k, j in enumerate(joints)
    )
    # initial frame poses from the forward kinematics at t = 0
    initial, x, y, th = {}, 0.0, 0.0, 0.0
    for k, n in enumerate(names):
        th += q0[k]
        initial[n] = (x, y, th)
        x, y = x + L[k] * math.cos(th), y + L[k] * math.sin(th)
    return Model("3R arm (paper 003)", tuple(bodies), joints, drivers, initial, frame_points={"O": (0.0, 0.0)})


def slider_crank_stages() -> tuple[list[tuple[str, Model]], tuple, tuple, float]:
    loaded = load(ROOT / "specs" / "scott_russell.yaml")
    spec = loaded.spec
    stages = registry.balance(spec).stages
    return ([(s.name, s.model) for s in stages], gravity_vector(spec), tuple(spec.analysis.moment_point),
            spec.motion.duration)


def slider_crank_new_geometry() -> Model:
    """The unbalanced Scott-Russell slider-crank with a crank 1 % shorter (a sweep's next design:
    built from the spec's data as ``balpipe sweep`` builds it)."""
    import yaml

    from balpipe.spec import Spec

    data = yaml.safe_load((ROOT / "specs" / "scott_russell.yaml").read_text())
    data["mechanism"]["crank"]["length"] = "0.198 m"
    return registry.unbalanced_model(Spec.model_validate(data))


def new_geometry_time(base: Model, other: Model, t: np.ndarray, grav, mpt, repeats: int,
                      warm_start: bool = True) -> float:
    """Best time of analyse() on a new geometry, as a sweep runs it: the base design's motion
    recorded as the anchor (:func:`balpipe.engine.record_anchors`), each call on a fresh copy of
    ``other`` (compiled again, its motion not known) within :func:`balpipe.engine.warm_start`.
    ``warm_start=False``: without the anchors (the sequential continuation, as before them)."""
    from balpipe.engine import fastpath

    engine.clear_cache()
    with engine.record_anchors() as anchors:
        analyse(base, t, grav, mpt)
    motions = dict(fastpath._MOTIONS)

    def call():
        fastpath._MOTIONS.clear()
        fastpath._MOTIONS.update(motions)
        anchors.solved.clear()
        analyse(dataclasses.replace(other), t, grav, mpt)

    with engine.warm_start(anchors if warm_start else None):
        return best_of(call, repeats, min_total=MIN_TOTAL)


def bench_engine(counts: list[int], repeats: int) -> dict:
    print("\n== 2. engine throughput: analyse() = compile + positions + velocities/accelerations"
          " + inverse dynamics + both shaking-load routes ==")
    stages, g, mp, T = slider_crank_stages()
    cases = [(f"slider-crank/{name}", model, g, mp, T) for name, model in stages]
    arm = arm_model()
    cases.append(("3R arm (paper 003)", arm, (0.0, 0.0), (0.0, 0.0), ARM_MOTION["duration"]))
    rows = []
    times: dict[str, dict[int, float]] = {}
    for label, model, grav, mpt, dur in cases:
        for n in counts:
            t = np.linspace(0.0, dur, n)
            analyse(model, t, grav, mpt)  # warm-up
            best = best_of(lambda: analyse(model, t, grav, mpt), repeats, min_total=MIN_TOTAL)
            rows.append([label, len(engine.compile_model(model).names), n, f"{best * 1e3:.3f}",
                         f"{best / n * 1e6:.2f}", fmt_rate(n / best)])
            times.setdefault(label, {})[n] = best
    table(["model", "bodies", "samples", "best ms", "us/sample", "samples/s"], rows,
          f"best of {repeats} repeats (time.perf_counter), Python {platform.python_version()}, numpy {np.__version__}; "
          "repeated calls on the same model and grid (compiled model, block structure and a closed loop's "
          "motion reused):")
    # fixed cost per call: 3 samples; warm (as above), cold (every cache emptied before each call),
    # and a design not seen before (a copy of the model with another mass: compiled again, the
    # structure reused, a closed loop's motion reused when its joints and drivers are the same)
    fixed = []
    for label, model, grav, mpt, dur in [cases[0], cases[-1]]:
        t = np.linspace(0.0, dur, 3)
        warm = best_of(lambda: analyse(model, t, grav, mpt), repeats, min_total=MIN_TOTAL)

        def cold():
            engine.clear_cache()
            analyse(model, t, grav, mpt)

        def new_design():
            b = model.bodies[0]
            analyse(model.replace_body(dataclasses.replace(b, mass=b.mass * 1.01)), t, grav, mpt)

        geometry = ["-"] * 5
        if label.startswith("slider-crank"):
            # as a sweep analyses a design (its canonical model: centres of mass at the frames'
            # origins, the base's motion recorded on the same), at 3 and 100 samples, then the
            # model as built (its motion solved on its frame model, compiled once more)
            from balpipe.sweep import canonical

            other = slider_crank_new_geometry()
            t3, t100 = np.linspace(0.0, dur, 3), np.linspace(0.0, dur, 100)
            geometry = [f"{new_geometry_time(*pair, tt, grav, mpt, repeats, w) * 1e3:.3f}" for pair, tt, w in (
                ((canonical(model), canonical(other)), t3, True), ((canonical(model), canonical(other)), t3, False),
                ((canonical(model), canonical(other)), t100, True), ((canonical(model), canonical(other)), t100, False),
                ((model, other), t3, True))]
        t100 = np.linspace(0.0, dur, 100)

        def cold100():  # a closed loop's first call follows 17 coarse samples when N >= 17
            engine.clear_cache()
            analyse(model, t100, grav, mpt)

        fixed.append([label, f"{warm * 1e3:.3f}", f"{best_of(new_design, repeats, min_total=MIN_TOTAL) * 1e3:.3f}",
                      *geometry, f"{best_of(cold, repeats, min_total=MIN_TOTAL) * 1e3:.3f}",
                      f"{best_of(cold100, repeats, min_total=MIN_TOTAL) * 1e3:.3f}"])
        times.setdefault(label, {})[3] = warm
    table(["model", "same model ms", "new mass design ms", "new geometry ms", "(continuation)",
           "new geometry 100 samples ms", "(continuation)", "new geometry as built ms", "cold ms",
           "cold ms, 100 samples"], fixed,
          "fixed cost per analyse() call (3 samples unless said, best of repeats): the same model again; a new "
          "model differing in one mass; a new geometry (the crank 1 % shorter) as a sweep analyses it (its "
          "canonical model, started from the spec's design's motion recorded as an anchor; in brackets the "
          "sequential continuation it replaces), and the model as built (centres of mass off the frames' "
          "origins: its motion is solved on its frame model, compiled once more); cold (engine.clear_cache() "
          "before each call), also at 100 samples:")
    return times


# ------------------------------------------------------------------------------------------
# 3. Pinocchio


def pinocchio_arm(pin):
    L, r, m, I = ARM["lengths"], ARM["com"], ARM["mass"], ARM["inertia"]
    model = pin.Model()
    model.gravity = pin.Motion.Zero()  # horizontal plane
    parent, offset = 0, 0.0
    for k in range(3):
        placement = pin.SE3(np.eye(3), np.array([offset, 0.0, 0.0]))
        jid = model.addJoint(parent, pin.JointModelRZ(), placement, f"q{k + 1}")
        inertia = pin.Inertia(m[k], np.array([r[k], 0.0, 0.0]), np.diag([1e-6, 1e-6, I[k]]))
        model.appendBodyToJoint(jid, inertia, pin.SE3.Identity())
        if k == 2:
            payload = pin.Inertia(ARM["payload"], np.array([L[2], 0.0, 0.0]), np.zeros((3, 3)))
            model.appendBodyToJoint(jid, payload, pin.SE3.Identity())
        parent, offset = jid, L[k]
    return model


def joint_samples(an) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Joint angles, rates and accelerations (N, 3) from balpipe's absolute body angles."""
    def rel(x):
        th = x[:, :, 2]
        return np.stack([th[:, 0], th[:, 1] - th[:, 0], th[:, 2] - th[:, 1]], axis=1)

    return rel(an.q), rel(an.v), rel(an.a)


def bench_pinocchio(counts: list[int], repeats: int, times: dict) -> None:
    print("\n== 3. Pinocchio RNEA on the same 3R samples ==")
    try:
        import pinocchio as pin
    except ImportError:
        print("skipped: pinocchio is not installed (install it with `pip install pin`)")
        return
    pmodel = pinocchio_arm(pin)
    pdata = pmodel.createData()
    arm = arm_model()
    threads = os.cpu_count() or 1
    pool = pin.ModelPool(pmodel, threads) if hasattr(pin, "rneaInParallel") else None
    arm_times = times["3R arm (paper 003)"]
    crank = next(k for k in times if k.startswith("slider-crank/"))
    rows, agree, ratios = [], [], []
    for n in counts:
        t = np.linspace(0.0, ARM_MOTION["duration"], n)
        an = analyse(arm, t)
        q, v, a = joint_samples(an)
        tau_bal = np.stack([an.efforts[f"q{k + 1}"] for k in range(3)], axis=1)
        # check on every sample
        tau_pin = np.stack([pin.rnea(pmodel, pdata, q[k], v[k], a[k]).copy() for k in range(n)])
        peak = np.abs(tau_pin).max(axis=0)
        agree.append([n, *[f"{e:.2e}" for e in (np.abs(tau_bal - tau_pin).max(axis=0) / peak)],
                      *[f"{p:.1f}" for p in peak]])

        def loop():
            for k in range(n):
                pin.rnea(pmodel, pdata, q[k], v[k], a[k])

        best_loop = best_of(loop, repeats, min_total=MIN_TOTAL)
        row = [n, f"{best_loop * 1e3:.3f}", fmt_rate(n / best_loop)]
        if pool is not None:
            qT, vT, aT = (np.asfortranarray(x.T) for x in (q, v, a))
            tau = np.zeros((3, n), order="F")
            best_par = best_of(lambda: pin.rneaInParallel(threads, pool, qT, vT, aT, tau), repeats, min_total=MIN_TOTAL)
            row += [f"{best_par * 1e3:.3f}", fmt_rate(n / best_par)]
        bal = arm_times.get(n)
        row += [fmt_rate(n / bal) if bal else "-",
                f"{best_loop / bal:.3g}" if bal else "-"]
        if pool is not None:
            row.append(f"{best_par / bal:.3g}" if bal else "-")
        rows.append(row)
        sc = times[crank].get(n)
        ratios.append([n, fmt_rate(n / best_loop), fmt_rate(n / bal), f"{best_loop / bal:.3g}",
                       fmt_rate(n / sc) if sc else "-", f"{best_loop / sc:.3g}" if sc else "-"])
    table(["samples", "max rel diff q1", "q2", "q3", "peak |tau1| N m", "|tau2|", "|tau3|"], agree,
          "Joint torques: balpipe driver efforts vs pinocchio.rnea (max |difference| / peak |tau|, per joint):")
    headers = ["samples", "rnea loop ms", "samples/s"]
    if pool is not None:
        headers += [f"rneaInParallel({threads}) ms", "samples/s"]
    headers += ["balpipe samples/s", "ratio balpipe/pin (loop)"]
    if pool is not None:
        headers.append("ratio balpipe/pin (batch)")
    table(headers, rows, f"pinocchio {pin.__version__}: rnea called once per sample from Python, and the batched "
          f"rneaInParallel; ratio = balpipe throughput / Pinocchio throughput (below 1: Pinocchio is faster; "
          f"balpipe also solves the kinematics and both shaking-load routes, RNEA only the joint torques):")
    table(["samples", "pin rnea loop samples/s", "balpipe 3R arm", "ratio", f"balpipe {crank}", "ratio"], ratios,
          "Summary: balpipe analyse() throughput relative to Pinocchio's rnea called per sample on the 3R arm, "
          "same run (targets of issue 13 on the arm: >= 0.1 at 10^2, >= 0.5 at 10^4; the slider-crank, a "
          "closed loop, is given against the same anchor):")


# ------------------------------------------------------------------------------------------


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--quick", action="store_true", help="small sample counts, no simulated build (~30 s)")
    p.add_argument("--specs", default=str(ROOT / "specs"), help="folder of specs to build (default: specs/)")
    p.add_argument("-j", "--jobs", type=int, default=1, help="balpipe build -j (default 1)")
    p.add_argument("--no-build", action="store_true", help="skip the builds (sections 1 and 4)")
    args = p.parse_args(argv)
    counts = [100, 1000] if args.quick else [100, 1000, 10000]
    repeats = 3 if args.quick else 5
    global MIN_TOTAL
    MIN_TOTAL = 0.3 if args.quick else 1.0
    print(f"balpipe benchmarks: {platform.platform()}, {os.cpu_count()} CPUs, Python {platform.python_version()}")
    start = time.perf_counter()
    runs = None if args.no_build else bench_builds(Path(args.specs), args.quick, args.jobs)
    times = bench_engine(counts, repeats)
    bench_pinocchio(counts, repeats, times)
    report_validation(runs)
    print(f"\n(benchmarks took {time.perf_counter() - start:.1f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
