"""The 3-RPR family: the parallel manipulator, its idler-loop and Scott-Russell balancings."""

from ...plugins import Family, Method, Paper, Ref, Template, packaged_examples

FAMILY = Family(
    name="rpr3",
    order=4,
    package=__name__,
    examples=packaged_examples(__file__),
    # paper 000's stored text starts at its abstract, without a title block: the spec's title is cited
    papers=(Paper("000", figures=("4", "8")),),
    templates=(
        Template("rpr3", Ref(f"{__name__}.template:Rpr3Mechanism"), Ref(f"{__name__}.template:build"),
                 "3-RPR parallel manipulator", Ref(f"{__name__}.figures:figures"),
                 notation=Ref(f"{__name__}.template:NOTATION")),
    ),
    methods=(
        Method("rpr3_idler_loop", Ref(f"{__name__}.specs:Rpr3IdlerLoop"), Ref(f"{__name__}.idler_loop:balance"), ("rpr3",),
               "idler loop E-F-P, counterweights (eqs. 5a-d), chained counter-rotations (eqs. 9a-d)",
               notation=Ref(f"{__name__}.idler_loop:NOTATION"), figures=Ref(f"{__name__}.figures:idler_loop_figures")),
        Method("rpr3_scott_russell", Ref(f"{__name__}.specs:Rpr3ScottRussell"), Ref(f"{__name__}.scott_russell:balance"), ("rpr3",),
               "Scott-Russell legs, counterweights (eqs. 30a-d), eq. 30e, one counter-rotation per leg (eq. 30f)",
               notation=Ref(f"{__name__}.scott_russell:NOTATION"),
               figures=Ref(f"{__name__}.figures:scott_russell_figures")),
    ),
)
