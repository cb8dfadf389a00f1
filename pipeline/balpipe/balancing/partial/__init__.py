"""Partial balancing (``method: partial_balance``): the least peak or RMS shaking load for a mass
budget, as a cone programme on active samples; its spec section, maps, Pareto fronts and
motions. The method itself is in :mod:`balpipe.balancing.partial.method`."""
