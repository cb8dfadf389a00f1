"""Independent check of a stage's shaking loads with a pymunk simulation of the jointed mechanism.

One module per job:

* :mod:`.space`: building the simulation (a :class:`~balpipe.model.Model` translated into a
  pymunk space: bodies, joints, gears, drivers);
* :mod:`.settings`: numerical settings, the time step and the corners of the motion laws;
* :mod:`.extend`: the motion before t0 and after T (laws continued; a run-in for a
  motion that is moving at t0, from the cycle's own state for a periodic one);
* :mod:`.run`: running it along the analysed motion and recording the loads on the frame;
* :mod:`.loads`: measuring a stage's loads against the analysis, the verdict (``validate``);
* :mod:`.floating`: the reactionless demonstration on a free-floating frame;
* :mod:`.torque`: the torque-driven run, which checks the inverse dynamics (the actuators apply
  the engine's efforts; pymunk integrates the motion).
* :mod:`.verdict`: the pass/fail verdict the results share.

Public API
    ``validate(model, analysis, unbalanced_peaks, settings=None, expect=()) -> StageValidation``
    ``free_floating(model, analysis, base_mass=10.0, base_inertia=None, settings=None,
    simulate_pymunk=True) -> FreeFloating``
    ``torque_driven(model, analysis, ...) -> TorqueDriven``
    ``ValidationSettings``, ``default_settings(model, analysis)``, and, lower down,
    ``simulate(model, analysis, dt, iterations, ...) -> SimulationRun`` and
    :func:`balpipe.validate.space.build_space` (the translation of a model into pymunk).
"""

from importlib import import_module

# the public names, loaded on first use: importing balpipe.validate.settings (the step size, for
# the pre-run limits of ``balpipe check``) does not load pymunk
_WHERE = {
    "FreeFloating": ".floating", "free_floating": ".floating",
    "StageValidation": ".loads", "validate": ".loads",
    "SimulationRun": ".run", "simulate": ".run",
    "ValidationSettings": ".settings", "default_settings": ".settings",
    "TorqueDriven": ".torque", "torque_driven": ".torque",
}


def __getattr__(name: str):
    if name not in _WHERE:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(import_module(_WHERE[name], __name__), name)
    globals()[name] = value
    return value


__all__ = [
    "ValidationSettings",
    "StageValidation",
    "FreeFloating",
    "SimulationRun",
    "default_settings",
    "simulate",
    "validate",
    "free_floating",
    "TorqueDriven",
    "torque_driven",
]
