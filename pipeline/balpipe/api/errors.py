"""The API's one exception for a bad spec: ``SpecError``, every problem located."""

from __future__ import annotations

from ..loader import SpecError as Problem, SpecErrors


class SpecError(SpecErrors):
    """A spec that balpipe refuses, with every problem located as the command line prints it
    (``file:line:column: field: what is wrong``).

    Attributes:
        problems: every problem, each with ``file``, ``line``, ``column`` (1-based, None where
            the problem has no place in the text), ``path`` (the field, dotted: ``mechanism.crank.mass``)
            and ``message``.
        file, line, column, field, message: those of the first problem.

    ``str(error)`` is the command line's message, one problem per line. It is also a
    ``ValueError``-like ``Exception`` subclass of the loader's ``SpecErrors``, so code that
    caught that keeps working."""

    def __init__(self, problems: list[Problem]):
        super().__init__(list(problems))
        self.problems: list[Problem] = list(problems)

    @classmethod
    def of(cls, exc: SpecErrors) -> "SpecError":
        """The public exception carrying the problems of the loader's ``exc``."""
        return exc if isinstance(exc, cls) else cls(exc.errors)

    def _first(self) -> Problem | None:
        return self.problems[0] if self.problems else None

    @property
    def file(self) -> str | None:
        """The file of the first problem (``<text>`` for a spec given as text)."""
        first = self._first()
        return first.file if first else None

    @property
    def line(self) -> int | None:
        """The line of the first problem (1-based), or None."""
        first = self._first()
        return first.line if first else None

    @property
    def column(self) -> int | None:
        """The column of the first problem (1-based), or None."""
        first = self._first()
        return first.column if first else None

    @property
    def field(self) -> str:
        """The field of the first problem, dotted (``mechanism.bodies[0].mass``); "" for the
        whole file."""
        first = self._first()
        return first.path if first else ""

    @property
    def message(self) -> str:
        """What is wrong, for the first problem."""
        first = self._first()
        return first.message if first else ""
