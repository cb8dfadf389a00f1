"""The verdict that the validation results share (:class:`.loads.StageValidation`,
:class:`.torque.TorqueDriven`): the status word and the head of their JSON summaries.

Three outcomes, and only one of them is a failure:

* ``pass``: the simulation agrees with the analysis within the tolerance, at an error it resolved;
* ``fail``: a claim shown false: the simulation contradicts the analysis beyond its own resolved
  error (a claimed cancellation that does not hold, loads or a motion off the analysis by more
  than the error the run resolves), or it does not follow the plan with an error that does not
  shrink with the step (the design's, not the integrator's);
* ``unconfirmed``: the run could not resolve its own error within the validator's budget (finer
  steps, more solver iterations): nothing is shown false, and ``remedy`` names the setting that
  would resolve it. A build exits 0 on it unless ``--strict``.
"""

from __future__ import annotations


class Verdict:
    """Mixin for a validation result dataclass with fields ``passed``, ``reasons``,
    ``unconfirmed`` and ``remedy``."""

    passed: bool
    reasons: list[str]
    unconfirmed: bool
    remedy: str

    @property
    def status(self) -> str:
        if self.passed:
            return "pass"
        return "unconfirmed" if self.unconfirmed else "fail"

    def verdict_json(self) -> dict:
        """``passed``, ``status``, ``reasons`` (joined by "; ") and ``remedy``, the first keys of ``to_json``."""
        return {"passed": bool(self.passed), "status": self.status, "reasons": "; ".join(self.reasons),
                "remedy": self.remedy}
