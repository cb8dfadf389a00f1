"""Planar mechanics below the engine: the planar vocabulary (cross, rotate, wrap_angle, world_point,
the bar body; :mod:`.planar`), gear meshes, pose-driven joint laws, whether a stage can be
built, time grids and gravity, drivers' effort units, the time series' positions, the precision a
claim is judged at. Imports only the core vocabulary (units, model, motion)."""
