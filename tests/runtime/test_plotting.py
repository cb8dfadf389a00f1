"""Issue 43: the command line's processes import matplotlib without the property docstrings it
writes for ``help()`` (``balpipe.runtime.plotting``): the build's workers each saved 0.12 s of
CPU. Python code that imports balpipe keeps matplotlib's docstrings, and the figures are the
same bytes either way."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

#: a figure with lines, markers, a legend, texts and patches, as SVG, and the docstring of Line2D.set
FIGURE = """
import json, sys
if sys.argv[1] == "lean":
    from balpipe.runtime.plotting import lean_docstrings
    lean_docstrings()
from balpipe.draw.figures import plt, to_svg
fig, ax = plt.subplots(figsize=(4, 3))
ax.plot([0, 1, 2], [0, 1, 4], "o--", label="a curve")
ax.bar([0.5, 1.5], [2, 3], label="bars")
ax.annotate("peak", (2, 4), (1, 3.5), arrowprops={"arrowstyle": "->"})
ax.set_xlabel("t (s)"); ax.set_title("title"); ax.legend()
import matplotlib.lines
print(json.dumps({"svg": to_svg(fig, "f"), "doc": matplotlib.lines.Line2D.set.__doc__}))
"""


def _figure(mode: str) -> dict:
    out = subprocess.run([sys.executable, "-c", FIGURE, mode], capture_output=True, text=True, check=True, cwd=ROOT)
    return json.loads(out.stdout)


def test_lean_docstrings_leave_the_figure_the_same_bytes_and_only_the_docstrings_shorter():
    lean, full = _figure("lean"), _figure("full")
    assert lean["svg"] == full["svg"] and "<svg" in lean["svg"]
    assert "antialiased" in full["doc"]  # matplotlib's listing of Line2D's properties
    assert "antialiased" not in lean["doc"]


def test_the_command_line_asks_for_them_and_python_code_does_not(tmp_path):
    spec = ROOT / "specs" / "offset_slider_crank.yaml"
    script = f"""
import sys
from balpipe.cli import main
if sys.argv[1] == "cli":
    main(["build", {str(spec)!r}, "-o", {str(tmp_path / 'out')!r}, "--no-sim", "-j", "1", "-q"])
else:
    from balpipe.api.spec import load
    from balpipe.api.study import run
    from balpipe.draw import figures
    run(load({str(spec)!r}))
import matplotlib.lines
print(len(matplotlib.lines.Line2D.set.__doc__), "antialiased" in matplotlib.lines.Line2D.set.__doc__)
"""
    for mode, listed in (("cli", "False"), ("api", "True")):
        out = subprocess.run([sys.executable, "-c", script, mode], capture_output=True, text=True, check=True, cwd=ROOT)
        assert out.stdout.split()[-1] == listed, (mode, out.stdout, out.stderr[-2000:])
