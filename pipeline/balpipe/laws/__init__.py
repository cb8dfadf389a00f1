"""Motion laws for real machines (constant speed, cams, cycles of segments, tables, paths),
beside the point-to-point laws of :mod:`balpipe.motion`. Every law is a :class:`balpipe.model.Law`: a function of time returning
q, q', q'' with exact derivatives, vectorised over t.

* :mod:`.periodic`: constant speed (steady state, or from rest on a ramp), cam laws (cycloidal,
  harmonic, 3-4-5 rise / dwell / return / dwell) and Fourier series; every cycle's end state is
  the next cycle's start state;
* :mod:`.cycle`: a cycle of segments (pick, move, dwell, return), each with its own law and
  duration, states matched at the joins;
* :mod:`.table`: a tabulated law read from a CSV file, through a cubic or smoothing spline whose
  derivatives are the spline's own (consistent);
* :mod:`.paths`: curves parametrised by arc length (line, circle, arc, polyline with rounded
  corners) composed with a timing law on the length, for a point or a pose;
* :mod:`.drives`: the spec's drive sections for these laws and the function that builds them.
"""
