"""balpipe: declarative dynamic balancing of planar mechanisms."""

__version__ = "0.1.0"
