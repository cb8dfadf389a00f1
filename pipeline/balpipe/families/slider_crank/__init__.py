"""The slider-crank family: the template and the counterweight recipe (with eq. 20's inertia for
a Scott-Russell mechanism)."""

from ...plugins import Family, Method, Template
from . import counterweights, template

FAMILY = Family(
    name="slider_crank",
    order=0,
    package=__name__,
    templates=(
        Template("slider_crank", template.SliderCrankMechanism, template.build, "slider-crank",
                 notation=template.NOTATION),
    ),
    methods=(
        Method("slider_crank_counterweights", counterweights.SliderCrankCounterweights, counterweights.balance,
               ("slider_crank",), "counterweights (+ eq. 20 inertia for Scott-Russell)",
               notation=counterweights.NOTATION),
    ),
)
