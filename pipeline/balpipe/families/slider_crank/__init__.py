"""The slider-crank family: the template and the counterweight recipe (with eq. 20's inertia for
a Scott-Russell mechanism)."""

from ...plugins import Family, Method, Ref, Template, packaged_examples

FAMILY = Family(
    name="slider_crank",
    order=0,
    package=__name__,
    examples=packaged_examples(__file__),
    templates=(
        Template("slider_crank", Ref(f"{__name__}.template:SliderCrankMechanism"), Ref(f"{__name__}.template:build"),
                 "slider-crank", notation=Ref(f"{__name__}.template:NOTATION")),
    ),
    methods=(
        Method("slider_crank_counterweights", Ref(f"{__name__}.specs:SliderCrankCounterweights"), Ref(f"{__name__}.counterweights:balance"),
               ("slider_crank",), "counterweights (+ eq. 20 inertia for Scott-Russell)",
               notation=Ref(f"{__name__}.counterweights:NOTATION")),
    ),
)
