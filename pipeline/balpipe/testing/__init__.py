"""Conformance checks for mechanism families, importable by any package that ships one (as
scikit-learn's ``check_estimator``): balpipe's own families run them in its suite, and so can a
family of one's own.

    from balpipe.testing import check_family
    check_family(FAMILY)                       # every check; raises FamilyCheckError listing failures

    import pytest
    from balpipe.testing import family_cases

    @pytest.mark.parametrize("check", family_cases(FAMILY))
    def test_my_family(check):                 # one test per check, named for it
        check()

The checks (:func:`family_checks`): the family is found by balpipe and complete
(:mod:`.conformance`: templates and methods with labels, notation, spec literals; the examples
use every template and method; each example builds a consistent model), and each example,
balanced and analysed, obeys the physics (:mod:`.physics`: a stage that claims a balance meets
its tolerance; the frame's reactions equal the momentum rates; all masses times k scale the
loads by k). The examples are :attr:`balpipe.plugins.Family.examples` (spec files shipped with
the family's package, or spec texts) unless given: no check reads balpipe's ``specs/``.

The family must be installed (found by :func:`balpipe.plugins.discover`) before balpipe builds
its spec schema, as for any use of it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, Sequence

from .. import plugins
from ..study import run
from . import conformance, physics
from .conformance import ConformanceError, Example, example_name, load_example
from .physics import PhysicsError

__all__ = ["Check", "FamilyCheckError", "ConformanceError", "PhysicsError", "family_checks", "check_family",
           "family_cases", "check_example_physics"]


class FamilyCheckError(AssertionError):
    """Some checks of a family failed: one line per failed check, with its name."""


@dataclass(frozen=True)
class Check:
    """One conformance check, named ``what[subject]``; calling it runs it (raising an
    AssertionError that says what is wrong)."""

    name: str
    run: Callable[[], None]

    def __call__(self) -> None:
        self.run()


def check_example_physics(example: Example) -> None:
    """Balance and analyse the example (:func:`balpipe.study.run`, no page), then check every
    stage's model (:func:`.conformance.check_model`, drivers included) and run every
    :data:`.physics.STAGE_CHECKS` on it."""
    study = run(load_example(example).spec, page=False)
    for sr in study.stages:
        conformance.check_model(sr.stage.model, f"example {example_name(example)!r}, stage {sr.stage.name!r}")
        for check in physics.STAGE_CHECKS:
            check(sr)


def _bind(fn: Callable[..., None], *args: Any) -> Callable[[], None]:
    return lambda: fn(*args)


def family_checks(family: plugins.Family, examples: Sequence[Example] | None = None) -> list[Check]:
    """Every check of ``family`` on ``examples`` (default: ``family.examples``), in order: found
    by balpipe, each template and method complete, the examples cover the family, each example's
    model consistent and its physics sound."""
    ex = tuple(family.examples if examples is None else examples)
    checks = [Check(f"discovered[{family.name}]", _bind(conformance.check_discovered, family))]
    checks += [Check(f"template[{t.name}]", _bind(conformance.check_template, t)) for t in family.templates]
    checks += [Check(f"method[{m.name}]", _bind(conformance.check_method, m)) for m in family.methods]
    checks.append(Check(f"examples_cover[{family.name}]", _bind(conformance.check_examples_cover, family, ex)))
    for e in ex:
        name = example_name(e)
        checks.append(Check(f"example_model[{name}]", _bind(conformance.check_example_model, family, e)))
        checks.append(Check(f"example_physics[{name}]", _bind(check_example_physics, e)))
    return checks


def check_family(family: plugins.Family, examples: Sequence[Example] | None = None) -> None:
    """Run every check of :func:`family_checks`; raise :class:`FamilyCheckError` naming each
    that failed and why (all are run, one failure does not hide the next)."""
    failed = []
    for check in family_checks(family, examples):
        try:
            check()
        except Exception as exc:  # every failure reported, not the first only
            failed.append(f"{check.name}: {type(exc).__name__}: {exc}")
    if failed:
        raise FamilyCheckError(f"family {family.name!r} fails {len(failed)} check(s):\n" + "\n".join(failed))


def family_cases(family: plugins.Family, examples: Sequence[Example] | None = None) -> list[Any]:
    """The checks of :func:`family_checks` as ``pytest.param`` objects with their names as ids,
    for ``@pytest.mark.parametrize("check", family_cases(FAMILY))`` (imports pytest)."""
    import pytest

    return [pytest.param(c, id=c.name) for c in family_checks(family, examples)]
