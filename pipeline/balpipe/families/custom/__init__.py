"""The custom family: a mechanism written body by body and joint by joint (the generic methods
balance it)."""

from ...plugins import Family, Ref, Template, packaged_examples

FAMILY = Family(
    name="custom",
    order=1,
    package=__name__,
    examples=packaged_examples(__file__),
    templates=(
        Template("custom", Ref(f"{__name__}.template:CustomMechanism"), Ref(f"{__name__}.template:build"),
                 "custom mechanism", notation=Ref(f"{__name__}.template:notation")),
    ),
)
