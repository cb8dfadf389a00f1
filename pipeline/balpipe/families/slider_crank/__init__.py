"""The slider-crank family: the template and the counterweight recipe (with eq. 20's inertia for
a Scott-Russell mechanism)."""

from ...plugins import Family, Method, Ref, Template, packaged_examples
from . import specs, template

FAMILY = Family(
    name="slider_crank",
    order=0,
    package=__name__,
    examples=packaged_examples(__file__),
    templates=(
        Template("slider_crank", template.SliderCrankMechanism, template.build, "slider-crank",
                 notation=template.NOTATION),
    ),
    methods=(
        Method("slider_crank_counterweights", specs.SliderCrankCounterweights, Ref(f"{__name__}.counterweights:balance"),
               ("slider_crank",), "counterweights (+ eq. 20 inertia for Scott-Russell)",
               notation=Ref(f"{__name__}.counterweights:NOTATION")),
    ),
)
