"""A parameter study of a machine of one's own through balpipe's Python API (docs/api.md).

A crank-rocker four-bar built in Python, part by part (balpipe.families.custom.builders), force
balanced by counterweights of least added mass; then the coupler's mass varied with
``Spec.with_values`` and, for each design, the peak shaking force and moment before and after
balancing and the counterweights' added mass, printed as a table and plotted.

    python docs/examples/parameter_study.py [OUTPUT_FOLDER]

writes ``parameter_study.png`` and ``parameter_study.csv`` into OUTPUT_FOLDER (default: the
working folder). The tests run it (tests/test_docs_site.py).
"""

from __future__ import annotations

import csv
import sys
from pathlib import Path

import balpipe
from balpipe.families.custom import builders as b


def my_mechanism():
    """The machine: crank 80 mm, coupler 280 mm, rocker 220 mm, pivots 300 mm apart, uniform
    bars (the four-bar of specs/custom_four_bar_balancing.yaml)."""
    return b.mechanism(
        frame_points={"O2": (0, 0), "O4": ("300 mm", 0)},
        bodies=[
            b.body("crank", "0.4 kg", com=(0.04, 0), inertia="0.000213 kg m^2", pose=(0, 0, 0),
                   points={"O2": (0, 0), "A": (0.08, 0)}),
            b.body("coupler", "1.2 kg", com=(0.14, 0), inertia="0.00784 kg m^2", pose=(0.08, 0, 1.2),
                   points={"A": (0, 0), "B": (0.28, 0)}),
            b.body("rocker", "0.9 kg", com=(0.11, 0), inertia="0.00363 kg m^2", pose=(0.30, 0, 1.8),
                   points={"O4": (0, 0), "B": (0.22, 0)}),
        ],
        joints=[b.revolute("O2", "frame", "crank", "O2", "O2"), b.revolute("A", "crank", "coupler", "A", "A"),
                b.revolute("B", "coupler", "rocker", "B", "B"), b.revolute("O4", "frame", "rocker", "O4", "O4")],
        drivers=[b.driver("crank", joint="O2")],
    )


def my_four_bar() -> balpipe.Spec:
    """The machine force balanced, the crank turning once in 0.5 s on the 3-4-5 law."""
    method = b.force_balance([
        b.counterweight("crank", segment=((0, 0), (-0.08, 0))),       # behind the crank's pivot
        b.counterweight("coupler", disc=((0.14, 0), 0.25)),           # anywhere near the coupler
        b.counterweight("rocker", segment=((0, 0), (-0.12, 0))),      # behind the rocker's pivot
    ])
    motion = {"law": "quintic", "duration": "0.5 s", "drive": {"crank": {"from": "0 deg", "to": "360 deg"}}}
    return balpipe.Spec.from_parts("My four-bar", my_mechanism(), motion, method, analysis={"samples": 201})


def study(spec: balpipe.Spec, masses: list[float]) -> list[dict]:
    """One row per coupler mass (kg): the peaks of the unbalanced and the balanced stage."""
    rows = []
    for m in masses:
        st = balpipe.run(spec.with_values({"mechanism.bodies.1.mass": m}))
        unbalanced, balanced = st.stages[0].metrics, st.stages[-1].metrics
        rows.append({"coupler_mass_kg": m,
                     "unbalanced_force_N": unbalanced["max_shaking_force"],
                     "unbalanced_moment_Nm": unbalanced["max_shaking_moment"],
                     "balanced_force_N": balanced["max_shaking_force"],
                     "balanced_moment_Nm": balanced["max_shaking_moment"],
                     "added_mass_kg": balanced["added_mass"]})
    return rows


def plot(rows: list[dict], path: Path) -> None:
    from matplotlib.figure import Figure

    m = [r["coupler_mass_kg"] for r in rows]
    fig = Figure(figsize=(7, 4.5), layout="constrained")
    ax1, ax2 = fig.subplots(2, 1, sharex=True)
    ax1.plot(m, [r["unbalanced_moment_Nm"] for r in rows], "o-", label="shaking moment, unbalanced")
    ax1.plot(m, [r["balanced_moment_Nm"] for r in rows], "s--", label="shaking moment, force balanced")
    ax1.set_ylabel("peak moment (N m)")
    ax1.legend(fontsize=8)
    ax2.plot(m, [r["added_mass_kg"] for r in rows], "o-", color="tab:red")
    ax2.set_ylabel("counterweights (kg)")
    ax2.set_xlabel("coupler mass (kg)")
    fig.suptitle("My four-bar: what the coupler's mass costs")
    fig.savefig(path, dpi=100)


def main(out: Path) -> list[dict]:
    out.mkdir(parents=True, exist_ok=True)
    rows = study(my_four_bar(), [0.6, 0.9, 1.2, 1.5, 1.8])
    with open(out / "parameter_study.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    plot(rows, out / "parameter_study.png")
    for r in rows:
        print(f"coupler {r['coupler_mass_kg']:.1f} kg: force {r['unbalanced_force_N']:7.2f} -> {r['balanced_force_N']:.1e} N, "
              f"moment {r['unbalanced_moment_Nm']:6.3f} -> {r['balanced_moment_Nm']:6.3f} N m, "
              f"counterweights {r['added_mass_kg']:.3f} kg")
    return rows


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path("."))
