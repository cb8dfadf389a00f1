"""A ladder of N four-bar loops in series, written as a ``custom`` spec: a test machine of any size.

Body ``b0`` (the crank) turns once about frame point ``O0``; loop k (1..N) is a four-bar whose
input is body ``b{k-1}`` (its point ``A``), whose coupler is ``c{k}`` and whose output is body
``b{k}``, pivoted on the frame at ``O{k}`` and carrying point ``A`` (behind its pivot) for the
next loop. 2 N + 1 bodies, 3 N + 1 revolute joints, one degree of freedom. The first loop is a
Grashof crank-rocker (its rocker swings between 94 and 138 deg); every further loop is a
parallelogram (input arm = rocker, coupler = ground) driven by that swing, far from its
change point, so that velocities pass along the whole ladder undiminished (loops that each
reduced them, as a chain of crank-rockers does, would leave the far bodies' momentum below
round-off). The initial pose is assembled here exactly.

Balancing: ``force_balance`` with a disc region for a counterweight on every body (the least
added mass that cancels the shaking force). ``seed`` > 0 draws each loop's lengths (+-5 %),
each body's mass, centre of mass (off its axis too) and inertia at random (a "random ladder");
seed 0 gives the regular ladder.

    python benchmarks/ladder.py 40 -o /tmp/ladder40.yaml            # 81 bodies
    python benchmarks/ladder.py 10 --seed 3 -o /tmp/ladder10.yaml   # a random ladder
"""

from __future__ import annotations

import argparse
import math
import random
import sys
from pathlib import Path

A, B, C, D = 0.08, 0.28, 0.22, 0.30  # first loop: crank, coupler, rocker, ground (m), a crank-rocker
P, G = 0.15, 0.30  # further loops: input arm = rocker, coupler = ground (m), a parallelogram


def _fmt(x: float) -> str:
    return repr(round(float(x), 12))


def _pt(p: tuple[float, float]) -> str:
    return f"[{_fmt(p[0])}, {_fmt(p[1])}]"


def ladder_spec(loops: int, seed: int = 0, samples: int = 201, duration: float = 0.5) -> str:
    """The YAML text of a ladder of ``loops`` four-bar loops (see the module's docstring)."""
    if loops < 1:
        raise ValueError("a ladder has at least one loop")
    rnd = random.Random(seed)
    jit = (lambda: 1.0 + rnd.uniform(-0.05, 0.05)) if seed else (lambda: 1.0)
    bodies: list[str] = []
    joints: list[str] = []
    frame_points = {"O0": (0.0, 0.0)}

    def body(name: str, length: float, points: dict[str, tuple[float, float]], pose, mass_per_m: float) -> None:
        m = mass_per_m * length * (rnd.uniform(0.7, 1.3) if seed else 1.0)
        com = (0.5 * length * (rnd.uniform(0.6, 1.4) if seed else 1.0), rnd.uniform(-0.05, 0.05) * length if seed else 0.0)
        inertia = m * length * length / 12.0 * (rnd.uniform(0.8, 1.2) if seed else 1.0)
        pts = ", ".join(f"{k}: {_pt(v)}" for k, v in points.items())
        bodies.append(f"    - {{name: {name}, mass: {_fmt(m)} kg, com: {_pt(com)}, inertia: {_fmt(inertia)} kg m^2, "
                      f"pose: [{_fmt(pose[0])}, {_fmt(pose[1])}, {_fmt(pose[2])}], points: {{{pts}}}}}")

    a = A * jit()
    body("b0", a, {"O0": (0.0, 0.0), "A": (a, 0.0)}, (0.0, 0.0, 0.0), 5.0)
    joints.append("    - {type: revolute, name: J0, a: frame, b: b0, point_a: O0, point_b: O0}")
    pivot, th_in, x_pivot = (0.0, 0.0), 0.0, 0.0  # the input's pivot, the angle of its arm to A
    for k in range(1, loops + 1):
        if k == 1:
            b, c, d = B * jit(), C * jit(), D * jit()
        else:
            b, c, d = G * jit(), P * jit(), G * jit()
        x_pivot += d
        ok = (x_pivot, 0.0)
        frame_points[f"O{k}"] = ok
        ax, ay = pivot[0] + a * math.cos(th_in), pivot[1] + a * math.sin(th_in)
        # B: circle (A, b) meets circle (O_k, c); the first loop takes the upper point, the
        # others the one whose rocker is nearest parallel to the input arm (the parallelogram)
        dx, dy = ok[0] - ax, ok[1] - ay
        dist = math.hypot(dx, dy)
        along = (b * b - c * c + dist * dist) / (2 * dist)
        h = math.sqrt(max(b * b - along * along, 0.0))
        both = [(ax + along * dx / dist + s * h * dy / dist, ay + along * dy / dist - s * h * dx / dist) for s in (1, -1)]
        if k == 1:
            bx, by = max(both, key=lambda q: q[1])
        else:
            bx, by = min(both, key=lambda q: abs(math.remainder(math.atan2(q[1] - ok[1], q[0] - ok[0]) - th_in, 2 * math.pi)))
        th_c = math.atan2(by - ay, bx - ax)
        th_r = math.atan2(by - ok[1], bx - ok[0])
        body(f"c{k}", b, {"A": (0.0, 0.0), "B": (b, 0.0)}, (ax, ay, th_c), 3.0)
        # the rocker: B at distance c; the next loop's input point A at distance P, behind the pivot
        a = (P * jit()) if k < loops else P
        body(f"b{k}", c, {f"O{k}": (0.0, 0.0), "B": (c, 0.0), "A": (-a, 0.0)}, (ok[0], ok[1], th_r), 4.0)
        prev = f"b{k - 1}"
        joints.append(f"    - {{type: revolute, name: A{k}, a: {prev}, b: c{k}, point_a: A, point_b: A}}")
        joints.append(f"    - {{type: revolute, name: B{k}, a: c{k}, b: b{k}, point_a: B, point_b: B}}")
        joints.append(f"    - {{type: revolute, name: O{k}, a: frame, b: b{k}, point_a: O{k}, point_b: O{k}}}")
        pivot, th_in = ok, th_r + math.pi
    names = ["b0"] + [n for k in range(1, loops + 1) for n in (f"c{k}", f"b{k}")]
    cws = "\n".join(f"    - {{body: {n}, name: cw_{n}, disc: {{centre: [0, 0], radius: 0.3}}}}" for n in names)
    fps = ", ".join(f"{k}: {_pt(v)}" for k, v in frame_points.items())
    return "\n".join([
        f"name: Ladder of {loops} four-bar loops{f' (random, seed {seed})' if seed else ''}",
        "description: >",
        f"  A benchmark machine (benchmarks/ladder.py): {loops} crank-rocker loops in series, "
        f"{2 * loops + 1} bodies, one degree of freedom, force balanced by least-mass counterweights.",
        "mechanism:",
        "  template: custom",
        f"  frame_points: {{{fps}}}",
        "  bodies:",
        *bodies,
        "  joints:",
        *joints,
        "  drivers:",
        "    - {name: crank, joint: J0}",
        "motion:",
        "  law: quintic",
        f"  duration: {_fmt(duration)} s",
        "  drive:",
        "    crank: {from: 0 deg, to: 360 deg}",
        "balancing:",
        "  method: force_balance",
        "  counterweights:",
        cws,
        "analysis:",
        f"  samples: {samples}",
        "",
    ])


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("loops", type=int, help="number of four-bar loops (2 N + 1 bodies)")
    ap.add_argument("--seed", type=int, default=0, help="0: the regular ladder; else random lengths and masses")
    ap.add_argument("--samples", type=int, default=201, help="analysis samples of the motion")
    ap.add_argument("-o", "--output", help="file to write (default: standard output)")
    args = ap.parse_args(argv)
    text = ladder_spec(args.loops, args.seed, args.samples)
    if args.output:
        Path(args.output).write_text(text)
    else:
        sys.stdout.write(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
