"""Mechanism families shipped with balpipe, one package each (see :mod:`balpipe.plugins`)."""
