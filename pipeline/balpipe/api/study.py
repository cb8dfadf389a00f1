"""A study in Python: ``run`` balances and analyses a ``balpipe.api.spec.Spec`` through
the engine that ``balpipe build`` runs (``balpipe.build.study_of``: ``balpipe.runner``),
and the ``Study`` it returns gives what the page holds: ``results.json`` as a dict, the
time series, the page's figures and the page itself."""

from __future__ import annotations

import copy
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .. import loader
from ..spec_parts import SpecFieldError
from .errors import SpecError
from .spec import Spec


@dataclass(frozen=True)
class Stage:
    """One balancing stage of a study (the unbalanced mechanism first).

    Attributes:
        name: short name (the CSV columns' prefix; ``design:stage`` for a ``compare`` design).
        label: the label of the page's figures and tables.
        metrics: the stage's entry of ``results.json``'s ``stages`` (peaks, ratios, whether it is
            force and moment balanced, added mass and inertia, ...; docs/site.md lists them).
        model: the stage's mechanism, a ``balpipe.model.Model`` (bodies, joints, drivers).
        analysis: the engine's analysis of the stage's motion (``balpipe.engine.Analysis``:
            ``t``, ``force``, ``moment``, ``efforts``, ``reactions``)."""

    name: str
    label: str
    metrics: dict
    model: Any
    analysis: Any


class Study:
    """A balanced and analysed spec, as its page shows it. Made by ``balpipe.run``."""

    def __init__(self, spec: Spec, study: Any, input_hash: str):
        self.spec = spec
        self._study = study
        self._input_hash = input_hash
        self._results: dict | None = None

    @property
    def engine_study(self):
        """The pipeline's own study (``balpipe.study.Study``), for what the API does not
        give; its fields may change between versions."""
        return self._study

    @property
    def stages(self) -> tuple[Stage, ...]:
        """Every stage, the unbalanced mechanism first, in the page's order."""
        metrics = self._results_view()["stages"]
        return tuple(Stage(s.stage.name, s.stage.label, copy.deepcopy(m), s.stage.model, s.analysis)
                     for s, m in zip(self._study.stages, metrics))

    @property
    def verdict(self) -> dict:
        """The page's verdict (``results.json``'s ``verdict``): ``text``, ``words``, ``level``,
        the force and moment outcomes and each stage's (docs/site.md)."""
        return copy.deepcopy(self._results_view()["verdict"])

    @property
    def ok(self) -> bool:
        """Whether every check passed (``results.json``'s ``status`` is ``ok``)."""
        return self._study.ok

    @property
    def problems(self) -> list[str]:
        """The failed checks, as the page lists them (empty when ``ok``)."""
        return list(self._study.problems)

    @property
    def simulated(self) -> bool:
        """Whether every stage was checked by the pymunk simulation (``run(..., simulate=True)``)."""
        return self._study.stages[0].validation is not None

    def _results_view(self) -> dict:
        if self._results is None:
            from ..build import page_results

            self._results = page_results(self.spec._loaded, self._study, self._input_hash)
        return self._results

    def results(self) -> dict:
        """``results.json`` as a dict: exactly what ``balpipe build`` writes for this spec (its
        ``source`` is ``Spec.source``, its ``input_hash`` that of a page folder without history).

        Returns:
            A fresh copy (changing it changes nothing here)."""
        return copy.deepcopy(self._results_view())

    def timeseries(self) -> Any:
        """The columns of ``timeseries.csv`` (t, then per stage the shaking force and moment,
        the efforts, the joint reactions, the centre of mass and the poses; SI units; full
        precision, where the CSV keeps 12 significant digits).

        Returns:
            A ``pandas.DataFrame`` when pandas is installed, else a dict of column name ->
                1-D ``numpy.ndarray``, in the CSV's order."""
        from ..report.results import timeseries_columns

        columns = {name: values.copy() for name, values in timeseries_columns(self._study)}
        try:
            import pandas as pd
        except ImportError:
            return columns
        return pd.DataFrame(columns)

    @property
    def figure_names(self) -> tuple[str, ...]:
        """The names ``figure`` draws: ``loads`` (shaking force and moment), ``efforts``
        (actuators), ``joints`` (joint loads) when the mechanism has joint loads, and
        ``mechanism`` (its drawings, a panel per stage)."""
        from ..report.page import time_curves

        return tuple(k for k, c in time_curves(self._study).items() if c.panels) + ("mechanism",)

    def figure(self, name: str) -> Any:
        """One of the page's figures, drawn with matplotlib: a time series from the very curves
        the page plots (every stage shown on the page, a panel per quantity), or the page's
        drawings of the mechanism (``mechanism``).

        Args:
            name: one of ``figure_names``.

        Returns:
            A ``matplotlib.figure.Figure`` (not shown; ``fig.savefig(...)`` or display it).

        Raises:
            KeyError: an unknown name."""
        from ..report.notation_table import names_for
        from ..report.page import time_curves
        from .figures import matplotlib_figure, mechanism_figure

        if name == "mechanism":
            return mechanism_figure(self._study, names_for(self._study.spec))
        curves = time_curves(self._study)
        if name not in curves or not curves[name].panels:
            raise KeyError(f"no figure {name!r}; figures: {', '.join(self.figure_names)}")
        return matplotlib_figure(curves[name], title=f"{self.spec.name}: {name}")

    def write(self, folder: str | Path) -> Path:
        """Write the study's page into ``folder`` (created if needed): ``index.html``,
        ``results.json``, ``timeseries.csv`` (and ``timing.json`` after a simulation), the
        files ``balpipe build`` writes into the spec's page folder, the folder replaced whole.

        Returns:
            The path of ``index.html``."""
        from ..build import page_files
        from ..runtime.fsutil import write_atomic_dir

        target = Path(folder)
        target.parent.mkdir(parents=True, exist_ok=True)
        try:
            files = page_files(self.spec._loaded, self._study, self._results_view())
        except SpecFieldError as exc:
            raise SpecError.of(self.spec._loaded.error(exc)) from None
        write_atomic_dir(target, files)
        return target / "index.html"

    def _repr_html_(self) -> str:
        from .notebook import study_html

        return study_html(self)

    def __repr__(self) -> str:
        return (f"<balpipe.Study {self.spec.name!r}: {len(self._study.stages)} stages, "
                f"{self._results_view()['verdict']['text']}>")


def run(spec: Spec, simulate: bool = False, workers: int = 1) -> Study:
    """Balance and analyse a spec: every stage of its method (and of its ``compare`` designs), the
    checks, and with ``simulate`` the pymunk validation of every stage, as ``balpipe build``
    computes them (the same code: ``balpipe.build.study_of``). Runs on one BLAS thread
    whatever was imported first (``balpipe.runtime.threads``).

    Args:
        spec: a ``Spec`` (``balpipe.load``).
        simulate: also run the pymunk validation (slower: seconds to a minute a spec); off by
            default, as ``balpipe build --no-sim``.
        workers: processes for the stages' simulations (the same results for any number).

    Returns:
        The ``Study``.

    Raises:
        SpecError: a problem found while balancing or analysing (a motion the mechanism cannot
            follow, a reference that nothing computes), located in the spec."""
    from ..build import input_hash, study_of, Options
    from ..laws.drives import table_texts

    if not isinstance(spec, Spec):
        raise TypeError(f"run() takes a balpipe.Spec (balpipe.load(...)), not {type(spec).__name__}")
    loaded = spec._loaded
    try:
        st = study_of(loaded, simulate, workers)
    except loader.SpecErrors as exc:
        raise SpecError.of(exc) from None
    except SpecFieldError as exc:
        raise SpecError.of(loaded.error(exc)) from None
    h = input_hash(loaded.text + table_texts(loaded.spec), Options(out=Path("."), simulate=simulate))
    return Study(spec, st, h)
