"""balpipe's public Python API: load a spec, run it, read its results.

    import balpipe
    spec = balpipe.load("specs/offset_slider_crank.yaml")
    study = balpipe.run(spec.with_values({"mechanism.slider.mass": "0.8 kg"}))
    print(study.verdict["text"], study.results()["stages"][-1]["max_shaking_force"])
    study.write("out/slider_crank")

The names of ``__all__`` are balpipe's stable API (docs/api.md states the policy); they are
also reachable as ``balpipe.<name>``, loaded on first use so that ``import balpipe`` stays cheap.
This layer sits beside the build (``balpipe build`` and ``run`` compute their studies with the
same functions, ``balpipe.build.study_of`` and ``balpipe.build.page_files``)."""

from __future__ import annotations

from .errors import SpecError
from .spec import Spec, load, loads
from .study import Stage, Study, run

__all__ = ["Spec", "SpecError", "Stage", "Study", "load", "loads", "run"]
