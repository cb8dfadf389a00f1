"""The pass/fail verdict that the validation results share (:class:`.loads.StageValidation`,
:class:`.torque.TorqueDriven`): the status word and the head of their JSON summaries."""

from __future__ import annotations


class Verdict:
    """Mixin for a validation result dataclass with fields ``passed`` and ``reasons``."""

    passed: bool
    reasons: list[str]

    @property
    def status(self) -> str:
        return "pass" if self.passed else "fail"

    def verdict_json(self) -> dict:
        """``passed``, ``status`` and ``reasons`` (joined by "; "), the first keys of ``to_json``."""
        return {"passed": bool(self.passed), "status": self.status, "reasons": "; ".join(self.reasons)}
