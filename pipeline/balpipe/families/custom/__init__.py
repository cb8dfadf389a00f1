"""The custom family: a mechanism written body by body and joint by joint (the generic methods
balance it)."""

from ...plugins import Family, Template, packaged_examples
from . import template

FAMILY = Family(
    name="custom",
    order=1,
    package=__name__,
    examples=packaged_examples(__file__),
    templates=(
        Template("custom", template.CustomMechanism, template.build, "custom mechanism", notation=template.notation),
    ),
)
