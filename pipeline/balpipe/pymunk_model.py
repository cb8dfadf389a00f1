"""Compatibility name: the translation of a model into pymunk now lives in
:mod:`balpipe.validate.space`."""

from .validate.space import SimModel, assembled_state, build_space

__all__ = ["SimModel", "build_space", "assembled_state"]
