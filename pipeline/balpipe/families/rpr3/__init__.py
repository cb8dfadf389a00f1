"""The 3-RPR family: the parallel manipulator, its idler-loop and Scott-Russell balancings."""

from ...plugins import Family, Method, Template
from . import figures, idler_loop, scott_russell, template

FAMILY = Family(
    name="rpr3",
    order=4,
    package=__name__,
    templates=(
        Template("rpr3", template.Rpr3Mechanism, template.build, "3-RPR parallel manipulator", figures.figures,
                 notation=template.NOTATION),
    ),
    methods=(
        Method("rpr3_idler_loop", idler_loop.Rpr3IdlerLoop, idler_loop.balance, ("rpr3",),
               "idler loop E-F-P, counterweights (eqs. 5a-d), chained counter-rotations (eqs. 9a-d)",
               notation=idler_loop.NOTATION, figures=figures.paper_figures("Fig. 4", "idler_loop", 17)),
        Method("rpr3_scott_russell", scott_russell.Rpr3ScottRussell, scott_russell.balance, ("rpr3",),
               "Scott-Russell legs, counterweights (eqs. 30a-d), eq. 30e, one counter-rotation per leg (eq. 30f)",
               notation=scott_russell.NOTATION, figures=figures.paper_figures("Fig. 8", "scott_russell", 28)),
    ),
)
